// bbm meshing, internal: pieces of the generation pipeline shared between its
// translation units. Not part of the public interface (blocks.hpp is).
#pragma once

#include "meshing/blocks.hpp"
#include "meshing/cgal_ops.hpp"

#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <span>
#include <vector>

namespace bbm::meshing::detail {

/// Reproducible uniform numbers: mt19937_64 is fully specified by the standard,
/// the conversion to [0, 1) is ours (std's distributions are not portable).
class Random {
public:
    explicit Random(std::uint64_t seed) : engine_(seed) {}
    double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

private:
    std::mt19937_64 engine_;
};

/// Hash of a point by its bits: bit-identical coordinates are one point (the
/// cutting and clipping round each shared vertex once, so shared means identical).
struct PointHash {
    std::size_t operator()(Vec2 p) const {
        std::uint64_t a, b;
        std::memcpy(&a, &p.x, 8);
        std::memcpy(&b, &p.y, 8);
        return std::hash<std::uint64_t>{}(a * 0x9E3779B97F4A7C15ull ^ b);
    }
};

/// Segments in a uniform grid, for "which segments are near this box" queries.
class SegmentGrid {
public:
    SegmentGrid(std::vector<std::pair<Vec2, Vec2>> segments, double cell_hint);
    /// Calls f(index) for each segment whose box overlaps `b` (possibly repeatedly).
    template <class F> void for_each_near(const Box2& b, F&& f) const {
        if (segments_.empty() || b.hi.x < box_.lo.x || b.lo.x > box_.hi.x || b.hi.y < box_.lo.y ||
            b.lo.y > box_.hi.y)
            return;
        for (int j = cy(b.lo.y); j <= cy(b.hi.y); ++j)
            for (int i = cx(b.lo.x); i <= cx(b.hi.x); ++i)
                for (std::uint32_t k = start_[j * nx_ + i]; k < start_[j * nx_ + i + 1]; ++k)
                    f(items_[k]);
    }
    /// Distance from q to the nearest segment within `radius`, or +inf.
    double distance_within(Vec2 q, double radius) const;
    const std::vector<std::pair<Vec2, Vec2>>& segments() const { return segments_; }

private:
    int cx(double x) const;
    int cy(double y) const;
    std::vector<std::pair<Vec2, Vec2>> segments_;
    Box2 box_;
    double cell_ = 1.0;
    int nx_ = 1, ny_ = 1;
    std::vector<std::uint32_t> start_;
    std::vector<int> items_;
};

bool domain_contains(const cgal::Domain& d, Vec2 q);

/// Blocks filling one rock block (a face of the real-joint arrangement).
struct FaceFill {
    std::vector<std::vector<Vec2>> polygons;
    std::vector<int> parent;  ///< local parent id (the Voronoi cell of a trigon triangle)
    int collapsed_edges = 0;
};
/// The blocks of a pattern filling a rock block that no trace cuts: its cells
/// clipped to it (Boolean operations), short edges collapsed.
FaceFill fill_face(const cgal::PolygonWithHoles& face, const PatternSpec& pattern, Random& rng);

using Cells = std::vector<std::vector<Vec2>>;
/// Clips cells to a rock block: pieces with the index of their cell as parent.
using ClipCells = std::function<FaceFill(const Cells&)>;
/// The cells a pattern lays over a rock block before they are cut to it: Voronoi
/// cells of its seeds (relaxed with `clip` when it asks for Lloyd iterations),
/// lattice hexagons or bricks, constrained Delaunay triangles; none for "single".
/// `exact`: for an exact cut, every vertex a cell has on another's edge is a vertex
/// of that one too (the corners of a running bond's next course).
struct PatternCells {
    Cells cells;
    bool fitted = false; ///< Delaunay: the triangles already fill the face as it was sampled
    bool fans = false;   ///< trigon: each clipped cell is then fanned into triangles
};
PatternCells pattern_cells(const cgal::PolygonWithHoles& face, const PatternSpec& pattern, Random& rng,
                           const ClipCells& clip, bool exact = false);
/// A point from which every edge of the polygon is seen (its kernel), preferring
/// the centroid; false if the polygon is not star-shaped.
bool star_center(const std::vector<Vec2>& poly, Vec2& center);
/// The pattern's minimum edge: given, or a tenth of its size.
double min_edge_of(const PatternSpec& p);

/// The pattern the generators run with: `size` as the diameter of the mean area of
/// their cells (SizeMeasure::area). A size given as a mean Feret diameter is
/// converted with the ratio measured on a reference patch of the same pattern
/// (same settings, a fixed seed).
PatternSpec generator_pattern(const PatternSpec& pattern);

/// Collapses edges shorter than min_edge; shared vertices move together so the
/// polygons still tile the same area. Outline vertices of `face` never move, and
/// vertices on the outline move only along it. Returns the number collapsed.
int collapse_short_edges(std::vector<std::vector<Vec2>>& polygons, const cgal::PolygonWithHoles& face,
                         double min_edge);

/// Joint records from shared edge stretches (see blocks.hpp, step 5).
void build_joints(BlockAssembly& a);

} // namespace bbm::meshing::detail
