// The exact cutter of cutting.hpp: arrangements of segments on CGAL's exact kernel.
// A translation unit of its own (no Boolean operations here), so that it compiles
// beside cgal_ops.cpp.
#include "meshing/cutting.hpp"

#include "meshing/cgal_ops.hpp"

#include <CGAL/Arr_consolidated_curve_data_traits_2.h>
#include <CGAL/Arr_extended_dcel.h>
#include <CGAL/Arr_observer.h>
#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace bbm::meshing::detail {
namespace cut_faces {
// Outside the anonymous namespace on purpose: CGAL registers an observer of an
// Arrangement_2 as one of its base class (a cast), and with every type of the
// arrangement internal to this file GCC 12 at -O3 proves that no class derives
// from that base's observer and calls its empty notification instead of ours.
struct FaceData {
    signed char inside = -1; ///< inside the region (rock block): 1, outside 0, not yet known −1
    bool block = false;      ///< one of the blocks (not where cells kept whole lie)
    bool stuck = false;      ///< a small block with no neighbour to merge into
    int cell = -1;           ///< the cell the face lies in (its parent); −1: none
};
} // namespace cut_faces

namespace {
using cut_faces::FaceData;

using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using FT = EK::FT;
using Point = EK::Point_2;
using Segment = EK::Segment_2;
using SegmentTraits = CGAL::Arr_segment_traits_2<EK>;
/// Every edge carries the origins of the curves it lies on (several where curves
/// overlap): indices into Overlay::origins.
using Traits = CGAL::Arr_consolidated_curve_data_traits_2<SegmentTraits, int>;

using Dcel = CGAL::Arr_face_extended_dcel<Traits, FaceData>;
using Arr = CGAL::Arrangement_2<Traits, Dcel>;
using Face = Arr::Face_handle;
using Halfedge = Arr::Halfedge_handle;
using Vertex = Arr::Vertex_handle;

/// What a curve is: the boundary of the region or rock block being cut (with it on
/// the left of from→to), a trace, an edge of a pattern's cells (with the cells on
/// its left and right), a rock bridge, or a cut opening a hole.
enum class Kind : std::uint8_t { boundary, trace, cell, bridge, cut };

struct Origin {
    Kind kind = Kind::cell;
    Point from, to;
    int left = -1, right = -1;
    bool on_trace = false; ///< a rock block's boundary edge lying on a trace
};

Point exact(Vec2 p) { return {p.x, p.y}; }
// Rounds the exact value, not the lazy interval, so equal exact points give
// bit-identical doubles whatever construction produced them.
double round_exact(const FT& v) { return CGAL::to_double(CGAL::exact(v)); }
Vec2 rounded(const Point& p) { return {round_exact(p.x()), round_exact(p.y())}; }
/// Within an ulp or so of the exact value: for areas, lengths and boxes only.
Vec2 approx(const Point& p) { return {CGAL::to_double(p.x()), CGAL::to_double(p.y())}; }

/// A face split in two passes what it knows to both halves.
class InheritFaceData : public CGAL::Arr_observer<Arr> {
public:
    explicit InheritFaceData(Arr& arr) : CGAL::Arr_observer<Arr>(arr) {}
    void after_split_face(Face f, Face new_f, bool) override { new_f->set_data(f->data()); }
};

/// The halfedges of a face's boundary walks: its outer one first, then its holes'.
template <class F> void for_each_boundary(Face f, F&& visit) {
    auto walk = [&](Arr::Ccb_halfedge_circulator first) {
        auto c = first;
        do visit(Halfedge(c));
        while (++c != first);
    };
    if (!f->is_unbounded()) walk(f->outer_ccb());
    for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h) walk(*h);
}

/// An arrangement with the origin of every curve in it.
class Overlay {
public:
    Overlay() : observer_(arr) {}
    Overlay(const Overlay&) = delete;
    Overlay& operator=(const Overlay&) = delete;

    Arr arr;
    std::vector<Origin> origins;

    /// Records a curve to insert with the next flush(); a point is no curve.
    void queue(Origin o) {
        if (o.from == o.to) return;
        origins.push_back(std::move(o));
        const Origin& r = origins.back();
        pending_.emplace_back(Segment(r.from, r.to), int(origins.size()) - 1);
    }
    /// Records a curve for an origin already recorded.
    void queue_id(const Segment& s, int origin) { pending_.emplace_back(s, origin); }
    /// Inserts the queued curves at once (one sweep).
    void flush() {
        if (pending_.empty()) return;
        CGAL::insert(arr, pending_.begin(), pending_.end());
        pending_.clear();
    }
    /// Inserts one curve now (a zone walk: cheap for a curve inside one face).
    void insert_now(Origin o) {
        if (o.from == o.to) return;
        origins.push_back(std::move(o));
        const Origin& r = origins.back();
        CGAL::insert(arr, Traits::Curve_2(Segment(r.from, r.to), int(origins.size()) - 1));
    }

    template <class F> void each_origin(Halfedge h, F&& f) const {
        for (int id : h->curve().data()) f(origins[id]);
    }
    bool has(Halfedge h, Kind k) const {
        for (int id : h->curve().data())
            if (origins[id].kind == k) return true;
        return false;
    }
    static bool same_direction(Halfedge h, const Origin& o) {
        return CGAL::compare_xy(h->source()->point(), h->target()->point()) == CGAL::compare_xy(o.from, o.to);
    }
    /// Whether the face on h's left is inside the boundary's region: 1 or 0 from a
    /// boundary curve under h, −1 when h lies on none.
    int side_of(Halfedge h) const {
        int side = -1;
        each_origin(h, [&](const Origin& o) {
            if (o.kind != Kind::boundary) return;
            if (same_direction(h, o)) side = 1;
            else if (side < 0) side = 0;
        });
        return side;
    }

