#include "core/flow.hpp"

#include "base/error.hpp"
#include "fem/sparse_solve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace bbm::flow {

namespace {

/// Joint ends within `tol` of each other are one domain: points hashed to cells
/// of size `tol`, each compared with the domains of its 3 × 3 cells.
class DomainIndex {
public:
    DomainIndex(Network& n, double tol) : n_(n), tol_(tol) {}

    int domain_at(Vec2 p) {
        const std::int64_t ix = std::llround(std::floor(p.x / tol_)), iy = std::llround(std::floor(p.y / tol_));
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy) {
                const auto it = cells_.find(key(ix + dx, iy + dy));
                if (it == cells_.end()) continue;
                for (int d : it->second)
                    if (norm(n_.domain_position[d] - p) <= tol_) return d;
            }
        const int d = n_.domains();
        n_.domain_position.push_back(p);
        cells_[key(ix, iy)].push_back(d);
        return d;
    }

private:
    static std::uint64_t key(std::int64_t ix, std::int64_t iy) {
        return (std::uint64_t(ix) * 0x9E3779B97F4A7C15ull) ^ std::uint64_t(iy);
    }
    Network& n_;
    double tol_;
    std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

/// Σ_j c_ij of each domain and its volume Σ a L / 2.
void domain_sums(const Network& n, const FluidSpec& f, const State& s, std::vector<double>& conductance_sum,
                 std::vector<double>& volume) {
    conductance_sum.assign(n.domains(), 0.0);
    volume.assign(n.domains(), 0.0);
    for (int k = 0; k < n.pipes(); ++k) {
        const double c = conductance(n, f, s, k);
        const double half = 0.5 * hydraulic_aperture(f, s.aperture[k]) * n.pipe_length[k];
        conductance_sum[n.pipe_from[k]] += c, conductance_sum[n.pipe_to[k]] += c;
        volume[n.pipe_from[k]] += half, volume[n.pipe_to[k]] += half;
    }
}

/// min over free domains of V / (K_w Σ c): the explicit stage's stable step.
double stable_step_of(const Network& n, const FluidSpec& f, const State& s, const std::vector<double>& conductance_sum,
                      const std::vector<double>& volume) {
    double dt = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n.domains(); ++i)
        if (!s.held[i] && conductance_sum[i] > 0.0)
            dt = std::min(dt, volume[i] / (f.bulk_modulus * conductance_sum[i]));
    return dt;
}

/// The driving pressure difference of pipe k: (p_i − p_j) − ρ_w g·(x_i − x_j).
double drive(const Network& n, const FluidSpec& f, const State& s, int k) {
    const int i = n.pipe_from[k], j = n.pipe_to[k];
    return (s.pressure[i] - s.pressure[j]) -
           f.density * dot(f.gravity, n.domain_position[i] - n.domain_position[j]);
}

} // namespace

Network Network::of_joints(const meshing::BlockAssembly& a, double tolerance,
                           const std::vector<std::uint8_t>* joint_in) {
    Network n;
    if (!(tolerance > 0.0)) {
        Box2 all;
        for (const Vec2& p : a.points) all.add(p);
        tolerance = 1e-9 * std::max({all.width(), all.height(), 1e-300});
    }
    n.merge_tolerance = tolerance;
    DomainIndex index(n, tolerance);
    for (int j = 0; j < int(a.joints.size()); ++j) {
        if (joint_in && !(*joint_in)[j]) continue;
        const auto& joint = a.joints[j];
        const double length = joint.length();
        if (!(length > tolerance)) continue;
        const int from = index.domain_at(joint.p0), to = index.domain_at(joint.p1);
        if (from == to) continue;
        n.pipe_from.push_back(from);
        n.pipe_to.push_back(to);
        n.pipe_length.push_back(length);
        n.pipe_joint.push_back(j);
    }
    return n;
}

int Network::domain_at(Vec2 p) const {
    // Linear: used while building links and boundaries, not per step.
    int best = -1;
    double best_d = merge_tolerance;
    for (int d = 0; d < domains(); ++d)
        if (const double dist = norm(domain_position[d] - p); dist <= best_d) best = d, best_d = dist;
    return best;
}

double hydraulic_aperture(const FluidSpec& f, double a) {
    return a == 0.0 ? 0.0 : std::clamp(a, f.residual_aperture, f.max_aperture);
}

double conductance(const Network& n, const FluidSpec& f, const State& s, int pipe) {
    const double a = hydraulic_aperture(f, s.aperture[pipe]);
    return a * a * a / (12.0 * f.viscosity * n.pipe_length[pipe]);
}

std::vector<double> pipe_flows(const Network& n, const FluidSpec& f, const State& s) {
    std::vector<double> q(n.pipes());
    for (int k = 0; k < n.pipes(); ++k) q[k] = conductance(n, f, s, k) * drive(n, f, s, k);
    return q;
}

double stable_timestep(const Network& n, const FluidSpec& f, const State& s) {
    std::vector<double> csum, volume;
    domain_sums(n, f, s, csum, volume);
    return stable_step_of(n, f, s, csum, volume);
}

