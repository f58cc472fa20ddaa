// What a run is measured by (core/measures.hpp).
#include "core/measures.hpp"

#include "core/supports/ties.hpp"

#include <cmath>

namespace bbm {

const contact::Contacts& contacts(const World& w) {
    if (w.normals_stale) {
        // The normals are a cache of the last step's geometry (World::normals_stale).
        contact::update_normals(const_cast<contact::Contacts&>(w.contacts), block_view(w), w.detection.corner_radius);
        w.normals_stale = false;
    }
    return w.contacts;
}

contact::Contacts& contacts(World& w) {
    contacts(static_cast<const World&>(w));
    return w.contacts;
}

double force_scale(const World& w) {
    // The root-mean-square contact (and zone nodal) force. SPEC §5 says "mean
    // contact force magnitude"; RMS >= mean, and it needs no square root per contact.
    // Supports add the elements that may be all that holds a block (a bar's segments).
    const auto& z = w.zones;
    double terms = double(w.contacts.size()) + 3.0 * double(z.size());
    double squares = contact::contact_force_squares(w.contacts) + (z.size() > 0 ? fem::zone_force_squares(z) : 0.0);
    for_each_support(w.supports, [&](auto type, const auto& state) {
        decltype(type)::type::add_force_scale(state, terms, squares);
    });
    double mean_force = terms > 0 ? std::sqrt(squares / terms) : 0.0;
    if (mean_force <= 0.0) {
        const Vec2 g = w.settings.gravity;
        for (int i = 0; i < w.bodies.count(); ++i) mean_force += norm(w.loads.block_force[i] + w.blocks.real_mass[i] * g);
        for (int i = 0; i < w.nodes.count(); ++i) mean_force += norm(w.loads.node_force[i] + w.nodes.real_mass[i] * g);
        for_each_support(w.supports,
                         [&](auto type, const auto& state) { decltype(type)::type::add_applied_loads(state, mean_force); });
        mean_force /= std::max(1, w.bodies.count() + w.nodes.count());
    }
    return mean_force;
}

double kinetic_energy(const World& w) {
    double e = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i)
        if (!w.bodies.removed[i] && !w.blocks.deformable[i]) {
            const auto& b = w.bodies.state[i];
            e += 0.5 * w.blocks.real_mass[i] * norm2(b.velocity) + 0.5 * w.blocks.real_inertia[i] * b.omega * b.omega;
        }
    for (int i = 0; i < w.nodes.count(); ++i)
        if (!w.bodies.removed[w.nodes.block[i]]) e += 0.5 * w.nodes.real_mass[i] * norm2(w.nodes.velocity[i]);
    return e;
}

double strain_energy(const World& w) {
    double e = 0.0;
    const auto& c = w.contacts;
    for (int i = 0; i < c.size(); ++i) {
        const auto& h = c.history[i];
        const auto& law = w.properties.laws[c.property[i]];
        e += c.length[i] * (h.sn * h.sn / (2.0 * contact::normal_stiffness(law)) +
                            h.tau * h.tau / (2.0 * contact::shear_stiffness(law)));
    }
    return e + zone_strain_energy(w);
}

double zone_strain_energy(const World& w) {
    double e = 0.0;
    const auto& z = w.zones;
    const auto& x = w.nodes.position;
    for (int k = 0; k < z.size(); ++k) {
        if (w.bodies.removed[z.block[k]]) continue;
        const auto& t = z.node[k];
        const double area = fem::gradients(x[t[0]], x[t[1]], x[t[2]]).area;
        // ½ σ·D⁻¹σ, plane strain: D⁻¹ from the Lamé constants (σzz = λ(εxx + εyy)).
        const auto& s = z.stress[k];
        const double l = z.elasticity[k].lambda, G = z.elasticity[k].shear;
        const double tr = s[0] + s[1];
        const double exx = (s[0] - l / (2.0 * (l + G)) * tr) / (2.0 * G);
        const double eyy = (s[1] - l / (2.0 * (l + G)) * tr) / (2.0 * G);
        const double exy = s[2] / (2.0 * G);
        e += 0.5 * area * (s[0] * exx + s[1] * eyy + 2.0 * s[2] * exy);
    }
    return e;
}

double dissipated_energy(const World& w) {
    double e = w.detection.dissipated_removed; // the joints since removed took theirs with them
    for (int i = 0; i < w.contacts.size(); ++i) e += w.contacts.length[i] * w.contacts.history[i].dissipated;
    return e;
}

namespace {
/// Kinetic energy at the masses the step integrates (before any step: the
/// account then uses this; after one, the step's own, Clock::kinetic).
double integrated_kinetic_energy(const World& w) {
    double e = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i)
        if (!w.bodies.removed[i] && !w.blocks.deformable[i]) {
            const auto& b = w.bodies.state[i];
            e += 0.5 * w.bodies.mass[i] * norm2(b.velocity) + 0.5 * w.bodies.inertia[i] * b.omega * b.omega;
        }
    for (int i = 0; i < w.nodes.count(); ++i)
        if (!w.bodies.removed[w.nodes.block[i]]) e += 0.5 * w.nodes.mass[i] * norm2(w.nodes.velocity[i]);
    return e;
}

