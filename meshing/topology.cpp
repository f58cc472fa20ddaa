// Vertex welding, short-edge collapse and joint records (blocks.hpp, steps 4–5).
#include "base/error.hpp"
#include "meshing/detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

namespace bbm::meshing::detail {

// ---------------------------------------------------------------------------
SegmentGrid::SegmentGrid(std::vector<std::pair<Vec2, Vec2>> segments, double cell_hint)
    : segments_(std::move(segments)) {
    for (const auto& [p, q] : segments_) box_.add(p), box_.add(q);
    if (segments_.empty()) return;
    const double span = std::max(box_.width(), box_.height());
    cell_ = std::max(cell_hint, span / 2048.0);
    if (!(cell_ > 0)) cell_ = 1.0;
    nx_ = std::max(1, int(box_.width() / cell_) + 1);
    ny_ = std::max(1, int(box_.height() / cell_) + 1);
    start_.assign(std::size_t(nx_) * ny_ + 1, 0);
    auto visit = [&](auto&& f) {
        for (int s = 0; s < int(segments_.size()); ++s) {
            const auto& [p, q] = segments_[s];
            for (int j = cy(std::min(p.y, q.y)); j <= cy(std::max(p.y, q.y)); ++j)
                for (int i = cx(std::min(p.x, q.x)); i <= cx(std::max(p.x, q.x)); ++i) f(j * nx_ + i, s);
        }
    };
    visit([&](int c, int) { ++start_[c + 1]; });
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    items_.resize(start_.back());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    visit([&](int c, int s) { items_[fill[c]++] = s; });
}

int SegmentGrid::cx(double x) const { return std::clamp(int((x - box_.lo.x) / cell_), 0, nx_ - 1); }
int SegmentGrid::cy(double y) const { return std::clamp(int((y - box_.lo.y) / cell_), 0, ny_ - 1); }

double SegmentGrid::distance_within(Vec2 q, double radius) const {
    Box2 b;
    b.add(q - Vec2{radius, radius});
    b.add(q + Vec2{radius, radius});
    double best = INFINITY;
    for_each_near(b, [&](int s) {
        best = std::min(best, distance_to_segment(q, segments_[s].first, segments_[s].second));
    });
    return best;
}

bool domain_contains(const cgal::Domain& d, Vec2 q) {
    for (const auto& p : d) {
        if (!point_in_polygon(q, p.outer)) continue;
        bool in_hole = false;
        for (const auto& h : p.holes) in_hole = in_hole || point_in_polygon(q, h);
        if (!in_hole) return true;
    }
    return false;
}

// ---------------------------------------------------------------------------
namespace {


std::uint64_t edge_key(int u, int v) {
    return (std::uint64_t(std::uint32_t(std::min(u, v))) << 32) | std::uint32_t(std::max(u, v));
}

} // namespace

namespace {

/// Cells welded into shared vertices (bit-identical coordinates are one vertex:
/// the Voronoi and clipping steps guarantee shared vertices are bit-identical),
/// with how many cells use each edge.
struct WeldedCells {
    std::unordered_map<Vec2, int, PointHash> index;
    std::vector<Vec2> pos;
    std::vector<std::vector<int>> polys;
    std::unordered_map<std::uint64_t, int> uses;

