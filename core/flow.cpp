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

namespace {

/// The steady system over `cluster` (per domain, its cluster's representative;
/// itself unless merged): one unknown per free cluster connected to a held
/// domain. A cluster's domains share its head: p_i = P + ρ_w g·(x_i − x_rep).
/// Solves and writes the pressures; returns the solve's relative residual.
double solve_clusters(const Network& n, const FluidSpec& f, State& s, const std::vector<double>& c,
                      const std::vector<int>& cluster, const std::vector<std::uint8_t>& anchored_part,
                      const std::vector<int>& part, SteadyReport& report) {
    auto offset = [&](int i) { return f.density * dot(f.gravity, n.domain_position[i] - n.domain_position[cluster[i]]); };
    // A cluster with a held domain is held: P from that domain's pressure.
    std::vector<std::uint8_t> cluster_held(n.domains(), 0);
    std::vector<double> cluster_p(n.domains(), 0.0);
    for (int i = 0; i < n.domains(); ++i)
        if (s.held[i]) cluster_held[cluster[i]] = 1, cluster_p[cluster[i]] = s.pressure[i] - offset(i);
    std::vector<int> unknown(n.domains(), -1);
    report.free_domains = 0;
    for (int i = 0; i < n.domains(); ++i)
        if (cluster[i] == i && !cluster_held[i] && anchored_part[part[i]]) unknown[i] = report.free_domains++;
    if (report.free_domains == 0) return 0.0;
    fem::SparseTriplets k;
    k.size = report.free_domains;
    std::vector<double> rhs(report.free_domains, 0.0);
    for (int i = 0; i < n.domains(); ++i)
        if (unknown[cluster[i]] >= 0) rhs[unknown[cluster[i]]] += s.source[i];
    for (int p = 0; p < n.pipes(); ++p) {
        if (!(c[p] > 0.0)) continue;
        const int i = n.pipe_from[p], j = n.pipe_to[p], a = cluster[i], b = cluster[j];
        if (a == b) continue;
        // q_ij = c (p_i − p_j − g_ij), g_ij = ρ_w g·(x_i − x_j); Σ_j q_ij = Q_i. With
        // p_i = P_a + o_i: q = c (P_a − P_b − (g_ij − o_i + o_j)).
        const double g = f.density * dot(f.gravity, n.domain_position[i] - n.domain_position[j]) - offset(i) + offset(j);
        const int ua = unknown[a], ub = unknown[b];
        if (ua >= 0) k.add(ua, ua, c[p]), rhs[ua] += c[p] * g;
        if (ub >= 0) k.add(ub, ub, c[p]), rhs[ub] -= c[p] * g;
        if (ua >= 0 && ub >= 0) k.add(ua, ub, -c[p]), k.add(ub, ua, -c[p]);
        else if (ua >= 0 && cluster_held[b]) rhs[ua] += c[p] * cluster_p[b];
        else if (ub >= 0 && cluster_held[a]) rhs[ub] += c[p] * cluster_p[a];
    }
    fem::SolveReport solved;
    const std::vector<double> x = fem::solve_sparse(k, rhs, &solved);
    for (int i = 0; i < n.domains(); ++i) {
        const int a = cluster[i];
        if (s.held[i]) continue;
        if (unknown[a] >= 0) s.pressure[i] = x[unknown[a]] + offset(i);
        else if (cluster_held[a]) s.pressure[i] = cluster_p[a] + offset(i);
    }
    return solved.relative_residual;
}

/// The root of i's tree in the union-find `up`, halving the path on the way.
int find_root(std::vector<int>& up, int i) {
    while (up[i] != i) i = up[i] = up[up[i]];
    return i;
}

/// Each pipe's conductance (into c), and each domain's part of the network: the
/// domains joined by conducting pipes (union-find) share it.
std::vector<int> conducting_parts(const Network& n, const FluidSpec& f, const State& s, std::vector<double>& c) {
    std::vector<int> parent(n.domains());
    for (int i = 0; i < n.domains(); ++i) parent[i] = i;
    c.resize(n.pipes());
    for (int k = 0; k < n.pipes(); ++k) {
        c[k] = conductance(n, f, s, k);
        if (c[k] > 0.0) parent[find_root(parent, n.pipe_from[k])] = find_root(parent, n.pipe_to[k]);
    }
    std::vector<int> part(n.domains());
    for (int i = 0; i < n.domains(); ++i) part[i] = find_root(parent, i);
    return part;
}

/// The domains of a part with no held domain, counted; none may have a rate
/// injected (there is no steady state).
void check_isolated_domains(const Network& n, const State& s, const std::vector<int>& part,
                            const std::vector<std::uint8_t>& anchored, SteadyReport& report) {
    for (int i = 0; i < n.domains(); ++i) {
        if (s.held[i] || anchored[part[i]]) continue;
        ++report.isolated_domains;
        if (s.source[i] != 0.0)
            throw InputError("", 0, "flow",
                             "a rate is injected where the joints lead to no held pressure: no steady state "
                             "(domain at " + std::to_string(n.domain_position[i].x) + ", " +
                                 std::to_string(n.domain_position[i].y) + ")");
    }
}

/// Per domain, the representative of the cluster it is merged into (itself if
/// none). Conductances over more decades than double precision resolves (intact
/// bonds of 0.05 μm beside blocks parted by 1 cm: 16 decades): a strong pipe whose
/// end has only weak ones beside it floats on them, and eliminating it cancels
/// their conductance to rounding — a solution with a small residual and wrong
/// pressures (tests/test_flow.cpp). Such a pipe's ends are at one head (its
/// pressure drop is below 1e-10 of those across the weak pipes) and are merged,
/// unless that joins two held pressures. Only where the network's conductances
/// span more than 10 decades: a network within them keeps its bits.
std::vector<int> merge_floating_pipes(const Network& n, const State& s, const std::vector<double>& c,
                                      SteadyReport& report) {
    constexpr double kappa = 1e10;
    std::vector<int> cluster(n.domains());
    for (int i = 0; i < n.domains(); ++i) cluster[i] = i;
    double weakest = INFINITY, strongest = 0.0;
    for (double ck : c)
        if (ck > 0.0) weakest = std::min(weakest, ck), strongest = std::max(strongest, ck);
    if (!(strongest > kappa * weakest)) return cluster;
    std::vector<double> total(n.domains(), 0.0);
    for (int k = 0; k < n.pipes(); ++k) total[n.pipe_from[k]] += c[k], total[n.pipe_to[k]] += c[k];
    std::vector<std::uint8_t> has_held(s.held.begin(), s.held.end());
    for (int k = 0; k < n.pipes(); ++k) {
        const int i = n.pipe_from[k], j = n.pipe_to[k];
        // A held end is tied to its boundary as strongly as to anything: not the end that floats.
        const double others_i = s.held[i] ? INFINITY : total[i] - c[k];
        const double others_j = s.held[j] ? INFINITY : total[j] - c[k];
        // A sealed pipe (c = 0, e.g. an intact bond without an aperture) joins nothing.
        if (!(c[k] > 0.0) || !(c[k] >= kappa * std::min(others_i, others_j))) continue;
        const int a = find_root(cluster, i), b = find_root(cluster, j);
        if (a == b || (has_held[a] && has_held[b])) continue;
        const int keep = std::min(a, b), gone = std::max(a, b);
        cluster[gone] = keep, has_held[keep] = has_held[keep] || has_held[gone];
        ++report.merged_pipes;
    }
    for (int i = 0; i < n.domains(); ++i) cluster[i] = find_root(cluster, i);
    return cluster;
}

} // namespace

SteadyReport solve_steady(const Network& n, const FluidSpec& f, State& s) {
    // Parts of the network joined by conducting pipes (union-find); a part with a
    // held domain is solved, one without keeps its pressures.
    std::vector<double> c;
    const std::vector<int> part = conducting_parts(n, f, s, c);
    std::vector<std::uint8_t> anchored(n.domains(), 0);
    for (int i = 0; i < n.domains(); ++i)
        if (s.held[i]) anchored[part[i]] = 1;
    SteadyReport report;
    check_isolated_domains(n, s, part, anchored, report);
    const std::vector<int> cluster = merge_floating_pipes(n, s, c, report);
    try {
        report.relative_residual = solve_clusters(n, f, s, c, cluster, anchored, part, report);
    } catch (const std::runtime_error& e) {
        throw NumericalError(std::string("steady flow: ") + e.what() +
                             ": the joints' conductances leave the water's pressure undetermined");
    }
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
