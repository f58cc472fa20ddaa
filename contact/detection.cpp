#include "contact/detection.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <omp.h>
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

namespace {

bool known(const Detector& d, const Contacts& c, int vertex_block, int vertex, int edge_block, const DetectionInput& in) {
    // An existing contact of the pair (either way round) at this point? Searched
    // among the contacts of the block that has fewer.
    const Vec2 x = in.blocks.vertex[vertex];
    const double tol2 = in.tolerance * in.tolerance;
    const int a = vertex_block, b = edge_block;
    const bool from_a = c.block_first[a + 1] - c.block_first[a] <= c.block_first[b + 1] - c.block_first[b];
    const int own = from_a ? a : b, other = from_a ? b : a;
    for (int e = c.block_first[own]; e < c.block_first[own + 1]; ++e) {
        const int i = c.block_entry[e] >> 1;
        const int partner = (c.block_entry[e] & 1) ? c.vertex_block[i] : c.edge_block[i];
        if (partner != other || d.drop[i]) continue;
        if (norm2(in.blocks.vertex[c.vertex_id[i]] - x) <= tol2) return true;
    }
    return false;
}

Box2 current_box(const Detector::Piece& pc, const BlockView& b, double inflate) {
    // An edge's box holds both its ends: the next vertex closes it.
    Box2 box;
    for (std::uint32_t v = pc.v0; v < pc.v1; ++v) {
        box.add(b.vertex[v]);
        box.add(b.vertex[next_vertex(b.first, pc.block, int(v))]);
    }
    box.lo -= Vec2{inflate, inflate};
    box.hi += Vec2{inflate, inflate};
    return box;
}

/// The blocks as pieces, made again when the number of blocks changes. A block
/// with many vertices (a deformable block's boundary, hundreds of nodes) enters
/// as pieces of at most `chunk` consecutive vertices, each with its own box:
/// otherwise its one box, as large as the model, would pair it with every block
/// and the narrow phase would test every vertex against all its edges.
void split_into_pieces(Detector& d, const DetectionInput& in) {
    constexpr std::uint32_t chunk = 16;
    const BlockView& b = in.blocks;
    const int nb = in.block_count;
    if (int(d.block_piece.size()) != nb + 1) {
        d.pieces.clear();
        d.block_piece.assign(1, 0);
        for (int k = 0; k < nb; ++k) {
            for (std::uint32_t v0 = b.first[k]; v0 < b.first[k + 1]; v0 += chunk)
                d.pieces.push_back({k, v0, std::min(b.first[k + 1], v0 + chunk)});
            d.block_piece.push_back(int(d.pieces.size()));
        }
    }
}

/// Each piece's stored box: its current box inflated by the tolerance and the
/// margin (a tenth of the pieces' mean extent, at least four tolerances); the
/// grid's box around them. Returns the pieces' mean extent.
double store_piece_boxes(Detector& d, const DetectionInput& in) {
    const BlockView& b = in.blocks;
    const int np = int(d.pieces.size());
    d.stored.resize(np);
    d.grid_box = Box2{};
    double extent = 0.0;
    int counted = 0;
    for (int p = 0; p < np; ++p) {
        if (in.removed && in.removed[d.pieces[p].block]) continue;
        d.stored[p] = current_box(d.pieces[p], b, in.tolerance);
        extent += d.stored[p].width() + d.stored[p].height();
        ++counted;
    }
    extent /= std::max(1, 2 * counted);
    d.margin = std::max(4.0 * in.tolerance, 0.1 * extent);
    for (int p = 0; p < np; ++p) {
        if (in.removed && in.removed[d.pieces[p].block]) continue;
        d.stored[p].lo -= Vec2{d.margin, d.margin};
        d.stored[p].hi += Vec2{d.margin, d.margin};
        d.grid_box.add(d.stored[p].lo);
        d.grid_box.add(d.stored[p].hi);
    }
    return extent;
}

/// Visits the index of every grid cell the box covers.
template <class Visit>
inline void for_cells(const Detector& d, const Box2& bx, Visit&& visit) {
    const int i0 = std::clamp(int((bx.lo.x - d.grid_box.lo.x) / d.cell), 0, d.nx - 1);
    const int i1 = std::clamp(int((bx.hi.x - d.grid_box.lo.x) / d.cell), 0, d.nx - 1);
    const int j0 = std::clamp(int((bx.lo.y - d.grid_box.lo.y) / d.cell), 0, d.ny - 1);
    const int j1 = std::clamp(int((bx.hi.y - d.grid_box.lo.y) / d.cell), 0, d.ny - 1);
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) visit(std::size_t(j) * d.nx + i);
}

