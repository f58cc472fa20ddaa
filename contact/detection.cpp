#include "contact/detection.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace bbm::contact {
namespace {

struct EdgeFrame {
    double s;   ///< position along the edge, 0 at its start, 1 at its end
    double gap; ///< signed distance along the outward normal
};

EdgeFrame frame(Vec2 x, Vec2 p, Vec2 q) {
    const Vec2 d = q - p;
    const double l2 = norm2(d), l = std::sqrt(l2);
    return {dot(x - p, d) / l2, cross(d, x - p) / -l};
}

int prev_vertex(const std::uint32_t* first, int block, int v) {
    return v == int(first[block]) ? int(first[block + 1]) - 1 : v - 1;
}

} // namespace

std::vector<Junction> find_junctions(const std::vector<Vec2>& vertex, const std::vector<std::uint32_t>& first,
                                     const std::vector<std::uint64_t>& joined, double eps) {
    std::vector<Junction> out;
    const int nb = int(first.size()) - 1;
    if (nb < 2) return out;
    // Vertices in a uniform grid of about one edge per cell.
    Box2 all;
    double edges = 0.0;
    std::vector<int> owner(vertex.size());
    for (int k = 0; k < nb; ++k)
        for (std::uint32_t v = first[k]; v < first[k + 1]; ++v) {
            owner[v] = k;
            all.add(vertex[v]);
            edges += norm(vertex[next_vertex(first.data(), k, int(v))] - vertex[v]);
        }
    const double cell = std::max(edges / double(vertex.size()), 1e-12);
    const long nx = std::clamp(long(all.width() / cell) + 1, 1L, 1L << 20);
    auto cx = [&](double x) { return std::clamp(long((x - all.lo.x) / cell), 0L, nx - 1); };
    const long ny = std::clamp(long(all.height() / cell) + 1, 1L, 1L << 20);
    auto cy = [&](double y) { return std::clamp(long((y - all.lo.y) / cell), 0L, ny - 1); };
    std::unordered_map<long, std::vector<int>> grid;
    for (int v = 0; v < int(vertex.size()); ++v) grid[cy(vertex[v].y) * nx + cx(vertex[v].x)].push_back(v);
    for (int k = 0; k < nb; ++k)
        for (std::uint32_t e = first[k]; e < first[k + 1]; ++e) {
            const int e1 = next_vertex(first.data(), k, int(e));
            const Vec2 p = vertex[e], d = vertex[e1] - p;
            const double l2 = norm2(d);
            if (l2 <= 0.0) continue;
            Box2 box;
            box.add(p);
            box.add(vertex[e1]);
            for (long j = cy(box.lo.y - eps); j <= cy(box.hi.y + eps); ++j)
                for (long i = cx(box.lo.x - eps); i <= cx(box.hi.x + eps); ++i) {
                    const auto it = grid.find(j * nx + i);
                    if (it == grid.end()) continue;
                    for (int v : it->second) {
                        if (owner[v] == k) continue;
                        const double s = dot(vertex[v] - p, d) / l2;
                        if (s < -1e-9 || s > 1.0 + 1e-9 || norm(vertex[v] - (p + s * d)) > eps) continue;
                        if (std::binary_search(joined.begin(), joined.end(), block_pair_key(owner[v], k))) continue;
                        out.push_back({v, k, int(e), e1, std::clamp(s, 0.0, 1.0)});
                    }
                }
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end(),
                          [](const Junction& a, const Junction& b) { return a.vertex == b.vertex && a.block == b.block; }),
              out.end());
    return out;
}

