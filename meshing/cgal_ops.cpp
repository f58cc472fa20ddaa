// The one translation unit that instantiates CGAL (see cgal_ops.hpp).
#include "meshing/cgal_ops.hpp"

#include "base/error.hpp"
#include "meshing/detail.hpp"

#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_set_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <numbers>

namespace bbm::meshing::cgal {
namespace {

using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = EK::Point_2;
using Poly = CGAL::Polygon_2<EK>;
using Pwh = CGAL::Polygon_with_holes_2<EK>;
using PolySet = CGAL::Polygon_set_2<EK>;

Point to_exact(Vec2 p) { return {p.x, p.y}; }
// Rounds the exact value, not the lazy interval, so equal exact points give
// bit-identical doubles whatever construction produced them.
double round_exact(const EK::FT& v) { return CGAL::to_double(CGAL::exact(v)); }
Vec2 to_vec(const Point& p) { return {round_exact(p.x()), round_exact(p.y())}; }

Poly to_poly(std::span<const Vec2> pts) {
    Poly p;
    for (Vec2 q : pts) p.push_back(to_exact(q));
    return p;
}

std::vector<Vec2> to_ring(const Poly& p) {
    std::vector<Vec2> r;
    r.reserve(p.size());
    for (auto it = p.vertices_begin(); it != p.vertices_end(); ++it) {
        const Vec2 v = to_vec(*it);
        if (r.empty() || !(r.back() == v)) r.push_back(v);
    }
    while (r.size() > 1 && r.front() == r.back()) r.pop_back();
    return r;
}

PolygonWithHoles to_pwh(const Pwh& p) {
    PolygonWithHoles out;
    out.outer = to_ring(p.outer_boundary());
    for (auto h = p.holes_begin(); h != p.holes_end(); ++h) out.holes.push_back(to_ring(*h));
    return out;
}

Pwh to_exact_pwh(const PolygonWithHoles& p) {
    Poly outer = to_poly(p.outer);
    if (outer.is_clockwise_oriented()) outer.reverse_orientation();
    std::vector<Poly> holes;
    for (const auto& h : p.holes) {
        Poly ph = to_poly(h);
        if (ph.is_counterclockwise_oriented()) ph.reverse_orientation();
        holes.push_back(std::move(ph));
    }
    return Pwh(outer, holes.begin(), holes.end());
}

PolySet to_set(const Domain& d) {
    PolySet s;
    for (const auto& p : d) s.join(to_exact_pwh(p));
    return s;
}

Domain from_set(const PolySet& s) {
    std::vector<Pwh> res;
    s.polygons_with_holes(std::back_inserter(res));
    Domain d;
    for (const auto& p : res) d.push_back(to_pwh(p));
    return d;
}

/// Half-plane to the left of the directed line a→b, as a big exact quadrilateral
/// whose first edge lies exactly on the line, large enough to cover `extent`.
Poly half_plane(const Point& a, const Point& b, double extent, bool left) {
    const EK::Vector_2 d = b - a;
    const double len = std::sqrt(CGAL::to_double(d.squared_length()));
    const EK::FT k = std::ceil(4.0 * extent / len + 4.0);
    EK::Vector_2 n(-d.y(), d.x());
    if (!left) n = -n;
    Poly p;
    p.push_back(a - d * k);
    p.push_back(b + d * k);
    p.push_back(b + d * k + n * k);
    p.push_back(a - d * k + n * k);
    if (p.is_clockwise_oriented()) p.reverse_orientation();
    return p;
}

double extent_of(std::span<const Vec2> pts) {
    const Box2 b = bounding_box(pts);
    return std::max(b.width(), b.height()) + std::abs(b.lo.x) + std::abs(b.lo.y) + 1.0;
}

} // namespace

bool is_simple(std::span<const Vec2> polygon) {
    if (polygon.size() < 3) return false;
    return to_poly(polygon).is_simple();
}

double area(const Domain& d) {
    double a = 0.0;
    for (const auto& p : d) {
        a += std::abs(signed_area(p.outer));
        for (const auto& h : p.holes) a -= std::abs(signed_area(h));
    }
    return a;
}

Domain make_domain(std::span<const Vec2> outer_ccw, const std::vector<std::vector<Vec2>>& holes) {
    PolySet s;
    Poly outer = to_poly(outer_ccw);
    if (outer.is_clockwise_oriented()) outer.reverse_orientation();
    s.insert(outer);
    for (const auto& h : holes) {
        Poly ph = to_poly(h);
        if (ph.is_clockwise_oriented()) ph.reverse_orientation();
        s.difference(ph);
    }
    return from_set(s);
}

Domain difference(const Domain& a, const Domain& b) {
    PolySet s = to_set(a);
    s.difference(to_set(b));
    return from_set(s);
}

Domain intersection(const Domain& a, const Domain& b) {
    PolySet s = to_set(a);
    s.intersection(to_set(b));
    return from_set(s);
}

Domain join(const Domain& a, const Domain& b) {
    PolySet s = to_set(a);
    s.join(to_set(b));
    return from_set(s);
}

// ---------------------------------------------------------------------------
// Clipper: boundary edges in a uniform grid decide cheaply whether a polygon is
// wholly inside or outside; only polygons touching the boundary go to CGAL.
struct Clipper::Impl {
    std::vector<Pwh> exact;
    std::vector<Box2> boxes;
    Domain domain;
    std::vector<std::pair<Vec2, Vec2>> edges;
    Box2 grid_box;
    double cell = 1.0;
    int nx = 1, ny = 1;
    std::vector<std::vector<int>> grid;