/// Counting sort of the pieces into the cells their stored boxes cover.
void sort_pieces_into_cells(Detector& d, const DetectionInput& in) {
    const int np = int(d.pieces.size());
    d.cell_first.assign(std::size_t(d.nx) * d.ny + 1, 0);
    for (int p = 0; p < np; ++p)
        if (!(in.removed && in.removed[d.pieces[p].block])) for_cells(d, d.stored[p], [&](std::size_t k) { ++d.cell_first[k + 1]; });
    for (std::size_t k = 0; k + 1 < d.cell_first.size(); ++k) d.cell_first[k + 1] += d.cell_first[k];
    d.cell_piece.resize(d.cell_first.back());
    for (int p = 0; p < np; ++p)
        if (!(in.removed && in.removed[d.pieces[p].block]))
            for_cells(d, d.stored[p], [&](std::size_t k) { d.cell_piece[d.cell_first[k]++] = p; });
    for (std::size_t k = d.cell_first.size() - 1; k > 0; --k) d.cell_first[k] = d.cell_first[k - 1];
    d.cell_first[0] = 0;
}

void build_grid(Detector& d, const DetectionInput& in) {
    split_into_pieces(d, in);
    const double extent = store_piece_boxes(d, in);
    d.cell = std::max(extent + 2.0 * d.margin, 1e-12);
    d.nx = std::clamp(int(d.grid_box.width() / d.cell) + 1, 1, 1 << 14);
    d.ny = std::clamp(int(d.grid_box.height() / d.cell) + 1, 1, 1 << 14);
    sort_pieces_into_cells(d, in);
    d.grid_valid = true;
}

/// The edge of Q nearest the vertex x, within the tolerance of its line and of
/// its ends; -1 if none.
inline int nearest_edge(Vec2 x, const Detector::Piece& Q, const BlockView& b, double tol) {
    const int B = Q.block;
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
    return best;
}

/// Still on the point vertex v touched block B at in the tessellation?
inline bool on_its_junction(const std::vector<Junction>& J, int v, int B, const BlockView& b, Vec2 x, double tol) {
    const auto it = std::lower_bound(J.begin(), J.end(), Junction{v, B, 0, 0, 0.0});
    if (it != J.end() && it->vertex == v && it->block == B) {
        const Vec2 touched = b.vertex[it->e0] + it->s * (b.vertex[it->e1] - b.vertex[it->e0]);
        if (norm(x - touched) <= tol) return true;
    }
    return false;
}