EnergyAccount raw_account(const World& w) {
    EnergyAccount a;
    a.work = w.clock.work, a.wave_input = wave_energy(w);
    a.kinetic = w.clock.steps > 0 ? w.clock.kinetic : integrated_kinetic_energy(w), a.strain = strain_energy(w), a.joints = dissipated_energy(w);
    a.damping = w.clock.damped, a.radiated = absorbed_energy(w);
    if (!w.ties.reaction.empty()) {
        const SupportRock rock = support_rock(w);
        for_each_support(w.supports, [&](auto type, const auto& state) {
            using T = typename decltype(type)::type;
            if (T::tie_count(state) > 0) a.supports += T::energy(state, rock);
        });
    }
    a.error = a.work + a.wave_input - (a.kinetic + a.strain + a.joints + a.damping + a.radiated + a.supports);
    return a;
}
} // namespace

EnergyAccount energy_account(const World& w) {
    EnergyAccount a = raw_account(w);
    a.error -= w.clock.energy_origin;
    return a;
}

void start_energy_account(World& w) { w.clock.energy_origin = raw_account(w).error; }

double absorbed_energy(const World& w) {
    double e = 0.0;
    for (double a : w.viscous.absorbed) e += a;
    return e;
}

double wave_energy(const World& w) {
    double e = 0.0;
    for (double s : w.viscous.supplied) e += s;
    return e;
}

int cracks(const World& w, contact::JointState mode) {
    // Broken contacts still present plus those detection removed since.
    using contact::JointState;
    const auto& t = w.detection.totals;
    int n = mode == JointState::broken_tension ? t.removed_tensile : mode == JointState::broken_shear ? t.removed_shear : 0;
    for (const auto& h : w.contacts.history) n += h.broken == mode;
    return n;
}

Vec2 boundary_force(const World& w, const std::string& name) {
    for (std::size_t k = 0; k < w.boundaries.names.size(); ++k)
        if (w.boundaries.names[k] == name) return w.boundaries.force[k];
    return {};
}

std::vector<std::array<double, 3>> block_stresses(const World& w) {
    const auto& c = contacts(w);
    const auto& body = w.bodies.state;
    std::vector<std::array<double, 3>> m(w.bodies.count(), {0.0, 0.0, 0.0});
    auto add = [&](int blk, Vec2 r, Vec2 f) {
        if (w.blocks.deformable[blk]) return;
        m[blk][0] += r.x * f.x;
        m[blk][1] += r.y * f.y;
        m[blk][2] += 0.5 * (r.x * f.y + r.y * f.x);
    };
    for (int i = 0; i < c.size(); ++i) {
        const int A = c.vertex_block[i], B = c.edge_block[i];
        const Vec2 x = w.vertices.position[c.vertex_id[i]], f = contact::contact_force(c, i);
        add(A, x - body[A].centroid, f);
        add(B, x - body[B].centroid, -1.0 * f);
    }
    // Boundary tractions are surface forces too (at their points, rotating with the
    // block); gravity, uniform over the block, has no first moment about the centroid.
    for (const auto& t : w.loads.tractions) add(t.block, rotation(body[t.block].theta)(t.offset), t.force);
    // Supports (reaction = minus the force on the prescribed components), where a
    // `touching` boundary holds the block: without them a block on a symmetry
    // plane would show half its stress across the plane.
    for (const auto& held : w.boundaries.held) {
        const int i = held.block;
        const std::uint8_t fixed = w.loads.block_fixed[i];
        const Vec2 reaction{(fixed & 1) ? -w.bodies.force[i].x : 0.0, (fixed & 2) ? -w.bodies.force[i].y : 0.0};
        add(i, rotation(body[i].theta)(held.offset), reaction);
    }
    // Deformable blocks: area-weighted mean of their zone stresses.
    const auto& z = w.zones;
    const auto& x = w.nodes.position;
    for (int k = 0; k < z.size(); ++k) {
        const auto& t = z.node[k];
        const double a = fem::gradients(x[t[0]], x[t[1]], x[t[2]]).area;
        for (int j = 0; j < 3; ++j) m[z.block[k]][j] += a * z.stress[k][j];
    }
    for (int b = 0; b < w.bodies.count(); ++b)
        for (double& v : m[b]) v /= w.blocks.area[b];
    return m;
}

int block_at(const World& w, Vec2 p) {
    int best = -1;
    double dmin = INFINITY;
    for (int i = 0; i < w.bodies.count(); ++i) {
        const double d = norm(w.bodies.state[i].centroid - p);
        if (d < dmin) dmin = d, best = i;
    }
    return best;
}

} // namespace bbm
