// bbm meshing: the exact-geometry operations, behind a plain-double interface.
//
// Everything that needs CGAL lives in cgal_ops.cpp, so that only one translation
// unit pays for the exact kernel and the Boolean-operation templates. Inputs and
// outputs are doubles; inside, the exact kernel (Epeck) is used, and results are
// rounded once at the end. The rounding is deterministic: two cells that share a
// Voronoi edge and are clipped by the same boundary edge get the bit-identical
// crossing point, which is what lets the topology pass weld vertices exactly.
#pragma once

#include "base/vec2.hpp"
#include "meshing/spec.hpp"

#include <array>
#include <span>
#include <vector>

namespace bbm::meshing::cgal {

struct PolygonWithHoles {
    std::vector<Vec2> outer;               ///< counter-clockwise
    std::vector<std::vector<Vec2>> holes;  ///< clockwise
};
/// A planar region: disjoint polygons with holes.
using Domain = std::vector<PolygonWithHoles>;

bool is_simple(std::span<const Vec2> polygon);
double area(const Domain& d);
Domain make_domain(std::span<const Vec2> outer_ccw, const std::vector<std::vector<Vec2>>& holes_ccw);
Domain difference(const Domain& a, const Domain& b);
Domain intersection(const Domain& a, const Domain& b);
Domain join(const Domain& a, const Domain& b);

/// A domain prepared once for clipping many small polygons against it.
class Clipper {
public:
    explicit Clipper(const Domain& d);
    ~Clipper();
    Clipper(const Clipper&) = delete;
    Clipper& operator=(const Clipper&) = delete;
    /// Pieces of `poly ∩ domain` (polygon with holes each).
    Domain clip(std::span<const Vec2> poly) const;

private:
    struct Impl;
    Impl* impl_;
};

/// A closed walk that passes a vertex more than once split into simple loops there
/// (a "relatively simple" polygon, as CGAL's Boolean operations may return one:
/// two pieces touching at a point).
std::vector<std::vector<Vec2>> split_at_repeats(const std::vector<Vec2>& ring);

/// Splits a polygon with holes into simple polygons (cuts through each hole).
std::vector<std::vector<Vec2>> split_holes(const PolygonWithHoles& p);

/// Voronoi cells of `seeds` (bounded by far ghost points placed around `frame`):
/// cell i lists indices into `vertices` counter-clockwise. Vertices are the
/// circumcentres of Delaunay triangles, computed once each, so neighbouring cells
/// share them exactly.
struct VoronoiCells {
    std::vector<Vec2> vertices;
    std::vector<std::vector<int>> cells;
};
VoronoiCells voronoi(std::span<const Vec2> seeds, Box2 frame);

/// Constrained Delaunay triangles of `points` inside `domain`, whose boundary
/// (every vertex of it) is inserted as constraints. Triangles counter-clockwise.
std::vector<std::array<Vec2, 3>> constrained_delaunay(const Domain& domain,
                                                      std::span<const Vec2> interior_points);

} // namespace bbm::meshing::cgal
