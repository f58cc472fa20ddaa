// bbm core: the keys of a [[stage]] table — the steps of an analysis — one
// declaration each (base/keys.hpp), with the stage types each belongs to. The
// model file's reader checks a stage by them, the keys of its type only
// (io/read_stages.cpp), and docs/reference/stage.md is generated from them
// (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using StageKey = Key<StageSpec>;

/// The stage types, in the order of StageSpec::Kind.
inline constexpr std::string_view stage_type_words = "initialize, solve, excavate, cycle, elastic, install, pressurise, creep";

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[stage]], in the order the reference lists them. The values are
/// read by io/read_stages.cpp with these bounds; which keys a stage may have is
/// its type's rows.
inline constexpr StageKey stage_keys[] = {
    {.key = "name", .kind = KeyKind::text, .meaning = "Non-empty, unique; used in outputs", .absent = "\"stage N\""},
    {.key = "type", .kind = KeyKind::choice, .required = true,
     .meaning = "What the stage does; each type takes only its own keys (a key of another type is an error)",
     .words = stage_type_words},
    {.key = "sxx", .bounds = unbounded(" Pa"), .only = "initialize",
     .meaning = "The in-situ stress field, as for a stress boundary (σ = σ0 + dσ/dy (y − y_ref)): joints and zones "
                "start from it, in equilibrium (SPEC §5)",
     .absent = "0"},
    {.key = "syy", .bounds = unbounded(" Pa"), .only = "initialize", .meaning = "σyy at y_ref", .absent = "0"},
    {.key = "sxy", .bounds = unbounded(" Pa"), .only = "initialize", .meaning = "σxy at y_ref", .absent = "0"},
    {.key = "y_ref", .bounds = unbounded(" m"), .only = "initialize", .meaning = "The level the stresses are given at",
     .absent = "0"},
    {.key = "dsxx_dy", .bounds = unbounded(" Pa/m"), .only = "initialize", .meaning = "dσxx/dy", .absent = "0"},
    {.key = "dsyy_dy", .bounds = unbounded(" Pa/m"), .only = "initialize", .meaning = "dσyy/dy", .absent = "0"},
    {.key = "dsxy_dy", .bounds = unbounded(" Pa/m"), .only = "initialize", .meaning = "dσxy/dy", .absent = "0"},
    {.key = "ratio", .bounds = {.lo = 0, .hi = 1, .lo_open = true, .hi_open = true}, .only = "solve, creep",
     .meaning = "Run until the unbalanced-force ratio falls below it, or max_steps (creep: the equilibrium each "
                "creep step is taken at)",
     .absent = "1e-5"},
    {.key = "max_steps", .kind = KeyKind::integer, .bounds = at_least(1, " steps"), .only = "solve, creep",
     .meaning = "The stage's step limit (creep: of mechanical steps, over all its creep steps)",
     .absent = "200000 (creep: 10000000)"},
    {.key = "duration", .bounds = {.lo = 0, .hi = 3.2e10, .lo_open = true, .unit = " s"}, .required = true,
     .only = "creep",
     .meaning = "The creep time the stage runs, in real seconds (3.156e7 a year; at most about 1000 years): "
                "equilibrium and creep steps of stress corrosion in turn (theory.md §17); a bond that breaks is "
                "equilibrated before the next creep step; a rock that collapses under its held load (a body moving "
                "a quarter of the detection tolerance in a step) ends the stage there, its creep time the time to "
                "failure (summary.json's creep.failed_at)"},
    {.key = "loss", .bounds = {.lo = 0, .hi = 0.5, .lo_open = true}, .only = "creep",
     .meaning = "The largest fraction of a bond's intact section one creep step takes (divided by β s where "
                "the rate is steeper): halving it checks the time steps' convergence",
     .absent = "0.02"},
    {.key = "settle_steps", .kind = KeyKind::integer, .bounds = at_least(1000, " steps"), .only = "creep",
     .meaning = "Mechanical steps after a creep step in which the model does not come back to rest mean it is "
                "failing under its held load, as a collapse does: the stage ends there, its creep time the time to "
                "failure (a pillar whose roof follows it down fails too slowly for the collapse test)",
     .absent = "200000"},
    {.key = "until", .kind = KeyKind::choice, .only = "solve",
     .meaning = "ratio: stop at the model's ratio; rest: also once the rock mass is at rest, no crack in the last "
                "quiet_steps and the ratio of the rock mass without its detached fragments at ratio (theory.md "
                "§10.3); equilibrium: only at the verdict of equilibrium, no crack over the verdict's window and the "
                "ratio at ratio (a brittle rock can reach the ratio while it still cracks)",
     .absent = "ratio", .words = "ratio, rest, equilibrium"},
    {.key = "quiet_steps", .kind = KeyKind::integer, .bounds = at_least(100, " steps"), .only = "solve",
     .meaning = "The crack-free stretch until = \"rest\" asks for", .absent = "2000"},
    {.key = "regions", .kind = KeyKind::names, .required = true, .only = "excavate",
     .meaning = "Existing region names, not empty, no repeats: their blocks are removed"},
    {.key = "relax_steps", .kind = KeyKind::integer, .bounds = at_least(0, " steps"), .only = "excavate",
     .meaning = "The removed blocks' support on the new boundary is relaxed to zero over this many steps (0 = at "
                "once)",
     .absent = "0"},
    {.key = "keep", .bounds = below(0, 1, ""), .only = "excavate",
     .meaning = "The fraction of the removed blocks' support that stays on the new boundary for good: a support "
                "pressure, (1 − λ) × the in-situ support in the convergence–confinement method; a later excavate "
                "replaces it",
     .absent = "0"},
    {.key = "support_path", .kind = KeyKind::rows, .only = "excavate",
     .meaning = "The support's path as a tunnel face goes by, instead of a linear relaxation: rows [t, k_mean, "
                "k_deviator], t from 0 to 1 (increasing) over relax_steps, the fractions of the in-situ support's "
                "mean and deviatoric parts left at t, interpolated linearly; the last row's stay for good. "
                "examples/field/face_path.py computes it from the elastic three-dimensional solution (theory.md "
                "§6.5); needs relax_steps ≥ 1, an initialize stage before it, and no keep",
     .absent = "a linear relaxation"},
    {.key = "pressure", .bounds = at_least(0, " Pa"), .only = "excavate, pressurise",
     .meaning = "excavate: a constant pressure on the new boundary, normal to it, from this stage on (a later "
                "excavate replaces it); with [flow] also the water's pressure in the opening, held at its wall's "
                "junctions (0: drained). pressurise (required): the latest opening's new pressure, ramped to over "
                "steps (that opening's excavate must have given one > 0)",
     .absent = "0"},
    {.key = "steps", .kind = KeyKind::integer, .bounds = at_least(0, " steps"), .only = "excavate, cycle, pressurise",
     .meaning = "excavate: steps run in this stage, at most relax_steps (fewer stop part-way through the relaxation, "
                "to install support there); cycle (≥ 1; or its time): run exactly this many steps; pressurise: the "
                "ramp's steps (0: at once; under steady flow the water is solved at every step of it)",
     .absent = "excavate: relax_steps; pressurise: 0"},
    {.key = "time", .bounds = {.lo = 0, .hi = 1e4, .lo_open = true, .unit = " s"}, .only = "cycle",
     .meaning = "cycle, [solver] mode = \"dynamic\" only: the model time the stage runs, instead of steps (one or "
                "the other); it ends on its energy, settled or still moving (theory.md §19.2)"},
    {.key = "supports", .kind = KeyKind::names, .required = true, .only = "install",
     .meaning = "Names of support sets (the tables of any registered support type), not empty, no repeats: put in "
                "place, tied to the rock where it is now and unstressed (theory.md §13); a bar's ends must lie in rock"},
};
#pragma GCC diagnostic pop

/// The bounds a stage's number or integer key is read with.
inline const Bounds& stage_key_bounds(std::string_view key) { return find_key(stage_keys, key)->bounds; }

/// docs/reference/stage.md: the table of keys.
inline std::string stage_keys_markdown() {
    return "# [[stage]] keys\n\n"
           "Generated from core/stage_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). The analysis runs the stages in file order; `type` selects what a stage "
           "does and which keys it takes (the column *types*). An `elastic` stage has no keys of its own: it puts "
           "the model into elastic equilibrium by one implicit sparse solve (SPEC §5, [theory.md](../theory.md) §9); "
           "a floating block, or a model its boundaries do not hold, stops the run. Examples of every type: "
           "[input.md](../input.md).\n\n" +
           key_table_markdown(stage_keys, "types");
}

} // namespace bbm
