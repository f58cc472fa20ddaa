// Liners as a support type (core/supports/liner.hpp for the model).
#include "core/supports/liner.hpp"

#include "core/supports/beam.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

namespace {
constexpr double degree = std::numbers::pi / 180.0;
}

std::string liner_keys_markdown() {
    return "# [[liner]] keys\n\n"
           "Generated from core/supports/liner.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). Beam elements on the wall of a circular opening, each node tied to the "
           "rock it touches by interface springs that separate in tension and slide in shear; it exists from the "
           "`install` stage that names it. Thrust in kN/m and moment in kNm/m (summary.json `liners`, `bbm "
           "compare`, liners.pvd, failure.png, Python `Model.liners`). The elements: [theory.md](../theory.md) §14; "
           "examples: [the support tutorial](../guide/support.md).\n\n" +
           key_table_markdown(liner_keys);
}

LinerSpec Liners::read(TableReader& t) {
    std::vector<std::string_view> keys;
    for (const auto& k : liner_keys) keys.push_back(k.key);
    t.check_keys(keys, "a liner");
    LinerSpec l;
    l.name = t.name();
    l.center = t.required_point("center");
    t.declared(liner_keys, l);
    l.to = t.number("to", find_key(liner_keys, "to")->bounds).value_or(l.from + 360.0);
    if (!(l.to > l.from) || l.to - l.from > 360.0 + 1e-9)
        t.fail("", t.owner() + "'to' must be above 'from' by at most 360 degrees, got from " + shortest_text(l.from) +
                       " to " + shortest_text(l.to));
    if (l.tension_capacity > 0.0 && l.thrust_capacity == 0.0)
        t.fail("tension_capacity", "a tension capacity needs a thrust capacity (the lining's compressive yield) too");
    if (l.symmetric_ends && std::abs(l.to - l.from - 360.0) < 1e-9)
        t.fail("symmetric_ends", "a closed ring (from " + shortest_text(l.from) + " to " + shortest_text(l.to) +
                                     " degrees) has no ends");
    t.check_length_resolves("radius", l.radius);
    t.check_length_resolves("segment_length", l.segment_length);
    t.check_length_resolves("thickness", l.thickness, 1e-4);
    return l;
}

LinerState Liners::make(const std::vector<LinerSpec>& specs) {
    LinerState L;
    L.specs = specs;
    for (const auto& spec : specs) {
        const double e = spec.young / (1.0 - spec.poisson * spec.poisson), t = spec.thickness;
        const double ring = e * t / (spec.radius * spec.radius);
        const double kn = spec.normal_stiffness > 0.0 ? spec.normal_stiffness : 10.0 * ring;
        L.names.push_back(spec.name);
        L.sets.push_back({e * t, e * t * t * t / 12.0, spec.density * t, spec.density * t * t * t / 12.0, kn,
                               spec.shear_stiffness > 0.0 ? spec.shear_stiffness : kn, spec.tensile_strength,
                               spec.cohesion, std::tan(spec.friction * 3.141592653589793 / 180.0),
                               spec.thrust_capacity, spec.tension_capacity, spec.moment_capacity,
                               std::uint8_t(spec.symmetric_ends)});
    }
    L.installed.assign(L.sets.size(), 0);
    return L;
}

