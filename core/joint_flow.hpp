// bbm core: water in the joints, coupled to the blocks (docs/theory.md §16.4).
//
// The network of core/flow.hpp over the joints of the "flow regions" (by default
// every region with a block pattern; the elastic far field is dry), tied to the
// solver's contacts and stepped as one stage of the step:
//
//   aperture   each point contact of a pipe's joint gives a = a0 + un, bounded to
//              [a_res, a_max] (un: its normal opening, SPEC §4), or the bond's own
//              aperture while it is intact (0: sealed); a pipe takes the mean of
//              its contacts'. A pipe with a removed block is closed.
//   pressure   steady (drained: one sparse solve every `steady_every` steps, and
//              after an excavation) or transient (explicit sub-steps under the
//              flow's stable step, dynamic mode only).
//   coupling   the joint laws act on the effective stress σn' = σn − p: a
//              contact's law force is the skeleton's, and the fluid adds p over the
//              contact's share of its pipes' lengths along the normal (pushing the
//              blocks apart). p is the pressure of the domain at the contact's
//              vertex — a joint's two end contacts take its two ends' pressures.
//   boundaries the far-field interface held at the undisturbed pressure (or
//              sealed), an opening's wall drained to atmospheric when excavated,
//              [[flow_boundary]] boxes held at a pressure or a head, rates at points.
//
// Arrays: per contact, Contacts::flow_link {domain, pipe, pipe} (empty in a dry
// model, moved with its contact) and Contacts::fluid_pressure (written by the
// stage before the contact pass); per domain the pressure, held and drained flags
// (saved and hashed: visit_fields).
#pragma once

#include "contact/contacts.hpp"
#include "core/flow.hpp"
#include "base/fields.hpp"
#include "meshing/blocks.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bbm {

/// [[flow_boundary]]: the domains in a box held at a pressure or a hydraulic head.
struct FlowBoundarySpec {
    std::string name;
    Box2 box;
    std::optional<double> pressure; ///< Pa
    std::optional<double> head;     ///< m: p = ρ_w |g| (head − y)
};

/// [[flow_source]]: a rate injected (negative: extracted) at the domain nearest a point.
struct FlowSourceSpec {
    Vec2 at{};
    double rate = 0.0; ///< m²/s per unit depth
};

/// [flow]: the fluid, the joints' apertures, the initial pressure and the boundaries.
struct FlowSpec {
    bool on = false;
    flow::FluidSpec fluid;        ///< gravity: the solver's unless `gravity_given`
    bool gravity_given = false;
    double aperture = 1.0e-4;     ///< a0: hydraulic aperture of a broken or unbonded joint at zero normal stress, m
    double bond_aperture = 0.0;   ///< an intact bond's; 0 = sealed
    std::vector<std::string> regions; ///< empty = every region with a block pattern
    std::optional<double> water_table; ///< y of the free surface: hydrostatic below it
    double pressure = 0.0;             ///< uniform initial pressure when no water table, Pa
    enum class Mode { steady, transient };
    Mode mode = Mode::steady;
    int steady_every = 100;            ///< steps between steady solves
    bool far_field_held = true;        ///< the interface with dry regions held at the initial pressure
    bool drain_openings = true;        ///< an excavated opening's wall at atmospheric pressure
    std::vector<FlowBoundarySpec> boundaries;
    std::vector<FlowSourceSpec> sources;
};

/// The water in the joints: the network, its state, and its ties to the blocks
/// (plain data; the functions below build and step it).
struct JointFlow {
    FlowSpec spec;
    flow::FluidSpec fluid; ///< gravity: the solver's unless the spec gives its own
    flow::Network net;
    flow::State state{flow::Network{}};
    std::vector<int> joint_pipe;         ///< per joint: its pipe, −1 if none
    std::vector<int> pipe_block_a, pipe_block_b; ///< per pipe, the two blocks of its joint
    std::vector<std::uint8_t> pipe_open; ///< 0: a block of it removed
    /// per domain: 0, or the number (from 1) of the excavation whose opening's
    /// wall it is on (a later one keeps the earlier's number)
    std::vector<std::uint8_t> drained;
    std::vector<double> aperture_sum;    ///< update_apertures' scratch, per pipe
    std::vector<int> aperture_count;
    std::uint8_t pending_solve = 1;      ///< a steady solve due at the next stage
    int solves = 0;                      ///< steady solves so far
};

/// Its fields (base/fields.hpp): the pressures and what holds them evolve.
template <part_of<JointFlow> F, class Visit>
void visit_fields(F& f, Visit&& v) {
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"flow.pressure", MemoryGroup::other, E}, f.state.pressure);
    v(FieldInfo{"flow.held", MemoryGroup::other, E}, f.state.held);
    v(FieldInfo{"flow.drained", MemoryGroup::other, E}, f.drained);
    v(FieldInfo{"flow.pipe_open", MemoryGroup::other, E}, f.pipe_open);
    v(FieldInfo{"flow.time", MemoryGroup::other, E}, f.state.time);
    v(FieldInfo{"flow.pending_solve", MemoryGroup::other, E}, f.pending_solve);
    v(FieldInfo{"flow.aperture", MemoryGroup::other, R}, f.state.aperture);
    v(FieldInfo{"flow.source", MemoryGroup::other, R}, f.state.source);
}

/// The network of the flow regions' joints, initial pressures and held domains.
/// Throws InputError (key "flow") for a water table or head without gravity, a
/// flow region that does not exist, a network with no joint, or a source farther
/// from every junction than the longest joint of the network.
JointFlow make_joint_flow(const meshing::BlockAssembly& a, const FlowSpec& spec, Vec2 solver_gravity);

/// Ties contact `contact` (at end p0 or p1 of joint `joint`) to its domain and
/// pipe; call for both ends of every joint as its contacts are made.
void link_contact(const JointFlow& f, contact::Contacts& c, int contact, int joint, bool at_p0);

/// The stage: apertures from the contacts, pressures (steady or transient over
/// `dt`), then each contact's fluid pressure. Serial.
void advance_flow(JointFlow& f, contact::Contacts& c, double dt, long step);
/// Only the contacts' fluid pressures from the current domain pressures.
void write_contact_pressures(const JointFlow& f, contact::Contacts& c);
/// After an excavation: pipes of removed blocks close; their walls' domains
/// (ends of a pipe with one removed block) are held at the opening's water
/// pressure, `wall_pressure` (0: drained to atmospheric; a pressurised borehole:
/// the excavate stage's `pressure`), if `drain_openings`.
void flow_excavated(JointFlow& f, const std::vector<std::uint8_t>& removed, double wall_pressure = 0.0);
/// The latest opening's water pressure changed (a `pressurise` stage): its
/// wall's domains are held at `wall_pressure`; `solve_now` asks for a steady
/// solve at the next stage (a jump), else the usual cadence follows a ramp.
void set_flow_opening_pressure(JointFlow& f, double wall_pressure, bool solve_now);

/// Net flow into the drained walls of openings, m²/s per unit depth (positive: out of the rock).
double inflow(const JointFlow& f);
/// Per contact: its pipes' mean hydraulic aperture (m; 0 where it has none).
std::vector<double> contact_apertures(const JointFlow& f, const contact::Contacts& c);

} // namespace bbm
