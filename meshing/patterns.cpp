// Inner-block patterns (paper §3.1): each fills one rock block exactly.
#include "base/error.hpp"
#include "meshing/detail.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm::meshing::detail {
namespace {

using cgal::Domain;
using cgal::PolygonWithHoles;

double face_area(const PolygonWithHoles& f) { return cgal::area(Domain{f}); }

Box2 face_box(const PolygonWithHoles& f) { return bounding_box(f.outer); }

std::vector<std::pair<Vec2, Vec2>> face_edges(const PolygonWithHoles& f) {
    std::vector<std::pair<Vec2, Vec2>> e;
    auto add = [&](const std::vector<Vec2>& r) {
        for (std::size_t i = 0; i < r.size(); ++i) e.push_back({r[i], r[(i + 1) % r.size()]});
    };
    add(f.outer);
    for (const auto& h : f.holes) add(h);
    return e;
}

/// Appends the pieces of `poly ∩ face` as simple polygons.
void clip_into(const cgal::Clipper& clipper, std::span<const Vec2> poly, int parent, FaceFill& out) {
    for (const auto& piece : clipper.clip(poly)) {
        if (piece.holes.empty()) {
            // Two pieces touching at a point are two blocks.
            auto loops = cgal::split_at_repeats(piece.outer);
            const bool all_outer = std::all_of(loops.begin(), loops.end(),
                                               [](const std::vector<Vec2>& l) { return signed_area(l) > 0; });
            if (loops.size() < 2 || !all_outer) loops = {piece.outer};
            for (auto& l : loops) {
                out.polygons.push_back(std::move(l));
                out.parent.push_back(parent);
            }
        } else {
            for (auto& p : cgal::split_holes(piece)) {
                out.polygons.push_back(std::move(p));
                out.parent.push_back(parent);
            }
        }
    }
}

std::vector<Vec2> random_seeds(const PolygonWithHoles& face, int n, Random& rng) {
    const Box2 b = face_box(face);
    const Domain d{face};
    std::vector<Vec2> seeds;
    seeds.reserve(n);
    while (int(seeds.size()) < n) {
        const Vec2 q{rng.uniform(b.lo.x, b.hi.x), rng.uniform(b.lo.y, b.hi.y)};
        if (domain_contains(d, q)) seeds.push_back(q);
    }
    return seeds;
}

/// Voronoi cells of the seeds (unclipped; a cell that is no polygon left empty).
Cells voronoi_cells(std::span<const Vec2> seeds, const Box2& frame) {
    const auto vor = cgal::voronoi(seeds, frame);
    Cells cells(vor.cells.size());
    for (std::size_t i = 0; i < vor.cells.size(); ++i) {
        if (vor.cells[i].size() < 3) continue;
        for (int v : vor.cells[i]) cells[i].push_back(vor.vertices[v]);
    }
    return cells;
}

/// Lloyd relaxation: each seed moves to the centroid of its clipped cell.
void lloyd(const PolygonWithHoles& face, const ClipCells& clip, std::vector<Vec2>& seeds, int iterations) {
    for (int it = 0; it < iterations; ++it) {
        const FaceFill cells = clip(voronoi_cells(seeds, face_box(face)));
        std::vector<double> area(seeds.size(), 0.0);
        std::vector<Vec2> moment(seeds.size());
        for (std::size_t k = 0; k < cells.polygons.size(); ++k) {
            const std::size_t i = std::size_t(cells.parent[k]);
            if (i >= seeds.size()) continue; // a piece of the block no cell covers
            const double a = signed_area(cells.polygons[k]);
            area[i] += a;
            moment[i] += a * centroid(cells.polygons[k]);
        }
        for (std::size_t i = 0; i < seeds.size(); ++i)
            if (area[i] > 0) seeds[i] = moment[i] / area[i];
    }
}

int cell_count(double area, double size) {
    return std::max(1, int(std::lround(area / (std::numbers::pi * size * size / 4.0))));
}

Cells voronoi_pattern(const PolygonWithHoles& face, const PatternSpec& p, Random& rng, const ClipCells& clip) {
    auto seeds = random_seeds(face, cell_count(face_area(face), p.size), rng);
    lloyd(face, clip, seeds, p.lloyd_iterations);
    return voronoi_cells(seeds, face_box(face));
}

} // namespace

