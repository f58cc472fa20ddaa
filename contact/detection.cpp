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

bool Detector::known(const Contacts& c, int vertex_block, int vertex, int edge_block, const DetectionInput& in) const {
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
        if (partner != other || drop_[i]) continue;
        if (norm2(in.blocks.vertex[c.vertex_id[i]] - x) <= tol2) return true;
    }
    return false;
}

Box2 Detector::current_box(const Piece& pc, const BlockView& b, double inflate) const {
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

void Detector::build_grid(const DetectionInput& in) {
    // A block with many vertices (a deformable block's boundary, hundreds of
    // nodes) enters as pieces of at most `chunk` consecutive vertices, each with
    // its own box: otherwise its one box, as large as the model, would pair it
    // with every block and the narrow phase would test every vertex against all
    // its edges.
    constexpr std::uint32_t chunk = 16;
    const BlockView& b = in.blocks;
    const int nb = in.block_count;
    if (int(block_piece_.size()) != nb + 1) {
        pieces_.clear();
        block_piece_.assign(1, 0);
        for (int k = 0; k < nb; ++k) {
            for (std::uint32_t v0 = b.first[k]; v0 < b.first[k + 1]; v0 += chunk)
                pieces_.push_back({k, v0, std::min(b.first[k + 1], v0 + chunk)});
            block_piece_.push_back(int(pieces_.size()));
        }
    }
    const int np = int(pieces_.size());
    stored_.resize(np);
    grid_box_ = Box2{};
    double extent = 0.0;
    int counted = 0;
    for (int p = 0; p < np; ++p) {
        if (in.removed && in.removed[pieces_[p].block]) continue;
        stored_[p] = current_box(pieces_[p], b, in.tolerance);
        extent += stored_[p].width() + stored_[p].height();
        ++counted;
    }
    extent /= std::max(1, 2 * counted);
    margin_ = std::max(4.0 * in.tolerance, 0.1 * extent);
    for (int p = 0; p < np; ++p) {
        if (in.removed && in.removed[pieces_[p].block]) continue;
        stored_[p].lo -= Vec2{margin_, margin_};
        stored_[p].hi += Vec2{margin_, margin_};
        grid_box_.add(stored_[p].lo);
        grid_box_.add(stored_[p].hi);
    }
    cell_ = std::max(extent + 2.0 * margin_, 1e-12);
    nx_ = std::clamp(int(grid_box_.width() / cell_) + 1, 1, 1 << 14);
    ny_ = std::clamp(int(grid_box_.height() / cell_) + 1, 1, 1 << 14);
    auto for_cells = [&](const Box2& bx, auto&& visit) {
        const int i0 = std::clamp(int((bx.lo.x - grid_box_.lo.x) / cell_), 0, nx_ - 1);
        const int i1 = std::clamp(int((bx.hi.x - grid_box_.lo.x) / cell_), 0, nx_ - 1);
        const int j0 = std::clamp(int((bx.lo.y - grid_box_.lo.y) / cell_), 0, ny_ - 1);
        const int j1 = std::clamp(int((bx.hi.y - grid_box_.lo.y) / cell_), 0, ny_ - 1);
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i) visit(std::size_t(j) * nx_ + i);
    };
    // Counting sort of the pieces into the cells their stored boxes cover.
    cell_first_.assign(std::size_t(nx_) * ny_ + 1, 0);
    for (int p = 0; p < np; ++p)
        if (!(in.removed && in.removed[pieces_[p].block])) for_cells(stored_[p], [&](std::size_t k) { ++cell_first_[k + 1]; });
    for (std::size_t k = 0; k + 1 < cell_first_.size(); ++k) cell_first_[k + 1] += cell_first_[k];
    cell_piece_.resize(cell_first_.back());
    for (int p = 0; p < np; ++p)
        if (!(in.removed && in.removed[pieces_[p].block]))
            for_cells(stored_[p], [&](std::size_t k) { cell_piece_[cell_first_[k]++] = p; });
    for (std::size_t k = cell_first_.size() - 1; k > 0; --k) cell_first_[k] = cell_first_[k - 1];
    cell_first_[0] = 0;
    grid_valid_ = true;
    ++grid_builds_;
}

