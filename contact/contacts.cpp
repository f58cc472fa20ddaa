#include "contact/contacts.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>
#include <span>

#include <cmath>

namespace bbm::contact {

void add_contact(Contacts& c, int a, int vertex, int b, int edge, int end, double l, int prop, const JointHistory& h) {
    c.edge_end.push_back(end);
    c.vertex_block.push_back(a);
    c.vertex_id.push_back(vertex);
    c.edge_block.push_back(b);
    c.edge_id.push_back(edge);
    c.length.push_back(l);
    c.property.push_back(prop);
    c.history.push_back(h);
    c.normal.push_back({});
    if (c.flow_on) c.flow_link.push_back({-1, -1, -1}), c.fluid_pressure.push_back(0.0);
    if (c.corroding) c.bond_section.push_back(1.0);
}

void remove_flagged_contacts(Contacts& c, const std::vector<std::uint8_t>& remove) {
    int out = 0;
    for (int i = 0; i < c.size(); ++i) {
        if (remove[i]) continue;
        c.vertex_block[out] = c.vertex_block[i];
        c.vertex_id[out] = c.vertex_id[i];
        c.edge_block[out] = c.edge_block[i];
        c.edge_id[out] = c.edge_id[i];
        c.edge_end[out] = c.edge_end[i];
        c.length[out] = c.length[i];
        c.property[out] = c.property[i];
        c.history[out] = c.history[i];
        c.normal[out] = c.normal[i];
        if (c.flow_on) c.flow_link[out] = c.flow_link[i], c.fluid_pressure[out] = c.fluid_pressure[i];
        if (c.corroding) c.bond_section[out] = c.bond_section[i];
        ++out;
    }
    if (c.flow_on) c.flow_link.resize(out), c.fluid_pressure.resize(out);
    if (c.corroding) c.bond_section.resize(out);
    for (auto* v : {&c.vertex_block, &c.vertex_id, &c.edge_block, &c.edge_id, &c.edge_end, &c.property}) v->resize(out);
    c.length.resize(out);
    c.history.resize(out);
    c.normal.resize(out);
}

bool sort_contacts_by_blocks(Contacts& c) {
    const int n = c.size();
    auto key = [&](int i) {
        const int a = c.vertex_block[i], b = c.edge_block[i];
        return std::tuple{std::min(a, b), std::max(a, b), c.vertex_id[i], c.edge_id[i]};
    };
    bool sorted = true;
    for (int i = 1; i < n && sorted; ++i) sorted = !(key(i) < key(i - 1));
    if (sorted) return false;
    c.fill.resize(n);
    std::iota(c.fill.begin(), c.fill.end(), 0);
    std::sort(c.fill.begin(), c.fill.end(), [&](int i, int j) { return key(i) < key(j); });
    // Apply the permutation in place, cycle by cycle (new position k takes the
    // contact at c.fill[k]); a visited cycle is marked by negating its entries.
    for (int start = 0; start < n; ++start) {
        if (c.fill[start] < 0 || c.fill[start] == start) continue;
        auto rotate_cycle = [&](auto& v) {
            auto held = v[start];
            int k = start;
            while (c.fill[k] != start) {
                v[k] = v[c.fill[k]];
                k = c.fill[k];
            }
            v[k] = held;
        };
        rotate_cycle(c.vertex_block), rotate_cycle(c.vertex_id), rotate_cycle(c.edge_block), rotate_cycle(c.edge_id);
        rotate_cycle(c.edge_end), rotate_cycle(c.length), rotate_cycle(c.property), rotate_cycle(c.history);
        rotate_cycle(c.normal);
        if (c.flow_on) rotate_cycle(c.flow_link), rotate_cycle(c.fluid_pressure);
        if (c.corroding) rotate_cycle(c.bond_section);
        for (int k = start; c.fill[k] >= 0;) {
            const int next = c.fill[k];
            c.fill[k] = -1 - next;
            k = next;
        }
    }
    return true;
}

namespace {

/// The contacts by batch (property set, and whether a deformable block takes
/// part), by counting sort in contact order; the batches cut into work items and
/// their costs; the per-contact scratch sized.
void index_batches(Contacts& c, int property_sets, const std::uint8_t* deformable) {
    const int n = c.size();
    auto is_deformable = [&](int blk) { return deformable && deformable[blk]; };
    const int batches = 2 * property_sets;
    c.batch_first.assign(batches + 1, 0);
    auto batch_of = [&](int i) {
        const bool mixed = is_deformable(c.vertex_block[i]) || is_deformable(c.edge_block[i]);
        return 2 * c.property[i] + (mixed ? 1 : 0);
    };
    for (int i = 0; i < n; ++i) ++c.batch_first[batch_of(i) + 1];
    for (int k = 0; k < batches; ++k) c.batch_first[k + 1] += c.batch_first[k];
    c.batch_contact.resize(n);
    c.fill.assign(c.batch_first.begin(), c.batch_first.end() - 1);
    for (int i = 0; i < n; ++i) c.batch_contact[c.fill[batch_of(i)]++] = i;
    c.work.clear();
    for (int k = 0; k < batches; ++k) {
        const int size = c.batch_first[k + 1] - c.batch_first[k];
        for (int begin = 0; begin < size; begin += Contacts::work_item_size)
            c.work.push_back({k, begin, std::min(size, begin + Contacts::work_item_size)});
    }
    c.work_cost_before.resize(c.work.size() + 1);
    double cost = 0.0;
    for (std::size_t w = 0; w < c.work.size(); ++w) {
        c.work_cost_before[w] = cost;
        cost += double(c.work[w].end - c.work[w].begin) * (c.work[w].batch % 2 ? Contacts::mixed_contact_cost : 1.0);
    }
    c.work_cost_before[c.work.size()] = cost;
    c.force.resize(n);
    c.partial_sum.resize(c.work.size());
    c.partial_damped.assign(c.work.size(), 0.0);
    if (c.marking) c.bond_change.assign(c.length.size(), 0), c.force_before.resize(c.length.size());
}

/// Per-block and per-node lists of the contacts' ends, in contact order: count,
/// prefix sum, fill (`c.fill` is kept between calls: this runs inside steps that
/// change contacts).
void index_blocks_and_nodes(Contacts& c, int blocks, const std::uint8_t* deformable, int nodes, const int* vertex_node) {
    const int n = c.size();
    auto is_deformable = [&](int blk) { return deformable && deformable[blk]; };
    c.block_first.assign(blocks + 1, 0);
    c.node_first.assign(nodes + 1, 0);
    for (int i = 0; i < n; ++i) {
        ++c.block_first[c.vertex_block[i] + 1], ++c.block_first[c.edge_block[i] + 1];
        if (is_deformable(c.vertex_block[i])) ++c.node_first[vertex_node[c.vertex_id[i]] + 1];
        if (is_deformable(c.edge_block[i])) ++c.node_first[vertex_node[c.edge_id[i]] + 1], ++c.node_first[vertex_node[c.edge_end[i]] + 1];
    }
    for (int k = 0; k < blocks; ++k) c.block_first[k + 1] += c.block_first[k];
    for (int k = 0; k < nodes; ++k) c.node_first[k + 1] += c.node_first[k];
    c.block_entry.resize(c.block_first[blocks]);
    c.node_entry.resize(c.node_first[nodes]);
    c.fill.assign(c.block_first.begin(), c.block_first.end() - 1);
    for (int i = 0; i < n; ++i) {
        c.block_entry[c.fill[c.vertex_block[i]]++] = 2 * i;
        c.block_entry[c.fill[c.edge_block[i]]++] = 2 * i + 1;
    }
    c.fill.assign(c.node_first.begin(), c.node_first.end() - 1);
    for (int i = 0; i < n; ++i) {
        if (is_deformable(c.vertex_block[i])) c.node_entry[c.fill[vertex_node[c.vertex_id[i]]]++] = 4 * i;
        if (is_deformable(c.edge_block[i])) {
            c.node_entry[c.fill[vertex_node[c.edge_id[i]]]++] = 4 * i + 1;
            c.node_entry[c.fill[vertex_node[c.edge_end[i]]]++] = 4 * i + 2;
        }
    }
}

} // namespace

void rebuild_contact_index(Contacts& c, int property_sets, int blocks, const std::uint8_t* deformable, int nodes,
                           const int* vertex_node) {
    index_batches(c, property_sets, deformable);
    index_blocks_and_nodes(c, blocks, deformable, nodes, vertex_node);
}

void update_normals(Contacts& c, const BlockView& b, double corner_radius) {
    for (int i = 0; i < c.size(); ++i) contact_kinematics(c, i, b, corner_radius);
}

void assign_face_groups(Contacts& c, const BlockView& b, const std::vector<std::uint8_t>& face_shear) {
    c.face_group.clear();
    c.face_first.assign(1, 0);
    c.face_entry.clear();
    c.face_du_s.clear();
    if (std::find(face_shear.begin(), face_shear.end(), 1) == face_shear.end()) return; // (called at every rebuild)
    const int n = c.size();
    auto grouped = [&](int i) {
        const int p = c.property[i];
        return p < int(face_shear.size()) && face_shear[p] && b.deformable[c.vertex_block[i]] != b.deformable[c.edge_block[i]];
    };
    // A face is named by the global id of its first vertex (unique over blocks).
    auto& face_of = c.face_scratch; // (face, contact)
    face_of.clear();
    for (int i = 0; i < n; ++i) {
        if (!grouped(i)) continue;
        int face = c.edge_id[i];
        if (b.deformable[c.edge_block[i]]) {
            // The rigid block's vertex: of its two edges, the one most nearly
            // opposite to the deformable edge (faces in contact run opposite ways).
            const int A = c.vertex_block[i], v = c.vertex_id[i];
            const int prev = v == int(b.first[A]) ? int(b.first[A + 1]) - 1 : v - 1, next = next_vertex(b.first, A, v);
            const Vec2 t = b.vertex[c.edge_end[i]] - b.vertex[c.edge_id[i]];
            const Vec2 in = b.vertex[v] - b.vertex[prev], out = b.vertex[next] - b.vertex[v];
            face = dot(in, t) / norm(in) < dot(out, t) / norm(out) ? prev : v;
        }
        face_of.emplace_back(face, i);
    }
    if (face_of.empty()) return;
    std::sort(face_of.begin(), face_of.end());
    c.face_group.assign(n, -1);
    for (std::size_t k = 0; k < face_of.size(); ++k) {
        if (k > 0 && face_of[k].first != face_of[k - 1].first) c.face_first.push_back(int(k));
        c.face_group[face_of[k].second] = int(c.face_first.size()) - 1;
        c.face_entry.push_back(face_of[k].second);
    }
    c.face_first.push_back(int(face_of.size()));
    c.face_du_s.assign(c.face_first.size() - 1, 0.0);
}

void face_slip_pass(Contacts& c, const BlockView& b, double dt, double corner_radius, int first, int last) {
    for (int f = first; f < last; ++f) {
        double sum = 0.0, length = 0.0;
        for (int e = c.face_first[f]; e < c.face_first[f + 1]; ++e) {
            const int i = c.face_entry[e];
            const int A = c.vertex_block[i], B = c.edge_block[i];
            const Vec2 x = b.vertex[c.vertex_id[i]];
            const ContactFrame fr = contact_frame(x, b.vertex[c.edge_id[i]], b.vertex[c.edge_end[i]],
                                                  b.inv_edge_length[c.edge_id[i]], c.history[i].bonded, corner_radius,
                                                  b.corner, c.edge_id[i], c.edge_end[i]);
            const Vec2 vr = vertex_velocity(b, A, c.vertex_id[i], x) - edge_velocity(b, B, c.edge_id[i], c.edge_end[i], fr.s, x);
            sum += c.length[i] * dot(vr, fr.t) * dt;
            length += c.length[i];
        }
        c.face_du_s[f] = length > 0.0 ? sum / length : 0.0;
    }
}

namespace {
// The first pass reads everything through local restrict pointers: through the
// Contacts members the compiler must assume the stores alias them and would
// reload every base pointer on every contact. `Mixed` batches have a deformable
// side: the vertex velocity comes from its node, the edge velocity is interpolated
// between the edge's nodes (weights w), and the gather splits the force to those
// nodes with the same weights (so the contact does no work the nodes do not see).
// `Extras`: the seismic events' marks or Rayleigh's viscous stresses are wanted
// (a separate instance, so a model without them runs the plain loop: measured,
// their tests in the loop cost the trigon tunnel 13% of its contact pass).
template <bool Mixed, bool Extras, class Law>
[[gnu::flatten]] double batch_pass(const Law& law, std::span<const int> ids, Contacts& c, const BlockView& b, double dt,
                    double corner_radius, double beta, double& viscous_work) {
    // Rayleigh's stiffness part: viscous stresses of the step's rates.
    const double viscous_n = beta > 0.0 ? beta * law.kn / dt : 0.0, viscous_s = beta > 0.0 ? beta * law.ks / dt : 0.0;
    const int* __restrict va = c.vertex_block.data();
    const int* __restrict vid = c.vertex_id.data();
    const int* __restrict eb = c.edge_block.data();
    const int* __restrict e0 = c.edge_id.data();
    const int* __restrict e1 = c.edge_end.data();
    const double* __restrict len = c.length.data();
    const double* __restrict wet = c.wet() ? c.fluid_pressure.data() : nullptr;
    JointHistory* __restrict hist = c.history.data();
    ContactForce* __restrict out = c.force.data();
    const Vec2* __restrict vertex = b.vertex;
    const BodyState* __restrict body = b.body;
    const double* __restrict inv_edge = b.inv_edge_length;
    const int* __restrict face = c.face_group.empty() ? nullptr : c.face_group.data();
    const double* __restrict face_du_s = c.face_du_s.data();
    std::uint8_t* __restrict changed = c.marking ? c.bond_change.data() : nullptr;
    Vec2* __restrict before = c.marking ? c.force_before.data() : nullptr;
    double sum = 0.0;
    const std::size_t count = ids.size();
    for (std::size_t k = 0; k < count; ++k) {
        const int i = ids[k];
        // The block and vertex data a few contacts ahead are random gathers: ask for
        // them early (measured: the loop is bound by these loads, not arithmetic).
        if (k + 32 < count) {
            const int j = ids[k + 32];
            __builtin_prefetch(&vertex[vid[j]]);
            __builtin_prefetch(&vertex[e0[j]]);
            __builtin_prefetch(&inv_edge[e0[j]]);
            __builtin_prefetch(&body[va[j]]);
            __builtin_prefetch(&body[eb[j]]);
        }
        const int A = va[i], B = eb[i];
        const Vec2 x = vertex[vid[i]];
        JointHistory& h = hist[i];
        // Rigid blocks: every vertex is a corner (null: no load in the loop).
        const auto [n, t, s] = contact_frame(x, vertex[e0[i]], vertex[e1[i]], inv_edge[e0[i]], h.bonded, corner_radius,
                                             Mixed ? b.corner : nullptr, e0[i], e1[i]);
        const BodyState& bA = body[A];
        const BodyState& bB = body[B];
        const Vec2 ra = x - bA.centroid, rb = x - bB.centroid;
        Vec2 vr;
        if constexpr (Mixed)
            vr = vertex_velocity(b, A, vid[i], x) - edge_velocity(b, B, e0[i], e1[i], s, x);
        else
            vr = (bA.velocity + bA.omega * perp(ra)) - (bB.velocity + bB.omega * perp(rb));
        const double du_n = dot(vr, n) * dt;
        double du_s = dot(vr, t) * dt;
        if constexpr (Mixed)
            if (face && face[i] >= 0) du_s = face_du_s[face[i]];
        // Seismic events: a bond still sound (bit 2) and bonded (bit 1) before the update.
        int was = 0;
        if constexpr (Extras) was = changed ? int(h.bonded) | (h.damage == 0.0f ? 2 : 0) : 0;
        law.update(h, du_n, du_s);
        double sn = wet ? h.sn + wet[i] : h.sn; // effective stress + the fluid's
        double tau = h.tau;
        if constexpr (Extras)
            if (viscous_n > 0.0 && (h.bonded || h.sn > 0.0)) {
                sn -= viscous_n * du_n, tau += viscous_s * du_s;
                viscous_work += len[i] * (viscous_n * du_n * du_n + viscous_s * du_s * du_s);
            }
        const Vec2 f = len[i] * (sn * n - tau * t);
        if constexpr (Extras)
            if ((was & 1) && (!h.bonded || ((was & 2) && h.damage > 0.0f))) {
                // Its force before this pass: the last pass's, not yet overwritten.
                changed[i] = 1;
                before[i] = out[i].force;
            }
        double moment_b = -cross(rb, f);
        if constexpr (Mixed)
            if (b.deformable[B]) moment_b = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
        out[i] = {f, {cross(ra, f), moment_b}};
        sum += norm2(f);
    }
    return sum;
}
} // namespace

std::pair<int, int> team_share(const std::vector<double>& cost_before, int thread, int team,
                               const std::vector<double>* split) {
    // Item w belongs to the thread whose share of the total cost holds its middle.
    const int items = int(cost_before.size()) - 1;
    if (items <= 0) return {0, 0};
    const double total = cost_before[items];
    const bool given = split && int(split->size()) == team + 1;
    auto first_of = [&](int t) {
        if (t <= 0) return 0;
        if (t >= team) return items;
        const double from = total * (given ? (*split)[t] : double(t) / double(team));
        int lo = 0, hi = items; // first item whose middle is at or past `from`
        while (lo < hi) {
            const int mid = (lo + hi) / 2;
            if (0.5 * (cost_before[mid] + cost_before[mid + 1]) < from) lo = mid + 1;
            else hi = mid;
        }
        return lo;
    };
    return {first_of(thread), first_of(thread + 1)};
}

void contact_pass(Contacts& c, const std::vector<JointLaw>& laws, const BlockView& b, double dt,
                  double corner_radius, int first, int last, double stiffness_damping) {
    for (int w = first; w < last; ++w) {
        const auto& item = c.work[w];
        const std::span<const int> ids(c.batch_contact.data() + c.batch_first[item.batch] + item.begin,
                                       item.end - item.begin);
        double viscous_work = 0.0;
        c.partial_sum[w] = std::visit(
            [&](const auto& law) {
                const bool extras = c.marking || stiffness_damping > 0.0;
                if (extras)
                    return item.batch % 2
                               ? batch_pass<true, true>(law, ids, c, b, dt, corner_radius, stiffness_damping, viscous_work)
                               : batch_pass<false, true>(law, ids, c, b, dt, corner_radius, stiffness_damping, viscous_work);
                return item.batch % 2
                           ? batch_pass<true, false>(law, ids, c, b, dt, corner_radius, 0.0, viscous_work)
                           : batch_pass<false, false>(law, ids, c, b, dt, corner_radius, 0.0, viscous_work);
            },
            laws[item.batch / 2]);
        c.partial_damped[w] = viscous_work;
    }
}

double contact_force_squares(const Contacts& c) {
    double sum = 0.0;
    for (double s : c.partial_sum) sum += s;
    return sum;
}

} // namespace bbm::contact
