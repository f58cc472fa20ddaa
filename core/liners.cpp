// Liners in the explicit loop (core/liners.hpp for the model).
#include "core/solver.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

namespace {
constexpr double degree = std::numbers::pi / 180.0;
}

void Solver::install_liner(int set) {
    auto& L = liners_;
    const LinerSpec& spec = liner_specs_[set];
    L.installed[set] = 1;
    const double span = (spec.to - spec.from) * degree;
    const bool closed = std::abs(spec.to - spec.from - 360.0) < 1e-9;
    const int n = std::max(2, int(std::ceil(std::abs(span) * spec.radius / spec.segment_length - 1e-9)));
    const int first = L.node_count();
    const int nodes = closed ? n : n + 1;
    for (int j = 0; j < nodes; ++j) {
        const double a = spec.from * degree + span * double(j) / n;
        const Vec2 p = spec.center + spec.radius * Vec2{std::cos(a), std::sin(a)};
        const double chord = 2.0 * spec.radius * std::sin(0.5 * std::abs(span) / n);
        const BoltHost h = find_host(p, 0.5 * chord);
        if (h.block < 0)
            throw InputError("", 0, "liner[" + std::to_string(set) + "]",
                             "liner '" + spec.name + "': its node at (" + std::to_string(p.x) + ", " +
                                 std::to_string(p.y) + ") touches no rock: is the opening's wall at radius " +
                                 std::to_string(spec.radius) + " m around the center given?");
        L.position.push_back(p);
        L.velocity.push_back({});
        L.force.push_back({});
        L.theta.push_back(0.0);
        L.omega.push_back(0.0);
        L.moment.push_back(0.0);
        L.mass.push_back(0.0);
        L.inertia.push_back(0.0);
        L.length.push_back(closed || (j > 0 && j < n) ? chord : 0.5 * chord);
        L.shear_slip.push_back(0.0);
        L.host.push_back(h);
        L.separated.push_back(0);
        L.normal_stress.push_back(0.0);
        L.node_set.push_back(set);
        L.reaction.push_back({});
        L.reaction_moment.push_back(0.0);
        const bool end = !closed && spec.symmetric_ends && (j == 0 || j == n);
        L.held.push_back(end ? Vec2{-std::sin(a), std::cos(a)} : Vec2{});
    }
    for (int e = 0; e < n; ++e) { // n elements: an open liner has n + 1 nodes, a closed one n
        const int a = first + e;
        L.element_node.push_back(a);
        const Vec2 c = L.position[closed && e == n - 1 ? first : a + 1] - L.position[a];
        L.rest.push_back(norm(c));
        L.chord0.push_back(std::atan2(c.y, c.x));
        L.thrust.push_back(0.0);
        L.moment_a.push_back(0.0);
        L.moment_b.push_back(0.0);
        L.plastic_strain.push_back(0.0);
        L.plastic_rotation_a.push_back(0.0);
        L.plastic_rotation_b.push_back(0.0);
        L.yielded.push_back(0);
    }
    L.first.push_back(L.node_count());
    L.liner_set.push_back(set);
    L.closed.push_back(closed);
}

namespace {
/// The node after `a` along its liner (a closed liner wraps to its first node).
inline int next_node(const LinerState& L, int liner, int a) {
    return a + 1 < L.first[liner + 1] ? a + 1 : L.first[liner];
}
/// An angle in (−π, π].
inline double wrap(double angle) {
    while (angle > std::numbers::pi) angle -= 2.0 * std::numbers::pi;
    while (angle < -std::numbers::pi) angle += 2.0 * std::numbers::pi;
    return angle;
}
} // namespace