    /// Marks every face inside or outside the boundary curves: from the curves
    /// themselves, then across the other curves (which do not leave the region).
    void classify() {
        std::vector<Face> queue;
        for (auto f = arr.faces_begin(); f != arr.faces_end(); ++f) {
            FaceData d = f->data();
            d.inside = f->is_unbounded() ? 0 : -1;
            f->set_data(d);
        }
        for (auto h = arr.halfedges_begin(); h != arr.halfedges_end(); ++h) {
            const int side = side_of(h);
            Face f = h->face();
            if (side < 0 || side <= f->data().inside) continue;
            FaceData d = f->data();
            d.inside = static_cast<signed char>(side);
            f->set_data(d);
            queue.push_back(f);
        }
        for (std::size_t i = 0; i < queue.size(); ++i) {
            const Face f = queue[i];
            for_each_boundary(f, [&](Halfedge h) {
                const Face g = h->twin()->face();
                if (g->data().inside >= 0 || side_of(h) >= 0) return;
                FaceData d = g->data();
                d.inside = f->data().inside;
                g->set_data(d);
                queue.push_back(g);
            });
        }
        for (auto f = arr.faces_begin(); f != arr.faces_end(); ++f)
            if (f->data().inside < 0) {
                FaceData d = f->data();
                d.inside = 0;
                f->set_data(d);
            }
    }

private:
    InheritFaceData observer_;
    std::vector<Traits::Curve_2> pending_;
};

/// Twice the signed area of a closed walk, exactly.
FT twice_area(const std::vector<Halfedge>& loop) {
    FT a2 = 0;
    for (Halfedge h : loop) {
        const Point& p = h->source()->point();
        const Point& q = h->target()->point();
        a2 += p.x() * q.y() - q.x() * p.y();
    }
    return a2;
}

/// A walk split at the vertices it passes more than once into closed loops (two
/// lobes touching at a vertex, a hole touching the ring, a trace there and back).
std::vector<std::vector<Halfedge>> loops_of(Arr::Ccb_halfedge_circulator first) {
    std::vector<std::vector<Halfedge>> loops;
    std::vector<Halfedge> path;
    std::unordered_map<const void*, std::size_t> at; // vertex → its position on the path
    auto c = first;
    do {
        const Halfedge h(c);
        const void* v = &*h->source();
        if (auto it = at.find(v); it != at.end()) {
            const std::size_t i = it->second;
            loops.emplace_back(path.begin() + long(i), path.end());
            for (std::size_t k = i; k < path.size(); ++k) at.erase(&*path[k]->source());
            path.resize(i);
        }
        at[v] = path.size();
        path.push_back(h);
    } while (++c != first);
    if (!path.empty()) loops.push_back(std::move(path));
    return loops;
}

/// Whether the walk passes straight through the source of `next` where other
/// edges meet it from the other side (a T-junction: a neighbour's vertex on this
/// block's edge, which the block's polygon does not need).
bool t_junction(Halfedge prev, Halfedge next) {
    const Vertex v = next->source();
    if (v->degree() < 3) return false;
    const Point& p = prev->source()->point();
    const Point& q = next->target()->point();
    return CGAL::collinear(p, v->point(), q) && CGAL::collinear_are_strictly_ordered_along_line(p, v->point(), q);
}

/// The rounded ring of a loop without its T-junctions, consecutive repeats (points
/// closer than the rounding) made one.
std::vector<Vec2> rounded_ring(const std::vector<Halfedge>& loop) {
    std::vector<Vec2> r;
    r.reserve(loop.size());
    for (std::size_t i = 0; i < loop.size(); ++i) {
        if (loop.size() > 3 && t_junction(loop[(i + loop.size() - 1) % loop.size()], loop[i])) continue;
        const Vec2 q = rounded(loop[i]->source()->point());
        if (r.empty() || !(r.back() == q)) r.push_back(q);
    }
    while (r.size() > 1 && r.front() == r.back()) r.pop_back();
    return r;
}

Box2 approx_box(Face f) {
    Box2 b;
    for_each_boundary(f, [&](Halfedge h) { b.add(approx(h->source()->point())); });
    return b;
}

/// The nearest point, other than `from` itself, where the ray from `from` along `d`
/// meets the boundary of face f (which it enters at `from`); none if it meets none.
std::optional<Point> first_hit(Face f, const Point& from, const EK::Vector_2& d) {
    const Box2 b = approx_box(f);
    const Vec2 p = approx(from), dd{CGAL::to_double(d.x()), CGAL::to_double(d.y())};
    const double reach = 2.0 * (b.width() + b.height() + std::abs(p.x - b.lo.x) + std::abs(p.y - b.lo.y)) + 1.0;
    const FT k = std::ceil(reach / std::max(norm(dd), 1e-300)) + 1.0;
    const Segment ray(from, from + d * k);
    std::optional<Point> best;
    FT best_d2 = 0;
    auto consider = [&](const Point& q) {
        if (q == from) return;
        const FT d2 = CGAL::squared_distance(from, q);
        if (!best || d2 < best_d2) best = q, best_d2 = d2;
    };
    for_each_boundary(f, [&](Halfedge h) {
        const Segment s(h->source()->point(), h->target()->point());
        if (!CGAL::do_intersect(ray, s)) return;
        const auto x = CGAL::intersection(ray, s);
        if (!x) return;
        if (const Point* q = boost::get<Point>(&*x)) {
            consider(*q);
        } else if (const Segment* o = boost::get<Segment>(&*x)) {
            consider(o->source());
            consider(o->target());
        }
    });
    return best;
}

/// A point strictly inside a simple ring (with other rings' vertices as obstacles),
/// by the classic rule: at the leftmost vertex v with neighbours a and b, the
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

/// The rounded loops of one boundary walk of a region's face for the pattern
/// generators, antennas (traces ending inside it) left out. Where an antenna leads
/// from the walk to a closed cycle of traces, the walk makes an excursion around
/// that cycle: its own loop, a hole of the face.
std::vector<std::vector<Vec2>> loops_without_antennas(Arr::Ccb_halfedge_circulator first) {
    std::vector<Halfedge> edges;
    auto c = first;
    do {
        if (c->twin()->face() != c->face()) edges.push_back(Halfedge(c));
    } while (++c != first);
    const std::size_t n = edges.size();
    std::vector<char> used(n, 0);
    std::vector<std::vector<Vec2>> loops;
    for (std::size_t start = 0; start < n; ++start) {
        if (used[start]) continue;
        std::vector<Vec2> r;
        for (std::size_t e = start; !used[e];) {
            used[e] = 1;
            const Vec2 q = rounded(edges[e]->source()->point());
            if (r.empty() || !(r.back() == q)) r.push_back(q);
            std::size_t next = (e + 1) % n;
            for (std::size_t k = 1; k < n; ++k, next = (next + 1) % n)
                if (edges[next]->source() == edges[e]->target()) break;
            if (edges[next]->source() != edges[e]->target()) break;
            e = next;
        }
        while (r.size() > 1 && r.front() == r.back()) r.pop_back();
        if (r.size() >= 3) loops.push_back(std::move(r));
    }
    return loops;
}

