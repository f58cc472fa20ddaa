// bbm core: the keys of the [[bolt]] and [[dowel]] tables — grouted rock bolts and
// cables (core/bolts.hpp), dowels that also bend (core/dowels.hpp) — one
// declaration each (base/keys.hpp). The model file's reader checks both by them
// (io/read_bolts.cpp) and docs/reference/bolt.md is generated from them
// (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/dowels.hpp"

#include <string>

namespace bbm {

using BoltKey = Key<DowelSetSpec>;

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[bolt]] and [[dowel]], in the order the reference lists them;
/// `only` marks the two that belong to one of them. Forces are per bolt; a set
/// acts on the 1 m thick model divided by its out-of-plane spacing.
inline constexpr BoltKey bolt_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique among bolt sets, dowel sets and liners; install stages name it"},
    {.key = "bolts", .kind = KeyKind::segments, .bounds = unbounded(" m"),
     .meaning = "Each bolt's head (at the wall) and toe; head ≠ toe; with a ring or instead of it",
     .absent = "none"},
    {.key = "ring", .kind = KeyKind::table,
     .meaning = "Radial bolts around a circular opening, a table: center [x, y], radius (of the wall, > 0 m), "
                "length (> 0 m), count (≥ 1) or spacing along the wall (> 0 m), from and to (degrees "
                "counter-clockwise from +x; a full circle if absent; an arc gets bolts at both ends)",
     .absent = "none"},
    {.key = "segment_length", .bounds = above(0, " m"),
     .meaning = "Nodes along a bolt at most this far apart (fine beside the blocks it crosses)", .absent = "0.25",
     BBM_KEY_FIELD(DowelSetSpec, segment_length)},
    {.key = "young", .bounds = above(0, " Pa"), .meaning = "The steel's Young's modulus", .absent = "200e9",
     BBM_KEY_FIELD(DowelSetSpec, young)},
    {.key = "area", .bounds = above(0, " m²"), .meaning = "The steel's cross-section; not with diameter",
     .absent = "4.91e-4 (25 mm)"},
    {.key = "diameter", .bounds = above(0, " m"), .meaning = "The bar's diameter, for its area; not with area",
     .absent = "25 mm"},
    {.key = "density", .bounds = above(0, " kg/m³"), .meaning = "The steel's density (its weight; its mass in "
                                                                "dynamic mode)",
     .absent = "7850", BBM_KEY_FIELD(DowelSetSpec, density)},
    {.key = "yield_force", .bounds = above(0, " N"),
     .meaning = "Axial force at which the steel yields, in tension and compression (perfectly plastic); a dowel's "
                "plastic moment f_y d³/6 with f_y = yield_force / A",
     .absent = "elastic", BBM_KEY_FIELD(DowelSetSpec, yield_force)},
    {.key = "rupture_strain", .bounds = above(0, ""), .meaning = "A segment stretched past it breaks for good",
     .absent = "never", BBM_KEY_FIELD(DowelSetSpec, rupture_strain)},
    {.key = "cable", .kind = KeyKind::boolean, .only = "bolt", .meaning = "No compression: a cable goes slack",
     .absent = "false", BBM_KEY_FIELD(DowelSetSpec, cable)},
    {.key = "pretension", .bounds = at_least(0, " N"), .only = "dowel",
     .meaning = "Tension against the face plate and end anchor before grouting: every element starts at it, the "
                "rock between plate and anchor pressed by it; below yield_force; needs face_plate and end_anchor",
     .absent = "0", BBM_KEY_FIELD(DowelSetSpec, pretension)},
    {.key = "bond_stiffness", .bounds = above(0, " N/m per m"), .required = true,
     .meaning = "The grout's shear stiffness along the bolt, per metre of bolt", BBM_KEY_FIELD(DowelSetSpec, bond_stiffness)},
    {.key = "bond_strength", .bounds = above(0, " N/m"),
     .meaning = "The grout's shear strength along the bolt, per metre of bolt; past it the grout slips (plastic)",
     .absent = "no slip", BBM_KEY_FIELD(DowelSetSpec, bond_strength)},
    {.key = "normal_stiffness", .bounds = above(0, " N/m per m"),
     .meaning = "Stiffness across the bolt (its hole in the rock; a dowel's elastic foundation), no limit",
     .absent = "bond_stiffness", BBM_KEY_FIELD(DowelSetSpec, normal_stiffness)},
    {.key = "spacing", .bounds = above(0, " m"), .meaning = "Out of plane, between the rows of bolts", .absent = "1",
     BBM_KEY_FIELD(DowelSetSpec, spacing)},
    {.key = "face_plate", .kind = KeyKind::boolean, .meaning = "The head tied to its rock with no slip limit",
     .absent = "false", BBM_KEY_FIELD(DowelSetSpec, face_plate)},
    {.key = "end_anchor", .kind = KeyKind::boolean, .meaning = "The toe tied to its rock with no slip limit",
     .absent = "false", BBM_KEY_FIELD(DowelSetSpec, end_anchor)},
};
#pragma GCC diagnostic pop

/// docs/reference/bolt.md: the table of keys.
inline std::string bolt_keys_markdown() {
    return "# [[bolt]] and [[dowel]] keys\n\n"
           "Generated from core/bolt_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). A set exists from the `install` stage that names it. Its loads are "
           "reported per bolt (summary.json `bolts` and `dowels`, `bbm compare`, bolts.pvd, dowels.pvd, "
           "failure.png, Python `Model.bolts`). The elements and the grout: [theory.md](../theory.md) §13; "
           "examples: [input.md](../input.md) and [the support tutorial](../guide/support.md).\n\n" +
           key_table_markdown(bolt_keys, "tables");
}

} // namespace bbm