void Solver::liner_pass() {
    auto& L = liners_;
    std::fill(L.force.begin(), L.force.end(), Vec2{});
    std::fill(L.moment.begin(), L.moment.end(), 0.0);
    int liner = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[liner + 1]) ++liner;
        const int b = next_node(L, liner, a);
        const auto& set = L.sets[L.node_set[a]];
        const Vec2 c = L.position[b] - L.position[a];
        const double l = norm(c), l0 = L.rest[e];
        const Vec2 ex = c / l, ey = perp(ex);
        const double beta = wrap(std::atan2(c.y, c.x) - L.chord0[e]);
        const double ta = L.theta[a] - beta, tb = L.theta[b] - beta;
        const double strain = (l - l0) / l0;
        double tension = set.ea * (strain - L.plastic_strain[e]);
        if (set.thrust_capacity > 0.0 && (-tension > set.thrust_capacity || tension > set.tension_capacity)) {
            tension = std::clamp(tension, -set.thrust_capacity, set.tension_capacity);
            L.plastic_strain[e] = strain - tension / set.ea;
            L.yielded[e] |= 1;
        }
        const double ea_ = ta - L.plastic_rotation_a[e], eb_ = tb - L.plastic_rotation_b[e];
        double ma = set.ei / l0 * (4.0 * ea_ + 2.0 * eb_), mb = set.ei / l0 * (2.0 * ea_ + 4.0 * eb_);
        if (set.moment_capacity > 0.0 && (std::abs(ma) > set.moment_capacity || std::abs(mb) > set.moment_capacity)) {
            // Plastic rotations at the ends that bring each end moment back to the
            // capacity (a hinge), the other end's elastic rotation unchanged.
            ma = std::clamp(ma, -set.moment_capacity, set.moment_capacity);
            mb = std::clamp(mb, -set.moment_capacity, set.moment_capacity);
            // Elastic end rotations giving (ma, mb): the inverse of [[4, 2], [2, 4]] EI/l0.
            const double ra = l0 / set.ei * (4.0 * ma - 2.0 * mb) / 12.0, rb = l0 / set.ei * (4.0 * mb - 2.0 * ma) / 12.0;
            L.plastic_rotation_a[e] = ta - ra;
            L.plastic_rotation_b[e] = tb - rb;
            L.yielded[e] |= 2;
        }
        const double shear = (ma + mb) / l;
        L.thrust[e] = -tension;
        L.moment_a[e] = ma;
        L.moment_b[e] = mb;
        const Vec2 f = tension * ex - shear * ey;
        L.force[a] += f;
        L.force[b] -= f;
        L.moment[a] -= ma;
        L.moment[b] -= mb;
    }
    for (int l = 0; l < int(L.liner_set.size()); ++l) {
        const int first = L.first[l], last = L.first[l + 1] - 1;
        const bool closed = L.closed[l];
        for (int k = first; k <= last; ++k) {
            const BoltHost& h = L.host[k];
            if (h.block < 0 || b_.removed[h.block]) {
                L.reaction[k] = {}, L.reaction_moment[k] = 0.0, L.normal_stress[k] = 0.0;
                continue;
            }
            const auto& set = L.sets[L.node_set[k]];
            // The wall's tangent (along the liner, counter-clockwise) and its normal towards the rock.
            const int before = k > first ? k - 1 : (closed ? last : k), after = k < last ? k + 1 : (closed ? first : k);
            const Vec2 along = L.position[after] - L.position[before];
            const Vec2 t = along / norm(along), n{t.y, -t.x};
            const Vec2 x = host_position(h), d = x - L.position[k];
            const double dn = dot(d, n), ds = dot(d, t);
            double sn = set.kn * dn;
            if (!L.separated[k] && sn > set.tensile) L.separated[k] = 1;
            if (L.separated[k]) sn = std::min(sn, 0.0);
            const double limit = (L.separated[k] ? 0.0 : set.cohesion) + set.tan_friction * std::max(-sn, 0.0);
            const double tau = support::plastic_return(set.ks * (ds - L.shear_slip[k]), limit, set.ks, ds, L.shear_slip[k]);
            L.normal_stress[k] = sn;
            const Vec2 f = L.length[k] * (sn * n + tau * t);
            L.force[k] += f;
            tie_reaction(h, x, f, L.reaction[k], L.reaction_moment[k]);
        }
    }
}