cgal::PolygonWithHoles rounded_face(Face f) {
    cgal::PolygonWithHoles out;
    auto loops = loops_without_antennas(f->outer_ccb());
    if (!loops.empty()) {
        const auto ring = std::max_element(loops.begin(), loops.end(), [](const auto& p, const auto& q) {
            return std::abs(signed_area(p)) < std::abs(signed_area(q));
        });
        out.outer = std::move(*ring);
        loops.erase(ring);
        for (auto& l : loops) out.holes.push_back(std::move(l));
    }
    for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h)
        for (auto& l : loops_without_antennas(*h)) out.holes.push_back(std::move(l));
    if (signed_area(out.outer) < 0) std::reverse(out.outer.begin(), out.outer.end());
    for (auto& h : out.holes)
        if (signed_area(h) > 0) std::reverse(h.begin(), h.end());
    return out;
}

double approx_area(Face f) {
    double a2 = 0.0;
    for_each_boundary(f, [&](Halfedge h) { a2 += cross(approx(h->source()->point()), approx(h->target()->point())); });
    return 0.5 * a2;
}

double approx_length(Halfedge h) { return norm(approx(h->target()->point()) - approx(h->source()->point())); }

/// The face across f's boundary that shares the most length with it, over the
/// edges `accept` takes (first met on a tie); none if it takes none.
template <class Accept> std::optional<Face> neighbour_sharing_most(Face f, Accept&& accept) {
    std::vector<std::pair<Face, double>> shared; // few neighbours: a list
    for_each_boundary(f, [&](Halfedge h) {
        const Face g = h->twin()->face();
        if (g == f || !accept(h)) return;
        const auto it = std::find_if(shared.begin(), shared.end(), [&](const auto& s) { return s.first == g; });
        if (it == shared.end()) shared.push_back({g, approx_length(h)});
        else it->second += approx_length(h);
    });
    std::optional<Face> best;
    double longest = 0.0;
    for (const auto& [g, length] : shared)
        if (!best || length > longest) best = g, longest = length;
    return best;
}

struct EdgeHash {
    std::size_t operator()(const std::pair<Vec2, Vec2>& e) const {
        return PointHash{}(e.first) * 31 + PointHash{}(e.second);
    }
};

[[noreturn]] void bug(const char* what) {
    throw std::logic_error(std::string("bbm's exact cutting: ") + what + " (a bug)");
}

// ---------------------------------------------------------------------------
/// One rock block and the cells laid over it: an arrangement of its exact
/// boundary and the edges of the cells at its edges.
class FaceCut {
public:
    /// `antennas`: with the traces that end inside the rock block (edges with it on
    /// both sides); without them the cells are cut to it as if no trace ended there.
    FaceCut(const Overlay& region, Face rock, double min_area, double tol, bool antennas)
        : region_(region), rock_(rock), min_area_(min_area), tol_(tol) {
        std::vector<std::pair<Vec2, Vec2>> edges;
        std::vector<Traits::X_monotone_curve_2> curves;
        std::unordered_map<const void*, std::size_t> curve_of; // an antenna's edge: its curve
        for_each_boundary(rock, [&](Halfedge h) {
            const bool antenna = h->twin()->face() == rock;
            edges.push_back({approx(h->source()->point()), approx(h->target()->point())});
            boundary_exact_.push_back({h->source()->point(), h->target()->point()});
            // Left out, a trace ending inside still makes the cells near it cells to cut
            // (so that the trace can be added to them later): it is in the grid.
            if (!antennas && antenna) return;
            const int id = add_boundary_origin(h);
            if (antenna) {
                // Both sides of a trace ending inside are boundary: one curve, two origins.
                const void* e = &*h < &*h->twin() ? &*h : &*h->twin();
                if (const auto it = curve_of.find(e); it != curve_of.end()) {
                    auto data = curves[it->second].data();
                    data.insert(id);
                    curves[it->second] = Traits::X_monotone_curve_2(curves[it->second], data);
                    return;
                }
                curve_of[e] = curves.size();
            }
            // The rock block's edges do not cross: inserted without looking for crossings,
            // each on the supporting line of the trace it came from.
            curves.emplace_back(SegmentTraits::X_monotone_curve_2(h->curve()), Traits::Data_container(id));
        });
        // Inserted with the cells, in one sweep (add_cells): a rock block with many
        // holes (clusters of traces in sparse rock) inserted first and split by the
        // cells afterwards would move every hole at every split.
        boundary_curves_ = std::move(curves);
        double total = 0.0;
        for (const auto& [p, q] : edges) total += norm(q - p);
        boundary_ = std::make_unique<SegmentGrid>(std::move(edges), total / double(std::max<std::size_t>(1, edges.size())));
    }

    /// Adds the traces that end inside the rock block (left out at first).
    void add_antennas() {
        for_each_boundary(rock_, [&](Halfedge h) {
            if (h->twin()->face() != rock_) return;
            const int id = add_boundary_origin(h);
            ov_.queue_id(Segment(h->source()->point(), h->target()->point()), id);
        });
        ov_.flush();
    }

    /// Lays the cells over the rock block: those near its boundary are inserted,
    /// the others kept whole (inside) or dropped (outside). No cells: the rock block
    /// is one block. `tiled`: the cells are pieces that already tile the block (cut
    /// to it, rounded, then moved by a short-edge collapse): their edges along its
    /// boundary are left out, and their ends on it put exactly on it.
    void add_cells(const Cells& cells, const cgal::PolygonWithHoles& rounded, bool tiled = false) {
        cells_ = &cells;
        has_cells_ = !cells.empty();
        const std::vector<char> near = cells_near_boundary(cells, rounded, tiled);
        std::vector<std::vector<Vec2>> rings;
        EdgeOwners owner;
        cell_rings(cells, rings, owner);
        insert_cell_edges(cells, near, rings, owner, tiled);
        label_faces(cells, near);
    }

