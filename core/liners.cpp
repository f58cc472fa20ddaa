// Liners as a support type (core/liners.hpp for the model).
#include "core/liners.hpp"

#include "core/beam.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

namespace {
constexpr double degree = std::numbers::pi / 180.0;
}

LinerSupport::LinerSupport(const std::vector<LinerSpec>& specs) : specs_(specs) {
    for (const auto& spec : specs) {
        const double e = spec.young / (1.0 - spec.poisson * spec.poisson), t = spec.thickness;
        const double ring = e * t / (spec.radius * spec.radius);
        const double kn = spec.normal_stiffness > 0.0 ? spec.normal_stiffness : 10.0 * ring;
        names_.push_back(spec.name);
        state_.sets.push_back({e * t, e * t * t * t / 12.0, spec.density * t, spec.density * t * t * t / 12.0, kn,
                               spec.shear_stiffness > 0.0 ? spec.shear_stiffness : kn, spec.tensile_strength,
                               spec.cohesion, std::tan(spec.friction * 3.141592653589793 / 180.0),
                               spec.thrust_capacity, spec.tension_capacity, spec.moment_capacity,
                               std::uint8_t(spec.symmetric_ends)});
    }
    state_.installed.assign(state_.sets.size(), 0);
}

void LinerSupport::install(int set, const HostFinder& find) {
    auto& L = state_;
    const LinerSpec& spec = specs_[set];
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
        const BoltHost h = find(p, 0.5 * chord);
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
} // namespace

void LinerSupport::force_pass(const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& L = state_;
    std::fill(L.force.begin(), L.force.end(), Vec2{});
    std::fill(L.moment.begin(), L.moment.end(), 0.0);
    int liner = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[liner + 1]) ++liner;
        const int b = next_node(L, liner, a);
        const auto& set = L.sets[L.node_set[a]];
        const support::BeamSection section{set.ea, set.ei, set.thrust_capacity > 0.0, -set.thrust_capacity,
                                           set.tension_capacity, set.moment_capacity};
        const auto beam = support::beam_forces(L.position[a], L.position[b], L.theta[a], L.theta[b], L.rest[e],
                                               L.chord0[e], section, L.plastic_strain[e], L.plastic_rotation_a[e],
                                               L.plastic_rotation_b[e]);
        const double ma = beam.ma, mb = beam.mb;
        L.yielded[e] |= beam.yielded;
        L.thrust[e] = -beam.tension;
        L.moment_a[e] = ma;
        L.moment_b[e] = mb;
        const Vec2 f = beam.force_on_a;
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
            if (!rock.holds(h)) {
                reaction[k] = {}, reaction_moment[k] = 0.0, L.normal_stress[k] = 0.0;
                continue;
            }
            const auto& set = L.sets[L.node_set[k]];
            // The wall's tangent (along the liner, counter-clockwise) and its normal towards the rock.
            const int before = k > first ? k - 1 : (closed ? last : k), after = k < last ? k + 1 : (closed ? first : k);
            const Vec2 along = L.position[after] - L.position[before];
            const Vec2 t = along / norm(along), n{t.y, -t.x};
            const Vec2 x = rock.position(h), d = x - L.position[k];
            const double dn = dot(d, n), ds = dot(d, t);
            double sn = set.kn * dn;
            if (!L.separated[k] && sn > set.tensile) L.separated[k] = 1;
            if (L.separated[k]) sn = std::min(sn, 0.0);
            const double limit = (L.separated[k] ? 0.0 : set.cohesion) + set.tan_friction * std::max(-sn, 0.0);
            const double tau = support::plastic_return(set.ks * (ds - L.shear_slip[k]), limit, set.ks, ds, L.shear_slip[k]);
            L.normal_stress[k] = sn;
            const Vec2 f = L.length[k] * (sn * n + tau * t);
            L.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

double LinerSupport::integrate(const SupportMotion& motion, double& work) {
    auto& L = state_;
    const double alpha = motion.damping, dt = motion.dt;
    const Vec2 g = motion.gravity;
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

void LinerSupport::add_stiffness(RockStiffness& rock) {
    auto& L = state_;
    auto& own = stiffness_;
    auto& own_rotation = rotation_stiffness_;
    const double mass_factor = rock.mass_factor;
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
        if (rock.rock.holds(h)) {
            const double kg = L.length[i] * std::max(set.kn, set.ks);
            own[i] += kg;
            rock.add_tie(h, kg);
        }
        const double real = set.line_mass * L.length[i], real_inertia = set.line_inertia * L.length[i];
        L.mass[i] = mass_factor > 0.0 ? std::max(own[i] * mass_factor, 1e-300) : real;
        L.inertia[i] = mass_factor > 0.0 ? std::max(own_rotation[i] * mass_factor, 1e-300) : real_inertia;
    }
}