bool star_center(const std::vector<Vec2>& poly, Vec2& center) {
    auto sees_all = [&](Vec2 c) {
        const double a = std::abs(signed_area(poly));
        for (std::size_t i = 0; i < poly.size(); ++i)
            if (cross(poly[i] - c, poly[(i + 1) % poly.size()] - c) <= 1e-9 * a) return false;
        return true;
    };
    center = centroid(poly);
    if (sees_all(center)) return true;
    // Kernel = intersection of the inner half-planes of all edges (convex clipping).
    std::vector<Vec2> k;
    const Box2 b = bounding_box(poly);
    k = {b.lo, {b.hi.x, b.lo.y}, b.hi, {b.lo.x, b.hi.y}};
    for (std::size_t i = 0; i < poly.size() && k.size() >= 3; ++i) {
        const Vec2 a = poly[i], d = poly[(i + 1) % poly.size()] - a;
        std::vector<Vec2> next;
        for (std::size_t j = 0; j < k.size(); ++j) {
            const Vec2 p = k[j], q = k[(j + 1) % k.size()];
            const double sp = cross(d, p - a), sq = cross(d, q - a);
            if (sp >= 0) next.push_back(p);
            if ((sp >= 0) != (sq >= 0)) next.push_back(p + (sp / (sp - sq)) * (q - p));
        }
        k = std::move(next);
    }
    if (k.size() < 3 || signed_area(k) <= 0) return false;
    center = centroid(k);
    return sees_all(center);
}

double min_edge_of(const PatternSpec& p) { return p.min_edge >= 0 ? p.min_edge : 0.1 * p.size; }