/// The edge of B the vertex x faces, from its nearest edge `best`. Past an end of
/// the nearest edge, inside its line but outside the line of the edge across the
/// corner (a convex one): the vertex is outside B and faces that other edge. Taken
/// against the first, it was born in overlap with the rounded corner (a circle
/// tangent to the first edge reaches past an acute corner: 344 of 515 contacts
/// born below -0.1 mm in a 3 x 6 m area trigon specimen were outside B), and its
/// later approach across the other edge went unseen. It is the other edge's.
inline int edge_faced(const BlockView& b, int B, int best, Vec2 x) {
    const int e_end = next_vertex(b.first, B, best);
    const EdgeFrame f = frame(x, b.vertex[best], b.vertex[e_end]);
    if (f.gap < 0.0 && (f.s < 0.0 || f.s > 1.0)) {
        const int c0 = f.s < 0.0 ? prev_vertex(b.first, B, best) : e_end; // the other edge
        const int c1 = next_vertex(b.first, B, c0);
        const Vec2 arriving = f.s < 0.0 ? b.vertex[c1] - b.vertex[c0] : b.vertex[e_end] - b.vertex[best];
        const Vec2 leaving = f.s < 0.0 ? b.vertex[e_end] - b.vertex[best] : b.vertex[c1] - b.vertex[c0];
        if (cross(arriving, leaving) > 0.0 && frame(x, b.vertex[c0], b.vertex[c1]).gap > 0.0) return c0;
    }
    return best;
}

/// The length of the contact of vertex v of A (at x, s_on along B's edge `best`
/// of unit tangent tb): the vertex's share, half of its adjacent edge that lies
/// most along B's edge.
inline double contact_length(const DetectionInput& in, int A, int v, Vec2 x, int best, Vec2 tb, double s_on) {
    const BlockView& b = in.blocks;
    const int vp = prev_vertex(b.first, A, v), vn = next_vertex(b.first, A, v);
    const Vec2 ep = b.vertex[vp] - x, en = b.vertex[vn] - x;
    const Vec2 along = std::abs(cross(tb, ep)) / norm(ep) < std::abs(cross(tb, en)) / norm(en) ? ep : en;
    double l = 0.5 * norm(along);
    if (in.overlap_length) {
        // The part of B's edge that the vertex's edge covers, shared with the
        // contact at its other end; a corner touching a corner gets the arc of
        // its rounding.
        const double s_far = s_on + dot(along, tb) * b.inv_edge_length[best];
        const double overlap =
            std::max(0.0, std::min(std::max(s_on, s_far), 1.0) - std::max(std::min(s_on, s_far), 0.0)) /
            b.inv_edge_length[best];
        l = 0.5 * std::max(overlap, in.corner_radius);
    }
    return l;
}

/// The gap and normal of a vertex at x past an end of B's edge best → e1 (s_on
/// outside [0, 1]) at a rounded corner. Past the end of the edge the contact's
/// surface is the rounded corner (contact_kinematics), not the edge's line: a
/// vertex beside the corner but inside that line is not in overlap. Measured
/// against the line it would start compressed by up to the tolerance — at kn,
/// hundreds of MPa on a fresh vertex-vertex contact (docs/calibration.md, After
/// the peak). Past a node along a deformable face, the line goes on (contact_frame).
inline void gap_at_corner(const DetectionInput& in, int best, int e1, double s_on, Vec2 x, double& gap, Vec2& n) {
    const BlockView& b = in.blocks;
    if ((s_on < 0.0 || s_on > 1.0) && b.corner[s_on < 0.0 ? best : e1]) {
        const Vec2 centre = (s_on < 0.0 ? b.vertex[best] : b.vertex[e1]) - in.corner_radius * n;
        const Vec2 r = x - centre;
        const double rl = norm(r);
        if (rl > 0.0) gap = rl - in.corner_radius, n = r / rl;
    }
}