void Detector::add_candidates(const Piece& P, const Piece& Q, const Box2& q_box, const DetectionInput& in,
                              std::vector<Candidate>& out) const {
    // Vertices of P against edges of Q.
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int A = P.block, B = Q.block;
    for (std::uint32_t v = P.v0; v < P.v1; ++v) {
        const Vec2 x = b.vertex[v];
        if (x.x < q_box.lo.x || x.x > q_box.hi.x || x.y < q_box.lo.y || x.y > q_box.hi.y) continue;
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
        {
            // Past an end of the nearest edge, inside its line but outside the line
            // of the edge across the corner (a convex one): the vertex is outside B
            // and faces that other edge. Taken against the first, it was born in
            // overlap with the rounded corner (a circle tangent to the first edge
            // reaches past an acute corner: 344 of 515 contacts born below -0.1 mm
            // in a 3 x 6 m area trigon specimen were outside B), and its later
            // approach across the other edge went unseen. It is the other edge's.
            const int e_end = next_vertex(b.first, B, best);
            const EdgeFrame f = frame(x, b.vertex[best], b.vertex[e_end]);
            if (f.gap < 0.0 && (f.s < 0.0 || f.s > 1.0)) {
                const int c0 = f.s < 0.0 ? prev_vertex(b.first, B, best) : e_end; // the other edge
                const int c1 = next_vertex(b.first, B, c0);
                const Vec2 arriving = f.s < 0.0 ? b.vertex[c1] - b.vertex[c0] : b.vertex[e_end] - b.vertex[best];
                const Vec2 leaving = f.s < 0.0 ? b.vertex[e_end] - b.vertex[best] : b.vertex[c1] - b.vertex[c0];
                if (cross(arriving, leaving) > 0.0 && frame(x, b.vertex[c0], b.vertex[c1]).gap > 0.0) best = c0;
            }
        }
        const int e1 = next_vertex(b.first, B, best);
        const Vec2 tb = b.inv_edge_length[best] * (b.vertex[e1] - b.vertex[best]);
        // The vertex's share: half of its adjacent edge that lies most along B's edge.
        const int vp = prev_vertex(b.first, A, int(v)), vn = next_vertex(b.first, A, int(v));
        const Vec2 ep = b.vertex[vp] - x, en = b.vertex[vn] - x;
        const Vec2 along = std::abs(cross(tb, ep)) / norm(ep) < std::abs(cross(tb, en)) / norm(en) ? ep : en;
        Vec2 n{tb.y, -tb.x};
        const double s_on = dot(x - b.vertex[best], tb) * b.inv_edge_length[best];
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
        const Vec2 vr = vertex_velocity(b, A, int(v), x) - edge_velocity(b, B, best, e1, s_on, x);
        double gap = frame(x, b.vertex[best], b.vertex[e1]).gap;
        if ((s_on < 0.0 || s_on > 1.0) && b.corner[s_on < 0.0 ? best : e1]) {
            // Past the end of the edge the contact's surface is the rounded corner
            // (contact_kinematics), not the edge's line: a vertex beside the corner
            // but inside that line is not in overlap. Measured against the line it
            // would start compressed by up to the tolerance — at kn, hundreds of MPa
            // on a fresh vertex-vertex contact (docs/calibration.md, After the peak).
            // Past a node along a deformable face, the line goes on (contact_frame).
            const Vec2 centre = (s_on < 0.0 ? b.vertex[best] : b.vertex[e1]) - in.corner_radius * n;
            const Vec2 r = x - centre;
            const double rl = norm(r);
            if (rl > 0.0) gap = rl - in.corner_radius, n = r / rl;
        }
        const double un = gap - dot(vr, n) * in.dt;
        out.push_back({block_pair_key(A, B), A, int(v), B, best, e1, l, un});
    }
}

namespace {
/// A block that takes part in this pass: active (moving) and not removed.
inline bool is_active(const DetectionInput& in, int k) {
    return (!in.active || in.active[k]) && !(in.removed && in.removed[k]);
}
} // namespace

/// Every thread: the pass's active blocks and cleared scratch (one thread writes).
void Detector::start_pass(const Contacts& c, const DetectionInput& in) {
#pragma omp single
    {
        drop_.resize(c.size(), 0);
        active_blocks_.clear();
        for (int k = 0; k < in.block_count; ++k)
            if (is_active(in, k)) active_blocks_.push_back(k);
        team_.resize(std::max(1, omp_get_num_threads()));
        for (auto& t : team_) {
            t.candidates.clear();
            t.dropped = t.dropped_tensile = t.dropped_shear = t.transferred = t.transferred_on_nodes = 0;
        }
        stale_ = !grid_valid_;
        left_box_ = false;
    }
}

/// 1–2. Transfer along the edge block's boundary, and removal of separated
/// unbonded contacts: the contacts of active blocks, each once (from its vertex
/// block if that is active).
void Detector::transfer_and_drop(Contacts& c, const DetectionInput& in, ThreadScratch& mine) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int na = int(active_blocks_.size());
#pragma omp for schedule(static)
    for (int a = 0; a < na; ++a) {
        const int k = active_blocks_[a];
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
                drop_[i] = 1;
                ++mine.dropped;
                mine.dropped_tensile += c.history[i].broken == JointState::broken_tension;
                mine.dropped_shear += c.history[i].broken == JointState::broken_shear;
            }
        }
    }
}

/// 3a. The grid is rebuilt if it is invalid or one of the active pieces has left
/// its stored box (with a quarter tolerance to spare: a block is checked again
/// before it has moved that far). stale_ is read by every thread here and not
/// written before the single below: a thread's piece that left its box raises
/// left_box_ instead.
void Detector::refresh_grid(const DetectionInput& in) {
    const int na = int(active_blocks_.size());
    if (!stale_) {
        bool left = false;
#pragma omp for schedule(static) nowait
        for (int a = 0; a < na; ++a) {
            const int k = active_blocks_[a];
            for (int p = block_piece_[k]; p < block_piece_[k + 1] && !left; ++p) {
                const Box2 box = current_box(pieces_[p], in.blocks, 1.25 * in.tolerance);
                const Box2& s = stored_[p];
                left = box.lo.x < s.lo.x || box.lo.y < s.lo.y || box.hi.x > s.hi.x || box.hi.y > s.hi.y;
            }
        }
        if (left) {
#pragma omp atomic write
            left_box_ = true;
        }
#pragma omp barrier
    }
#pragma omp single
    if (stale_ || left_box_) build_grid(in);
}