DetectionResult update_contacts(Contacts& c, const DetectionInput& in) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    DetectionResult res;

    // 1–2. Transfer along the edge block's boundary, and removal of separated
    // unbonded contacts.
    std::vector<std::uint8_t> drop(c.size(), 0);
    auto is_active = [&](int k) { return !in.active || in.active[k]; };
    for (int i = 0; i < c.size(); ++i) {
        const int A = c.vertex_block[i], B = c.edge_block[i];
        if ((in.removed && (in.removed[A] || in.removed[B]))) {
            drop[i] = 1;
            continue;
        }
        if (!is_active(A) && !is_active(B)) continue;
        const Vec2 x = b.vertex[c.vertex_id[i]];
        EdgeFrame f = frame(x, b.vertex[c.edge_id[i]], b.vertex[c.edge_end[i]]);
        if (c.history[i].bonded) continue; // intact joints keep their edges (contacts.hpp)
        const double len = 1.0 / b.inv_edge_length[c.edge_id[i]];
        if (std::max(-f.s, f.s - 1.0) * len > tol) {
            const bool back = f.s < 0.0;
            const int e0 = back ? prev_vertex(b.first, B, c.edge_id[i]) : c.edge_end[i];
            const int e1 = back ? c.edge_id[i] : next_vertex(b.first, B, c.edge_end[i]);
            const EdgeFrame g = frame(x, b.vertex[e0], b.vertex[e1]);
            if (g.s >= 0.0 && g.s <= 1.0 && g.gap > -tol) {
                c.edge_id[i] = e0;
                c.edge_end[i] = e1;
                f = g;
                ++res.transferred;
            }
        }
        const double beyond = std::max(-f.s, f.s - 1.0) / b.inv_edge_length[c.edge_id[i]];
        if (f.gap > tol || beyond > 2.0 * tol) drop[i] = 1;
    }
    for (int i = 0; i < c.size(); ++i) {
        if (!drop[i]) continue;
        ++res.removed;
        res.removed_tensile += c.history[i].broken == JointState::broken_tension;
        res.removed_shear += c.history[i].broken == JointState::broken_shear;
    }
    if (res.removed > 0) c.remove_if_flagged(drop);

    // Existing contact points per block pair (either way round).
    std::unordered_map<std::uint64_t, std::vector<Vec2>> existing;
    for (int i = 0; i < c.size(); ++i)
        if (is_active(c.vertex_block[i]) || is_active(c.edge_block[i]))
            existing[block_pair_key(c.vertex_block[i], c.edge_block[i])].push_back(b.vertex[c.vertex_id[i]]);

    // 3. Broad phase: inflated boxes in a uniform grid. A block with many vertices
    // (a deformable block's boundary, hundreds of nodes) enters as chunks of at
    // most `chunk` consecutive vertices, each with its own box: otherwise its one
    // box, as large as the model, would pair it with every block and the narrow
    // phase would test every vertex against all its edges.
    constexpr std::uint32_t chunk = 16;
    struct Piece {
        int block;
        std::uint32_t v0, v1; ///< vertices [v0, v1) and the edges they start
        Box2 box;
    };
    const int nb = in.block_count;
    std::vector<Piece> pieces;
    Box2 all;
    double mean_size = 0.0;
    int active = 0;
    for (int k = 0; k < nb; ++k) {
        if (in.removed && in.removed[k]) continue;
        const std::uint32_t first = b.first[k], last = b.first[k + 1];
        for (std::uint32_t v0 = first; v0 < last; v0 += chunk) {
            Piece pc{k, v0, std::min(last, v0 + chunk), {}};
            // An edge's box holds both its ends: the next vertex closes it.
            for (std::uint32_t v = pc.v0; v < pc.v1; ++v) {
                pc.box.add(b.vertex[v]);
                pc.box.add(b.vertex[next_vertex(b.first, k, int(v))]);
            }
            pc.box.lo -= Vec2{tol, tol};
            pc.box.hi += Vec2{tol, tol};
            all.add(pc.box.lo);
            all.add(pc.box.hi);
            mean_size += pc.box.width() + pc.box.height();
            pieces.push_back(pc);
        }
        ++active;
    }
    if (active < 2) return res;
    const double cell = mean_size / double(pieces.size());
    const int nx = std::clamp(int(all.width() / cell) + 1, 1, 1 << 14);
    const int ny = std::clamp(int(all.height() / cell) + 1, 1, 1 << 14);
    auto cx = [&](double x) { return std::clamp(int((x - all.lo.x) / cell), 0, nx - 1); };
    auto cy = [&](double y) { return std::clamp(int((y - all.lo.y) / cell), 0, ny - 1); };
    std::vector<std::vector<int>> grid(std::size_t(nx) * ny);
    for (int k = 0; k < int(pieces.size()); ++k) {
        const Box2& bx = pieces[k].box;
        for (int j = cy(bx.lo.y); j <= cy(bx.hi.y); ++j)
            for (int i = cx(bx.lo.x); i <= cx(bx.hi.x); ++i) grid[std::size_t(j) * nx + i].push_back(k);
    }

    // Narrow phase for one ordered pair of pieces: vertices of P against edges of Q.
    auto try_vertices = [&](const Piece& P, const Piece& Q) {
        const int A = P.block, B = Q.block;
        for (std::uint32_t v = P.v0; v < P.v1; ++v) {
            const Vec2 x = b.vertex[v];
            if (x.x < Q.box.lo.x || x.x > Q.box.hi.x || x.y < Q.box.lo.y || x.y > Q.box.hi.y) continue;
            int best = -1;
            double best_gap = INFINITY;
            for (std::uint32_t e = Q.v0; e < Q.v1; ++e) {
                const int e1 = next_vertex(b.first, B, int(e));
                const EdgeFrame f = frame(x, b.vertex[e], b.vertex[e1]);
                const double len = 1.0 / b.inv_edge_length[e];
                const double beyond = std::max({0.0, -f.s, f.s - 1.0}) * len;
                if (f.gap > tol || f.gap < -tol || beyond > tol) continue;
                const double dist = std::abs(f.gap) + beyond;
                if (dist < best_gap) best_gap = dist, best = int(e);
            }
            if (best < 0) continue;
            if (in.junctions) {
                // Still on the point it touched in the tessellation?
                const auto& J = *in.junctions;
                const auto it = std::lower_bound(J.begin(), J.end(), Junction{int(v), B, 0, 0, 0.0});
                if (it != J.end() && it->vertex == int(v) && it->block == B) {
                    const Vec2 touched = b.vertex[it->e0] + it->s * (b.vertex[it->e1] - b.vertex[it->e0]);
                    if (norm(x - touched) <= tol) continue;
                }
            }
            auto& points = existing[block_pair_key(A, B)];
            bool known = false;
            for (Vec2 p : points) known = known || norm(p - x) <= tol;
            if (known) continue;
            const int e1 = next_vertex(b.first, B, best);
            const Vec2 tb = b.inv_edge_length[best] * (b.vertex[e1] - b.vertex[best]);
            // The vertex's share: half of its adjacent edge that lies most along B's edge.
            const int vp = prev_vertex(b.first, A, int(v)), vn = next_vertex(b.first, A, int(v));
            const Vec2 ep = b.vertex[vp] - x, en = b.vertex[vn] - x;
            const double l = 0.5 * (std::abs(cross(tb, ep)) / norm(ep) < std::abs(cross(tb, en)) / norm(en) ? norm(ep) : norm(en));
            JointHistory h;
            h.bonded = false;
            const Vec2 n{tb.y, -tb.x};
            const double s_on = dot(x - b.vertex[best], tb) * b.inv_edge_length[best];
            const Vec2 vr = vertex_velocity(b, A, int(v), x) - edge_velocity(b, B, best, e1, s_on, x);
            h.un = frame(x, b.vertex[best], b.vertex[e1]).gap - dot(vr, n) * in.dt;
            c.add(A, int(v), B, best, e1, l, in.new_contact_property, h);
            points.push_back(x);
            ++res.created;
        }
    };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const auto& list = grid[std::size_t(j) * nx + i];
            for (std::size_t p = 0; p < list.size(); ++p)
                for (std::size_t q = p + 1; q < list.size(); ++q) {
                    const Piece *P = &pieces[list[p]], *Q = &pieces[list[q]];
                    if (P->block == Q->block) continue;
                    if (P->block > Q->block) std::swap(P, Q);
                    if (!is_active(P->block) && !is_active(Q->block)) continue;
                    const Box2 &ba = P->box, &bb = Q->box;
                    if (ba.hi.x < bb.lo.x || bb.hi.x < ba.lo.x || ba.hi.y < bb.lo.y || bb.hi.y < ba.lo.y) continue;
                    // Handle the pair once: in the cell holding the low corner of the overlap.
                    if (cx(std::max(ba.lo.x, bb.lo.x)) != i || cy(std::max(ba.lo.y, bb.lo.y)) != j) continue;
                    try_vertices(*P, *Q);
                    try_vertices(*Q, *P);
                }
        }
    return res;
}

} // namespace bbm::contact