void add_candidates(const Detector::Piece& P, const Detector::Piece& Q, const Box2& q_box, const DetectionInput& in,
                    std::vector<Detector::Candidate>& out) {
    // Vertices of P against edges of Q.
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int A = P.block, B = Q.block;
    for (std::uint32_t v = P.v0; v < P.v1; ++v) {
        const Vec2 x = b.vertex[v];
        if (x.x < q_box.lo.x || x.x > q_box.hi.x || x.y < q_box.lo.y || x.y > q_box.hi.y) continue;
        int best = nearest_edge(x, Q, b, tol);
        if (best < 0) continue;
        if (in.junctions && on_its_junction(*in.junctions, int(v), B, b, x, tol)) continue;
        best = edge_faced(b, B, best, x);
        const int e1 = next_vertex(b.first, B, best);
        const Vec2 tb = b.inv_edge_length[best] * (b.vertex[e1] - b.vertex[best]);
        Vec2 n{tb.y, -tb.x};
        const double s_on = dot(x - b.vertex[best], tb) * b.inv_edge_length[best];
        const double l = contact_length(in, A, int(v), x, best, tb, s_on);
        const Vec2 vr = vertex_velocity(b, A, int(v), x) - edge_velocity(b, B, best, e1, s_on, x);
        double gap = frame(x, b.vertex[best], b.vertex[e1]).gap;
        gap_at_corner(in, best, e1, s_on, x, gap, n);
        const double un = gap - dot(vr, n) * in.dt;
        out.push_back({block_pair_key(A, B), A, int(v), B, best, e1, l, un});
    }
}

/// A block that takes part in this pass: active (moving) and not removed.
inline bool is_active(const DetectionInput& in, int k) {
    return (!in.active || in.active[k]) && !(in.removed && in.removed[k]);
}

/// Every thread: the pass's active blocks and cleared scratch (one thread writes).
void start_pass(Detector& d, const Contacts& c, const DetectionInput& in) {
#pragma omp single
    {
        d.drop.resize(c.size(), 0);
        d.active_blocks.clear();
        for (int k = 0; k < in.block_count; ++k)
            if (is_active(in, k)) d.active_blocks.push_back(k);
        d.team.resize(std::max(1, omp_get_num_threads()));
        for (auto& t : d.team) {
            t.candidates.clear();
            t.dropped = t.dropped_tensile = t.dropped_shear = t.transferred = t.transferred_on_nodes = 0;
        }
        d.stale = !d.grid_valid;
        d.left_box = false;
    }
}

/// 1–2. Transfer along the edge block's boundary, and removal of separated
/// unbonded contacts: the contacts of active blocks, each once (from its vertex
/// block if that is active).
void transfer_and_drop(Detector& d, Contacts& c, const DetectionInput& in, Detector::ThreadScratch& mine) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int na = int(d.active_blocks.size());
#pragma omp for schedule(static)
    for (int a = 0; a < na; ++a) {
        const int k = d.active_blocks[a];
        for (int e = c.block_first[k]; e < c.block_first[k + 1]; ++e) {
            const int i = c.block_entry[e] >> 1;
            const int A = c.vertex_block[i], B = c.edge_block[i];
            if (k == B && is_active(in, A)) continue;
            if (c.history[i].bonded) continue; // intact joints keep their edges (contacts.hpp)
            const Vec2 x = b.vertex[c.vertex_id[i]];
            EdgeFrame f = frame(x, b.vertex[c.edge_id[i]], b.vertex[c.edge_end[i]]);
            const double len = 1.0 / b.inv_edge_length[c.edge_id[i]];
            // Past a rigid block's corner the contact rides the rounding until it is
            // past by the tolerance. A deformable block's boundary is a chain of
            // short edges whose nodes are mostly no corners: a vertex that kept to
            // the first edge while it slid on would be measured against the wrong
            // line, and could pass into the block unresisted (blocks overlap in the
            // crushed notch of deformable blocks, docs/notes). It passes on at once.
            const bool chain = b.deformable[B];
            if (std::max(-f.s, f.s - 1.0) * len > (chain ? 0.0 : tol)) {
                const bool back = f.s < 0.0;
                const int e0 = back ? prev_vertex(b.first, B, c.edge_id[i]) : c.edge_end[i];
                const int e1 = back ? c.edge_id[i] : next_vertex(b.first, B, c.edge_end[i]);
                const EdgeFrame g = frame(x, b.vertex[e0], b.vertex[e1]);
                if (g.s >= 0.0 && g.s <= 1.0 && g.gap > -tol) {
                    c.edge_id[i] = e0;
                    c.edge_end[i] = e1;
                    if (chain) {
                        // Its normal displacement from the new edge's geometry, as a
                        // contact born there would have it (add_candidates): the
                        // rounding or the old line it was measured on is left behind.
                        const Vec2 vr = vertex_velocity(b, A, c.vertex_id[i], x) - edge_velocity(b, B, e0, e1, g.s, x);
                        const Vec2 n = b.inv_edge_length[e0] * (b.vertex[e1] - b.vertex[e0]);
                        c.history[i].un = g.gap - dot(vr, Vec2{n.y, -n.x}) * in.dt;
                        ++mine.transferred_on_nodes;
                    }
                    f = g;
                    ++mine.transferred;
                }
            }
            const double beyond = std::max(-f.s, f.s - 1.0) / b.inv_edge_length[c.edge_id[i]];
            if (f.gap > tol || beyond > 2.0 * tol) {
                d.drop[i] = 1;
                ++mine.dropped;
                mine.dropped_tensile += c.history[i].broken == JointState::broken_tension;
                mine.dropped_shear += c.history[i].broken == JointState::broken_shear;
            }
        }
    }
}