    int cx(double x) const { return std::clamp(int((x - grid_box.lo.x) / cell), 0, nx - 1); }
    int cy(double y) const { return std::clamp(int((y - grid_box.lo.y) / cell), 0, ny - 1); }

    bool boundary_touches(const Box2& b) const {
        if (b.hi.x < grid_box.lo.x || b.lo.x > grid_box.hi.x || b.hi.y < grid_box.lo.y ||
            b.lo.y > grid_box.hi.y)
            return false;
        for (int j = cy(b.lo.y); j <= cy(b.hi.y); ++j)
            for (int i = cx(b.lo.x); i <= cx(b.hi.x); ++i)
                for (int e : grid[j * nx + i]) {
                    const auto& [p, q] = edges[e];
                    if (std::max(p.x, q.x) >= b.lo.x && std::min(p.x, q.x) <= b.hi.x &&
                        std::max(p.y, q.y) >= b.lo.y && std::min(p.y, q.y) <= b.hi.y)
                        return true;
                }
        return false;
    }

    bool inside(Vec2 q) const { return detail::domain_contains(domain, q); }
};

Clipper::Clipper(const Domain& d) : impl_(new Impl) {
    impl_->domain = d;
    for (const auto& p : d) {
        impl_->exact.push_back(to_exact_pwh(p));
        impl_->boxes.push_back(bounding_box(p.outer));
        auto add_ring = [&](const std::vector<Vec2>& r) {
            for (std::size_t i = 0; i < r.size(); ++i) {
                impl_->edges.push_back({r[i], r[(i + 1) % r.size()]});
                impl_->grid_box.add(r[i]);
            }
        };
        add_ring(p.outer);
        for (const auto& h : p.holes) add_ring(h);
    }
    auto& m = *impl_;
    if (m.edges.empty()) return;
    double total = 0.0;
    for (const auto& [p, q] : m.edges) total += norm(q - p);
    m.cell = std::max(total / double(m.edges.size()) * 2.0, 1e-9 * (m.grid_box.width() + m.grid_box.height()));
    m.nx = std::clamp(int(m.grid_box.width() / m.cell) + 1, 1, 4096);
    m.ny = std::clamp(int(m.grid_box.height() / m.cell) + 1, 1, 4096);
    m.cell = std::max(m.grid_box.width() / m.nx, m.grid_box.height() / m.ny) * 1.000001 + 1e-300;
    m.grid.assign(std::size_t(m.nx) * m.ny, {});
    for (int e = 0; e < int(m.edges.size()); ++e) {
        const auto& [p, q] = m.edges[e];
        for (int j = m.cy(std::min(p.y, q.y)); j <= m.cy(std::max(p.y, q.y)); ++j)
            for (int i = m.cx(std::min(p.x, q.x)); i <= m.cx(std::max(p.x, q.x)); ++i)
                m.grid[j * m.nx + i].push_back(e);
    }
}

Clipper::~Clipper() { delete impl_; }

Domain Clipper::clip(std::span<const Vec2> poly) const {
    const Box2 b = bounding_box(poly);
    if (!impl_->boundary_touches(b)) {
        // No boundary edge near: the polygon is wholly inside or wholly outside.
        if (impl_->inside(centroid(poly))) return {PolygonWithHoles{{poly.begin(), poly.end()}, {}}};
        return {};
    }
    Poly p = to_poly(poly);
    if (p.is_clockwise_oriented()) p.reverse_orientation();
    Domain out;
    for (std::size_t k = 0; k < impl_->exact.size(); ++k) {
        const Box2& db = impl_->boxes[k];
        if (b.hi.x < db.lo.x || b.lo.x > db.hi.x || b.hi.y < db.lo.y || b.lo.y > db.hi.y) continue;
        std::vector<Pwh> res;
        CGAL::intersection(p, impl_->exact[k], std::back_inserter(res));
        for (const auto& r : res) out.push_back(to_pwh(r));
    }
    return out;
}

// ---------------------------------------------------------------------------
std::vector<std::vector<Vec2>> split_holes(const PolygonWithHoles& p) {
    std::vector<std::vector<Vec2>> out;
    std::deque<Pwh> work{to_exact_pwh(p)};
    const double extent = extent_of(p.outer);
    while (!work.empty()) {
        Pwh cur = std::move(work.front());
        work.pop_front();
        if (!cur.has_holes()) {
            out.push_back(to_ring(cur.outer_boundary()));
            continue;
        }
        // A vertical line through the first hole's interior splits it open.
        const Poly& h = *cur.holes_begin();
        const auto [lo, hi] = std::minmax_element(
            h.vertices_begin(), h.vertices_end(),
            [](const Point& a, const Point& b) { return a.x() < b.x(); });
        const EK::FT xc = (lo->x() + hi->x()) / 2;
        const Point a(xc, 0), b(xc, 1);
        for (bool left : {true, false}) {
            std::vector<Pwh> res;
            CGAL::intersection(cur, half_plane(a, b, extent, left), std::back_inserter(res));
            for (auto& r : res) work.push_back(std::move(r));
        }
    }
    return out;
}

std::vector<std::vector<Vec2>> split_by_line(std::span<const Vec2> poly, Vec2 a, Vec2 b) {
    Poly p = to_poly(poly);
    if (p.is_clockwise_oriented()) p.reverse_orientation();
    const double extent = extent_of(poly) + norm(a) + norm(b);
    std::vector<std::vector<Vec2>> out;
    for (bool left : {true, false}) {
        std::vector<Pwh> res;
        CGAL::intersection(p, half_plane(to_exact(a), to_exact(b), extent, left),
                           std::back_inserter(res));
        for (const auto& r : res) {
            BBM_ASSERT(!r.has_holes(), "a simple polygon cut by a half-plane has no holes");
            out.push_back(to_ring(r.outer_boundary()));
        }
    }
    return out;
}

std::vector<PolygonWithHoles> split_by_line(const PolygonWithHoles& poly, Vec2 a, Vec2 b) {
    const Pwh p = to_exact_pwh(poly);
    const double extent = extent_of(poly.outer) + norm(a) + norm(b);
    std::vector<PolygonWithHoles> out;
    for (bool left : {true, false}) {
        std::vector<Pwh> res;
        CGAL::intersection(p, half_plane(to_exact(a), to_exact(b), extent, left), std::back_inserter(res));
        for (const auto& r : res) out.push_back(to_pwh(r));
    }
    return out;
}

// ---------------------------------------------------------------------------
namespace {
using Traits = CGAL::Arr_segment_traits_2<EK>;
using Arrangement = CGAL::Arrangement_2<Traits>;

/// A point strictly inside a simple ring (with other rings' vertices as obstacles),
/// by the classic rule: at the leftmost vertex v with neighbours a and b, use the
/// centroid of triangle abv if no other vertex lies in it, else the midpoint of v
/// and the vertex inside it farthest from line ab.
Vec2 interior_point(const std::vector<Vec2>& ring, const std::vector<Vec2>& obstacles) {
    const std::size_t n = ring.size();
    std::size_t iv = 0;
    for (std::size_t i = 1; i < n; ++i)
        if (ring[i].x < ring[iv].x || (ring[i].x == ring[iv].x && ring[i].y < ring[iv].y)) iv = i;
    const Vec2 v = ring[iv], a = ring[(iv + n - 1) % n], b = ring[(iv + 1) % n];
    auto in_triangle = [&](Vec2 q) {
        const double d1 = cross(v - a, q - a), d2 = cross(b - v, q - v), d3 = cross(a - b, q - b);
        const bool neg = d1 < 0 || d2 < 0 || d3 < 0, pos = d1 > 0 || d2 > 0 || d3 > 0;
        return !(neg && pos);
    };
    double best = -1.0;
    Vec2 far{};
    auto consider = [&](Vec2 q) {
        if (q == v || q == a || q == b || !in_triangle(q)) return;
        const double d = std::abs(cross(b - a, q - a));
        if (d > best) best = d, far = q;
    };
    for (Vec2 q : ring) consider(q);
    for (Vec2 q : obstacles) consider(q);
    if (best < 0.0) return (a + b + v) / 3.0;
    return 0.5 * (v + far);
}

/// The closed loops of one boundary walk (CCB) of an arrangement face, antennas
/// (edges with the face on both sides: fractures ending inside it) left out.
/// Where an antenna leads from the walk to a closed cycle of fractures (a block
/// enclosed by fractures and tied to the rest by one more), the walk makes an
/// excursion around that cycle; it is its own loop — a hole of the face — not part
/// of the ring, whose corner it would otherwise cut. A loop goes on from an edge to
/// the first later edge of the walk that starts where it ends.
template <class Circ>
std::vector<std::vector<Vec2>> loops_without_antennas(Circ first) {
    using Halfedge = decltype(&*first);
    std::vector<Halfedge> edges;
    Circ c = first;
    do {
        if (c->twin()->face() != c->face()) edges.push_back(&*c);
    } while (++c != first);
    const std::size_t n = edges.size();
    std::vector<char> used(n, 0);
    std::vector<std::vector<Vec2>> loops;
    for (std::size_t start = 0; start < n; ++start) {
        if (used[start]) continue;
        std::vector<Vec2> r;
        for (std::size_t e = start; !used[e];) {
            used[e] = 1;
            // Two vertices closer than the rounding (crossings a hair apart in a
            // dense fracture network) become one.
            const Vec2 q = to_vec(edges[e]->source()->point());
            if (r.empty() || !(r.back() == q)) r.push_back(q);
            std::size_t next = (e + 1) % n;
            for (std::size_t k = 1; k < n; ++k, next = (next + 1) % n)
                if (edges[next]->source() == edges[e]->target()) break;
            if (edges[next]->source() != edges[e]->target()) break; // not closed: rounding left a gap
            e = next;
        }
        while (r.size() > 1 && r.front() == r.back()) r.pop_back();
        if (r.size() >= 3) loops.push_back(std::move(r));
    }
    return loops;
}
} // namespace

/// A closed walk that passes a vertex twice (a face pinched at a crossing: in a
/// dense fracture network, two opposite corners of an X belong to one face that
/// wraps around a small neighbour) split into simple loops at its repeated vertices.
std::vector<std::vector<Vec2>> split_at_repeats(const std::vector<Vec2>& ring) {
    std::vector<std::vector<Vec2>> loops;
    std::vector<Vec2> path;
    for (const Vec2 q : ring) {
        const auto again = std::find(path.begin(), path.end(), q);
        if (again != path.end()) {
            loops.emplace_back(again, path.end());
            path.erase(again + 1, path.end());
        } else {
            path.push_back(q);
        }
    }
    if (path.size() >= 3) loops.push_back(std::move(path));
    std::erase_if(loops, [](const std::vector<Vec2>& l) { return l.size() < 3; });
    return loops;
}

CutResult cut_by_segments(const Domain& d, std::span<const SegmentSpec> segments) {
    CutResult out;
    if (segments.empty()) {
        out.faces = d;
        return out;
    }
    std::vector<Traits::Segment_2> curves;
    for (const auto& p : d) {
        auto add_ring = [&](const std::vector<Vec2>& r) {
            for (std::size_t i = 0; i < r.size(); ++i)
                curves.emplace_back(to_exact(r[i]), to_exact(r[(i + 1) % r.size()]));
        };
        add_ring(p.outer);
        for (const auto& h : p.holes) add_ring(h);
    }
    for (const auto& s : segments)
        if (!(s.a == s.b)) curves.emplace_back(to_exact(s.a), to_exact(s.b));
    Arrangement arr;
    CGAL::insert(arr, curves.begin(), curves.end());

    std::vector<Arrangement::Face_const_handle> inside;
    for (auto f = arr.faces_begin(); f != arr.faces_end(); ++f) {
        if (f->is_unbounded() || !f->has_outer_ccb()) continue;
        PolygonWithHoles face;
        // The outer walk's loop of largest area is the ring; its other loops are
        // fracture cycles tied to it by an antenna: holes, as those of inner walks.
        auto outer_loops = loops_without_antennas(f->outer_ccb());
        if (outer_loops.empty()) continue;
        const auto ring = std::max_element(outer_loops.begin(), outer_loops.end(), [](const auto& p, const auto& q) {
            return std::abs(signed_area(p)) < std::abs(signed_area(q));
        });
        face.outer = std::move(*ring);
        outer_loops.erase(ring);
        for (auto& loop : outer_loops) face.holes.push_back(std::move(loop));
        for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h)
            for (auto& loop : loops_without_antennas(*h)) face.holes.push_back(std::move(loop));
        std::vector<Vec2> obstacles;
        for (const auto& h : face.holes) obstacles.insert(obstacles.end(), h.begin(), h.end());
        if (!detail::domain_contains(d, interior_point(face.outer, obstacles))) continue;
        inside.push_back(f);
        // A face pinched at a vertex: in a dense fracture network two opposite
        // corners of an X crossing can belong to one face that wraps around a small
        // neighbour block. Its walk splits there into one counter-clockwise loop,
        // the ring, and clockwise loops around the neighbours: holes that touch the
        // ring at a point, which the Boolean operations filling the face take.
        if (auto loops = split_at_repeats(face.outer); loops.size() > 1) {
            const auto ccw = std::count_if(loops.begin(), loops.end(), [](const auto& l) { return signed_area(l) > 0; });
            if (ccw == 1 && std::all_of(loops.begin(), loops.end(), [](const auto& l) { return is_simple(l); }))
                for (auto& l : loops) (signed_area(l) > 0 ? face.outer : face.holes.emplace_back()) = std::move(l);
        }
        // One that rounding made cross itself, or pinched otherwise, is no polygon
        // the pattern can fill: say where, rather than fail inside CGAL (the
        // caller's area check catches what slips through).
        if (const auto loops = split_at_repeats(face.outer); loops.size() > 1 || !is_simple(face.outer)) {
            Vec2 at = face.outer.front();
            for (std::size_t i = 1; i < face.outer.size(); ++i)
                if (std::find(face.outer.begin(), face.outer.begin() + long(i), face.outer[i]) !=
                    face.outer.begin() + long(i))
                    at = face.outer[i];
            out.pinched.push_back(at);
            continue;
        }
        if (signed_area(face.outer) < 0) std::reverse(face.outer.begin(), face.outer.end());
        for (auto& h : face.holes)
            if (signed_area(h) > 0) std::reverse(h.begin(), h.end());
        out.faces.push_back(std::move(face));
    }
    auto is_inside = [&](Arrangement::Face_const_handle f) {
        return std::find(inside.begin(), inside.end(), f) != inside.end();
    };
    for (auto e = arr.edges_begin(); e != arr.edges_end(); ++e) {
        const auto f1 = e->face(), f2 = e->twin()->face();
        const SegmentSpec s{to_vec(e->source()->point()), to_vec(e->target()->point())};
        if (s.a == s.b) continue; // an edge shorter than the rounding (crossings a hair apart)
        if (f1 == f2) {
            if (is_inside(f1)) out.dangling.push_back(s);
        } else if (is_inside(f1) && is_inside(f2)) {
            out.separating.push_back(s);
        }
    }
    return out;
}

