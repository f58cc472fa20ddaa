// bbm core: the keys of the [solver] table — time stepping, damping, gravity,
// contact detection and output intervals — one declaration each (base/keys.hpp).
// The model file's reader checks [solver] by them (io/model_input.cpp) and
// docs/reference/solver.md is generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using SolverKey = Key<SolverSpec>;

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [solver], in the order the reference lists them. Number and
/// integer keys are read from their row; the others by io/model_input.cpp.
inline constexpr SolverKey solver_keys[] = {
    {.key = "mode", .kind = KeyKind::choice,
     .meaning = "quasi_static: masses scaled so that every block converges at the same rate; dynamic: real masses "
                "(SPEC §5)",
     .absent = "quasi_static", .words = "quasi_static, dynamic"},
    {.key = "damping", .bounds = below(0, 1, ""), .meaning = "Local non-viscous damping coefficient (Cundall's: a quasi-static device, which also takes energy "
                "out of a wave)",
     .absent = "0.8; in the dynamic mode 0 (waves are not damped away unless asked)",
     BBM_KEY_FIELD(SolverSpec, damping)},
    {.key = "rayleigh_ratio", .bounds = below(0, 1, ""),
     .meaning = "Rayleigh damping's critical ratio ξ at rayleigh_frequency (dynamic mode; with it): C = α M + β K, "
                "α = ξ ω, β = ξ / ω, ω = 2π f — the ratio is ξ at f and larger on either side; the stable step is "
                "reduced as the stiffness part requires",
     .absent = "0: none", BBM_KEY_FIELD(SolverSpec, rayleigh_ratio)},
    {.key = "rayleigh_frequency", .bounds = above(0, " Hz"),
     .meaning = "Rayleigh damping's centre frequency (with rayleigh_ratio), e.g. the model's fundamental or the "
                "input's dominant frequency",
     .absent = "none", BBM_KEY_FIELD(SolverSpec, rayleigh_frequency)},
    {.key = "energy_account", .kind = KeyKind::boolean,
     .meaning = "Keep the energy account's damping work and kinetic energy every step (summary.json energy_balance, "
                "history damping_energy and energy_error; docs/theory.md §19.1)",
     .absent = "true in the dynamic mode or with a damping_energy or energy_error history; false otherwise",
     BBM_KEY_FIELD(SolverSpec, energy_account)},
    {.key = "safety", .bounds = {.lo = 0, .hi = 1, .lo_open = true}, .meaning = "Time step over the critical time step",
     .absent = "0.5", BBM_KEY_FIELD(SolverSpec, safety)},
    {.key = "timestep", .bounds = at_least(0, " s"),
     .meaning = "0 = automatic (dynamic) or 1 s (quasi-static, masses scaled to it)", .absent = "0",
     BBM_KEY_FIELD(SolverSpec, timestep)},
    {.key = "gravity", .kind = KeyKind::point, .bounds = unbounded(" m/s²"),
     .meaning = "Gravitational acceleration, e.g. [0.0, -9.81]", .absent = "[0, 0]"},
    {.key = "detection_tolerance", .bounds = at_least(0, " m"),
     .meaning = "Distance within which new contacts are formed; 0 = 0.02 × the mean size of the rigid blocks (of "
                "all blocks if none is rigid)",
     .absent = "0", BBM_KEY_FIELD(SolverSpec, detection_tolerance)},
    {.key = "corner_radius", .bounds = at_least(0, " m"),
     .meaning = "Radius of the rounded corners unbonded contacts see past the end of an edge (theory.md §3.3); 0 = "
                "0.05 × the mean joint length",
     .absent = "0", BBM_KEY_FIELD(SolverSpec, corner_radius)},
    {.key = "new_contact_property", .kind = KeyKind::text,
     .meaning = "The [[joint_property]] of contacts formed during the run; \"\" = a built-in frictional contact",
     .absent = "\"\""},
    {.key = "new_contact_length", .kind = KeyKind::choice,
     .meaning = "Length of a contact formed during the run: edge, half of the vertex's adjacent edge that lies most "
                "along the other block's edge; overlap, half of that edge's overlap with the other block's edge, at "
                "least the corner radius (a face shared by its two end contacts, as UDEC does)",
     .absent = "edge", .words = "edge, overlap"},
    {.key = "new_contact_overlap", .kind = KeyKind::choice,
     .meaning = "A contact formed already overlapped (its vertex passed into the other block between detection "
                "passes): push, the overlap loads it at once (energy no work paid for); rest, the overlap is its rest "
                "position and only further approach loads it (the energy account closes; docs/theory.md §19.4)",
     .absent = "rest in the dynamic mode, push in the quasi-static", .words = "push, rest"},
    {.key = "output_every", .kind = KeyKind::integer, .bounds = between(0, 2147483647, " steps"),
     .meaning = "Steps between VTK outputs; 0 = at the start and at the end of each stage only", .absent = "0",
     BBM_KEY_FIELD(SolverSpec, output_every)},
    {.key = "history_every", .kind = KeyKind::integer, .bounds = between(1, 2147483647, " steps"),
     .meaning = "Steps between history rows", .absent = "10", BBM_KEY_FIELD(SolverSpec, history_every)},
};
#pragma GCC diagnostic pop

/// docs/reference/solver.md: the table of keys.
inline std::string solver_keys_markdown() {
    return "# [solver] keys\n\n"
           "Generated from core/solver_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). The stepping scheme and its damping: [theory.md](../theory.md); where the "
           "table goes in a model file: [input.md](../input.md).\n\n" +
           key_table_markdown(solver_keys);
}

} // namespace bbm