double Solver::integrate_liners(double& work) {
    auto& L = liners_;
    const double alpha = settings_.damping, dt = dt_;
    const Vec2 g = settings_.gravity;
    double unbalanced = 0.0;
    for (int k = 0; k < L.node_count(); ++k) {
        const Vec2 weight = (L.sets[L.node_set[k]].line_mass * L.length[k]) * g;
        Vec2 f = L.force[k] + weight;
        const Vec2 held = L.held[k];
        if (held != Vec2{}) f -= dot(f, held) * held; // the symmetry plane's reaction
        unbalanced = std::max({unbalanced, std::abs(f.x), std::abs(f.y)});
        Vec2& v = L.velocity[k];
        v.x += support::damped(f.x, v.x, alpha) / L.mass[k] * dt;
        v.y += support::damped(f.y, v.y, alpha) / L.mass[k] * dt;
        if (held != Vec2{}) {
            v -= dot(v, held) * held;
            L.omega[k] = 0.0;
        } else {
            unbalanced = std::max(unbalanced, std::abs(L.moment[k]) / std::max(L.length[k], 1e-12));
            L.omega[k] += support::damped(L.moment[k], L.omega[k], alpha) / L.inertia[k] * dt;
        }
        L.position[k] += dt * v;
        L.theta[k] += dt * L.omega[k];
        work += dot(weight, v) * dt;
    }
    return unbalanced;
}

void Solver::add_liner_stiffness(std::vector<double>& k, std::vector<double>& kr, std::vector<double>& kn,
                                 double mass_factor) {
    auto& L = liners_;
    auto& own = liner_stiffness_;
    auto& own_rotation = liner_rotation_stiffness_;
    own.assign(L.node_count(), 0.0);
    own_rotation.assign(L.node_count(), 0.0);
    int liner = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[liner + 1]) ++liner;
        const int b = next_node(L, liner, a);
        const auto& set = L.sets[L.node_set[a]];
        const double l0 = L.rest[e];
        // Row sums of the beam's stiffness, the rotation's coupling terms taken per radian at the
        // element's length (an upper bound of the diagonal's share: a safe mass).
        const double kt = set.ea / l0 + 24.0 * set.ei / (l0 * l0 * l0), kr_e = 12.0 * set.ei / l0;
        own[a] += kt, own[b] += kt;
        own_rotation[a] += kr_e, own_rotation[b] += kr_e;
    }
    for (int i = 0; i < L.node_count(); ++i) {
        const auto& set = L.sets[L.node_set[i]];
        const BoltHost& h = L.host[i];
        if (h.block >= 0 && !b_.removed[h.block]) {
            const double kg = L.length[i] * std::max(set.kn, set.ks);
            own[i] += kg;
            add_tie_stiffness(h, kg, k, kr, kn);
        }
        const double real = set.line_mass * L.length[i], real_inertia = set.line_inertia * L.length[i];
        L.mass[i] = mass_factor > 0.0 ? std::max(own[i] * mass_factor, 1e-300) : real;
        L.inertia[i] = mass_factor > 0.0 ? std::max(own_rotation[i] * mass_factor, 1e-300) : real_inertia;
    }
}

double Solver::liner_time_limit() const {
    double limit = INFINITY;
    for (int i = 0; i < liners_.node_count(); ++i) {
        if (liner_stiffness_[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(liners_.mass[i] / liner_stiffness_[i]));
        if (liner_rotation_stiffness_[i] > 0.0)
            limit = std::min(limit, 2.0 * std::sqrt(liners_.inertia[i] / liner_rotation_stiffness_[i]));
    }
    return limit;
}

std::vector<LinerSetSummary> Solver::liner_summary() const {
    const auto& L = liners_;
    std::vector<LinerSetSummary> out;
    for (std::size_t set = 0; set < L.sets.size(); ++set) {
        if (!L.installed[set]) continue;
        LinerSetSummary s;
        s.name = liner_names_[set];
        s.min_thrust = INFINITY, s.max_thrust = -INFINITY;
        for (int e = 0; e < L.element_count(); ++e) {
            if (L.node_set[L.element_node[e]] != int(set)) continue;
            s.max_thrust = std::max(s.max_thrust, L.thrust[e]);
            s.min_thrust = std::min(s.min_thrust, L.thrust[e]);
            s.max_moment = std::max({s.max_moment, std::abs(L.moment_a[e]), std::abs(L.moment_b[e])});
            ++s.elements;
            s.yielded += L.yielded[e] != 0;
        }
        for (int k = 0; k < L.node_count(); ++k)
            if (L.node_set[k] == int(set)) ++s.nodes, s.open += L.separated[k] && L.normal_stress[k] == 0.0;
        if (!std::isfinite(s.max_thrust)) s.max_thrust = s.min_thrust = 0.0;
        out.push_back(s);
    }
    return out;
}

} // namespace bbm
