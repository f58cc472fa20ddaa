// The implicit elastic stage (SPEC §5): one sparse solve to elastic equilibrium.
//
// Unknowns: the displacement increment of every free component — (ux, uy, θ) of
// rigid blocks, (ux, uy) of FE nodes; prescribed components are held. The
// residual r is the unbalanced force of the current state, evaluated with the same
// code the explicit loop uses (contacts, zones, loads), so the two solutions meet
// at the same equilibrium. The stiffness is its linearisation at the current
// geometry without geometric terms:
//   zones     K_e = A Bᵀ D B                                   (fem/cst.hpp)
//   contacts  K_c = Gᵀ L (kn n nᵀ + ks t tᵀ) G,  with d = G u the relative
//             displacement at the contact point, exactly as contacts.hpp forms
//             relative velocities (rigid: u + θ × r; deformable edge: linear
//             between its nodes).
// Δu = K⁻¹ r is then applied as one step of velocity Δu/Δt through the contact
// laws and zones (so joint histories and zone stresses stay consistent), and
// velocities are zeroed.
#include "core/implicit.hpp"

#include "base/error.hpp"
#include "core/measures.hpp"
#include "core/step.hpp"
#include "fem/sparse_solve.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace bbm {

namespace {
std::string where(Vec2 p) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "(%.3g, %.3g)", p.x, p.y);
    return buf;
}
std::string fmt_value(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}
/// Every body at rest (the implicit stage's moves leave no velocity).
void stop_bodies(World& w) {
    for (auto& b : w.bodies.state) b.velocity = {}, b.omega = 0.0;
    std::fill(w.nodes.velocity.begin(), w.nodes.velocity.end(), Vec2{});
}

/// The free degrees of freedom of the elastic solve.
struct ElasticDofs {
    std::vector<std::array<int, 3>> block; ///< per block: x, y, rotation (−1: held or not in the model)
    std::vector<std::array<int, 2>> node;  ///< per FE node: x, y
    int count = 0;
};

ElasticDofs number_elastic_dofs(const World& w) {
    // Degrees of freedom: -1 where prescribed (held) or not part of the model.
    const int nb = w.bodies.count(), nn = w.nodes.count();
    ElasticDofs d{std::vector<std::array<int, 3>>(nb, {-1, -1, -1}), std::vector<std::array<int, 2>>(nn, {-1, -1}), 0};
    for (int i = 0; i < nb; ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i]) continue;
        for (int c = 0; c < 3; ++c)
            if (!(w.loads.block_fixed[i] & (1 << c))) d.block[i][c] = d.count++;
    }
    for (int k = 0; k < nn; ++k) {
        if (w.bodies.removed[w.nodes.block[k]]) continue;
        for (int c = 0; c < 2; ++c)
            if (!(w.loads.node_fixed[k] & (1 << c))) d.node[k][c] = d.count++;
    }
    return d;
}

/// Forces at the current state; the largest free force over the force scale.
double elastic_residual_ratio(World& w, const ElasticDofs& d) {
    place_bodies(w);
    evaluate_forces(w);
    double worst = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i)
        for (int c = 0; c < 2; ++c)
            if (d.block[i][c] >= 0) worst = std::max(worst, std::abs(c ? w.bodies.force[i].y : w.bodies.force[i].x));
    for (int k = 0; k < w.nodes.count(); ++k)
        for (int c = 0; c < 2; ++c)
            if (d.node[k][c] >= 0) worst = std::max(worst, std::abs(c ? w.nodes.force[k].y : w.nodes.force[k].x));
    const double scale = force_scale(w);
    return scale > 0 ? worst / scale : 0.0;
}

std::vector<double> elastic_residual(const World& w, const ElasticDofs& d) {
    std::vector<double> r(d.count, 0.0);
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (d.block[i][0] >= 0) r[d.block[i][0]] = w.bodies.force[i].x;
        if (d.block[i][1] >= 0) r[d.block[i][1]] = w.bodies.force[i].y;
        if (d.block[i][2] >= 0) r[d.block[i][2]] = w.bodies.moment[i];
    }
    for (int k = 0; k < w.nodes.count(); ++k) {
        if (d.node[k][0] >= 0) r[d.node[k][0]] = w.nodes.force[k].x;
        if (d.node[k][1] >= 0) r[d.node[k][1]] = w.nodes.force[k].y;
    }
    return r;
}