namespace {

/// Trigon: each cell fanned from a point of its kernel into triangles (the cell is
/// their parent); a cell that is not star-shaped (clipped by a strongly concave
/// outline) is kept whole.
FaceFill fan_cells(const FaceFill& cells) {
    FaceFill out;
    out.collapsed_edges = cells.collapsed_edges;
    for (int c = 0; c < int(cells.polygons.size()); ++c) {
        const auto& poly = cells.polygons[c];
        Vec2 center;
        if (!star_center(poly, center)) {
            out.polygons.push_back(poly);
            out.parent.push_back(c);
            continue;
        }
        for (std::size_t i = 0; i < poly.size(); ++i) {
            out.polygons.push_back({center, poly[i], poly[(i + 1) % poly.size()]});
            out.parent.push_back(c);
        }
    }
    return out;
}

Cells delaunay_pattern(const PolygonWithHoles& face, const PatternSpec& p, Random& rng, const ClipCells& clip) {
    // Triangles of mean area π d²/4; boundary sampled at the edge of an equilateral
    // triangle of that area, interior seeds kept apart (hard core) so that no
    // triangle edge is much shorter than the minimum.
    const double tri_area = std::numbers::pi * p.size * p.size / 4.0;
    const double spacing = std::sqrt(4.0 * tri_area / std::sqrt(3.0));
    PolygonWithHoles sampled;
    auto sample = [&](const std::vector<Vec2>& r) {
        std::vector<Vec2> out;
        for (std::size_t i = 0; i < r.size(); ++i) {
            const Vec2 a = r[i], b = r[(i + 1) % r.size()];
            const int n = std::max(1, int(std::lround(norm(b - a) / spacing)));
            for (int k = 0; k < n; ++k) out.push_back(k == 0 ? a : a + (double(k) / n) * (b - a));
        }
        return out;
    };
    sampled.outer = sample(face.outer);
    std::size_t boundary_points = sampled.outer.size();
    for (const auto& h : face.holes) {
        sampled.holes.push_back(sample(h));
        boundary_points += sampled.holes.back().size();
    }
    const double area = face_area(face);
    const int triangles = std::max(1, int(std::lround(area / tri_area)));
    const int interior = std::max(0, (triangles - int(boundary_points) + 2) / 2);
    const double hard_core = std::max(min_edge_of(p), 0.5 * spacing);

    auto seeds = random_seeds(face, interior, rng);
    lloyd(face, clip, seeds, p.lloyd_iterations);
    // Keep seeds away from the boundary and from each other.
    const SegmentGrid boundary(face_edges(sampled), hard_core);
    const Box2 b = face_box(face);
    const double cell = hard_core;
    const int nx = std::max(1, int(b.width() / cell) + 1), ny = std::max(1, int(b.height() / cell) + 1);
    std::vector<std::vector<Vec2>> grid(std::size_t(nx) * ny);
    auto gx = [&](double x) { return std::clamp(int((x - b.lo.x) / cell), 0, nx - 1); };
    auto gy = [&](double y) { return std::clamp(int((y - b.lo.y) / cell), 0, ny - 1); };
    std::vector<Vec2> kept;
    for (Vec2 s : seeds) {
        if (boundary.distance_within(s, hard_core) < hard_core) continue;
        bool close = false;
        for (int j = gy(s.y) - 1; j <= gy(s.y) + 1 && !close; ++j)
            for (int i = gx(s.x) - 1; i <= gx(s.x) + 1 && !close; ++i) {
                if (i < 0 || j < 0 || i >= nx || j >= ny) continue;
                for (Vec2 q : grid[j * nx + i]) close = close || norm(q - s) < hard_core;
            }
        if (close) continue;
        grid[gy(s.y) * nx + gx(s.x)].push_back(s);
        kept.push_back(s);
    }
    Cells out;
    for (const auto& t : cgal::constrained_delaunay(Domain{sampled}, kept)) {
        std::vector<Vec2> tri(t.begin(), t.end());
        if (signed_area(tri) < 0) std::reverse(tri.begin(), tri.end());
        out.push_back(std::move(tri));
    }
    return out;
}

/// Lattice frame: origin and rotated axes.
struct Lattice {
    Vec2 origin, u, v;
    explicit Lattice(const PatternSpec& p) {
        const double t = p.angle * std::numbers::pi / 180.0;
        origin = p.origin;
        u = {std::cos(t), std::sin(t)};
        v = perp(u);
    }
    Vec2 at(double a, double b) const { return origin + a * u + b * v; }
    /// Lattice coordinates range covering the box.
    void range(const Box2& box, double& amin, double& amax, double& bmin, double& bmax) const {
        amin = bmin = INFINITY;
        amax = bmax = -INFINITY;
        for (Vec2 c : {box.lo, Vec2{box.hi.x, box.lo.y}, box.hi, Vec2{box.lo.x, box.hi.y}}) {
            const double a = dot(c - origin, u), b = dot(c - origin, v);
            amin = std::min(amin, a), amax = std::max(amax, a);
            bmin = std::min(bmin, b), bmax = std::max(bmax, b);
        }
    }
};

Cells hexagonal_pattern(const PolygonWithHoles& face, const PatternSpec& p) {
    // Seeds on a triangular lattice of spacing s: their Voronoi cells are regular
    // hexagons of side s/√3.
    const Lattice lat(p);
    const double s = p.size, row = s * std::sqrt(3.0) / 2.0;
    double amin, amax, bmin, bmax;
    lat.range(face_box(face), amin, amax, bmin, bmax);
    std::vector<Vec2> seeds;
    for (long j = long(std::floor(bmin / row)) - 1; j <= long(std::ceil(bmax / row)) + 1; ++j)
        for (long i = long(std::floor(amin / s)) - 2; i <= long(std::ceil(amax / s)) + 1; ++i)
            seeds.push_back(lat.at((double(i) + 0.5 * double(j & 1)) * s, double(j) * row));
    return voronoi_cells(seeds, face_box(face));
}

Cells brick_pattern(const PolygonWithHoles& face, const PatternSpec& p, bool t_vertices) {
    // Corners are computed from integer half-brick indices, so neighbouring bricks
    // share bit-identical corners. With `t_vertices` (running bond) each long edge
    // also has the corner of the next course's bricks that meets it: on a rotated
    // lattice that rounded corner is off the rounded edge by an ulp, and an exact
    // cut would see slivers between them.
    const Lattice lat(p);
    const double h = p.size, half = 0.5 * p.aspect * p.size;
    double amin, amax, bmin, bmax;
    lat.range(face_box(face), amin, amax, bmin, bmax);
    Cells out;
    for (long j = long(std::floor(bmin / h)) - 1; j <= long(std::ceil(bmax / h)); ++j) {
        const long shift = p.running_bond ? (j & 1) : 0;
        for (long m = long(std::floor(amin / half)) - 3; m <= long(std::ceil(amax / half)) + 1; ++m) {
            if (((m - shift) & 1) != 0) continue;
            if (t_vertices && p.running_bond) {
                out.push_back({lat.at(double(m) * half, double(j) * h), lat.at(double(m + 1) * half, double(j) * h),
                               lat.at(double(m + 2) * half, double(j) * h), lat.at(double(m + 2) * half, double(j + 1) * h),
                               lat.at(double(m + 1) * half, double(j + 1) * h), lat.at(double(m) * half, double(j + 1) * h)});
                continue;
            }
            out.push_back({lat.at(double(m) * half, double(j) * h), lat.at(double(m + 2) * half, double(j) * h),
                           lat.at(double(m + 2) * half, double(j + 1) * h), lat.at(double(m) * half, double(j + 1) * h)});
        }
    }
    return out;
}

FaceFill fill_single(const PolygonWithHoles& face) {
    FaceFill out;
    if (face.holes.empty()) {
        out.polygons.push_back(face.outer);
    } else {
        out.polygons = cgal::split_holes(face);
    }
    for (std::size_t k = 0; k < out.polygons.size(); ++k) out.parent.push_back(int(k));
    return out;
}

} // namespace

