// bbm meshing: the keys of a [[region]] table and of the tables inside it — its
// outline, its block pattern, its joint sets and its mesh — one declaration each
// (base/keys.hpp), with the outline or pattern types each belongs to. The model
// file's reader checks them by these (io/model_input.cpp) and
// docs/reference/region.md is generated from them (tests/test_reference.cpp).
// A [[region.dfn]] set's keys are described in docs/input.md, "Fracture networks".
#pragma once

#include "base/keys.hpp"
#include "meshing/spec.hpp"

#include <string>

namespace bbm::meshing {

using RegionKey = Key<RegionSpec>;
using OutlineKey = Key<OutlineSpec>;
using PatternKey = Key<PatternSpec>;
using JointSetKey = Key<JointSetSpec>;
using MeshKey = Key<MeshSpec>;

/// In the order of OutlineSpec::Kind and PatternSpec::Kind.
inline constexpr std::string_view outline_type_words = "rectangle, polygon, circle, path, opening";
inline constexpr std::string_view pattern_type_words = "voronoi, trigon, delaunay, hexagonal, brick, single";

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[region]].
inline constexpr RegionKey region_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Unique, non-empty; used by minus and in messages and outputs"},
    {.key = "outline", .kind = KeyKind::table, .required = true, .meaning = "The region's boundary (below)"},
    {.key = "holes", .kind = KeyKind::table, .meaning = "An array of outline tables cut out of the outline",
     .absent = "none"},
    {.key = "minus", .kind = KeyKind::names,
     .meaning = "Other regions subtracted from this one (earlier or later in the file, not itself): how regions "
                "nest",
     .absent = "none"},
    {.key = "pattern", .kind = KeyKind::table, .required = true,
     .meaning = "The inner blocks that fill the region (below); they fill each piece its real joints leave"},
    {.key = "joints", .kind = KeyKind::segments, .bounds = unbounded(" m"),
     .meaning = "Explicit real joints, an array of { from = [x, y], to = [x, y] }: straight segments that may end "
                "inside the region",
     .absent = "none"},
    {.key = "joint_set", .kind = KeyKind::table,
     .meaning = "Statistical joint sets (below), usually written as [[region.joint_set]] sections", .absent = "none"},
    {.key = "dfn", .kind = KeyKind::table,
     .meaning = "Fracture sets of a discrete fracture network, usually [[region.dfn]] sections (input.md, "
                "\"Fracture networks\")",
     .absent = "none"},
    {.key = "material", .kind = KeyKind::text,
     .meaning = "The name of a [[material]]; without one the first [[material]] if no region names one, else "
                "density 2700 kg/m³ and no elasticity",
     .absent = "none"},
    {.key = "mesh", .kind = KeyKind::table,
     .meaning = "Makes the region's blocks deformable: each is meshed into triangles (below)", .absent = "rigid"},
};

/// Every key of an outline table; `type` selects the shape and its keys.
inline constexpr OutlineKey outline_keys[] = {
    {.key = "type", .kind = KeyKind::choice, .required = true, .meaning = "The shape", .words = outline_type_words},
    {.key = "min", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true, .only = "rectangle",
     .meaning = "Lower-left corner"},
    {.key = "max", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true, .only = "rectangle",
     .meaning = "Upper-right corner, above min in x and y"},
    {.key = "points", .kind = KeyKind::curve, .bounds = unbounded(" m"), .required = true, .only = "polygon",
     .meaning = "At least 3 vertices [[x, y], ...], in order, not repeating the first"},
    {.key = "center", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true, .only = "circle, opening",
     .meaning = "circle: its centre; opening: the centre of the roof arch, its y the springline"},
    {.key = "radius", .bounds = above(0, " m"), .required = true, .only = "circle", .meaning = "The circle's radius",
     BBM_KEY_FIELD(OutlineSpec, radius)},
    {.key = "start", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true, .only = "path",
     .meaning = "The path's first vertex"},
    {.key = "steps", .kind = KeyKind::table, .required = true, .only = "path",
     .meaning = "An array of steps, at least one: { to = [x, y] } a straight piece, { to = [x, y], center = [x, "
                "y], clockwise = false } an arc about center (its end within 1e-6 of the radius its start gives); "
                "the path closes back to start"},
    {.key = "width", .bounds = above(0, " m"), .required = true, .only = "opening",
     .meaning = "A horseshoe tunnel's span between its side walls, and its roof's diameter",
     BBM_KEY_FIELD(OutlineSpec, width)},
    {.key = "floor", .bounds = unbounded(" m"), .required = true, .only = "opening",
     .meaning = "y of the flat floor, below center.y"},
    {.key = "half", .kind = KeyKind::boolean, .only = "opening",
     .meaning = "Keep only the part x ≥ center.x, for a model cut on its symmetry plane", .absent = "false"},
    {.key = "max_segment", .bounds = above(0, " m"), .only = "circle, path, opening",
     .meaning = "The longest straight piece of the circle or arcs", .absent = "[model] max_segment",
     BBM_KEY_FIELD(OutlineSpec, max_segment)},
};