/// The linear stiffness of zones and contacts (not open cracks) at the current state.
void assemble_elastic_stiffness(const World& w, const ElasticDofs& d, fem::SparseTriplets& K, std::vector<double>& diagonal) {
    K.size = d.count;
    diagonal.assign(d.count, 0.0);
    auto add = [&](int a, int b, double v) {
        if (a < 0 || b < 0 || v == 0.0) return;
        K.add(a, b, v);
        if (a == b) diagonal[a] += v;
    };
    for (int z = 0; z < w.zones.size(); ++z) {
        if (w.bodies.removed[w.zones.block[z]]) continue;
        const auto& t = w.zones.node[z];
        const auto ke =
            fem::element_stiffness(fem::gradients(w.nodes.position[t[0]], w.nodes.position[t[1]], w.nodes.position[t[2]]), w.zones.elasticity[z]);
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b) add(d.node[t[a / 2]][a % 2], d.node[t[b / 2]][b % 2], ke[a * 6 + b]);
    }
    // Contact operator: d = Σ g_j u_j over at most 7 (dof, g) terms.
    struct Term {
        int dof;
        Vec2 g;
    };
    const auto& c = contacts(w);
    for (int i = 0; i < w.contacts.size(); ++i) {
        const auto& h = c.history[i];
        if (!h.bonded && h.sn <= 0.0) continue; // an open crack or unbonded contact carries nothing
        const int A = c.vertex_block[i], B = c.edge_block[i];
        const Vec2 x = w.vertices.position[c.vertex_id[i]], n = c.normal[i], tg = contact::tangent_of(n);
        Term terms[8];
        int count = 0;
        auto side = [&](int blk, double sign, int vertex, int e0, int e1) {
            if (!w.blocks.deformable[blk]) {
                const Vec2 lever = x - w.bodies.state[blk].centroid;
                terms[count++] = {d.block[blk][0], Vec2{sign, 0.0}};
                terms[count++] = {d.block[blk][1], Vec2{0.0, sign}};
                terms[count++] = {d.block[blk][2], sign * perp(lever)};
            } else if (vertex >= 0) {
                const int k = w.vertices.node[vertex];
                terms[count++] = {d.node[k][0], Vec2{sign, 0.0}};
                terms[count++] = {d.node[k][1], Vec2{0.0, sign}};
            } else {
                const Vec2 p = w.vertices.position[e0], q = w.vertices.position[e1];
                const double s = std::clamp(dot(x - p, q - p) / norm2(q - p), 0.0, 1.0);
                const int k0 = w.vertices.node[e0], k1 = w.vertices.node[e1];
                terms[count++] = {d.node[k0][0], Vec2{sign * (1.0 - s), 0.0}};
                terms[count++] = {d.node[k0][1], Vec2{0.0, sign * (1.0 - s)}};
                terms[count++] = {d.node[k1][0], Vec2{sign * s, 0.0}};
                terms[count++] = {d.node[k1][1], Vec2{0.0, sign * s}};
            }
        };
        side(A, 1.0, c.vertex_id[i], -1, -1);
        side(B, -1.0, -1, c.edge_id[i], c.edge_end[i]);
        const auto& law = w.properties.laws[c.property[i]];
        const double kn = c.length[i] * contact::normal_stiffness(law), ks = c.length[i] * contact::shear_stiffness(law);
        for (int a = 0; a < count; ++a)
            for (int b = 0; b < count; ++b)
                add(terms[a].dof, terms[b].dof,
                    kn * dot(terms[a].g, n) * dot(terms[b].g, n) + ks * dot(terms[a].g, tg) * dot(terms[b].g, tg));
    }
}

