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
#include "base/error.hpp"
#include "core/solver.hpp"
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
} // namespace

Solver::ElasticDofs Solver::number_elastic_dofs() const {
    // Degrees of freedom: -1 where prescribed (held) or not part of the model.
    const int nb = b_.count(), nn = n_.count();
    ElasticDofs d{std::vector<std::array<int, 3>>(nb, {-1, -1, -1}), std::vector<std::array<int, 2>>(nn, {-1, -1}), 0};
    for (int i = 0; i < nb; ++i) {
        if (b_.removed[i] || b_.deformable[i]) continue;
        for (int c = 0; c < 3; ++c)
            if (!(b_.fixed[i] & (1 << c))) d.block[i][c] = d.count++;
    }
    for (int k = 0; k < nn; ++k) {
        if (b_.removed[n_.block[k]]) continue;
        for (int c = 0; c < 2; ++c)
            if (!(n_.fixed[k] & (1 << c))) d.node[k][c] = d.count++;
    }
    return d;
}

double Solver::elastic_residual_ratio(const ElasticDofs& d) {
    update_vertices();
    compute_forces();
    double worst = 0.0;
    for (int i = 0; i < b_.count(); ++i)
        for (int c = 0; c < 2; ++c)
            if (d.block[i][c] >= 0) worst = std::max(worst, std::abs(c ? b_.force[i].y : b_.force[i].x));
    for (int k = 0; k < n_.count(); ++k)
        for (int c = 0; c < 2; ++c)
            if (d.node[k][c] >= 0) worst = std::max(worst, std::abs(c ? n_.force[k].y : n_.force[k].x));
    const double scale = force_scale();
    return scale > 0 ? worst / scale : 0.0;
}

std::vector<double> Solver::elastic_residual(const ElasticDofs& d) const {
    std::vector<double> r(d.count, 0.0);
    for (int i = 0; i < b_.count(); ++i) {
        if (d.block[i][0] >= 0) r[d.block[i][0]] = b_.force[i].x;
        if (d.block[i][1] >= 0) r[d.block[i][1]] = b_.force[i].y;
        if (d.block[i][2] >= 0) r[d.block[i][2]] = b_.moment[i];
    }
    for (int k = 0; k < n_.count(); ++k) {
        if (d.node[k][0] >= 0) r[d.node[k][0]] = n_.force[k].x;
        if (d.node[k][1] >= 0) r[d.node[k][1]] = n_.force[k].y;
    }
    return r;
}

void Solver::assemble_elastic_stiffness(const ElasticDofs& d, fem::SparseTriplets& K, std::vector<double>& diagonal) const {
    K.size = d.count;
    diagonal.assign(d.count, 0.0);
    auto add = [&](int a, int b, double v) {
        if (a < 0 || b < 0 || v == 0.0) return;
        K.add(a, b, v);
        if (a == b) diagonal[a] += v;
    };
    for (int z = 0; z < z_.size(); ++z) {
        if (b_.removed[z_.block[z]]) continue;
        const auto& t = z_.node[z];
        const auto ke =
            fem::element_stiffness(fem::gradients(n_.position[t[0]], n_.position[t[1]], n_.position[t[2]]), z_.elasticity[z]);
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b) add(d.node[t[a / 2]][a % 2], d.node[t[b / 2]][b % 2], ke[a * 6 + b]);
    }
    // Contact operator: d = Σ g_j u_j over at most 7 (dof, g) terms.
    struct Term {
        int dof;
        Vec2 g;
    };
    refresh_normals();
    for (int i = 0; i < c_.size(); ++i) {
        const auto& h = c_.history[i];
        if (!h.bonded && h.sn <= 0.0) continue; // an open crack or unbonded contact carries nothing
        const int A = c_.vertex_block[i], B = c_.edge_block[i];
        const Vec2 x = b_.vertex[c_.vertex_id[i]], n = c_.normal[i], tg = contact::tangent_of(n);
        Term terms[8];
        int count = 0;
        auto side = [&](int blk, double sign, int vertex, int e0, int e1) {
            if (!b_.deformable[blk]) {
                const Vec2 lever = x - b_.centroid[blk];
                terms[count++] = {d.block[blk][0], Vec2{sign, 0.0}};
                terms[count++] = {d.block[blk][1], Vec2{0.0, sign}};
                terms[count++] = {d.block[blk][2], sign * perp(lever)};
            } else if (vertex >= 0) {
                const int k = b_.vertex_node[vertex];
                terms[count++] = {d.node[k][0], Vec2{sign, 0.0}};
                terms[count++] = {d.node[k][1], Vec2{0.0, sign}};
            } else {
                const Vec2 p = b_.vertex[e0], q = b_.vertex[e1];
                const double w = std::clamp(dot(x - p, q - p) / norm2(q - p), 0.0, 1.0);
                const int k0 = b_.vertex_node[e0], k1 = b_.vertex_node[e1];
                terms[count++] = {d.node[k0][0], Vec2{sign * (1.0 - w), 0.0}};
                terms[count++] = {d.node[k0][1], Vec2{0.0, sign * (1.0 - w)}};
                terms[count++] = {d.node[k1][0], Vec2{sign * w, 0.0}};
                terms[count++] = {d.node[k1][1], Vec2{0.0, sign * w}};
            }
        };
        side(A, 1.0, c_.vertex_id[i], -1, -1);
        side(B, -1.0, -1, c_.edge_id[i], c_.edge_end[i]);
        const auto& law = laws_[c_.property[i]];
        const double kn = c_.length[i] * contact::normal_stiffness(law), ks = c_.length[i] * contact::shear_stiffness(law);
        for (int a = 0; a < count; ++a)
            for (int b = 0; b < count; ++b)
                add(terms[a].dof, terms[b].dof,
                    kn * dot(terms[a].g, n) * dot(terms[b].g, n) + ks * dot(terms[a].g, tg) * dot(terms[b].g, tg));
    }
}

