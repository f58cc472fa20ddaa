// bbm core: one explicit step (SPEC §5) as a table of stages over the world.
//
// Central differences (Cundall): each step places the bodies, updates the
// contacts, computes the forces of contacts and zones, gathers them per body with
// the loads, and integrates. The table below is that list, once: run_step() walks
// it, `bbm run --profile` times its rows, evaluate_forces() (the implicit stage,
// a kinematic move) runs the rows marked `force`, and docs/architecture.md lists
// them. Each row is a free function over (World&, a small StepContext, the
// thread's Range of the items it is over); a new stage is one row.
//
// Threads: a step is one OpenMP parallel region; a team row is called by every
// thread with its own range (contiguous runs of about equal estimated cost:
// contact::team_share), a serial row by one (the others wait at its end, or go on
// when it is marked so). Every sum — a block's force over its contacts, a node's
// over its zones and contacts, the work of the loads, the force scale — runs in
// an order fixed by the numbering of contacts, zones and bodies, never by the
// partition of the work: a model gives the same bits on 1 or 64 threads
// (tests/recorded_states.json, bbm_determinism_tests). Nothing is allocated
// inside a step once the scratch arrays have their sizes.
//
// Time step and masses: for one degree of freedom of mass m on springs of total
// stiffness K, central differences are stable for Δt < 2√(m/K). K of a block sums
// (kn + ks)·L over its contacts (translation) and the same times the squared
// lever arm (rotation). Dynamic mode: real masses, Δt = safety × the smallest
// limit. Quasi-static mode: Δt = 1 (or as given) and each block's mass and inertia
// are set to K (Δt / (2 safety))², so every block converges at the same rate;
// gravity still acts on the real mass. Local non-viscous damping (Cundall):
// each force component is reduced by α|F| against the velocity.
//
// Deformable blocks (SPEC §6): a block of a meshed region keeps its entry in the
// block arrays (region, removal, polygon) but moves through its FE nodes: its
// polygon vertices are its boundary nodes, so contacts treat it like any block
// (contacts.hpp interpolates velocities and splits forces along its edges). Nodes
// are damped, scaled and integrated like blocks (two degrees of freedom each). A
// node's stiffness for mass scaling and the stable step is the Gershgorin row sum
// of its zone stiffness (halved, to match the diagonal estimate used for blocks)
// plus its share of contact stiffness.
#pragma once

#include "core/world.hpp"

#include <array>
#include <cstddef>
#include <exception>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bbm {

/// A thread's share of a stage's items: [first, last).
struct Range {
    int first = 0, last = 0;
};

/// What a stage knows of the step besides the world: which thread of how large a
/// team runs it. (A serial row's exception is kept by run_step and thrown again
/// once the parallel region is over: one may not leave it.)
struct StepContext {
    int thread = 0, team = 1;
};

/// How a row's work is shared.
enum class Share : std::uint8_t {
    team,              ///< every thread, its own Range (row.range); the stage's own barriers
    one_thread,        ///< one thread; the others wait at its end
    one_thread_nowait, ///< one thread; the others go on to the next row
};

struct Stage {
    std::string_view name;
    std::string_view spec; ///< its item of SPEC §5's list
    std::string_view does; ///< what it does, for docs/architecture.md's list
    void (*run)(World&, const StepContext&, Range);
    Share share = Share::team;
    /// The thread's share (team rows); null: the whole of nothing ({0, 0}).
    Range (*range)(const World&, const StepContext&) = nullptr;
    /// The team meets at a barrier after it.
    bool barrier = false;
    /// Part of a force evaluation (evaluate_forces): the forces at the current state.
    bool force = false;
    /// Whether the model has anything for it to do (null: always); read by every
    /// thread before the row, of state no stage of the step changes.
    bool (*active)(const World&) = nullptr;
};

/// The stages of a step, in order (core/step.cpp): a new stage is one row there.
extern const std::span<const Stage> step_stages;

/// docs/architecture.md's list of the stages: a Markdown table of the rows
/// (tests/test_reference.cpp fails when the page's copy is stale).
std::string step_stages_markdown();

/// Wall time per row of the table (`bbm run --profile`): measured on the team's
/// first thread between rows, so a row's time includes its wait at the barrier
/// that ends it (the slowest thread's share). Off: one branch a row.
struct StepProfile {
    bool enabled = false;
    long steps = 0;
    std::vector<double> seconds = std::vector<double>(step_stages.size(), 0.0);
    double last = 0.0;
};

/// One step: the table's rows in order, on the world's thread count
/// (settings.threads). Throws what a serial stage threw.
void run_step(World& w, StepProfile* profile = nullptr);

/// The forces at the current state, the table's `force` rows on one thread
/// (no detection, no integration): the implicit stage's residual, a kinematic move.
void evaluate_forces(World& w);

/// Boundary reactions (measures' boundary_force) from the forces of the last evaluation.
void sum_boundary_forces(World& w);

/// World vertices of every body from its position (the first row, on one thread).
void place_bodies(World& w);

/// Recomputes the time step and (quasi-static) masses from the current contacts.
void update_timestep(World& w);

/// The contacts' index after contacts were added, removed or renumbered: batches,
/// per-block and per-node lists, the team's cost prefixes, the faces of face_shear.
void reindex_contacts(World& w);

} // namespace bbm