/// 3a. The grid is rebuilt if it is invalid or one of the active pieces has left
/// its stored box (with a quarter tolerance to spare: a block is checked again
/// before it has moved that far). d.stale is read by every thread here and not
/// written before the single below: a thread's piece that left its box raises
/// d.left_box instead.
void refresh_grid(Detector& d, const DetectionInput& in) {
    const int na = int(d.active_blocks.size());
    if (!d.stale) {
        bool left = false;
#pragma omp for schedule(static) nowait
        for (int a = 0; a < na; ++a) {
            const int k = d.active_blocks[a];
            for (int p = d.block_piece[k]; p < d.block_piece[k + 1] && !left; ++p) {
                const Box2 box = current_box(d.pieces[p], in.blocks, 1.25 * in.tolerance);
                const Box2& s = d.stored[p];
                left = box.lo.x < s.lo.x || box.lo.y < s.lo.y || box.hi.x > s.hi.x || box.hi.y > s.hi.y;
            }
        }
        if (left) {
#pragma omp atomic write
            d.left_box = true;
        }
#pragma omp barrier
    }
#pragma omp single
    if (d.stale || d.left_box) build_grid(d, in);
}

/// 3b. Broad phase from the active pieces: the pieces near each in the grid,
/// their vertex-edge candidates (narrow phase, add_candidates) into the thread's list.
void broad_phase(Detector& d, const DetectionInput& in, Detector::ThreadScratch& mine) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int na = int(d.active_blocks.size());
#pragma omp for schedule(static)
    for (int a = 0; a < na; ++a) {
        const int k = d.active_blocks[a];
        for (int p = d.block_piece[k]; p < d.block_piece[k + 1]; ++p) {
            const Box2 box = current_box(d.pieces[p], b, tol);
            const int i0 = std::clamp(int((box.lo.x - d.grid_box.lo.x) / d.cell), 0, d.nx - 1);
            const int i1 = std::clamp(int((box.hi.x - d.grid_box.lo.x) / d.cell), 0, d.nx - 1);
            const int j0 = std::clamp(int((box.lo.y - d.grid_box.lo.y) / d.cell), 0, d.ny - 1);
            const int j1 = std::clamp(int((box.hi.y - d.grid_box.lo.y) / d.cell), 0, d.ny - 1);
            auto& near = mine.near;
            near.clear();
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    const std::size_t cell = std::size_t(j) * d.nx + i;
                    for (int e = d.cell_first[cell]; e < d.cell_first[cell + 1]; ++e) {
                        const int q = d.cell_piece[e];
                        const int other = d.pieces[q].block;
                        // A pair of active pieces is handled from its lower piece.
                        if (other != k && !(is_active(in, other) && q < p)) near.push_back(q);
                    }
                }
            std::sort(near.begin(), near.end());
            near.erase(std::unique(near.begin(), near.end()), near.end());
            for (int q : near) {
                const Box2 q_box = current_box(d.pieces[q], b, tol);
                if (box.hi.x < q_box.lo.x || q_box.hi.x < box.lo.x || box.hi.y < q_box.lo.y || q_box.hi.y < box.lo.y)
                    continue;
                const Detector::Piece &P = d.pieces[p], &Q = d.pieces[q];
                if (P.block < Q.block) {
                    add_candidates(P, Q, q_box, in, mine.candidates);
                    add_candidates(Q, P, box, in, mine.candidates);
                } else {
                    add_candidates(Q, P, box, in, mine.candidates);
                    add_candidates(P, Q, q_box, in, mine.candidates);
                }
            }
        }
    }
}

