// bbm meshing: triangle meshes of deformable blocks (SPEC §6).
//
// A deformable block is a polygon filled with constant-strain triangles; its
// boundary nodes are its contact vertices, so the mesh must keep the boundary
// points it is given exactly and add none (a neighbouring block may share them).
// The work is split in two:
//   * subdivide_boundary() puts points on the polygon's edges at the local target
//     size h(x). The points of an edge depend only on its two endpoints, taken as
//     an unordered pair, so two blocks sharing an edge get bit-identical points on
//     it and their meshes conform without talking to each other;
//   * mesh_polygon() fills the polygon with gmsh (built-in kernel, one line per
//     boundary segment held at 2 nodes, Frontal-Delaunay in the interior with the
//     sizes given at the boundary points interpolated inside).
// fe_mesh.cpp is the only translation unit that includes <gmsh.h>; gmsh keeps a
// global state, so calls are serialised and each uses (then removes) its own model.
#pragma once

#include "base/vec2.hpp"

#include <array>
#include <functional>
#include <span>
#include <vector>

namespace bbm::meshing {

/// Target triangle size (m) at a point; must be > 0.
using SizeFunction = std::function<double(Vec2)>;

/// Points of a closed counter-clockwise polygon with every edge subdivided so that no
/// piece is much longer than the local size: an edge of length L gets
/// n = max(1, ceil(∫ 1/h ds)) pieces, with its points at equal fractions of ∫ 1/h ds
/// (1/h sampled at 17 points along the edge, integrated by the trapezoidal rule).
/// The interior points of an edge depend only on its two endpoints as an unordered
/// pair (they are computed from the lexicographically smaller endpoint, then
/// reversed if needed), so two polygons sharing an edge get bit-identical points
/// on it. The original vertices stay, in order, the first one first.
std::vector<Vec2> subdivide_boundary(std::span<const Vec2> polygon, const SizeFunction& size);

struct TriangleMesh {
    std::vector<Vec2> nodes; ///< nodes[0 .. boundary_nodes) are the boundary points given, in order
    int boundary_nodes = 0;
    std::vector<std::array<int, 3>> triangles; ///< counter-clockwise, positive area
};

/// Meshes a simple counter-clockwise polygon into linear triangles with gmsh: the
/// boundary points are kept exactly (no node is added on the boundary) and the
/// interior is graded between the sizes size(point) at the boundary points.
/// Deterministic: the same boundary and sizes give the same mesh. Throws
/// GeometryError (base/error.hpp; region -1, key "mesh") if gmsh fails, returns no
/// triangles, a node count inconsistent with the boundary, or triangles whose
/// areas do not add up to the polygon's.
TriangleMesh mesh_polygon(std::span<const Vec2> boundary, const SizeFunction& size,
                          bool verbose = false);

} // namespace bbm::meshing