    /// Whether any rule has work here: a trace ending inside a block, a block with
    /// a hole or touching itself.
    bool needs_rules() {
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f)
            if (is_block(f) && (f->number_of_inner_ccbs() > 0 || loops_of(f->outer_ccb()).size() > 1)) return true;
        return false;
    }

    /// The blocks as they stand, rounded, in the cells' order: the faces that are
    /// blocks (each lobe one) and the cells kept whole.
    FaceFill pieces() {
        struct Piece {
            int cell;
            std::vector<Vec2> ring;
        };
        std::vector<Piece> out;
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f) {
            if (!is_block(f)) continue;
            for (const auto& loop : loops_of(f->outer_ccb())) {
                if (!CGAL::is_positive(twice_area(loop))) continue;
                auto r = rounded_ring(loop);
                if (r.size() >= 3) out.push_back({f->data().cell, std::move(r)});
            }
        }
        if (!fanned_)
            for (std::size_t c = 0; c < whole_.size(); ++c)
                if (whole_[c] == 1) out.push_back({int(c), (*cells_)[c]});
        std::stable_sort(out.begin(), out.end(), [](const Piece& a, const Piece& b) { return a.cell < b.cell; });
        FaceFill fill;
        int fresh = int(whole_.size());
        for (auto& p : out) {
            fill.parent.push_back(p.cell >= 0 ? p.cell : fresh++);
            fill.polygons.push_back(std::move(p.ring));
        }
        return fill;
    }

    /// Trigon: every piece (as pieces() gives them, numbered in that order: the
    /// parents) fanned from a point of its kernel into triangles; a piece with none
    /// kept whole. Returns the triangles of the cells kept whole, fanned as they are.
    FaceFill fan(const CentreOf& centre_of) {
        struct Piece {
            int cell;
            Face face;
            std::vector<Halfedge> loop;
            std::size_t whole; ///< cell + 1 of a cell kept whole, else 0
        };
        std::vector<Piece> order;
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f) {
            if (!is_block(f)) continue;
            for (auto& loop : loops_of(f->outer_ccb()))
                if (CGAL::is_positive(twice_area(loop)) && rounded_ring(loop).size() >= 3)
                    order.push_back({f->data().cell, f, std::move(loop), 0});
        }
        for (std::size_t c = 0; c < whole_.size(); ++c)
            if (whole_[c] == 1) order.push_back({int(c), Face(), {}, c + 1});
        std::stable_sort(order.begin(), order.end(), [](const Piece& a, const Piece& b) { return a.cell < b.cell; });
        FaceFill whole;
        for (std::size_t k = 0; k < order.size(); ++k) {
            const Piece& p = order[k];
            const std::vector<Vec2> poly = p.whole ? (*cells_)[p.whole - 1] : rounded_ring(p.loop);
            Vec2 centre;
            const bool fans = centre_of(poly, centre);
            if (p.whole) {
                for (std::size_t i = 0; i < (fans ? poly.size() : 1); ++i) {
                    whole.polygons.push_back(fans ? std::vector<Vec2>{centre, poly[i], poly[(i + 1) % poly.size()]} : poly);
                    whole.parent.push_back(int(k));
                }
                continue;
            }
            FaceData d = p.face->data();
            d.cell = int(k);
            p.face->set_data(d);
            if (!fans) continue;
            const Point c = exact(centre);
            for (std::size_t i = 0; i < p.loop.size(); ++i) {
                const Halfedge h = p.loop[i];
                if (t_junction(p.loop[(i + p.loop.size() - 1) % p.loop.size()], h)) continue;
                Origin o;
                o.kind = Kind::cell;
                o.from = c;
                o.to = h->source()->point();
                ov_.queue(std::move(o));
            }
        }
        ov_.flush(); // the triangles inherit their piece's number as they split off
        fanned_ = true;
        return whole;
    }

    /// The rules of cutting.hpp, until nothing changes.
    void apply_rules(CutStats& stats) {
        for (int round = 0;; ++round) {
            if (round > 1000) bug("the rules did not settle");
            bool changed = extend_tips(stats);
            changed = cut_holes(stats) || changed;
            changed = merge_small(stats) || changed;
            if (!changed) break;
        }
    }