/// 4. One thread: the threads' candidates gathered in block order, accepted pair
/// by pair in the order they came, and the dropped contacts removed; the result
/// for every thread (the single's barrier).
void accept_candidates(Detector& d, Contacts& c, const DetectionInput& in) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
#pragma omp single
    {
        DetectionResult res;
        int on_nodes = 0;
        // The threads' runs of active blocks follow each other in block order.
        d.candidates.clear();
        for (auto& t : d.team) {
            d.candidates.insert(d.candidates.end(), t.candidates.begin(), t.candidates.end());
            res.transferred += t.transferred;
            on_nodes += t.transferred_on_nodes;
            res.removed += t.dropped;
            res.removed_tensile += t.dropped_tensile;
            res.removed_shear += t.dropped_shear;
        }
        d.order.resize(d.candidates.size());
        std::iota(d.order.begin(), d.order.end(), 0);
        // By pair, then in the order they came (a total order: std::sort gives the same
        // result as a stable sort, without the buffer std::stable_sort allocates).
        std::sort(d.order.begin(), d.order.end(), [&](int x, int y) {
            return d.candidates[x].pair < d.candidates[y].pair || (d.candidates[x].pair == d.candidates[y].pair && x < y);
        });
        d.accepted.clear();
        for (std::size_t k = 0; k < d.order.size(); ++k) {
            const Detector::Candidate& cand = d.candidates[d.order[k]];
            if (k == 0 || d.candidates[d.order[k - 1]].pair != cand.pair) d.accepted.clear();
            if (known(d, c, cand.vertex_block, cand.vertex, cand.edge_block, in)) continue;
            const Vec2 x = b.vertex[cand.vertex];
            bool duplicate = false;
            for (int a : d.accepted) duplicate = duplicate || norm(b.vertex[d.candidates[a].vertex] - x) <= tol;
            if (duplicate) continue;
            d.accepted.push_back(d.order[k]);
            JointHistory h;
            h.bonded = false;
            h.un = cand.un;
            if (in.overlap_at_rest) h.upn = std::min(0.0, cand.un);
            add_contact(c, cand.vertex_block, cand.vertex, cand.edge_block, cand.edge, cand.edge_end, cand.length,
                  in.new_contact_property, h);
            d.drop.push_back(0);
            ++res.created;
        }
        d.removed_dissipated = 0.0;
        if (res.removed > 0) {
            for (int i = 0; i < c.size(); ++i)
                if (d.drop[i]) d.removed_dissipated += c.length[i] * c.history[i].dissipated;
            remove_flagged_contacts(c, d.drop);
            d.drop.resize(c.size());
            std::fill(d.drop.begin(), d.drop.end(), 0);
        }
        d.result = res;
        d.transferred_on_nodes = on_nodes;
    }
}

} // namespace

DetectionResult detect(Contacts& c, Detector& d, const DetectionInput& in) {
    start_pass(d, c, in);
    Detector::ThreadScratch& mine = d.team[omp_get_thread_num()];
    transfer_and_drop(d, c, in, mine);
    refresh_grid(d, in);
    broad_phase(d, in, mine);
    accept_candidates(d, c, in);
    return d.result;
}

} // namespace bbm::contact