/// Throws naming a floating body, or loads no stiffness could carry.
void check_elastic_system(const World& w, const ElasticDofs& d, const std::vector<double>& diagonal,
                          const std::vector<double>& r) {
    const int nb = w.bodies.count(), nn = w.nodes.count();
    // A degree of freedom with no stiffness at all: name it.
    static const char* component[] = {"x", "y", "rotation"};
    for (int i = 0; i < nb; ++i)
        for (int c = 0; c < 3; ++c)
            if (d.block[i][c] >= 0 && !(diagonal[d.block[i][c]] > 0.0))
                throw SingularSystemError("elastic solve: block " + std::to_string(i) + " of region '" +
                                         w.region_names[w.blocks.region[i]] + "' at " + where(w.bodies.state[i].centroid) +
                                         " has no stiffness in " + component[c] +
                                         ": it floats (no joints and no support). Remove it, join it to the "
                                         "model or fix it with a velocity boundary.");
    for (int k = 0; k < nn; ++k)
        for (int c = 0; c < 2; ++c)
            if (d.node[k][c] >= 0 && !(diagonal[d.node[k][c]] > 0.0))
                throw SingularSystemError("elastic solve: node " + std::to_string(k) + " at " + where(w.nodes.position[k]) +
                                         " has no stiffness in " + component[c] + " (a zone-less node)");
    // Loads beyond what the stiffnesses carry (a stress of 1e300 Pa, a load in the
    // wrong unit): even the stiffest single spring would move by more than the
    // model's size, and the solve would overflow into a "singular" matrix.
    double load = 0.0, stiffest = 0.0;
    Box2 extent;
    auto translational = [&](int dof) {
        if (dof < 0) return;
        load = std::isfinite(r[dof]) && std::isfinite(load) ? std::max(load, std::abs(r[dof])) : INFINITY;
        stiffest = std::max(stiffest, diagonal[dof]);
    };
    for (int i = 0; i < nb; ++i)
        if (!w.bodies.removed[i] && !w.blocks.deformable[i]) translational(d.block[i][0]), translational(d.block[i][1]);
    for (int k = 0; k < nn; ++k)
        if (!w.bodies.removed[w.nodes.block[k]]) translational(d.node[k][0]), translational(d.node[k][1]);
    for (Vec2 v : w.vertices.position) extent.add(v);
    const double size = std::max(extent.width(), extent.height());
    if (!(load <= stiffest * size))
        throw NumericalError(
            "elastic solve: an unbalanced force of " + fmt_value(load) + " N/m against stiffnesses of at most " +
            fmt_value(stiffest) + " N/m² would move the model by more than its size (" + fmt_value(size) +
            " m): the stresses or loads are beyond what the joints and zones can carry. Check the initial "
            "stresses and loads (Pa, N/m) and the stiffnesses (Pa/m, Pa) for wrong units or magnitudes.");
}

/// Δu applied through the laws and zones as one kinematic step.
void apply_elastic_increment(World& w, const ElasticDofs& d, const std::vector<double>& du) {
    // Δu as one step of velocity Δu/Δt through laws and zones.
    const int nb = w.bodies.count(), nn = w.nodes.count();
    const double dt = w.clock.dt;
    for (int i = 0; i < nb; ++i) {
        if (d.block[i][0] >= 0) w.bodies.state[i].velocity.x = du[d.block[i][0]] / dt;
        if (d.block[i][1] >= 0) w.bodies.state[i].velocity.y = du[d.block[i][1]] / dt;
        if (d.block[i][2] >= 0) w.bodies.state[i].omega = du[d.block[i][2]] / dt;
    }
    for (int k = 0; k < nn; ++k) {
        if (d.node[k][0] >= 0) w.nodes.velocity[k].x = du[d.node[k][0]] / dt;
        if (d.node[k][1] >= 0) w.nodes.velocity[k].y = du[d.node[k][1]] / dt;
    }
    place_bodies(w);
    evaluate_forces(w);
    for (int i = 0; i < nb; ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i]) continue;
        w.bodies.state[i].centroid += dt * w.bodies.state[i].velocity;
        w.bodies.state[i].theta += dt * w.bodies.state[i].omega;
    }
    for (int k = 0; k < nn; ++k) w.nodes.position[k] += dt * w.nodes.velocity[k];
    stop_bodies(w);
}

} // namespace