private:
    /// Each edge of the cells, keyed by its two ends, and the cell whose own edge
    /// it is (its ring running that way).
    using EdgeOwners = std::unordered_map<std::pair<Vec2, Vec2>, int, EdgeHash>;

    /// The cells near the block's boundary (inserted); the others kept whole
    /// inside or dropped outside (whole_). A tiled piece of no width (a sliver the
    /// rounding flattened) is dropped: its neighbours cover it.
    std::vector<char> cells_near_boundary(const Cells& cells, const cgal::PolygonWithHoles& rounded, bool tiled) {
        whole_.assign(cells.size(), 0);
        std::vector<char> near(cells.size(), 0);
        const cgal::Domain face{rounded};
        for (std::size_t c = 0; c < cells.size(); ++c) {
            if (cells[c].size() < 3) continue;
            if (tiled && thinner_than_rounding(cells[c])) {
                whole_[c] = 2; // a piece of no width (a sliver the rounding flattened): its neighbours cover it
                continue;
            }
            Box2 b = bounding_box(cells[c]);
            b.lo = b.lo - Vec2{tol_, tol_};
            b.hi = b.hi + Vec2{tol_, tol_};
            bool touches = false;
            boundary_->for_each_near(b, [&](int e) {
                const auto& [p, q] = boundary_->segments()[e];
                touches = touches || (std::max(p.x, q.x) >= b.lo.x && std::min(p.x, q.x) <= b.hi.x &&
                                      std::max(p.y, q.y) >= b.lo.y && std::min(p.y, q.y) <= b.hi.y);
            });
            near[c] = touches;
            // Far from every edge of the block: wholly inside it or wholly outside.
            if (!touches) whole_[c] = tiled || domain_contains(face, centroid(cells[c])) ? 1 : 2;
        }
        return near;
    }

    /// Each cell not dropped as a counter-clockwise ring without repeated points,
    /// and the owner of each of its edges.
    void cell_rings(const Cells& cells, std::vector<std::vector<Vec2>>& rings, EdgeOwners& owner) const {
        rings.assign(cells.size(), {});
        for (std::size_t c = 0; c < cells.size(); ++c) {
            if (cells[c].size() < 3 || whole_[c] == 2) continue;
            auto& r = rings[c];
            for (Vec2 q : cells[c])
                if (r.empty() || !(r.back() == q)) r.push_back(q);
            while (r.size() > 1 && r.front() == r.back()) r.pop_back();
            if (signed_area(r) < 0) std::reverse(r.begin(), r.end());
            for (std::size_t i = 0; i < r.size(); ++i) owner[{r[i], r[(i + 1) % r.size()]}] = int(c);
        }
    }

    /// The edges of the cells near the boundary, each once with the cells on its
    /// two sides (those whose own edge it is, running the same way or the other),
    /// inserted with the block's boundary in one sweep.
    void insert_cell_edges(const Cells& cells, const std::vector<char>& near, const std::vector<std::vector<Vec2>>& rings,
                           const EdgeOwners& owner, bool tiled) {
        for (std::size_t c = 0; c < cells.size(); ++c) {
            if (!near[c]) continue;
            const auto& r = rings[c];
            for (std::size_t i = 0; i < r.size(); ++i) {
                const Vec2 p = r[i], q = r[(i + 1) % r.size()];
                const auto back = owner.find({q, p});
                // An edge two inserted cells share is inserted once, by the lower.
                if (back != owner.end() && near[std::size_t(back->second)] && std::size_t(back->second) < c) continue;
                // A piece's edge along the rock block's boundary: that boundary itself.
                if (tiled && on_boundary(p) && on_boundary(q) && on_boundary(0.5 * (p + q))) continue;
                Origin o;
                o.kind = Kind::cell;
                o.from = tiled ? onto_boundary(p) : exact(p);
                o.to = tiled ? onto_boundary(q) : exact(q);
                o.left = int(c);
                o.right = back != owner.end() ? back->second : -1;
                if (o.from == o.to) continue;
                ov_.origins.push_back(std::move(o));
                const Origin& added = ov_.origins.back();
                boundary_curves_.emplace_back(SegmentTraits::X_monotone_curve_2(Segment(added.from, added.to)),
                                              Traits::Data_container(int(ov_.origins.size()) - 1));
            }
        }
        CGAL::insert(ov_.arr, boundary_curves_.begin(), boundary_curves_.end());
        boundary_curves_.clear();
        ov_.classify();
    }

    int add_boundary_origin(Halfedge h) {
        Origin o;
        o.kind = Kind::boundary;
        o.from = h->source()->point();
        o.to = h->target()->point();
        o.on_trace = region_.has(h, Kind::trace);
        ov_.origins.push_back(std::move(o));
        return int(ov_.origins.size()) - 1;
    }

    bool thinner_than_rounding(const std::vector<Vec2>& poly) const {
        double perimeter = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i) perimeter += norm(poly[(i + 1) % poly.size()] - poly[i]);
        return std::abs(signed_area(poly)) <= tol_ * perimeter;
    }

    /// Within the rounding scale of the rock block's boundary.
    bool on_boundary(Vec2 p) const { return boundary_->distance_within(p, tol_) <= tol_; }

    /// A point of a rounded piece as the exact point it stands for: itself inside
    /// the block; on its boundary, the boundary's vertex it was rounded from, or its
    /// exact projection on the nearest boundary edge (a vertex a collapse slid along it).
    Point onto_boundary(Vec2 p) const {
        int best = -1;
        double best_d = tol_;
        Box2 b;
        b.add(p - Vec2{tol_, tol_});
        b.add(p + Vec2{tol_, tol_});
        boundary_->for_each_near(b, [&](int e) {
            const auto& [s, t] = boundary_->segments()[std::size_t(e)];
            const double d = distance_to_segment(p, s, t);
            if (d <= best_d) best = e, best_d = d;
        });
        if (best < 0) return exact(p);
        const auto& [s, t] = boundary_exact_[std::size_t(best)];
        if (rounded(s) == p) return s;
        if (rounded(t) == p) return t;
        const Point q = exact(p);
        const EK::Vector_2 d = t - s;
        const FT u = ((q - s) * d) / d.squared_length();
        if (!CGAL::is_positive(u)) return s;
        if (u >= FT(1)) return t;
        return s + d * u;
    }

    bool is_block(Face f) const { return !f->is_unbounded() && f->data().inside == 1 && f->data().block; }

    /// Each face takes the cell on its side of the cell edges on its boundary (the
    /// one along most of their length: laid again after a collapse, two pieces'
    /// edges can meet a rounding apart, leaving a face a stub of a third cell's edge);
    /// a face with none lies inside one cell, found by a point of it. Faces where
    /// cells kept whole lie are not blocks.
    void label_faces(const Cells& cells, const std::vector<char>& near) {
        std::vector<std::pair<int, double>> votes;
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f) {
            if (f->is_unbounded() || f->data().inside != 1) continue;
            votes.clear();
            for_each_boundary(f, [&](Halfedge h) {
                int side = -1;
                ov_.each_origin(h, [&](const Origin& o) {
                    if (side < 0 && o.kind == Kind::cell) side = Overlay::same_direction(h, o) ? o.left : o.right;
                });
                if (side < 0) return;
                const auto it = std::find_if(votes.begin(), votes.end(), [&](const auto& v) { return v.first == side; });
                if (it == votes.end()) votes.push_back({side, approx_length(h)});
                else it->second += approx_length(h);
            });
            int cell = -1;
            double longest = -1.0;
            for (const auto& [c, length] : votes)
                if (length > longest) cell = c, longest = length;
            if (cell < 0 && !cells.empty()) {
                // No cell edge: the face lies in one cell near the block's edges.
                const auto loops = loops_of(f->outer_ccb());
                const auto ring = std::max_element(loops.begin(), loops.end(), [](const auto& a, const auto& b) {
                    return twice_area(a) < twice_area(b);
                });
                const std::vector<Vec2> r = rounded_ring(*ring);
                std::vector<Vec2> obstacles;
                for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h)
                    for (const auto& l : loops_of(*h))
                        for (Vec2 q : rounded_ring(l)) obstacles.push_back(q);
                if (r.size() >= 3) {
                    const Vec2 q = interior_point(r, obstacles);
                    for (std::size_t c = 0; c < cells.size() && cell < 0; ++c)
                        if (near[c] && cells[c].size() >= 3 && point_in_polygon(q, cells[c])) cell = int(c);
                }
            }
            FaceData d = f->data();
            d.cell = cell;
            d.block = cell < 0 || whole_[std::size_t(cell)] == 0;
            f->set_data(d);
        }
    }

    /// Traces ending inside a block (vertices of degree 1) carried on along their
    /// line to the first edge they meet.
    bool extend_tips(CutStats& stats) {
        std::vector<Vertex> tips;
        for (auto v = ov_.arr.vertices_begin(); v != ov_.arr.vertices_end(); ++v)
            if (v->degree() == 1) tips.push_back(v);
        bool changed = false;
        for (Vertex v : tips) {
            if (v->degree() != 1) continue;
            const Halfedge in(v->incident_halfedges()); // its target is v
            if (!is_block(in->face())) continue;
            const Point tip = v->point();
            const auto hit = first_hit(in->face(), tip, tip - in->source()->point());
            if (!hit) bug("a trace's tip found no edge ahead of it");
            Origin o;
            o.kind = Kind::bridge;
            o.from = tip;
            o.to = *hit;
            ov_.insert_now(std::move(o));
            ++stats.rock_bridges;
            changed = true;
        }
        return changed;
    }

    /// The first hole of a block (a loop of its boundary walk that runs clockwise,
    /// or a walk of its own inside it); empty if it has none.
    static std::vector<Halfedge> hole_of(Face f) {
        for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h) {
            std::vector<Halfedge> loop;
            auto c = *h;
            do loop.push_back(Halfedge(c));
            while (++c != *h);
            return loop;
        }
        for (auto& loop : loops_of(f->outer_ccb()))
            if (CGAL::is_negative(twice_area(loop))) return loop;
        return {};
    }

    /// Opens every hole: the vertical line through the middle of the hole's x-range
    /// (moved off the block's vertices), from the hole's top up and from its bottom
    /// down to the next edges of the block.
    bool cut_holes(CutStats& stats) {
        bool changed = false;
        std::vector<Face> work;
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f)
            if (is_block(f)) work.push_back(f);
        for (std::size_t guard = 0; !work.empty(); ++guard) {
            if (guard > 1000000) bug("holes kept appearing");
            const Face f = work.back();
            const std::vector<Halfedge> hole = hole_of(f);
            if (hole.empty()) {
                work.pop_back();
                continue;
            }
            FT xmin = hole.front()->source()->point().x(), xmax = xmin;
            for (Halfedge h : hole) {
                const FT& x = h->source()->point().x();
                if (x < xmin) xmin = x;
                if (x > xmax) xmax = x;
            }
            if (!(xmin < xmax)) bug("a hole without width");
            std::vector<FT> xs;
            for_each_boundary(f, [&](Halfedge h) { xs.push_back(h->source()->point().x()); });
            auto on_vertex = [&](const FT& x) { return std::any_of(xs.begin(), xs.end(), [&](const FT& v) { return v == x; }); };
            FT xc = (xmin + xmax) / 2;
            for (int m = 3; on_vertex(xc); ++m) {
                if (m > 64) bug("no vertical line clear of the vertices");
                for (int j = 1; j < m && on_vertex(xc = xmin + (xmax - xmin) * FT(j) / FT(m)); ++j) {
                }
            }
            std::optional<FT> top, bottom;
            for (Halfedge h : hole) {
                const Point& p = h->source()->point();
                const Point& q = h->target()->point();
                if (!((p.x() < xc && xc < q.x()) || (q.x() < xc && xc < p.x()))) continue;
                const FT y = p.y() + (xc - p.x()) * (q.y() - p.y()) / (q.x() - p.x());
                if (!top || *top < y) top = y;
                if (!bottom || y < *bottom) bottom = y;
            }
            if (!top) bug("the line through a hole does not cross it");
            std::vector<Origin> cuts;
            for (const auto& [y, up] : {std::pair{*top, 1}, std::pair{*bottom, -1}}) {
                const Point from(xc, y);
                const auto hit = first_hit(f, from, EK::Vector_2(0, up));
                if (!hit) bug("a cut from a hole found no edge");
                Origin o;
                o.kind = Kind::cut;
                o.from = from;
                o.to = *hit;
                cuts.push_back(std::move(o));
            }
            // The face splits: look at all blocks again (few faces have holes).
            for (auto& o : cuts) ov_.insert_now(std::move(o));
            work.clear();
            for (auto g = ov_.arr.faces_begin(); g != ov_.arr.faces_end(); ++g)
                if (is_block(g) && (g->number_of_inner_ccbs() > 0 || !hole_of(g).empty())) work.push_back(g);
            ++stats.hole_cuts;
            changed = true;
        }
        return changed;
    }

    /// An edge a merge may take away: a cell edge only, not the rock block's
    /// boundary (a trace), a rock bridge or a cut opening a hole (which would close
    /// the hole again).
    bool removable(Halfedge h) const {
        bool cell_only = true;
        ov_.each_origin(h, [&](const Origin& o) { cell_only = cell_only && o.kind == Kind::cell; });
        return cell_only;
    }

    bool too_small(Face f) const {
        if (!is_block(f) || f->data().stuck) return false;
        const bool gap = has_cells_ && !fanned_ && f->data().cell < 0; // covered by no cell
        return gap || approx_area(f) < min_area_ || !simple_when_rounded(f);
    }

    /// Blocks too small (or gaps no cell covers, or whose rounded polygon is not
    /// simple) merged into the neighbour they share most removable boundary with.
    bool merge_small(CutStats& stats) {
        std::vector<Face> work;
        for (auto f = ov_.arr.faces_begin(); f != ov_.arr.faces_end(); ++f)
            if (too_small(f)) work.push_back(f);
        const bool changed = !work.empty();
        while (!work.empty()) {
            const Face small = work.back();
            work.pop_back();
            if (!too_small(small)) continue;
            const auto into_found = neighbour_sharing_most(
                small, [&](Halfedge h) { return is_block(h->twin()->face()) && removable(h); });
            if (!into_found) {
                FaceData d = small->data();
                d.stuck = true;
                small->set_data(d);
                ++stats.slivers_left;
                continue;
            }
            const Face into = *into_found;
            const FaceData keep = into->data();
            std::vector<Halfedge> between;
            for_each_boundary(small, [&](Halfedge h) {
                if (h->twin()->face() == into && removable(h)) between.push_back(h);
            });
            Face merged = into;
            for (Halfedge h : between) merged = ov_.arr.remove_edge(h);
            merged->set_data(keep);
            remove_cell_antennas(merged);
            std::erase_if(work, [&](Face g) { return g == small || g == into; });
            if (too_small(merged)) work.push_back(merged);
            ++stats.merged_slivers;
        }
        return changed;
    }

    /// Removes the edges a merge left with the block on both sides (pieces of cell
    /// edges), which would make its polygon touch itself.
    void remove_cell_antennas(Face f) {
        for (bool again = true; again;) {
            again = false;
            Halfedge antenna;
            for_each_boundary(f, [&](Halfedge h) {
                if (!again && h->twin()->face() == f && removable(h)) antenna = h, again = true;
            });
            if (again) ov_.arr.remove_edge(antenna);
        }
    }

    bool simple_when_rounded(Face f) const {
        for (const auto& l : loops_of(f->outer_ccb())) {
            if (!CGAL::is_positive(twice_area(l))) continue;
            const auto r = rounded_ring(l);
            if (r.size() < 3 || signed_area(r) <= 0.0 || !cgal::is_simple(r)) return false;
        }
        return true;
    }

    Overlay ov_;
    const Overlay& region_;
    Face rock_;
    double min_area_, tol_;
    std::unique_ptr<SegmentGrid> boundary_;
    std::vector<std::pair<Point, Point>> boundary_exact_; ///< the grid's segments, exactly
    std::vector<Traits::X_monotone_curve_2> boundary_curves_; ///< the rock block's, until add_cells inserts them
    const Cells* cells_ = nullptr;
    std::vector<char> whole_; ///< per cell: 1 kept whole inside, 2 wholly outside, 0 cut
    bool has_cells_ = false;
    bool fanned_ = false;
};

} // namespace

