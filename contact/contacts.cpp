#include "contact/contacts.hpp"

#include <algorithm>
#include <span>

#include <omp.h>
#include <cmath>

namespace bbm::contact {

void Contacts::add(int a, int vertex, int b, int edge, int end, double l, int prop, const JointHistory& h) {
    edge_end.push_back(end);
    vertex_block.push_back(a);
    vertex_id.push_back(vertex);
    edge_block.push_back(b);
    edge_id.push_back(edge);
    length.push_back(l);
    property.push_back(prop);
    history.push_back(h);
    normal.push_back({});
}

void Contacts::remove_if_flagged(const std::vector<std::uint8_t>& remove) {
    int out = 0;
    for (int i = 0; i < size(); ++i) {
        if (remove[i]) continue;
        vertex_block[out] = vertex_block[i];
        vertex_id[out] = vertex_id[i];
        edge_block[out] = edge_block[i];
        edge_id[out] = edge_id[i];
        edge_end[out] = edge_end[i];
        length[out] = length[i];
        property[out] = property[i];
        history[out] = history[i];
        normal[out] = normal[i];
        ++out;
    }
    for (auto* v : {&vertex_block, &vertex_id, &edge_block, &edge_id, &edge_end, &property}) v->resize(out);
    length.resize(out);
    history.resize(out);
    normal.resize(out);
}

void Contacts::rebuild_batches(int property_sets, const std::uint8_t* deformable) {
    batches.assign(2 * property_sets, {});
    for (int i = 0; i < size(); ++i) {
        const bool mixed = deformable && (deformable[vertex_block[i]] || deformable[edge_block[i]]);
        batches[2 * property[i] + (mixed ? 1 : 0)].push_back(i);
    }
}

void update_normals(Contacts& c, const BlockView& b, double corner_radius) {
    for (int i = 0; i < c.size(); ++i) contact_kinematics(c, i, b, corner_radius);
}

namespace {
// The fused loop reads everything through local restrict pointers: through the
// Contacts members the compiler must assume the force stores alias them and would
// reload every base pointer on every contact. `Mixed` batches have a deformable
// side: the vertex velocity comes from its node, the edge velocity is interpolated
// between the edge's nodes, and the forces go to those nodes with the same weights
// (so the contact does no work the nodes do not see).
template <bool Mixed, class Law>
double step_batch(const Law& law, std::span<const int> ids, Contacts& c, const BlockView& b, double dt,
                  double corner_radius, Vec2* __restrict force, double* __restrict moment,
                  Vec2* __restrict node_force) {
    const int* __restrict va = c.vertex_block.data();
    const int* __restrict vid = c.vertex_id.data();
    const int* __restrict eb = c.edge_block.data();
    const int* __restrict e0 = c.edge_id.data();
    const int* __restrict e1 = c.edge_end.data();
    const double* __restrict len = c.length.data();
    JointHistory* __restrict hist = c.history.data();
    Vec2* __restrict normal = c.normal.data();
    const Vec2* __restrict vertex = b.vertex;
    const Vec2* __restrict centroid = b.centroid;
    const Vec2* __restrict velocity = b.velocity;
    const double* __restrict omega = b.omega;
    const double* __restrict inv_edge = b.inv_edge_length;
    double sum = 0.0;
    const std::size_t count = ids.size();
    for (std::size_t k = 0; k < count; ++k) {
        const int i = ids[k];
        // The block and vertex data a few contacts ahead are random gathers: ask for
        // them early (measured: the loop is bound by these loads, not arithmetic).
        if (k + 8 < count) {
            const int j = ids[k + 8];
            __builtin_prefetch(&vertex[vid[j]]);
            __builtin_prefetch(&vertex[e0[j]]);
            __builtin_prefetch(&velocity[eb[j]]);
            __builtin_prefetch(&force[eb[j]], 1);
        }
        const int A = va[i], B = eb[i];
        const Vec2 x = vertex[vid[i]], p = vertex[e0[i]], q = vertex[e1[i]];
        const double inv_len = inv_edge[e0[i]];
        Vec2 t = inv_len * (q - p);
        Vec2 n{t.y, -t.x};
        JointHistory& h = hist[i];
        const double s = dot(x - p, t) * inv_len;
        if (!h.bonded && (s < 0.0 || s > 1.0)) [[unlikely]] {
            const Vec2 r = x - ((s < 0.0 ? p : q) - corner_radius * n);
            const double rl = norm(r);
            if (rl > 0.0) n = r / rl, t = Vec2{-n.y, n.x};
        }
        const Vec2 ra = x - centroid[A], rb = x - centroid[B];
        Vec2 vr;
        if constexpr (Mixed)
            vr = vertex_velocity(b, A, vid[i], x) - edge_velocity(b, B, e0[i], e1[i], s, x);
        else
            vr = (velocity[A] + omega[A] * perp(ra)) - (velocity[B] + omega[B] * perp(rb));
        const double du_n = dot(vr, n) * dt, du_s = dot(vr, t) * dt;
        normal[i] = n;
        law.update(h, du_n, du_s);
        const Vec2 f = len[i] * (h.sn * n - h.tau * t);
        if constexpr (Mixed) {
            if (b.deformable[A]) {
                node_force[b.vertex_node[vid[i]]] += f;
            } else {
                force[A] += f;
                moment[A] += cross(ra, f);
            }
            if (b.deformable[B]) {
                const double w = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
                node_force[b.vertex_node[e0[i]]] -= (1.0 - w) * f;
                node_force[b.vertex_node[e1[i]]] -= w * f;
            } else {
                force[B] -= f;
                moment[B] -= cross(rb, f);
            }
        } else {
            force[A] += f;
            moment[A] += cross(ra, f);
            force[B] -= f;
            moment[B] -= cross(rb, f);
        }
        sum += norm2(f);
    }
    return sum;
}
} // namespace

double step_contacts(Contacts& c, const std::vector<JointLaw>& laws, const BlockView& b, double dt,
                     double corner_radius, const ForceTargets& out, int threads, ThreadForces& scratch) {
    auto run = [&](std::size_t k, std::size_t begin, std::size_t end, Vec2* f, double* m, Vec2* nf) {
        const std::span<const int> ids(c.batches[k].data() + begin, end - begin);
        return std::visit(
            [&](const auto& law) {
                return k % 2 ? step_batch<true>(law, ids, c, b, dt, corner_radius, f, m, nf)
                             : step_batch<false>(law, ids, c, b, dt, corner_radius, f, m, nf);
            },
            laws[k / 2]);
    };
    if (threads <= 1) {
        double sum = 0.0;
        for (std::size_t k = 0; k < c.batches.size(); ++k)
            sum += run(k, 0, c.batches[k].size(), out.force, out.moment, out.node_force);
        return sum;
    }
    const std::size_t nb = std::size_t(out.blocks), nn = std::size_t(out.nodes);
    if (scratch.force.size() != nb * threads || scratch.node_force.size() != nn * threads) {
        scratch.force.assign(nb * threads, {});
        scratch.moment.assign(nb * threads, 0.0);
        scratch.node_force.assign(nn * threads, {});
        scratch.sum.assign(threads, 0.0);
    }
#pragma omp parallel num_threads(threads)
    {
        const int t = omp_get_thread_num();
        Vec2* f = scratch.force.data() + nb * t;
        double* m = scratch.moment.data() + nb * t;
        Vec2* nf = scratch.node_force.data() + nn * t;
        std::fill(f, f + nb, Vec2{});
        std::fill(m, m + nb, 0.0);
        std::fill(nf, nf + nn, Vec2{});
        double sum = 0.0;
        for (std::size_t k = 0; k < c.batches.size(); ++k) {
            const std::size_t n = c.batches[k].size();
            sum += run(k, n * t / threads, n * (t + 1) / threads, f, m, nf);
        }
        scratch.sum[t] = sum;
#pragma omp barrier
#pragma omp for schedule(static)
        for (std::size_t k = 0; k < nb; ++k) {
            Vec2 fs{};
            double ms = 0.0;
            for (int u = 0; u < threads; ++u) fs += scratch.force[nb * u + k], ms += scratch.moment[nb * u + k];
            out.force[k] += fs;
            out.moment[k] += ms;
        }
#pragma omp for schedule(static)
        for (std::size_t k = 0; k < nn; ++k) {
            Vec2 fs{};
            for (int u = 0; u < threads; ++u) fs += scratch.node_force[nn * u + k];
            out.node_force[k] += fs;
        }
    }
    double sum = 0.0;
    for (int u = 0; u < threads; ++u) sum += scratch.sum[u];
    return sum;
}

} // namespace bbm::contact