/// Every key of a pattern table; `type` selects the blocks and their keys.
inline constexpr PatternKey pattern_keys[] = {
    {.key = "type", .kind = KeyKind::choice, .required = true,
     .meaning = "voronoi: Voronoi cells of random points; trigon: those cells split into triangles about their "
                "centres; delaunay: Delaunay triangles of random points; hexagonal: regular hexagons; brick: "
                "bricks in rows; single: the whole region (or each piece its real joints leave) is one block",
     .words = pattern_type_words, BBM_KEY_FIELD(PatternSpec, kind), .flag = true, .flag_name = "pattern"},
    {.key = "size", .bounds = above(0, " m"), .required = true, .only = "voronoi, trigon, delaunay, hexagonal, brick",
     .meaning = "The blocks' mean size as size_measure says (voronoi, trigon, delaunay); hexagonal: the lattice "
                "spacing; brick: the brick's height",
     BBM_KEY_FIELD(PatternSpec, size), .flag = true},
    {.key = "size_measure", .kind = KeyKind::choice, .only = "voronoi, trigon, delaunay",
     .meaning = "feret: the blocks' mean Feret diameter, a block's width averaged over all directions (the paper's "
                "average dimension); area: the diameter of the circle of the generator cells' mean area",
     .absent = "feret", .words = "feret, area", BBM_KEY_FIELD(PatternSpec, size_measure), .flag = true},
    {.key = "lloyd", .kind = KeyKind::integer, .bounds = between(0, 2147483647, ""),
     .only = "voronoi, trigon, delaunay",
     .meaning = "Lloyd relaxation iterations: more makes the cells more regular (and the rock stronger)",
     .absent = "0", BBM_KEY_FIELD(PatternSpec, lloyd_iterations), .flag = true},
    {.key = "min_edge", .bounds = at_least(0, " m"), .only = "voronoi, trigon, delaunay, hexagonal, brick",
     .meaning = "Edges shorter than this are collapsed; below size", .absent = "0.1 × size"},
    {.key = "seed", .kind = KeyKind::integer, .bounds = at_least(0, ""), .only = "voronoi, trigon, delaunay",
     .meaning = "The random seed: the same seed gives the same blocks", .absent = "1", BBM_KEY_FIELD(PatternSpec, seed),
     .flag = true},
    {.key = "origin", .kind = KeyKind::point, .bounds = unbounded(" m"), .only = "hexagonal, brick",
     .meaning = "A lattice point", .absent = "[0, 0]"},
    {.key = "angle", .bounds = unbounded(" degrees"), .only = "hexagonal, brick",
     .meaning = "The lattice's rotation, counter-clockwise", .absent = "0", BBM_KEY_FIELD(PatternSpec, angle)},
    {.key = "aspect", .bounds = above(0, ""), .only = "brick", .meaning = "Brick length over height; 1 gives squares",
     .absent = "2", BBM_KEY_FIELD(PatternSpec, aspect)},
    {.key = "bond", .kind = KeyKind::choice, .only = "brick",
     .meaning = "running: rows offset by half a brick; stack: aligned", .absent = "running", .words = "running, stack"},
};