ElasticSolveReport solve_elastic(World& w) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!w.ties.reaction.empty())
        throw std::runtime_error("the elastic stage does not include support: put it before the stage that installs it");
    ElasticSolveReport report;
    const ElasticDofs dofs = number_elastic_dofs(w);
    report.equations = dofs.count;
    // Residual: the unbalanced force at rest.
    stop_bodies(w);
    report.ratio_before = elastic_residual_ratio(w, dofs);
    // Newton iterations with the linear stiffness: the first solve is exact for a
    // linear model; the geometric terms left out (normals turning with blocks,
    // lever arms) leave a residual of the order of the strain, which one or two
    // more solves remove.
    for (int iteration = 0; iteration < 4; ++iteration) {
        const std::vector<double> r = elastic_residual(w, dofs);
        fem::SparseTriplets K;
        std::vector<double> diagonal;
        assemble_elastic_stiffness(w, dofs, K, diagonal);
        report.nonzeros = long(K.value.size());
        check_elastic_system(w, dofs, diagonal, r);
        std::vector<double> du;
        try {
            fem::SolveReport sr;
            du = fem::solve_sparse(K, r, &sr);
            report.method = sr.method;
            report.relative_residual = sr.relative_residual;
        } catch (const std::runtime_error& e) {
            throw SingularSystemError(std::string("elastic solve: ") + e.what() +
                                     ". The model (or part of it) can move without resistance: check that the "
                                     "boundaries hold it in x, y and rotation, and that no group of blocks is "
                                     "joined to the rest only by broken joints.");
        }
        apply_elastic_increment(w, dofs, du);
        report.ratio_after = w.clock.ratio = elastic_residual_ratio(w, dofs);
        ++report.iterations;
        if (report.ratio_after < 1e-8) break;
    }
    sum_boundary_forces(w);
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return report;
}

void move_supports(World& w, double time) {
    std::vector<Vec2> du(w.bodies.count()), dn(w.nodes.count());
    std::vector<double> dtheta(w.bodies.count());
    for (int i = 0; i < w.bodies.count(); ++i) {
        const std::uint8_t fx = w.loads.block_fixed[i];
        du[i] = {(fx & 1) ? time * w.loads.block_velocity[i].x : 0.0, (fx & 2) ? time * w.loads.block_velocity[i].y : 0.0};
        dtheta[i] = (fx & 4) ? time * w.loads.block_omega[i] : 0.0;
    }
    for (int k = 0; k < w.nodes.count(); ++k) {
        const std::uint8_t fx = w.loads.node_fixed[k];
        dn[k] = {(fx & 1) ? time * w.loads.node_velocity[k].x : 0.0, (fx & 2) ? time * w.loads.node_velocity[k].y : 0.0};
    }
    move_bodies(w, du, dtheta, dn);
}

void move_bodies(World& w, const std::vector<Vec2>& du, const std::vector<double>& dtheta, const std::vector<Vec2>& dn) {
    for (int i = 0; i < w.bodies.count(); ++i) w.bodies.state[i].velocity = du[i] / w.clock.dt, w.bodies.state[i].omega = dtheta[i] / w.clock.dt;
    for (int k = 0; k < w.nodes.count(); ++k) w.nodes.velocity[k] = dn[k] / w.clock.dt;
    place_bodies(w);
    evaluate_forces(w); // the increments through the contact laws and zones
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i]) continue;
        w.bodies.state[i].centroid += du[i];
        w.bodies.state[i].theta += dtheta[i];
    }
    for (int k = 0; k < w.nodes.count(); ++k) w.nodes.position[k] += dn[k];
    stop_bodies(w);
    place_bodies(w);
}

} // namespace bbm
