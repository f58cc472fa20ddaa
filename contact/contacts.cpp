#include "contact/contacts.hpp"

#include <algorithm>
#include <cmath>

namespace bbm::contact {

void Contacts::add(int a, int vertex, int b, int edge, double l, int prop, const JointHistory& h) {
    vertex_block.push_back(a);
    vertex_id.push_back(vertex);
    edge_block.push_back(b);
    edge_id.push_back(edge);
    length.push_back(l);
    property.push_back(prop);
    history.push_back(h);
    normal.push_back({});
    tangent.push_back({});
    dun.push_back(0.0);
    dus.push_back(0.0);
}

void Contacts::remove_if_flagged(const std::vector<std::uint8_t>& remove) {
    int out = 0;
    for (int i = 0; i < size(); ++i) {
        if (remove[i]) continue;
        vertex_block[out] = vertex_block[i];
        vertex_id[out] = vertex_id[i];
        edge_block[out] = edge_block[i];
        edge_id[out] = edge_id[i];
        length[out] = length[i];
        property[out] = property[i];
        history[out] = history[i];
        normal[out] = normal[i];
        tangent[out] = tangent[i];
        dun[out] = dun[i];
        dus[out] = dus[i];
        ++out;
    }
    for (auto* v : {&vertex_block, &vertex_id, &edge_block, &edge_id, &property}) v->resize(out);
    length.resize(out);
    history.resize(out);
    normal.resize(out);
    tangent.resize(out);
    dun.resize(out);
    dus.resize(out);
}

void Contacts::rebuild_batches(int property_sets) {
    batches.assign(property_sets, {});
    for (int i = 0; i < size(); ++i) batches[property[i]].push_back(i);
}

void update_kinematics(Contacts& c, const BlockView& b, double dt, double corner_radius) {
    const int n = c.size();
    for (int i = 0; i < n; ++i) {
        const int A = c.vertex_block[i], B = c.edge_block[i];
        const int e0 = c.edge_id[i], e1 = next_vertex(b.first, B, e0);
        const Vec2 x = b.vertex[c.vertex_id[i]];
        const Vec2 p = b.vertex[e0], q = b.vertex[e1];
        const Vec2 d = q - p;
        const double len = norm(d);
        Vec2 t = d / len;
        Vec2 nrm{t.y, -t.x}; // outward normal of a counter-clockwise polygon's edge
        // Beyond an end of the edge: normal of the rounded corner (continuous).
        const double s = dot(x - p, t);
        if (s < 0.0 || s > len) {
            const Vec2 corner = s < 0.0 ? p : q;
            const Vec2 r = x - (corner - corner_radius * nrm);
            const double rl = norm(r);
            if (rl > 0.0) {
                nrm = r / rl;
                t = Vec2{-nrm.y, nrm.x};
            }
        }
        c.normal[i] = nrm;
        c.tangent[i] = t;
        const Vec2 va = b.velocity[A] + b.omega[A] * perp(x - b.centroid[A]);
        const Vec2 vb = b.velocity[B] + b.omega[B] * perp(x - b.centroid[B]);
        const Vec2 vr = va - vb;
        c.dun[i] = dot(vr, nrm) * dt;
        c.dus[i] = dot(vr, t) * dt;
    }
}

void update_stresses(Contacts& c, const std::vector<JointLaw>& laws) {
    for (std::size_t p = 0; p < c.batches.size(); ++p)
        update_batch(laws[p], c.batches[p], c.history.data(), c.dun.data(), c.dus.data());
}

double accumulate_forces(const Contacts& c, const BlockView& b, Vec2* force, double* moment) {
    const int n = c.size();
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const int A = c.vertex_block[i], B = c.edge_block[i];
        const Vec2 x = b.vertex[c.vertex_id[i]];
        const Vec2 f = contact_force(c, i);
        force[A] += f;
        moment[A] += cross(x - b.centroid[A], f);
        force[B] -= f;
        moment[B] -= cross(x - b.centroid[B], f);
        sum += norm(f);
    }
    return sum;
}

} // namespace bbm::contact