// ---------------------------------------------------------------------------
namespace {
using IK = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, IK>;
using Fb = CGAL::Triangulation_face_base_with_info_2<int, IK>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Delaunay = CGAL::Delaunay_triangulation_2<IK, Tds>;
} // namespace

VoronoiCells voronoi(std::span<const Vec2> seeds, Box2 frame) {
    std::vector<std::pair<IK::Point_2, int>> pts;
    pts.reserve(seeds.size() + 16);
    for (int i = 0; i < int(seeds.size()); ++i) pts.push_back({{seeds[i].x, seeds[i].y}, i});
    // Far ghost points keep every real seed off the convex hull (so its cell is
    // bounded) without taking area from it inside the frame.
    const Vec2 c = 0.5 * (frame.lo + frame.hi);
    const double r = 4.0 * (frame.width() + frame.height()) + 1.0;
    for (int k = 0; k < 16; ++k) {
        const double t = 2.0 * std::numbers::pi * k / 16.0;
        pts.push_back({{c.x + r * std::cos(t), c.y + r * std::sin(t)}, -1});
    }
    Delaunay dt(pts.begin(), pts.end());

    VoronoiCells out;
    out.vertices.reserve(2 * seeds.size() + 32);
    int next = 0;
    for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
        f->info() = next++;
        const auto cc = CGAL::circumcenter(f->vertex(0)->point(), f->vertex(1)->point(),
                                           f->vertex(2)->point());
        out.vertices.push_back({cc.x(), cc.y()});
    }
    out.cells.assign(seeds.size(), {});
    for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) {
        if (v->info() < 0) continue;
        auto& cell = out.cells[v->info()];
        auto fc = dt.incident_faces(v), done = fc;
        do {
            BBM_ASSERT(!dt.is_infinite(fc), "ghost points keep real cells bounded");
            const int id = fc->info();
            if (cell.empty() || (out.vertices[cell.back()] != out.vertices[id])) cell.push_back(id);
        } while (++fc != done);
        while (cell.size() > 1 && out.vertices[cell.front()] == out.vertices[cell.back()]) cell.pop_back();
    }
    return out;
}