void Solver::check_elastic_system(const ElasticDofs& d, const std::vector<double>& diagonal,
                                  const std::vector<double>& r) const {
    const int nb = b_.count(), nn = n_.count();
    // A degree of freedom with no stiffness at all: name it.
    static const char* component[] = {"x", "y", "rotation"};
    for (int i = 0; i < nb; ++i)
        for (int c = 0; c < 3; ++c)
            if (d.block[i][c] >= 0 && !(diagonal[d.block[i][c]] > 0.0))
                throw SingularSystemError("elastic solve: block " + std::to_string(i) + " of region '" +
                                         region_names_[b_.region[i]] + "' at " + where(b_.centroid[i]) +
                                         " has no stiffness in " + component[c] +
                                         ": it floats (no joints and no support). Remove it, join it to the "
                                         "model or fix it with a velocity boundary.");
    for (int k = 0; k < nn; ++k)
        for (int c = 0; c < 2; ++c)
            if (d.node[k][c] >= 0 && !(diagonal[d.node[k][c]] > 0.0))
                throw SingularSystemError("elastic solve: node " + std::to_string(k) + " at " + where(n_.position[k]) +
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
        if (!b_.removed[i] && !b_.deformable[i]) translational(d.block[i][0]), translational(d.block[i][1]);
    for (int k = 0; k < nn; ++k)
        if (!b_.removed[n_.block[k]]) translational(d.node[k][0]), translational(d.node[k][1]);
    for (Vec2 v : b_.vertex) extent.add(v);
    const double size = std::max(extent.width(), extent.height());
    if (!(load <= stiffest * size))
        throw NumericalError(
            "elastic solve: an unbalanced force of " + fmt_value(load) + " N/m against stiffnesses of at most " +
            fmt_value(stiffest) + " N/m² would move the model by more than its size (" + fmt_value(size) +
            " m): the stresses or loads are beyond what the joints and zones can carry. Check the initial "
            "stresses and loads (Pa, N/m) and the stiffnesses (Pa/m, Pa) for wrong units or magnitudes.");
}

void Solver::apply_elastic_increment(const ElasticDofs& d, const std::vector<double>& du) {
    // Δu as one step of velocity Δu/Δt through laws and zones.
    const int nb = b_.count(), nn = n_.count();
    const double dt = dt_;
    for (int i = 0; i < nb; ++i) {
        if (d.block[i][0] >= 0) b_.velocity[i].x = du[d.block[i][0]] / dt;
        if (d.block[i][1] >= 0) b_.velocity[i].y = du[d.block[i][1]] / dt;
        if (d.block[i][2] >= 0) b_.omega[i] = du[d.block[i][2]] / dt;
    }
    for (int k = 0; k < nn; ++k) {
        if (d.node[k][0] >= 0) n_.velocity[k].x = du[d.node[k][0]] / dt;
        if (d.node[k][1] >= 0) n_.velocity[k].y = du[d.node[k][1]] / dt;
    }
    update_vertices();
    compute_forces();
    for (int i = 0; i < nb; ++i) {
        if (b_.removed[i] || b_.deformable[i]) continue;
        b_.centroid[i] += dt * b_.velocity[i];
        b_.theta[i] += dt * b_.omega[i];
    }
    for (int k = 0; k < nn; ++k) n_.position[k] += dt * n_.velocity[k];
    std::fill(b_.velocity.begin(), b_.velocity.end(), Vec2{});
    std::fill(b_.omega.begin(), b_.omega.end(), 0.0);
    std::fill(n_.velocity.begin(), n_.velocity.end(), Vec2{});
}

Solver::ElasticSolveReport Solver::solve_elastic() {
    const auto t0 = std::chrono::steady_clock::now();
    if (!tie_reaction_.empty())
        throw std::runtime_error("the elastic stage does not include support: put it before the stage that installs it");
    ElasticSolveReport report;
    const ElasticDofs dofs = number_elastic_dofs();
    report.equations = dofs.count;
    // Residual: the unbalanced force at rest.
    std::fill(b_.velocity.begin(), b_.velocity.end(), Vec2{});
    std::fill(b_.omega.begin(), b_.omega.end(), 0.0);
    std::fill(n_.velocity.begin(), n_.velocity.end(), Vec2{});
    report.ratio_before = elastic_residual_ratio(dofs);
    // Newton iterations with the linear stiffness: the first solve is exact for a
    // linear model; the geometric terms left out (normals turning with blocks,
    // lever arms) leave a residual of the order of the strain, which one or two
    // more solves remove.
    for (int iteration = 0; iteration < 4; ++iteration) {
        const std::vector<double> r = elastic_residual(dofs);
        fem::SparseTriplets K;
        std::vector<double> diagonal;
        assemble_elastic_stiffness(dofs, K, diagonal);
        report.nonzeros = long(K.value.size());
        check_elastic_system(dofs, diagonal, r);
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
        apply_elastic_increment(dofs, du);
        report.ratio_after = ratio_ = elastic_residual_ratio(dofs);
        ++report.iterations;
        if (report.ratio_after < 1e-8) break;
    }
    sum_boundary_forces();
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return report;
}

void Solver::move_supports(double time) {
    std::vector<Vec2> du(b_.count()), dn(n_.count());
    std::vector<double> dtheta(b_.count());
    for (int i = 0; i < b_.count(); ++i) {
        const std::uint8_t fx = b_.fixed[i];
        du[i] = {(fx & 1) ? time * b_.fixed_velocity[i].x : 0.0, (fx & 2) ? time * b_.fixed_velocity[i].y : 0.0};
        dtheta[i] = (fx & 4) ? time * b_.fixed_omega[i] : 0.0;
    }
    for (int k = 0; k < n_.count(); ++k) {
        const std::uint8_t fx = n_.fixed[k];
        dn[k] = {(fx & 1) ? time * n_.fixed_velocity[k].x : 0.0, (fx & 2) ? time * n_.fixed_velocity[k].y : 0.0};
    }
    move_bodies(du, dtheta, dn);
}

void Solver::move_bodies(const std::vector<Vec2>& du, const std::vector<double>& dtheta, const std::vector<Vec2>& dn) {
    for (int i = 0; i < b_.count(); ++i) b_.velocity[i] = du[i] / dt_, b_.omega[i] = dtheta[i] / dt_;
    for (int k = 0; k < n_.count(); ++k) n_.velocity[k] = dn[k] / dt_;
    update_vertices();
    compute_forces(); // the increments through the contact laws and zones
    for (int i = 0; i < b_.count(); ++i) {
        if (b_.removed[i] || b_.deformable[i]) continue;
        b_.centroid[i] += du[i];
        b_.theta[i] += dtheta[i];
    }
    for (int k = 0; k < n_.count(); ++k) n_.position[k] += dn[k];
    std::fill(b_.velocity.begin(), b_.velocity.end(), Vec2{});
    std::fill(b_.omega.begin(), b_.omega.end(), 0.0);
    std::fill(n_.velocity.begin(), n_.velocity.end(), Vec2{});
    update_vertices();
}

} // namespace bbm