/// Every key of a [[region.joint_set]] table: parallel traces added to the region
/// written before it.
inline constexpr JointSetKey joint_set_keys[] = {
    {.key = "angle", .bounds = unbounded(" degrees"), .required = true,
     .meaning = "The traces' direction, counter-clockwise from +x", BBM_KEY_FIELD(JointSetSpec, angle)},
    {.key = "spacing", .bounds = above(0, " m"), .required = true, .meaning = "Mean normal distance between traces",
     BBM_KEY_FIELD(JointSetSpec, spacing)},
    {.key = "trace", .bounds = at_least(0, " m"),
     .meaning = "Mean trace length; 0 = persistent joints that cut through the region", .absent = "0",
     BBM_KEY_FIELD(JointSetSpec, trace_length)},
    {.key = "gap", .bounds = at_least(0, " m"), .meaning = "Mean rock bridge between collinear traces", .absent = "0",
     BBM_KEY_FIELD(JointSetSpec, gap)},
    {.key = "angle_deviation", .bounds = below(0, 90, " degrees"),
     .meaning = "Each trace's direction varies uniformly by ± this", .absent = "0",
     BBM_KEY_FIELD(JointSetSpec, angle_deviation)},
    {.key = "spacing_deviation", .bounds = below(0, 1, ""),
     .meaning = "Each trace line's offset varies uniformly by ± this × spacing", .absent = "0",
     BBM_KEY_FIELD(JointSetSpec, spacing_deviation)},
    {.key = "length_deviation", .bounds = below(0, 1, ""),
     .meaning = "Each trace length and gap varies uniformly by ± this fraction", .absent = "0",
     BBM_KEY_FIELD(JointSetSpec, length_deviation)},
    {.key = "origin", .kind = KeyKind::point, .bounds = unbounded(" m"),
     .meaning = "A point one trace line passes through (before deviation)", .absent = "[0, 0]"},
    {.key = "seed", .kind = KeyKind::integer, .bounds = at_least(0, ""), .meaning = "The deviations' random seed",
     .absent = "1"},
};

/// Every key of a region's mesh table: its blocks become deformable (SPEC §6).
inline constexpr MeshKey mesh_keys[] = {
    {.key = "size", .bounds = above(0, " m"), .required = true,
     .meaning = "The triangles' size (edge length) next to the toward regions, or everywhere without them",
     BBM_KEY_FIELD(MeshSpec, size)},
    {.key = "size_far", .bounds = above(0, " m"),
     .meaning = "The largest triangle size, far from the toward regions; at least size", .absent = "size"},
    {.key = "grading", .bounds = at_least(0, " m/m"),
     .meaning = "Growth of the size per metre from the toward regions, h = min(size_far, size + grading d); 0 = "
                "uniform; > 0 needs toward",
     .absent = "0", BBM_KEY_FIELD(MeshSpec, grading)},
    {.key = "toward", .kind = KeyKind::names, .meaning = "Other regions the mesh is refined toward, no repeats",
     .absent = "none"},
};
#pragma GCC diagnostic pop

/// docs/reference/region.md: the tables of keys.
inline std::string region_keys_markdown() {
    return "# [[region]] keys\n\n"
           "Generated from meshing/region_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; "
           "the test fails when it is stale). A region's domain is its outline minus its holes minus the regions "
           "it names in `minus`; regions must not otherwise overlap. What a pattern's size measures, how a path "
           "and an opening are drawn, how a mesh is graded and a [[region.dfn]] set's keys: "
           "[input.md](../input.md).\n\n"
           "## [[region]]\n\n" +
           key_table_markdown(region_keys) + "\n## The outline (and each of holes)\n\n" +
           key_table_markdown(outline_keys, "types") + "\n## The pattern\n\n" +
           key_table_markdown(pattern_keys, "types") + "\n## [[region.joint_set]]\n\n" +
           key_table_markdown(joint_set_keys) + "\n## The mesh\n\n" + key_table_markdown(mesh_keys);
}

} // namespace bbm::meshing
