// bbm core: the keys of the [[liner]] table — shotcrete or concrete lining along a
// circular opening (core/liners.hpp) — one declaration each (base/keys.hpp). The
// model file's reader checks [[liner]] by them (io/read_liners.cpp) and
// docs/reference/liner.md is generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/liners.hpp"

#include <string>

namespace bbm {

using LinerKey = Key<LinerSpec>;

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[liner]], in the order the reference lists them. Per metre of
/// tunnel (plane strain).
inline constexpr LinerKey liner_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique among bolt sets, dowel sets and liners; install stages name it"},
    {.key = "center", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true,
     .meaning = "The opening's center"},
    {.key = "radius", .bounds = above(0, " m"), .required = true,
     .meaning = "The wall's radius: the liner's line (each node must touch rock within half an element)",
     BBM_KEY_FIELD(LinerSpec, radius)},
    {.key = "from", .bounds = unbounded(" degrees"), .meaning = "Where the liner starts, counter-clockwise from +x",
     .absent = "0", BBM_KEY_FIELD(LinerSpec, from)},
    {.key = "to", .bounds = unbounded(" degrees"),
     .meaning = "Where it ends: above from by at most 360 (360: a closed ring)", .absent = "from + 360"},
    {.key = "segment_length", .bounds = above(0, " m"), .meaning = "Elements at most this long", .absent = "0.2",
     BBM_KEY_FIELD(LinerSpec, segment_length)},
    {.key = "young", .bounds = above(0, " Pa"), .meaning = "The lining's Young's modulus; E' = E / (1 − ν²)",
     .absent = "30e9", BBM_KEY_FIELD(LinerSpec, young)},
    {.key = "poisson", .bounds = below(0, 0.5, ""), .meaning = "The lining's Poisson's ratio", .absent = "0.2",
     BBM_KEY_FIELD(LinerSpec, poisson)},
    {.key = "thickness", .bounds = above(0, " m"), .required = true, .meaning = "A = t, I = t³/12 per metre",
     BBM_KEY_FIELD(LinerSpec, thickness)},
    {.key = "density", .bounds = above(0, " kg/m³"), .meaning = "The lining's density", .absent = "2400",
     BBM_KEY_FIELD(LinerSpec, density)},
    {.key = "normal_stiffness", .bounds = above(0, " Pa/m"),
     .meaning = "The interface's stiffness across the wall", .absent = "10 E't/R²",
     BBM_KEY_FIELD(LinerSpec, normal_stiffness)},
    {.key = "shear_stiffness", .bounds = above(0, " Pa/m"), .meaning = "The interface's stiffness along the wall",
     .absent = "normal_stiffness", BBM_KEY_FIELD(LinerSpec, shear_stiffness)},
    {.key = "tensile_strength", .bounds = above(0, " Pa"),
     .meaning = "The interface's bond in tension; once exceeded it separates for good", .absent = "no tension",
     BBM_KEY_FIELD(LinerSpec, tensile_strength)},
    {.key = "cohesion", .bounds = at_least(0, " Pa"),
     .meaning = "The interface's shear strength c + σ tan φ (c lost once separated)", .absent = "0",
     BBM_KEY_FIELD(LinerSpec, cohesion)},
    {.key = "friction", .bounds = below(0, 90, " degrees"), .meaning = "The interface's friction angle φ",
     .absent = "35", BBM_KEY_FIELD(LinerSpec, friction)},
    {.key = "symmetric_ends", .kind = KeyKind::boolean,
     .meaning = "The ends lie on symmetry planes (a half or quarter model): their displacement along the liner and "
                "their rotation are held; not for a closed ring",
     .absent = "false", BBM_KEY_FIELD(LinerSpec, symmetric_ends)},
    {.key = "thrust_capacity", .bounds = above(0, " N/m"),
     .meaning = "The thrust at which the lining yields in compression (σc t), perfectly plastic", .absent = "elastic",
     BBM_KEY_FIELD(LinerSpec, thrust_capacity)},
    {.key = "tension_capacity", .bounds = above(0, " N/m"),
     .meaning = "Yield in tension (σt t); needs a thrust capacity", .absent = "none",
     BBM_KEY_FIELD(LinerSpec, tension_capacity)},
    {.key = "moment_capacity", .bounds = above(0, " N·m/m"),
     .meaning = "Yield in bending at each end of an element (σc t²/6 at first yield, /4 fully plastic); "
                "independent of the thrust (no interaction diagram)",
     .absent = "elastic", BBM_KEY_FIELD(LinerSpec, moment_capacity)},
};
#pragma GCC diagnostic pop

/// docs/reference/liner.md: the table of keys.
inline std::string liner_keys_markdown() {
    return "# [[liner]] keys\n\n"
           "Generated from core/liner_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). Beam elements on the wall of a circular opening, each node tied to the "
           "rock it touches by interface springs that separate in tension and slide in shear; it exists from the "
           "`install` stage that names it. Thrust in kN/m and moment in kNm/m (summary.json `liners`, `bbm "
           "compare`, liners.pvd, failure.png, Python `Model.liners`). The elements: [theory.md](../theory.md) §14; "
           "examples: [the support tutorial](../guide/support.md).\n\n" +
           key_table_markdown(liner_keys);
}

} // namespace bbm
