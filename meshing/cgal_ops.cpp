// The one translation unit that instantiates CGAL (see cgal_ops.hpp).
#include "meshing/cgal_ops.hpp"

#include "base/error.hpp"
#include "meshing/detail.hpp"

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

// ---------------------------------------------------------------------------
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
    double r = 4.0 * (frame.width() + frame.height()) + 1.0;
    // Seeds far outside a small frame (a lattice's margin about a small rock
    // block): the ghosts go out beyond them, or those seeds would be on the hull.
    double farthest = 0.0;
    for (const Vec2 q : seeds) farthest = std::max(farthest, norm(q - c));
    if (farthest > 0.25 * r) r = 4.0 * farthest + r;
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