int advance(const Network& n, const FluidSpec& f, State& s, double dt, double safety) {
    if (!(dt > 0.0)) return 0;
    auto& w = s.scratch;
    std::vector<double>&csum = w.conductance_sum, &volume = w.volume, &c = w.c, &rate = w.rate;
    domain_sums(n, f, s, csum, volume);
    // Only the pipes that conduct and the free domains they reach change over the
    // step: in a rock whose intact joints are closed, a small part of the network.
    std::vector<int>&open = w.open, &wet = w.wet;
    open.clear(), c.clear(), wet.clear(), rate.clear();
    for (int k = 0; k < n.pipes(); ++k)
        if (const double ck = conductance(n, f, s, k); ck > 0.0) open.push_back(k), c.push_back(ck);
    // K_w / V of each wet domain
    for (int i = 0; i < n.domains(); ++i)
        if (!s.held[i] && volume[i] > 0.0) wet.push_back(i), rate.push_back(f.bulk_modulus / volume[i]);
    const double largest = safety * stable_step_of(n, f, s, csum, volume);
    const int substeps = std::isfinite(largest) ? std::max(1, int(std::ceil(dt / largest))) : 1;
    const double h = dt / substeps;
    std::vector<double>& net = w.net;
    net.assign(n.domains(), 0.0);
    for (int step = 0; step < substeps; ++step) {
        for (int i : wet) net[i] = s.source[i];
        for (std::size_t m = 0; m < open.size(); ++m) {
            const int k = open[m];
            const double q = c[m] * drive(n, f, s, k);
            net[n.pipe_from[k]] -= q, net[n.pipe_to[k]] += q;
        }
        for (std::size_t m = 0; m < wet.size(); ++m) s.pressure[wet[m]] += rate[m] * h * net[wet[m]];
        s.time += h;
    }
    return substeps;
}

SteadyReport solve_steady(const Network& n, const FluidSpec& f, State& s) {
    // Parts of the network joined by conducting pipes (union-find); a part with a
    // held domain is solved, one without keeps its pressures.
    std::vector<int> parent(n.domains());
    for (int i = 0; i < n.domains(); ++i) parent[i] = i;
    auto root = [&](int i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    std::vector<double> c(n.pipes());
    for (int k = 0; k < n.pipes(); ++k) {
        c[k] = conductance(n, f, s, k);
        if (c[k] > 0.0) parent[root(n.pipe_from[k])] = root(n.pipe_to[k]);
    }
    std::vector<std::uint8_t> anchored(n.domains(), 0);
    for (int i = 0; i < n.domains(); ++i)
        if (s.held[i]) anchored[root(i)] = 1;
    SteadyReport report;
    std::vector<int> unknown(n.domains(), -1);
    for (int i = 0; i < n.domains(); ++i) {
        if (s.held[i]) continue;
        if (anchored[root(i)]) {
            unknown[i] = report.free_domains++;
        } else {
            ++report.isolated_domains;
            if (s.source[i] != 0.0)
                throw InputError("", 0, "flow",
                                 "a rate is injected where the joints lead to no held pressure: no steady state "
                                 "(domain at " + std::to_string(n.domain_position[i].x) + ", " +
                                     std::to_string(n.domain_position[i].y) + ")");
        }
    }
    if (report.free_domains == 0) return report;
    fem::SparseTriplets k;
    k.size = report.free_domains;
    std::vector<double> rhs(report.free_domains, 0.0);
    for (int i = 0; i < n.domains(); ++i)
        if (unknown[i] >= 0) rhs[unknown[i]] += s.source[i];
    for (int p = 0; p < n.pipes(); ++p) {
        if (!(c[p] > 0.0)) continue;
        const int i = n.pipe_from[p], j = n.pipe_to[p];
        // q_ij = c (p_i − p_j − g_ij), g_ij = ρ_w g·(x_i − x_j); Σ_j q_ij = Q_i.
        const double g = f.density * dot(f.gravity, n.domain_position[i] - n.domain_position[j]);
        const int ui = unknown[i], uj = unknown[j];
        if (ui >= 0) k.add(ui, ui, c[p]), rhs[ui] += c[p] * g;
        if (uj >= 0) k.add(uj, uj, c[p]), rhs[uj] -= c[p] * g;
        if (ui >= 0 && uj >= 0) k.add(ui, uj, -c[p]), k.add(uj, ui, -c[p]);
        else if (ui >= 0) rhs[ui] += c[p] * s.pressure[j];
        else if (uj >= 0) rhs[uj] += c[p] * s.pressure[i];
    }
    fem::SolveReport solved;
    const std::vector<double> x = fem::solve_sparse(k, rhs, &solved);
    for (int i = 0; i < n.domains(); ++i)
        if (unknown[i] >= 0) s.pressure[i] = x[unknown[i]];
    report.relative_residual = solved.relative_residual;
    return report;
}

double outflow_at_held(const Network& n, const FluidSpec& f, const State& s, const std::vector<std::uint8_t>& which) {
    const std::vector<double> q = pipe_flows(n, f, s);
    double out = 0.0;
    for (int k = 0; k < n.pipes(); ++k) {
        if (which[n.pipe_to[k]]) out += q[k];
        if (which[n.pipe_from[k]]) out -= q[k];
    }
    return out;
}

} // namespace bbm::flow
