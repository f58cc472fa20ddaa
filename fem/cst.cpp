#include "fem/cst.hpp"

#include <algorithm>
#include <cstdint>

namespace bbm::fem {

std::array<double, 36> element_stiffness(const TriangleGradients& g, const Elasticity& e) {
    // K = A Bᵀ D B with B rows (εxx, εyy, γxy) and ∂N/∂x = b/(2A): the 1/(4A²) of
    // the two B factors and the area leave 1/(4A).
    const double l2g = e.p_modulus(), l = e.lambda, G = e.shear, f = 1.0 / (4.0 * g.area);
    std::array<double, 36> k{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double bi = g.b[i], ci = g.c[i], bj = g.b[j], cj = g.c[j];
            k[(2 * i) * 6 + 2 * j] = f * (l2g * bi * bj + G * ci * cj);
            k[(2 * i) * 6 + 2 * j + 1] = f * (l * bi * cj + G * ci * bj);
            k[(2 * i + 1) * 6 + 2 * j] = f * (l * ci * bj + G * bi * cj);
            k[(2 * i + 1) * 6 + 2 * j + 1] = f * (l2g * ci * cj + G * bi * bj);
        }
    return k;
}

void index_zone_nodes(Zones& z, int nodes) {
    z.node_first.assign(nodes + 1, 0);
    for (const auto& t : z.node)
        for (int k : t) ++z.node_first[k + 1];
    for (int k = 0; k < nodes; ++k) z.node_first[k + 1] += z.node_first[k];
    z.node_entry.resize(z.node_first[nodes]);
    std::vector<int> fill(z.node_first.begin(), z.node_first.end() - 1);
    for (int k = 0; k < z.size(); ++k)
        for (int c = 0; c < 3; ++c) z.node_entry[fill[z.node[k][c]]++] = 3 * k + c;
    z.nodal_force.resize(z.size());
    z.partial_sum.resize((z.size() + Zones::work_item_size - 1) / Zones::work_item_size);
    z.partial_damped.assign(z.partial_sum.size(), 0.0);
}

namespace {
/// One zone's update: its stress from the step's velocity gradient, and the
/// nodal forces of that stress; returns Σ|f|² over its three nodes.
inline double zone_update(Zones& z, int k, const Vec2* x, const Vec2* v, double dt, double beta, double& viscous_work) {
    const auto& n = z.node[k];
    const auto g = gradients(x[n[0]], x[n[1]], x[n[2]]);
    // Velocity gradient × Δt: the step's displacement gradient.
    const double f = dt / (2.0 * g.area);
    double uxx = 0, uxy = 0, uyx = 0, uyy = 0; // ∂u_x/∂x, ∂u_x/∂y, ∂u_y/∂x, ∂u_y/∂y
    for (int i = 0; i < 3; ++i) {
        const Vec2 vi = v[n[i]];
        uxx += vi.x * g.b[i], uxy += vi.x * g.c[i];
        uyx += vi.y * g.b[i], uyy += vi.y * g.c[i];
    }
    uxx *= f, uxy *= f, uyx *= f, uyy *= f;
    const double exx = uxx, eyy = uyy, exy = 0.5 * (uxy + uyx), w = 0.5 * (uyx - uxy);
    auto& s = z.stress[k];
    const Elasticity& e = z.elasticity[k];
    // Jaumann rotation of the stress by the step's spin w.
    const double rot_xx = -2.0 * w * s[2], rot_xy = w * (s[0] - s[1]);
    const double tr = e.lambda * (exx + eyy);
    s[0] += rot_xx + tr + 2.0 * e.shear * exx;
    s[1] += -rot_xx + tr + 2.0 * e.shear * eyy;
    s[2] += rot_xy + 2.0 * e.shear * exy;
    auto& eps = z.strain[k];
    eps[0] += exx, eps[1] += eyy, eps[2] += exy;
    // Rayleigh's stiffness part: the viscous stress β D ε̇ (ε̇ = the step's strain / Δt).
    std::array<double, 3> t = s;
    if (beta > 0.0) {
        const double b = beta / dt;
        t[0] += b * (tr + 2.0 * e.shear * exx);
        t[1] += b * (tr + 2.0 * e.shear * eyy);
        t[2] += b * 2.0 * e.shear * exy;
        // Its work over the step: A (β/Δt) ε:D:ε, ε the step's strain.
        viscous_work += g.area * b * (tr * (exx + eyy) + 2.0 * e.shear * (exx * exx + eyy * eyy + 2.0 * exy * exy));
    }
    // f_i = −A σ ∇N_i = −½ σ (b_i, c_i).
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) {
        const Vec2 fi{-0.5 * (t[0] * g.b[i] + t[2] * g.c[i]), -0.5 * (t[2] * g.b[i] + t[1] * g.c[i])};
        z.nodal_force[k][i] = fi;
        sum += norm2(fi);
    }
    return sum;
}
} // namespace

void zone_pass(Zones& z, const Vec2* x, const Vec2* v, double dt, const std::uint8_t* skip, int first_item,
               int last_item, double stiffness_damping) {
    const int count = z.size();
    for (int w = first_item; w < last_item; ++w) {
        double sum = 0.0, viscous_work = 0.0;
        for (int k = w * Zones::work_item_size; k < std::min(count, (w + 1) * Zones::work_item_size); ++k) {
            if (skip[z.block[k]]) {
                z.nodal_force[k] = {};
                continue;
            }
            sum += zone_update(z, k, x, v, dt, stiffness_damping, viscous_work);
        }
        z.partial_sum[w] = sum;
        if (!z.partial_damped.empty()) z.partial_damped[w] = viscous_work;
    }
}

double zone_force_squares(const Zones& z) {
    double sum = 0.0;
    for (double s : z.partial_sum) sum += s;
    return sum;
}

} // namespace bbm::fem