void Liners::install(LinerState& L, int set, const HostFinder& find) {
    const LinerSpec& spec = L.specs[set];
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
        const TieHost h = find(p, 0.5 * chord);
        if (h.block < 0)
            throw InputError("", 0, "liner[" + std::to_string(set) + "]",
                             "liner '" + spec.name + "': its node at (" + std::to_string(p.x) + ", " +
                                 std::to_string(p.y) + ") touches no rock: is the opening's wall at radius " +
                                 std::to_string(spec.radius) + " m around the center given?");
        add_node(L.nodes, p, closed || (j > 0 && j < n) ? chord : 0.5 * chord, h, set, true);
        L.shear_slip.push_back(0.0);
        L.separated.push_back(0);
        L.normal_stress.push_back(0.0);
        const bool end = !closed && spec.symmetric_ends && (j == 0 || j == n);
        L.held.push_back(end ? Vec2{-std::sin(a), std::cos(a)} : Vec2{});
    }
    for (int e = 0; e < n; ++e) { // n elements: an open liner has n + 1 nodes, a closed one n
        const int a = first + e;
        L.element_node.push_back(a);
        const Vec2 c = L.nodes.position[closed && e == n - 1 ? first : a + 1] - L.nodes.position[a];
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

void Liners::force_pass(LinerState& L, const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& N = L.nodes;
    std::fill(N.force.begin(), N.force.end(), Vec2{});
    std::fill(N.moment.begin(), N.moment.end(), 0.0);
    int liner = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[liner + 1]) ++liner;
        const int b = next_node(L, liner, a);
        const auto& set = L.sets[N.set[a]];
        const support::BeamSection section{set.ea, set.ei, set.thrust_capacity > 0.0, -set.thrust_capacity,
                                           set.tension_capacity, set.moment_capacity};
        const auto beam = support::beam_forces(N.position[a], N.position[b], N.theta[a], N.theta[b], L.rest[e],
                                               L.chord0[e], section, L.plastic_strain[e], L.plastic_rotation_a[e],
                                               L.plastic_rotation_b[e]);
        const double ma = beam.ma, mb = beam.mb;
        L.yielded[e] |= beam.yielded;
        L.thrust[e] = -beam.tension;
        L.moment_a[e] = ma;
        L.moment_b[e] = mb;
        const Vec2 f = beam.force_on_a;
        N.force[a] += f;
        N.force[b] -= f;
        N.moment[a] -= ma;
        N.moment[b] -= mb;
    }
    for (int l = 0; l < int(L.liner_set.size()); ++l) {
        const int first = L.first[l], last = L.first[l + 1] - 1;
        const bool closed = L.closed[l];
        for (int k = first; k <= last; ++k) {
            const TieHost& h = N.host[k];
            if (!rock.holds(h)) {
                reaction[k] = {}, reaction_moment[k] = 0.0, L.normal_stress[k] = 0.0;
                continue;
            }
            const auto& set = L.sets[N.set[k]];
            // The wall's tangent (along the liner, counter-clockwise) and its normal towards the rock.
            const int before = k > first ? k - 1 : (closed ? last : k), after = k < last ? k + 1 : (closed ? first : k);
            const Vec2 along = N.position[after] - N.position[before];
            const Vec2 t = along / norm(along), n{t.y, -t.x};
            const Vec2 x = rock.position(h), d = x - N.position[k];
            const double dn = dot(d, n), ds = dot(d, t);
            double sn = set.kn * dn;
            if (!L.separated[k] && sn > set.tensile) L.separated[k] = 1;
            if (L.separated[k]) sn = std::min(sn, 0.0);
            const double limit = (L.separated[k] ? 0.0 : set.cohesion) + set.tan_friction * std::max(-sn, 0.0);
            const double tau = support::plastic_return(set.ks * (ds - L.shear_slip[k]), limit, set.ks, ds, L.shear_slip[k]);
            L.normal_stress[k] = sn;
            const Vec2 f = N.length[k] * (sn * n + tau * t);
            N.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

void Liners::add_stiffness(LinerState& L, RockStiffness& rock) {
    auto& N = L.nodes;
    support::clear_stiffness(N);
    int liner = 0;
    for (int e = 0; e < L.element_count(); ++e) {
        const int a = L.element_node[e];
        while (a >= L.first[liner + 1]) ++liner;
        const int b = next_node(L, liner, a);
        const auto& set = L.sets[N.set[a]];
        const support::BeamSection section{set.ea, set.ei, false, 0.0, 0.0, 0.0};
        const double kt = support::beam_translation_stiffness(section, L.rest[e]);
        const double kr = support::beam_rotation_stiffness(section, L.rest[e]);
        N.stiffness[a] += kt, N.stiffness[b] += kt;
        N.rotation_stiffness[a] += kr, N.rotation_stiffness[b] += kr;
    }
    support::tie_and_set_masses(N, L.sets, rock, [&](int i) {
        const auto& set = L.sets[N.set[i]];
        return std::max(set.kn, set.ks);
    });
}

void Liners::parameters(const LinerState& L, std::vector<double>& out) {
    for (const auto& set : L.sets)
        out.insert(out.end(), {set.ea, set.ei, set.line_mass, set.line_inertia, set.kn, set.ks, set.tensile,
                               set.cohesion, set.tan_friction, set.thrust_capacity, set.tension_capacity,
                               set.moment_capacity, double(set.symmetric_ends)});
    for (const auto& spec : L.specs)
        out.insert(out.end(), {spec.center.x, spec.center.y, spec.radius, spec.from, spec.to, spec.segment_length});
}

std::vector<SupportSetSummary> Liners::summary(const LinerState& L) {
    std::vector<SupportSetSummary> out;
    for (std::size_t set = 0; set < L.sets.size(); ++set) {
        if (!L.installed[set]) continue;
        double min_thrust = INFINITY, max_thrust = -INFINITY, max_moment = 0.0;
        int elements = 0, yielded = 0, nodes = 0, open = 0;
        for (int e = 0; e < L.element_count(); ++e) {
            if (L.nodes.set[L.element_node[e]] != int(set)) continue;
            max_thrust = std::max(max_thrust, L.thrust[e]);
            min_thrust = std::min(min_thrust, L.thrust[e]);
            max_moment = std::max({max_moment, std::abs(L.moment_a[e]), std::abs(L.moment_b[e])});
            ++elements;
            yielded += L.yielded[e] != 0;
        }
        for (int k = 0; k < L.node_count(); ++k)
            if (L.nodes.set[k] == int(set)) ++nodes, open += L.separated[k] && L.normal_stress[k] == 0.0;
        if (!std::isfinite(max_thrust)) max_thrust = min_thrust = 0.0;
        out.push_back({L.names[set],
                       {{"nodes", double(nodes), true},
                        {"max_thrust_kN_per_m", max_thrust / 1e3},
                        {"min_thrust_kN_per_m", min_thrust / 1e3},
                        {"max_moment_kNm_per_m", max_moment / 1e3},
                        {"open_interface_nodes", double(open), true},
                        {"elements", double(elements), true},
                        {"yielded_elements", double(yielded), true}}});
    }
    return out;
}

SupportLines Liners::lines(const LinerState& L) {
    SupportLines out;
    out.points = L.nodes.position;
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
    out.names = {{"liner_names", L.names}};
    out.look = SupportLines::Look::lining;
    out.shade = 0;
    out.shade_label = "kN/m thrust";
    return out;
}

} // namespace bbm