double LinerSupport::time_limit() const {
    double limit = INFINITY;
    for (int i = 0; i < state_.node_count(); ++i) {
        if (stiffness_[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(state_.mass[i] / stiffness_[i]));
        if (rotation_stiffness_[i] > 0.0)
            limit = std::min(limit, 2.0 * std::sqrt(state_.inertia[i] / rotation_stiffness_[i]));
    }
    return limit;
}

void LinerSupport::model_parameters(std::vector<double>& out) const {
    for (const auto& set : state_.sets)
        out.insert(out.end(), {set.ea, set.ei, set.line_mass, set.line_inertia, set.kn, set.ks, set.tensile,
                               set.cohesion, set.tan_friction, set.thrust_capacity, set.tension_capacity,
                               set.moment_capacity, double(set.symmetric_ends)});
}

std::vector<SupportField> LinerSupport::fields() {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    auto& L = state_;
    return {{{"liners.installed", G::other, E}, &L.installed},
            {{"liners.position", G::other, E}, &L.position},
            {{"liners.velocity", G::other, E}, &L.velocity},
            {{"liners.theta", G::other, E}, &L.theta},
            {{"liners.omega", G::other, E}, &L.omega},
            {{"liners.mass", G::other, E}, &L.mass},
            {{"liners.inertia", G::other, E}, &L.inertia},
            {{"liners.length", G::other, E}, &L.length},
            {{"liners.shear_slip", G::other, E}, &L.shear_slip},
            {{"liners.host", G::other, E}, &L.host},
            {{"liners.separated", G::other, E}, &L.separated},
            {{"liners.normal_stress", G::other, E}, &L.normal_stress},
            {{"liners.node_set", G::other, E}, &L.node_set},
            {{"liners.held", G::other, E}, &L.held},
            {{"liners.element_node", G::other, E}, &L.element_node},
            {{"liners.rest", G::other, E}, &L.rest},
            {{"liners.chord0", G::other, E}, &L.chord0},
            {{"liners.thrust", G::other, E}, &L.thrust},
            {{"liners.moment_a", G::other, E}, &L.moment_a},
            {{"liners.moment_b", G::other, E}, &L.moment_b},
            {{"liners.plastic_strain", G::other, E}, &L.plastic_strain},
            {{"liners.plastic_rotation_a", G::other, E}, &L.plastic_rotation_a},
            {{"liners.plastic_rotation_b", G::other, E}, &L.plastic_rotation_b},
            {{"liners.yielded", G::other, E}, &L.yielded},
            {{"liners.first", G::other, E}, &L.first},
            {{"liners.liner_set", G::other, E}, &L.liner_set},
            {{"liners.closed", G::other, E}, &L.closed},
            {{"liners.force", G::other, R}, &L.force},
            {{"liners.moment", G::other, R}, &L.moment},
            {{"liners.stiffness", G::other, R}, &stiffness_},
            {{"liners.rotation_stiffness", G::other, R}, &rotation_stiffness_}};
}

void LinerSupport::after_load() {
    state_.force.assign(state_.position.size(), {});
    state_.moment.assign(state_.position.size(), 0.0);
}

std::vector<LinerSetSummary> LinerSupport::set_summary() const {
    const auto& L = state_;
    std::vector<LinerSetSummary> out;
    for (std::size_t set = 0; set < L.sets.size(); ++set) {
        if (!L.installed[set]) continue;
        LinerSetSummary s;
        s.name = names_[set];
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

std::vector<SupportSetSummary> LinerSupport::summary() const {
    std::vector<SupportSetSummary> out;
    for (const auto& l : set_summary())
        out.push_back({l.name,
                       {{"nodes", double(l.nodes), true},
                        {"max_thrust_kN_per_m", l.max_thrust / 1e3},
                        {"min_thrust_kN_per_m", l.min_thrust / 1e3},
                        {"max_moment_kNm_per_m", l.max_moment / 1e3},
                        {"open_interface_nodes", double(l.open), true},
                        {"elements", double(l.elements), true},
                        {"yielded_elements", double(l.yielded), true}}});
    return out;
}

SupportLines LinerSupport::lines() const {
    const auto& L = state_;
    SupportLines out;
    out.points = L.position;
    SupportLines::Array thrust{"thrust_kN_per_m", {}, false}, moment{"moment_kNm_per_m", {}, false},
        liner{"liner", {}, true}, yielded{"yielded", {}, true};
    int l = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[l + 1]) ++l; // element e's liner, and so its second node
        out.cells.push_back({a, next_node(L, l, a)});
        thrust.values.push_back(L.thrust[e] / 1e3);
        moment.values.push_back(
            (std::abs(L.moment_a[e]) >= std::abs(L.moment_b[e]) ? L.moment_a[e] : -L.moment_b[e]) / 1e3);
        liner.values.push_back(l);
        yielded.values.push_back(L.yielded[e]);
        out.mark.push_back(L.yielded[e] ? 1 : 0);
    }
    out.cell_data = {thrust, moment, liner, yielded};
    SupportLines::Array normal{"interface_normal_MPa", {}, false}, open{"interface_open", {}, true};
    for (int k = 0; k < L.node_count(); ++k) {
        normal.values.push_back(L.normal_stress[k] / 1e6);
        open.values.push_back(L.separated[k] && L.normal_stress[k] == 0.0);
    }
    out.point_data = {normal, open};
    out.names = {{"liner_names", names_}};
    out.look = SupportLines::Look::lining;
    out.shade = 0;
    out.shade_label = "kN/m thrust";
    return out;
}

} // namespace bbm