// ---------------------------------------------------------------------------
struct RegionCut::Impl {
    Overlay ov;
    std::vector<Face> faces;
    std::vector<cgal::PolygonWithHoles> rounded;
    double min_area = 0, min_face_area = 0, tol = 0;
    int merged = 0;
    double merged_trace = 0.0;

    /// Rock blocks under min_face_area merged into the inside neighbour they share the
    /// most trace with (that stretch of trace is lost).
    void merge_small_faces() {
        std::vector<Face> work;
        for (auto f = ov.arr.faces_begin(); f != ov.arr.faces_end(); ++f)
            if (f->data().inside == 1 && approx_area(f) < min_face_area) work.push_back(f);
        while (!work.empty()) {
            const Face f = work.back();
            work.pop_back();
            if (f->data().inside != 1 || approx_area(f) >= min_face_area) continue;
            const auto into_found =
                neighbour_sharing_most(f, [](Halfedge h) { return h->twin()->face()->data().inside == 1; });
            if (!into_found) continue; // the region itself is that small
            const Face into = *into_found;
            std::vector<Halfedge> between;
            for_each_boundary(f, [&](Halfedge h) {
                if (h->twin()->face() == into) between.push_back(h);
            });
            const FaceData keep = into->data();
            Face merged_face = into;
            for (Halfedge h : between) {
                if (ov.has(h, Kind::trace)) merged_trace += approx_length(h);
                merged_face = ov.arr.remove_edge(h);
            }
            merged_face->set_data(keep);
            ++merged;
            // Faces merged away are no longer faces: drop them from the work list.
            std::erase_if(work, [&](Face g) { return g == f || g == into; });
            if (approx_area(merged_face) < min_face_area) work.push_back(merged_face);
        }
    }
};