    explicit WeldedCells(const std::vector<std::vector<Vec2>>& polygons) : polys(polygons.size()) {
        for (std::size_t k = 0; k < polygons.size(); ++k)
            for (Vec2 p : polygons[k]) {
                auto [it, fresh] = index.try_emplace(p, int(pos.size()));
                if (fresh) pos.push_back(p);
                polys[k].push_back(it->second);
            }
        for (const auto& p : polys)
            for (std::size_t i = 0; i < p.size(); ++i) ++uses[edge_key(p[i], p[(i + 1) % p.size()])];
    }
    /// Twice the signed area of p with vertex `moved` at `at`.
    double area(const std::vector<int>& p, int moved, Vec2 at) const {
        double a2 = 0.0;
        for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
            const Vec2 a = p[j] == moved ? at : pos[p[j]], b = p[i] == moved ? at : pos[p[i]];
            a2 += cross(a, b);
        }
        return 0.5 * a2;
    }
};

/// Which vertices may move: 0 free, 1 on the face outline (slides along it), 2
/// fixed (an outline corner, or the end of a T-junction's edge). `t_junction`
/// gets the edges used once that are not on the outline.
std::vector<int> vertex_classes(const WeldedCells& w, const cgal::PolygonWithHoles& face, double min_edge,
                                std::unordered_set<std::uint64_t>& t_junction) {
    std::vector<int> cls(w.pos.size(), 0);
    // An edge used once lies on the face's outline, or is one side of a T-junction
    // (a brick's edge with the corners of the bricks of the next course on it): the
    // ends of such an edge stay put, as moving them would open the tiling.
    std::vector<std::pair<Vec2, Vec2>> rings;
    Box2 box;
    auto add_ring = [&](const std::vector<Vec2>& r) {
        for (std::size_t i = 0; i < r.size(); ++i) rings.push_back({r[i], r[(i + 1) % r.size()]}), box.add(r[i]);
    };
    add_ring(face.outer);
    for (const auto& h : face.holes) add_ring(h);
    const double tol = 1e-9 * std::max(box.width(), box.height());
    const SegmentGrid outline(rings, std::max(min_edge, tol));
    for (const auto& [key, n] : w.uses) {
        if (n != 1) continue;
        const int u = int(key >> 32), v = int(key & 0xffffffffu);
        if (outline.distance_within(0.5 * (w.pos[u] + w.pos[v]), tol) <= tol) {
            cls[u] = std::max(cls[u], 1), cls[v] = std::max(cls[v], 1);
        } else {
            t_junction.insert(key);
        }
    }
    for (std::uint64_t key : t_junction) cls[key >> 32] = cls[key & 0xffffffffu] = 2;
    auto mark_fixed = [&](const std::vector<Vec2>& ring) {
        for (Vec2 q : ring)
            if (auto it = w.index.find(q); it != w.index.end()) cls[it->second] = 2;
    };
    mark_fixed(face.outer);
    for (const auto& h : face.holes) mark_fixed(h);
    // A vertex on the outline within the rounding of one of its corners (a cell's
    // edge cut the outline there: the cut ends a rounding away from the corner) is
    // that corner: sliding it along one edge of the outline would cut the corner off.
    for (std::size_t v = 0; v < w.pos.size(); ++v) {
        if (cls[v] != 1) continue;
        Box2 b;
        b.add(w.pos[v] - Vec2{tol, tol});
        b.add(w.pos[v] + Vec2{tol, tol});
        outline.for_each_near(b, [&](int s) {
            const auto& [p, q] = outline.segments()[std::size_t(s)];
            if (norm(p - w.pos[v]) <= tol || norm(q - w.pos[v]) <= tol) cls[v] = 2;
        });
    }
    return cls;
}

/// A polygon with vertex `from` replaced by `to` (repeats dropped).
std::vector<int> merged_polygon(const std::vector<int>& p, int from, int to) {
    std::vector<int> r;
    for (int v : p) {
        const int w = (v == from) ? to : v;
        if (r.empty() || r.back() != w) r.push_back(w);
    }
    while (r.size() > 1 && r.front() == r.back()) r.pop_back();
    return r;
}

struct ShortEdge {
    double length;
    int u, v;
};

/// The edges shorter than min_edge, shortest first (ties by their vertices).
std::vector<ShortEdge> short_edges(const WeldedCells& w, double min_edge) {
    std::vector<ShortEdge> cand;
    for (const auto& [key, n] : w.uses) {
        const int u = int(key >> 32), v = int(key & 0xffffffffu);
        const double l = norm(w.pos[u] - w.pos[v]);
        if (l < min_edge) cand.push_back({l, u, v});
    }
    std::sort(cand.begin(), cand.end(), [](const ShortEdge& a, const ShortEdge& b) {
        return a.length < b.length || (a.length == b.length && (a.u < b.u || (a.u == b.u && a.v < b.v)));
    });
    return cand;
}

} // namespace

