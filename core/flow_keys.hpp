// bbm core: the keys of the [flow] table — water in the joints (core/joint_flow.hpp)
// — one declaration each (base/keys.hpp). The model file's reader checks [flow] by
// them (io/read_flow.cpp) and docs/reference/flow.md is generated from them
// (tests/test_reference.cpp), so the reference cannot drift from the reader.
#pragma once

#include "base/keys.hpp"
#include "core/joint_flow.hpp"

#include <string>

namespace bbm {

using FlowKey = Key<FlowSpec>;
using FlowBoundaryKey = Key<FlowBoundarySpec>;
using FlowSourceKey = Key<FlowSourceSpec>;

// Each row names only the members it sets; the rest keep their defaults.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [flow], in the order the reference lists them. Number, integer
/// and boolean keys are read from their row alone; the others (a point, names, a
/// choice) and the checks between keys are read by io/read_flow.cpp.
inline constexpr FlowKey flow_keys[] = {
    {.key = "regions", .kind = KeyKind::names,
     .meaning = "The regions whose joints carry water: a joint between two of their blocks is a pipe",
     .absent = "every region with a block pattern"},
    {.key = "aperture", .bounds = above(0, " m"),
     .meaning = "a0: the hydraulic aperture of a broken or unbonded joint at zero normal stress; a = a0 + un (un: "
                "its normal opening, negative when pressed), bounded to [residual_aperture, max_aperture]; at most "
                "max_aperture",
     .absent = "1e-4", BBM_KEY_FIELD(FlowSpec, aperture)},
    {.key = "bond_aperture", .bounds = at_least(0, " m"),
     .meaning = "An intact bond's hydraulic aperture: the intact rock's permeability; 0 seals intact bonds",
     .absent = "0", BBM_KEY_FIELD(FlowSpec, bond_aperture)},
    {.key = "residual_aperture", .bounds = at_least(0, " m"), .meaning = "The smallest aperture of a joint pressed shut",
     .absent = "0", BBM_KEY_FIELD(FlowSpec, fluid.residual_aperture)},
    {.key = "max_aperture", .bounds = above(0, " m"),
     .meaning = "The largest aperture, also that of a joint whose blocks have moved apart; more than "
                "residual_aperture",
     .absent = "0.01", BBM_KEY_FIELD(FlowSpec, fluid.max_aperture)},
    {.key = "viscosity", .bounds = above(0, " Pa·s"), .meaning = "The fluid's dynamic viscosity μ", .absent = "1e-3",
     BBM_KEY_FIELD(FlowSpec, fluid.viscosity)},
    {.key = "bulk_modulus", .bounds = above(0, " Pa"), .meaning = "The fluid's bulk modulus K_w (storage in transient flow)",
     .absent = "2e9", BBM_KEY_FIELD(FlowSpec, fluid.bulk_modulus)},
    {.key = "density", .bounds = at_least(0, " kg/m³"), .meaning = "The fluid's density ρ_w", .absent = "1000",
     BBM_KEY_FIELD(FlowSpec, fluid.density)},
    {.key = "gravity", .kind = KeyKind::point, .bounds = unbounded(" m/s²"),
     .meaning = "The fluid's gravity, if not the solver's", .absent = "[solver] gravity"},
    {.key = "water_table", .bounds = unbounded(" m"),
     .meaning = "y of the free surface: hydrostatic pressure ρ_w g (water_table − y) below it, atmospheric above; "
                "needs gravity; not with pressure",
     .absent = "none", .set = [](FlowSpec& s, double v) { s.water_table = v; }},
    {.key = "pressure", .bounds = at_least(0, " Pa"),
     .meaning = "A uniform initial pressure instead of a water table", .absent = "0", BBM_KEY_FIELD(FlowSpec, pressure)},
    {.key = "mode", .kind = KeyKind::choice,
     .meaning = "steady: the drained pressure field, one sparse solve every steady_every steps and after each "
                "excavation; transient: explicit flow in real time, sub-stepped under its own stable step (needs "
                "[solver] mode = \"dynamic\")",
     .absent = "steady", .words = "steady, transient"},
    {.key = "steady_every", .kind = KeyKind::integer, .bounds = between(1, 1e9, " steps"),
     .meaning = "Steps between steady solves", .absent = "100", BBM_KEY_FIELD(FlowSpec, steady_every)},
    {.key = "far_field", .kind = KeyKind::choice,
     .meaning = "The junctions on the interface with the dry regions: held at their initial pressure, or no flow "
                "across it",
     .absent = "held", .words = "held, sealed"},
    {.key = "drain_openings", .kind = KeyKind::boolean,
     .meaning = "An excavated opening's wall at atmospheric pressure (its inflow is the inflow history and "
                "summary.json's flow.inflow)",
     .absent = "true", BBM_KEY_FIELD(FlowSpec, drain_openings)},
};

/// Every key of [[flow_boundary]]: the junctions of the network inside a box held at
/// a pressure or a hydraulic head.
inline constexpr FlowBoundaryKey flow_boundary_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true, .meaning = "Non-empty, unique"},
    {.key = "box", .kind = KeyKind::table, .bounds = unbounded(" m"), .required = true,
     .meaning = "{ min = [x, y], max = [x, y] }: the junctions inside it are held; a box that holds none is an error"},
    {.key = "pressure", .bounds = at_least(0, " Pa"), .meaning = "The pressure held; or head"},
    {.key = "head", .bounds = unbounded(" m"), .meaning = "The hydraulic head held, p = ρ_w |g| (head − y) (needs gravity); or pressure"},
};

/// Every key of [[flow_source]]: a rate injected at the junction nearest a point.
inline constexpr FlowSourceKey flow_source_keys[] = {
    {.key = "at", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true,
     .meaning = "The point: the junction nearest it gets the rate"},
    {.key = "rate", .bounds = unbounded(" m²/s per m"), .required = true,
     .meaning = "Injected (negative: extracted), per metre of depth; where no pressure is held it has no steady state"},
};
#pragma GCC diagnostic pop

/// docs/reference/flow.md: the table of keys.
inline std::string flow_keys_markdown() {
    std::string md = "# [flow] keys\n\n"
                     "Generated from core/flow_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` "
                     "rewrites it; the test fails when it is stale). Water in the joints: the equations in "
                     "[theory.md](../theory.md) §16, [[flow_boundary]] and [[flow_source]] in "
                     "[input.md](../input.md), \"Water in the joints\".\n\n";
    return md + key_table_markdown(flow_keys) + "\n## [[flow_boundary]]\n\n" + key_table_markdown(flow_boundary_keys) +
           "\n## [[flow_source]]\n\n" + key_table_markdown(flow_source_keys);
}

} // namespace bbm