namespace {

/// The domain's rings as boundary origins on the overlay, outer rings
/// counter-clockwise and holes clockwise; the box they span.
Box2 queue_domain_boundary(Overlay& ov, const cgal::Domain& domain) {
    Box2 box;
    auto ring = [&](std::vector<Vec2> r, bool outer) {
        if ((signed_area(r) > 0) != outer) std::reverse(r.begin(), r.end());
        for (std::size_t i = 0; i < r.size(); ++i) {
            box.add(r[i]);
            Origin o;
            o.kind = Kind::boundary;
            o.from = exact(r[i]);
            o.to = exact(r[(i + 1) % r.size()]);
            ov.queue(std::move(o));
        }
    };
    for (const auto& p : domain) {
        ring(p.outer, true);
        for (const auto& h : p.holes) ring(h, false);
    }
    return box;
}

/// The domain's edges, outer rings and holes.
std::vector<std::pair<Vec2, Vec2>> domain_edges(const cgal::Domain& domain) {
    std::vector<std::pair<Vec2, Vec2>> edges;
    for (const auto& p : domain) {
        auto add = [&](const std::vector<Vec2>& r) {
            for (std::size_t i = 0; i < r.size(); ++i) edges.push_back({r[i], r[(i + 1) % r.size()]});
        };
        add(p.outer);
        for (const auto& h : p.holes) add(h);
    }
    return edges;
}

EK::Line_2 line_of(const CutTrace& t) { return EK::Line_2(exact(t.line_a), exact(t.line_b)); }

std::optional<Point> meet(const EK::Line_2& l, const EK::Line_2& l2) {
    const auto x = CGAL::intersection(l, l2);
    if (x)
        if (const Point* p = boost::get<Point>(&*x)) return *p;
    return std::nullopt;
}

/// A trace's ends, exactly: where its line meets that of the trace it ends at, or
/// of the region's edge it was clipped at (the region's edges, to put a clipped
/// fracture's end exactly on the one it crosses: the rounded clip point lies off
/// both lines by an ulp); else as given.
class TraceEnds {
public:
    TraceEnds(std::span<const CutTrace> traces, std::vector<std::pair<Vec2, Vec2>> edges, double cell, double tol)
        : traces_(traces), edges_(std::move(edges)), boundary_(edges_, cell), tol_(tol) {}

    Point operator()(const CutTrace& t, bool b) const {
        const int at = b ? t.b_at : t.a_at;
        const Vec2 given = b ? t.b : t.a;
        if (at >= 0 && at < int(traces_.size()))
            if (const auto p = meet(line_of(t), line_of(traces_[std::size_t(at)]))) return *p;
        if (at == CutTrace::on_boundary)
            if (const auto p = on_region_edge(t, given)) return *p;
        return exact(given);
    }

private:
    /// Where the trace's line meets that of the region's edge nearest the given
    /// end (within the tolerance).
    std::optional<Point> on_region_edge(const CutTrace& t, Vec2 given) const {
        int best = -1;
        double best_d = INFINITY;
        Box2 near;
        near.add(given - Vec2{tol_, tol_});
        near.add(given + Vec2{tol_, tol_});
        boundary_.for_each_near(near, [&](int e) {
            const double d = distance_to_segment(given, edges_[std::size_t(e)].first, edges_[std::size_t(e)].second);
            if (d < best_d) best = e, best_d = d;
        });
        if (best >= 0 && best_d <= tol_)
            return meet(line_of(t), EK::Line_2(exact(edges_[std::size_t(best)].first), exact(edges_[std::size_t(best)].second)));
        return std::nullopt;
    }