PatternSpec generator_pattern(const PatternSpec& p) {
    using K = PatternSpec::Kind;
    const bool random = p.kind == K::voronoi || p.kind == K::trigon || p.kind == K::delaunay;
    if (!random || p.size_measure == PatternSpec::SizeMeasure::area) return p;
    // The mean Feret diameter of the blocks is proportional to the generator's size
    // (same seeds, scaled), so their ratio is a property of the pattern: measured on
    // a square patch of about 1,500 cells with the same settings, its blocks clear
    // of the patch's sides (cut blocks are smaller), always with the same seed, so
    // that every realization of a pattern gets the same number of cells per area.
    // The minimum edge stays the one of the size asked for. Two passes: the first
    // guess (typical ratios) only sets the scale of the minimum edge.
    PatternSpec q = p;
    q.size_measure = PatternSpec::SizeMeasure::area;
    q.min_edge = min_edge_of(p);
    double ratio = p.kind == K::trigon ? 0.6 : (p.kind == K::delaunay ? 1.35 : 1.13);
    for (int pass = 0; pass < 2; ++pass) {
        q.size = p.size / ratio;
        const double side = q.size * std::sqrt(1500.0 * std::numbers::pi / 4.0);
        PolygonWithHoles patch;
        patch.outer = {{0.0, 0.0}, {side, 0.0}, {side, side}, {0.0, side}};
        Random rng(0x5eed5eed5eed5eedull);
        const FaceFill fill = fill_face(patch, q, rng);
        const double margin = 1e-9 * side;
        double sum = 0.0;
        int n = 0;
        for (const auto& poly : fill.polygons) {
            const bool cut = std::any_of(poly.begin(), poly.end(), [&](Vec2 v) {
                return v.x < margin || v.y < margin || v.x > side - margin || v.y > side - margin;
            });
            if (!cut) sum += mean_feret_diameter(poly), ++n;
        }
        if (n == 0) break; // cannot happen with ~1,500 cells; keep the first guess
        ratio = sum / n / q.size;
    }
    q.size = p.size / ratio;
    return q;
}