int collapse_short_edges(std::vector<std::vector<Vec2>>& polygons, const cgal::PolygonWithHoles& face,
                         double min_edge) {
    if (min_edge <= 0 || polygons.empty()) return 0;
    WeldedCells w(polygons);
    std::unordered_set<std::uint64_t> t_junction;
    const std::vector<int> cls = vertex_classes(w, face, min_edge, t_junction);
    std::vector<std::vector<int>> incident(w.pos.size());
    for (int k = 0; k < int(w.polys.size()); ++k)
        for (int v : w.polys[k]) incident[v].push_back(k);
    std::vector<int> alias(w.pos.size());
    std::iota(alias.begin(), alias.end(), 0);
    auto root = [&](int v) {
        while (alias[v] != v) v = alias[v] = alias[alias[v]];
        return v;
    };
    int collapsed = 0;
    for (const ShortEdge& c : short_edges(w, min_edge)) {
        int u = root(c.u), v = root(c.v);
        if (u == v || norm(w.pos[u] - w.pos[v]) >= min_edge) continue;
        if (cls[u] < cls[v]) std::swap(u, v); // u keeps its place unless both are free
        const bool on_outline = w.uses[edge_key(u, v)] == 1 && !t_junction.count(edge_key(u, v));
        if (cls[u] == 2 && cls[v] == 2) continue;
        if (cls[v] >= 1 && !on_outline) continue; // an outline vertex slides only along the outline
        const Vec2 target = (cls[u] == 0 && cls[v] == 0) || (cls[u] == 1 && cls[v] == 1)
                                ? 0.5 * (w.pos[u] + w.pos[v])
                                : w.pos[u];
        // Every polygon touching u or v must stay a polygon with positive area.
        bool ok = true;
        std::vector<int> touched = incident[u];
        touched.insert(touched.end(), incident[v].begin(), incident[v].end());
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        for (int k : touched) {
            const auto m = merged_polygon(w.polys[k], v, u);
            if (m.size() < 3 || !(w.area(m, u, target) > 0.25 * w.area(w.polys[k], -1, {}))) {
                ok = false;
                break;
            }
        }
        if (!ok) continue;
        auto count_edges = [&](int delta) {
            for (int k : touched)
                for (std::size_t i = 0; i < w.polys[k].size(); ++i)
                    w.uses[edge_key(w.polys[k][i], w.polys[k][(i + 1) % w.polys[k].size()])] += delta;
        };
        count_edges(-1);
        for (int k : touched) w.polys[k] = merged_polygon(w.polys[k], v, u);
        count_edges(+1);
        w.pos[u] = target;
        alias[v] = u;
        incident[u] = touched;
        ++collapsed;
    }
    for (std::size_t k = 0; k < polygons.size(); ++k) {
        polygons[k].clear();
        for (int v : w.polys[k]) polygons[k].push_back(w.pos[v]);
    }
    return collapsed;
}

// ---------------------------------------------------------------------------
namespace {

/// Names what a joint between two blocks is: an interface between regions, a
/// fracture of a set or a real joint (it lies on one of their traces), else by
/// the blocks' pattern.
class JointClassifier {
public:
    JointClassifier(const BlockAssembly& a, double tol, double cell)
        : a_(a), tol_(tol), real_(segments(a.real_segments), cell), fracture_(segments(a.fracture_traces), cell) {}

    void classify(JointRecord& j) const {
        if (a_.region[j.block_a] != a_.region[j.block_b]) {
            j.tag = JointTag::interface;
        } else if (const int hit = on_segment(fracture_, j.p0, j.p1); hit >= 0) {
            j.tag = JointTag::fracture;
            j.fracture_set = a_.fracture_trace_set[hit];
        } else if (on_segment(real_, j.p0, j.p1) >= 0) {
            j.tag = JointTag::real_joint;
        } else if (a_.pattern[j.block_a] == PatternSpec::Kind::trigon) {
            j.tag = a_.parent[j.block_a] == a_.parent[j.block_b] ? JointTag::radial : JointTag::peripheral;
        } else {
            j.tag = JointTag::inner;
        }
    }

private:
    template <class Segments>
    static std::vector<std::pair<Vec2, Vec2>> segments(const Segments& from) {
        std::vector<std::pair<Vec2, Vec2>> out;
        for (const auto& s : from) out.push_back({s.a, s.b});
        return out;
    }
    /// The segment of `g` that the joint p0p1 lies on (its middle on it, parallel), or −1.
    int on_segment(const SegmentGrid& g, Vec2 p0, Vec2 p1) const {
        const Vec2 m = 0.5 * (p0 + p1);
        int hit = -1;
        Box2 b;
        b.add(m);
        g.for_each_near(b, [&](int s) {
            const auto& [ra, rb] = g.segments()[s];
            if (hit < 0 && distance_to_segment(m, ra, rb) <= tol_ &&
                std::abs(cross(rb - ra, p1 - p0)) <= tol_ * norm(rb - ra))
                hit = s;
        });
        return hit;
    }