// ---------------------------------------------------------------------------
namespace {
struct FaceInfo {
    int nesting = -1;
    bool in_domain() const { return nesting % 2 == 1; }
};
using CVb = CGAL::Triangulation_vertex_base_2<IK>;
using CFbi = CGAL::Triangulation_face_base_with_info_2<FaceInfo, IK>;
using CFb = CGAL::Constrained_triangulation_face_base_2<IK, CFbi>;
using CTds = CGAL::Triangulation_data_structure_2<CVb, CFb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<IK, CTds, CGAL::Exact_predicates_tag>;

// Flood fill from the infinite face; crossing a constraint increments nesting.
void mark_domains(CDT& cdt) {
    std::deque<std::pair<CDT::Face_handle, int>> queue{{cdt.infinite_face(), 0}};
    while (!queue.empty()) {
        auto [start, level] = queue.front();
        queue.pop_front();
        if (start->info().nesting != -1) continue;
        std::deque<CDT::Face_handle> region{start};
        start->info().nesting = level;
        while (!region.empty()) {
            auto f = region.front();
            region.pop_front();
            for (int i = 0; i < 3; ++i) {
                auto n = f->neighbor(i);
                if (n->info().nesting != -1) continue;
                if (cdt.is_constrained({f, i})) {
                    queue.push_back({n, level + 1});
                } else {
                    n->info().nesting = level;
                    region.push_back(n);
                }
            }
        }
    }
}
} // namespace

std::vector<std::array<Vec2, 3>> constrained_delaunay(const Domain& domain,
                                                      std::span<const Vec2> interior_points) {
    CDT cdt;
    auto add_ring = [&](const std::vector<Vec2>& r) {
        for (std::size_t i = 0; i < r.size(); ++i) {
            const Vec2 p = r[i], q = r[(i + 1) % r.size()];
            cdt.insert_constraint(IK::Point_2(p.x, p.y), IK::Point_2(q.x, q.y));
        }
    };
    for (const auto& p : domain) {
        add_ring(p.outer);
        for (const auto& h : p.holes) add_ring(h);
    }
    std::vector<IK::Point_2> pts;
    for (Vec2 q : interior_points) pts.emplace_back(q.x, q.y);
    cdt.insert(pts.begin(), pts.end());
    mark_domains(cdt);
    std::vector<std::array<Vec2, 3>> out;
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (!f->info().in_domain()) continue;
        std::array<Vec2, 3> t;
        for (int i = 0; i < 3; ++i) t[i] = {f->vertex(i)->point().x(), f->vertex(i)->point().y()};
        out.push_back(t);
    }
    return out;
}

} // namespace bbm::meshing::cgal