/// 3b. Broad phase from the active pieces: the pieces near each in the grid,
/// their vertex-edge candidates (narrow phase, add_candidates) into the thread's list.
void Detector::broad_phase(const DetectionInput& in, ThreadScratch& mine) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
    const int na = int(active_blocks_.size());
#pragma omp for schedule(static)
    for (int a = 0; a < na; ++a) {
        const int k = active_blocks_[a];
        for (int p = block_piece_[k]; p < block_piece_[k + 1]; ++p) {
            const Box2 box = current_box(pieces_[p], b, tol);
            const int i0 = std::clamp(int((box.lo.x - grid_box_.lo.x) / cell_), 0, nx_ - 1);
            const int i1 = std::clamp(int((box.hi.x - grid_box_.lo.x) / cell_), 0, nx_ - 1);
            const int j0 = std::clamp(int((box.lo.y - grid_box_.lo.y) / cell_), 0, ny_ - 1);
            const int j1 = std::clamp(int((box.hi.y - grid_box_.lo.y) / cell_), 0, ny_ - 1);
            auto& near = mine.near;
            near.clear();
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    const std::size_t cell = std::size_t(j) * nx_ + i;
                    for (int e = cell_first_[cell]; e < cell_first_[cell + 1]; ++e) {
                        const int q = cell_piece_[e];
                        const int other = pieces_[q].block;
                        // A pair of active pieces is handled from its lower piece.
                        if (other != k && !(is_active(in, other) && q < p)) near.push_back(q);
                    }
                }
            std::sort(near.begin(), near.end());
            near.erase(std::unique(near.begin(), near.end()), near.end());
            for (int q : near) {
                const Box2 q_box = current_box(pieces_[q], b, tol);
                if (box.hi.x < q_box.lo.x || q_box.hi.x < box.lo.x || box.hi.y < q_box.lo.y || q_box.hi.y < box.lo.y)
                    continue;
                const Piece &P = pieces_[p], &Q = pieces_[q];
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
void Detector::accept_candidates(Contacts& c, const DetectionInput& in) {
    const BlockView& b = in.blocks;
    const double tol = in.tolerance;
#pragma omp single
    {
        DetectionResult res;
        int on_nodes = 0;
        // The threads' runs of active blocks follow each other in block order.
        candidates_.clear();
        for (auto& t : team_) {
            candidates_.insert(candidates_.end(), t.candidates.begin(), t.candidates.end());
            res.transferred += t.transferred;
            on_nodes += t.transferred_on_nodes;
            res.removed += t.dropped;
            res.removed_tensile += t.dropped_tensile;
            res.removed_shear += t.dropped_shear;
        }
        order_.resize(candidates_.size());
        std::iota(order_.begin(), order_.end(), 0);
        // By pair, then in the order they came (a total order: std::sort gives the same
        // result as a stable sort, without the buffer std::stable_sort allocates).
        std::sort(order_.begin(), order_.end(), [&](int x, int y) {
            return candidates_[x].pair < candidates_[y].pair || (candidates_[x].pair == candidates_[y].pair && x < y);
        });
        accepted_.clear();
        for (std::size_t k = 0; k < order_.size(); ++k) {
            const Candidate& cand = candidates_[order_[k]];
            if (k == 0 || candidates_[order_[k - 1]].pair != cand.pair) accepted_.clear();
            if (known(c, cand.vertex_block, cand.vertex, cand.edge_block, in)) continue;
            const Vec2 x = b.vertex[cand.vertex];
            bool duplicate = false;
            for (int a : accepted_) duplicate = duplicate || norm(b.vertex[candidates_[a].vertex] - x) <= tol;
            if (duplicate) continue;
            accepted_.push_back(order_[k]);
            JointHistory h;
            h.bonded = false;
            h.un = cand.un;
            c.add(cand.vertex_block, cand.vertex, cand.edge_block, cand.edge, cand.edge_end, cand.length,
                  in.new_contact_property, h);
            drop_.push_back(0);
            ++res.created;
        }
        if (res.removed > 0) {
            c.remove_if_flagged(drop_);
            drop_.resize(c.size());
            std::fill(drop_.begin(), drop_.end(), 0);
        }
        result_ = res;
        transferred_on_nodes_ = on_nodes;
    }
}

DetectionResult Detector::update(Contacts& c, const DetectionInput& in) {
    start_pass(c, in);
    ThreadScratch& mine = team_[omp_get_thread_num()];
    transfer_and_drop(c, in, mine);
    refresh_grid(in);
    broad_phase(in, mine);
    accept_candidates(c, in);
    return result_;
}

} // namespace bbm::contact