    std::span<const CutTrace> traces_;
    std::vector<std::pair<Vec2, Vec2>> edges_;
    SegmentGrid boundary_;
    double tol_;
};

} // namespace

RegionCut::RegionCut(const cgal::Domain& domain, std::span<const CutTrace> traces, double min_area,
                     double min_face_area, double tol)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.min_area = min_area;
    m.min_face_area = min_face_area;
    m.tol = tol;
    const Box2 box = queue_domain_boundary(m.ov, domain);
    const TraceEnds end_of(traces, domain_edges(domain), std::max(box.width(), box.height()) / 64.0, tol);
    for (const CutTrace& t : traces) {
        Origin o;
        o.kind = Kind::trace;
        o.from = end_of(t, false);
        o.to = end_of(t, true);
        m.ov.queue(std::move(o));
    }
    m.ov.flush();
    m.ov.classify();
    if (min_face_area > 0) m.merge_small_faces();
    for (auto f = m.ov.arr.faces_begin(); f != m.ov.arr.faces_end(); ++f)
        if (!f->is_unbounded() && f->data().inside == 1) {
            m.faces.push_back(f);
            m.rounded.push_back(rounded_face(f));
        }
}

RegionCut::~RegionCut() = default;

int RegionCut::face_count() const { return int(impl_->faces.size()); }
const cgal::PolygonWithHoles& RegionCut::face(int k) const { return impl_->rounded[std::size_t(k)]; }
int RegionCut::merged_faces() const { return impl_->merged; }
double RegionCut::merged_trace_length() const { return impl_->merged_trace; }

bool RegionCut::plain(int k) const {
    const Face f = impl_->faces[std::size_t(k)];
    if (f->number_of_inner_ccbs() > 0) return false;
    const auto loops = loops_of(f->outer_ccb());
    if (loops.size() != 1) return false;
    for (Halfedge h : loops.front())
        if (h->twin()->face() == f) return false;
    std::vector<Vec2> ring;
    for (Halfedge h : loops.front()) ring.push_back(rounded(h->source()->point()));
    for (std::size_t i = 0; i < ring.size(); ++i)
        if (ring[i] == ring[(i + 1) % ring.size()]) return false;
    return true;
}

std::vector<SegmentSpec> RegionCut::real_segments() const {
    std::vector<SegmentSpec> separating, dangling;
    for (auto e = impl_->ov.arr.edges_begin(); e != impl_->ov.arr.edges_end(); ++e) {
        if (!impl_->ov.has(e, Kind::trace)) continue;
        const Face f1 = e->face(), f2 = e->twin()->face();
        if (f1->data().inside != 1 || f2->data().inside != 1) continue;
        const SegmentSpec s{rounded(e->source()->point()), rounded(e->target()->point())};
        if (s.a == s.b) continue;
        (f1 == f2 ? dangling : separating).push_back(s);
    }
    separating.insert(separating.end(), dangling.begin(), dangling.end());
    return separating;
}

FaceFill RegionCut::clip(int k, const Cells& cells) const {
    FaceCut cut(impl_->ov, impl_->faces[std::size_t(k)], impl_->min_area, impl_->tol, false);
    cut.add_cells(cells, impl_->rounded[std::size_t(k)]);
    return cut.pieces();
}

FaceFill RegionCut::blocks(int k, const Cells& cells, bool fitted, const Collapse& collapse,
                           const CentreOf& centre_of, CutStats& stats) const {
    const std::size_t kk = std::size_t(k);
    const cgal::PolygonWithHoles& face = impl_->rounded[kk];
    const Face rock = impl_->faces[kk];
    bool antennas = false; // traces ending inside the rock block
    for_each_boundary(rock, [&](Halfedge h) { antennas = antennas || h->twin()->face() == rock; });
    // First as in a rock block no trace ends in: the cells cut to it and their
    // short edges collapsed. Then the collapsed pieces are laid again with the
    // traces that end inside, and the rules applied: they change only the blocks
    // those traces cut.
    auto cut = std::make_unique<FaceCut>(impl_->ov, rock, impl_->min_area, impl_->tol, fitted);
    cut->add_cells(cells, face, fitted);
    int collapsed = 0;
    Cells pieces;
    std::vector<int> parent_of; // of each piece: its cell
    if (collapse || (antennas && !fitted)) {
        FaceFill p = cut->pieces();
        if (collapse) collapsed = collapse(p.polygons);
        if (!centre_of && !antennas && !cut->needs_rules()) {
            p.collapsed_edges = collapsed;
            return p;
        }
        if (collapsed > 0) {
            // The collapse moved vertices: the pieces laid again, exactly.
            pieces = std::move(p.polygons);
            parent_of = std::move(p.parent);
            cut = std::make_unique<FaceCut>(impl_->ov, rock, impl_->min_area, impl_->tol, true);
            cut->add_cells(pieces, face, true);
        } else if (antennas && !fitted) {
            cut->add_antennas();
        }
    }
    FaceFill whole_fans;
    if (centre_of && (!cells.empty())) whole_fans = cut->fan(centre_of);
    cut->apply_rules(stats);
    FaceFill fill = cut->pieces();
    fill.collapsed_edges = collapsed;
    if (!parent_of.empty() && !centre_of) {
        // Back from pieces to the cells they came from; a block no piece covered
        // gets a parent of its own.
        int fresh = parent_of.empty() ? 0 : *std::max_element(parent_of.begin(), parent_of.end()) + 1;
        for (int& p : fill.parent) p = p < int(parent_of.size()) ? parent_of[std::size_t(p)] : fresh++;
    }
    for (std::size_t i = 0; i < whole_fans.polygons.size(); ++i) {
        fill.polygons.push_back(std::move(whole_fans.polygons[i]));
        fill.parent.push_back(whole_fans.parent[i]);
    }
    return fill;
}

} // namespace bbm::meshing::detail