PatternCells pattern_cells(const PolygonWithHoles& face, const PatternSpec& p, Random& rng, const ClipCells& clip,
                           bool exact) {
    using K = PatternSpec::Kind;
    switch (p.kind) {
    case K::voronoi: return {voronoi_pattern(face, p, rng, clip), false, false};
    case K::trigon: return {voronoi_pattern(face, p, rng, clip), false, true};
    case K::delaunay: return {delaunay_pattern(face, p, rng, clip), true, false};
    case K::hexagonal: return {hexagonal_pattern(face, p), false, false};
    case K::brick: return {brick_pattern(face, p, exact), false, false};
    case K::single: return {};
    }
    return {};
}

FaceFill fill_face(const PolygonWithHoles& face, const PatternSpec& p, Random& rng) {
    using K = PatternSpec::Kind;
    if (p.kind == K::single) return fill_single(face);
    const cgal::Clipper clipper(Domain{face});
    const ClipCells clip = [&](const Cells& cells) {
        FaceFill out;
        for (std::size_t i = 0; i < cells.size(); ++i)
            if (cells[i].size() >= 3) clip_into(clipper, cells[i], int(i), out);
        return out;
    };
    PatternCells pc = pattern_cells(face, p, rng, clip);
    FaceFill out;
    if (pc.fitted) { // Delaunay: the triangles fill the sampled face
        out.polygons = std::move(pc.cells);
        for (std::size_t k = 0; k < out.polygons.size(); ++k) out.parent.push_back(int(k));
        return out;
    }
    out = clip(pc.cells);
    if (p.kind == K::brick)
        for (std::size_t k = 0; k < out.parent.size(); ++k) out.parent[k] = int(k);
    out.collapsed_edges = collapse_short_edges(out.polygons, face, min_edge_of(p));
    return pc.fans ? fan_cells(out) : out;
}

} // namespace bbm::meshing::detail

namespace bbm::meshing {

double mean_feret_diameter(std::span<const Vec2> poly) {
    // Cauchy: the mean width of a convex set over all directions is its perimeter / π;
    // a non-convex block has the mean width of its convex hull (monotone chain).
    std::vector<Vec2> pts(poly.begin(), poly.end());
    std::sort(pts.begin(), pts.end(), [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (pts.size() < 3) return pts.size() == 2 ? 2.0 * norm(pts[1] - pts[0]) / std::numbers::pi : 0.0;
    std::vector<Vec2> hull(2 * pts.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross(hull[k - 1] - hull[k - 2], pts[i] - hull[k - 2]) <= 0) --k;
        hull[k++] = pts[i];
    }
    for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
        while (k >= lower && cross(hull[k - 1] - hull[k - 2], pts[i] - hull[k - 2]) <= 0) --k;
        hull[k++] = pts[i];
    }
    double perimeter = 0.0;
    for (std::size_t i = 0; i + 1 < k; ++i) perimeter += norm(hull[i + 1] - hull[i]);
    return perimeter / std::numbers::pi;
}

double mean_feret_diameter(const BlockAssembly& a, int region) {
    double total = 0.0;
    int n = 0;
    for (int b = 0; b < a.block_count(); ++b)
        if (region < 0 || a.region[b] == region) total += mean_feret_diameter(a.block(b)), ++n;
    return n ? total / n : 0.0;
}

} // namespace bbm::meshing
