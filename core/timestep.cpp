// The time step and the masses (core/step.hpp, "Time step and masses").
#include "core/step.hpp"
#include "core/supports/ties.hpp"

#include <algorithm>
#include <cmath>

namespace bbm {

namespace {

/// Each body's translational and rotational stiffness (and each node's) from its
/// contacts: (kn + ks)·L, times the squared lever arm for a rotation; a contact
/// on a deformable edge shares it between the edge's two nodes.
void add_contact_stiffness(const World& w, std::vector<double>& k, std::vector<double>& kr, std::vector<double>& kn) {
    const auto& c = w.contacts;
    const auto& x = w.vertices.position;
    const auto& node = w.vertices.node;
    for (int i = 0; i < c.size(); ++i) {
        const auto& law = w.properties.laws[c.property[i]];
        const double kk = (contact::normal_stiffness(law) + contact::shear_stiffness(law)) * c.length[i];
        const Vec2 p0 = x[c.vertex_id[i]];
        const int A = c.vertex_block[i], B = c.edge_block[i];
        if (w.blocks.deformable[A]) {
            kn[node[c.vertex_id[i]]] += kk;
        } else {
            k[A] += kk;
            kr[A] += kk * norm2(p0 - w.bodies.state[A].centroid);
        }
        if (w.blocks.deformable[B]) {
            const Vec2 p = x[c.edge_id[i]], q = x[c.edge_end[i]];
            const double s = std::clamp(dot(p0 - p, q - p) / norm2(q - p), 0.0, 1.0);
            kn[node[c.edge_id[i]]] += (1.0 - s) * kk;
            kn[node[c.edge_end[i]]] += s * kk;
        } else {
            k[B] += kk;
            kr[B] += kk * norm2(p0 - w.bodies.state[B].centroid);
        }
    }
}

/// Zones: half the Gershgorin row sum of each node's rows (the larger of x, y).
void add_zone_stiffness(const World& w, std::vector<double>& kn) {
    const auto& z = w.zones;
    const auto& x = w.nodes.position;
    for (int e = 0; e < z.size(); ++e) {
        if (w.bodies.removed[z.block[e]]) continue;
        const auto& t = z.node[e];
        const auto ke = fem::element_stiffness(fem::gradients(x[t[0]], x[t[1]], x[t[2]]), z.elasticity[e]);
        for (int a = 0; a < 3; ++a) {
            double rx = 0.0, ry = 0.0;
            for (int j = 0; j < 6; ++j) rx += std::abs(ke[(2 * a) * 6 + j]), ry += std::abs(ke[(2 * a + 1) * 6 + j]);
            kn[t[a]] += 0.5 * std::max(rx, ry);
        }
    }
}

/// Quasi-static: Δt as given (1 s) and every mass scaled to its stiffness.
void scale_masses(World& w, const std::vector<double>& k, const std::vector<double>& kr, const std::vector<double>& kn) {
    const double s = w.settings.safety;
    w.clock.dt = w.settings.timestep > 0 ? w.settings.timestep : 1.0;
    const double f = (w.clock.dt / (2.0 * s)) * (w.clock.dt / (2.0 * s));
    // A block that has lost all its contacts keeps its scaled mass: with the
    // real mass and Δt = 1 s it would fall metres per step.
    auto& b = w.bodies;
    for (int i = 0; i < b.count(); ++i) {
        b.mass[i] = k[i] > 0 ? k[i] * f : std::max(b.mass[i], w.blocks.real_mass[i]);
        b.inertia[i] = kr[i] > 0 ? kr[i] * f : std::max(b.inertia[i], w.blocks.real_inertia[i]);
    }
    auto& n = w.nodes;
    for (int i = 0; i < n.count(); ++i) n.mass[i] = kn[i] > 0 ? kn[i] * f : std::max(n.mass[i], n.real_mass[i]);
}

/// Dynamic: real masses and Δt the safety times the smallest stable step.
void real_masses(World& w, const std::vector<double>& k, const std::vector<double>& kr, const std::vector<double>& kn) {
    double limit = INFINITY;
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i]) continue;
        if (k[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(w.blocks.real_mass[i] / k[i]));
        if (kr[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(w.blocks.real_inertia[i] / kr[i]));
    }
    for (int i = 0; i < w.nodes.count(); ++i)
        if (!w.bodies.removed[w.nodes.block[i]] && kn[i] > 0)
            limit = std::min(limit, 2.0 * std::sqrt(w.nodes.real_mass[i] / kn[i]));
    for_each_support(w.supports, [&](auto type, const auto& state) {
        using T = typename decltype(type)::type;
        if (T::tie_count(state) > 0) limit = std::min(limit, T::time_limit(state));
    });
    // Stiffness-proportional damping shortens the stable step (Belytschko et al.
    // 2000, §6.2): Δt ≤ (2/ω_max)(√(1 + ξ²) − ξ), ξ = β ω_max / 2, ω_max = 2 / limit.
    if (const double beta = w.settings.rayleigh_beta(); beta > 0.0 && std::isfinite(limit)) {
        const double xi = beta / limit;
        limit *= std::sqrt(1.0 + xi * xi) - xi;
    }
    w.clock.dt = w.settings.timestep > 0 ? w.settings.timestep : (std::isfinite(limit) ? w.settings.safety * limit : 1e-3);
    w.bodies.mass = w.blocks.real_mass;
    w.bodies.inertia = w.blocks.real_inertia;
    w.nodes.mass = w.nodes.real_mass;
}

} // namespace

void update_timestep(World& w) {
    // Scratch kept between calls: detection calls this inside a step.
    auto& k = w.team.block_stiffness;
    auto& kr = w.team.rotation_stiffness;
    auto& kn = w.team.node_stiffness;
    k.assign(w.bodies.count(), 0.0), kr.assign(w.bodies.count(), 0.0), kn.assign(w.nodes.count(), 0.0);
    add_contact_stiffness(w, k, kr, kn);
    add_zone_stiffness(w, kn);
    const double s = w.settings.safety;
    const bool scaled = w.settings.mode == SolverSpec::Mode::quasi_static;
    if (!w.ties.reaction.empty()) {
        const double step = scaled ? (w.settings.timestep > 0 ? w.settings.timestep : 1.0) : 0.0;
        const SupportRock rock_now = support_rock(w);
        RockStiffness rock{rock_now, k, kr, kn, scaled ? (step / (2.0 * s)) * (step / (2.0 * s)) : 0.0};
        for_each_support(w.supports, [&](auto type, auto& state) {
            using T = typename decltype(type)::type;
            if (T::tie_count(state) > 0) T::add_stiffness(state, rock);
        });
    }
    if (scaled) scale_masses(w, k, kr, kn);
    else real_masses(w, k, kr, kn);
    if (w.clock.first_dt == 0.0) w.clock.first_dt = w.clock.dt;
}

} // namespace bbm