    const BlockAssembly& a_;
    double tol_;
    SegmentGrid real_, fracture_;
};

/// An edge of a block: its ends, the block and its index there.
struct BlockEdge {
    Vec2 p, q;
    int block, index;
};

/// Every block's edges, the box of the blocks and the edges' total length.
std::vector<BlockEdge> block_edges(const BlockAssembly& a, Box2& all, double& total) {
    std::vector<BlockEdge> edges;
    edges.reserve(a.points.size());
    for (int b = 0; b < a.block_count(); ++b) {
        const auto poly = a.block(b);
        for (int i = 0; i < int(poly.size()); ++i) {
            const Vec2 p = poly[i], q = poly[(i + 1) % poly.size()];
            edges.push_back({p, q, b, i});
            all.add(p);
            total += norm(q - p);
        }
    }
    return edges;
}

/// The joints of edge e1 with the edges of other blocks that run against it along
/// its line (within tol) and overlap it; each pair from its lower-numbered edge.
void add_joints_of_edge(BlockAssembly& a, const std::vector<BlockEdge>& edges, const SegmentGrid& grid,
                        const JointClassifier& classifier, double tol, int e1) {
    const BlockEdge& E = edges[e1];
    const Vec2 d = E.q - E.p;
    const double len = norm(d);
    if (len <= tol) return;
    const Vec2 t = d / len;
    Box2 b;
    b.add(E.p);
    b.add(E.q);
    int last = -1;
    grid.for_each_near(b, [&](int e2) {
        // A pair is visited from its lower-numbered edge only; the grid can
        // report the same neighbour from several cells, hence `last`.
        if (e2 <= e1 || e2 == last) return;
        const BlockEdge& F = edges[e2];
        if (F.block == E.block) return;
        const Vec2 f = F.q - F.p;
        if (dot(f, d) >= 0) return; // shared boundaries of two CCW polygons run opposite ways
        if (std::abs(cross(t, F.p - E.p)) > tol || std::abs(cross(t, F.q - E.p)) > tol) return;
        const double sp = dot(F.p - E.p, t), sq = dot(F.q - E.p, t);
        // F runs against E, so F.q is the start of the overlap along E.
        const double lo = std::max(0.0, sq), hi = std::min(len, sp);
        if (hi - lo <= tol) return;
        last = e2;
        JointRecord j;
        j.block_a = E.block;
        j.edge_a = E.index;
        j.block_b = F.block;
        j.edge_b = F.index;
        j.p0 = (sq > 0.0) ? F.q : E.p; // actual vertices, never re-rounded projections
        j.p1 = (sp < len) ? F.p : E.q;
        classifier.classify(j);
        a.joints.push_back(j);
    });
}

/// A pair of edges might be reported twice if the grid gave it from two cells
/// between other candidates: remove exact duplicates.
void remove_duplicate_joints(std::vector<JointRecord>& joints) {
    std::sort(joints.begin(), joints.end(), [](const JointRecord& x, const JointRecord& y) {
        return std::tie(x.block_a, x.edge_a, x.block_b, x.edge_b) <
               std::tie(y.block_a, y.edge_a, y.block_b, y.edge_b);
    });
    joints.erase(std::unique(joints.begin(), joints.end(),
                             [](const JointRecord& x, const JointRecord& y) {
                                 return x.block_a == y.block_a && x.edge_a == y.edge_a &&
                                        x.block_b == y.block_b && x.edge_b == y.edge_b;
                             }),
                 joints.end());
}

} // namespace

void build_joints(BlockAssembly& a) {
    a.joints.clear();
    const int nb = a.block_count();
    if (nb < 2) return;
    Box2 all;
    double total = 0.0;
    const std::vector<BlockEdge> edges = block_edges(a, all, total);
    const double tol = 1e-9 * std::max(all.width(), all.height());
    std::vector<std::pair<Vec2, Vec2>> segs;
    segs.reserve(edges.size());
    for (const auto& e : edges) segs.push_back({e.p, e.q});
    const double cell = 2.0 * total / double(edges.size());
    const SegmentGrid grid(std::move(segs), cell);

    const JointClassifier classifier(a, tol, cell);

    for (int e1 = 0; e1 < int(edges.size()); ++e1) add_joints_of_edge(a, edges, grid, classifier, tol, e1);
    remove_duplicate_joints(a.joints);
}

} // namespace bbm::meshing::detail
