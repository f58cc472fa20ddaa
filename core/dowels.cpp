// Dowels as a support type (core/dowels.hpp for the model).
#include "core/dowels.hpp"

#include "base/error.hpp"
#include "core/beam.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

DowelSupport::DowelSupport(const std::vector<DowelSetSpec>& specs) : specs_(specs) {
    // A solid round bar: I = A²/(4π); plastic moment f_y d³/6. Per metre of model.
    for (const auto& spec : specs) {
        const double S = spec.spacing, A = spec.area, pi = std::numbers::pi;
        const double d = std::sqrt(4.0 * A / pi), inertia = A * A / (4.0 * pi);
        const double moment_capacity = spec.yield_force > 0.0 ? spec.yield_force / A * d * d * d / 6.0 : 0.0;
        names_.push_back(spec.name);
        state_.sets.push_back({spec.young * A / S, spec.young * inertia / S, spec.yield_force / S, moment_capacity / S,
                               spec.rupture_strain, spec.bond_stiffness / S, spec.bond_strength / S,
                               (spec.normal_stiffness > 0.0 ? spec.normal_stiffness : spec.bond_stiffness) / S,
                               spec.density * A / S, spec.density * inertia / S, S, spec.pretension / S});
    }
    state_.installed.assign(state_.sets.size(), 0);
}

void DowelSupport::install(int set, const HostFinder& find) {
    auto& D = state_;
    const DowelSetSpec& spec = specs_[set];
    const auto& props = D.sets[set];
    D.installed[set] = 1;
    if (D.first.empty()) D.first.push_back(0);
    const auto dowels = expand_bolts(spec);
    for (std::size_t b = 0; b < dowels.size(); ++b) {
        const auto [head, toe] = dowels[b];
        const double length = norm(toe - head);
        const int n = std::max(1, int(std::ceil(length / spec.segment_length - 1e-9)));
        const double segment = length / n;
        const int first = D.node_count();
        for (int j = 0; j <= n; ++j) {
            const Vec2 p = head + (double(j) / n) * (toe - head);
            const BoltHost h = find(p, 0.5 * segment);
            if (h.block < 0 && (j == 0 || j == n))
                throw InputError("", 0, "dowel[" + std::to_string(set) + "]",
                                 "dowel " + std::to_string(b) + " of set '" + spec.name + "': its point (" +
                                     std::to_string(p.x) + ", " + std::to_string(p.y) +
                                     ") lies in no rock (inside an opening, or outside the model): its " +
                                     (j == 0 ? "head" : "toe") + " must be in a block");
            const double tributary = j == 0 || j == n ? 0.5 * segment : segment;
            // A pretension is held by the plate and the anchor: their ties start
            // pushing the rock with T (slip offsets), the grout between unstressed.
            double slip = 0.0;
            if (props.pretension > 0.0 && (j == 0 || j == n))
                slip = (j == 0 ? 1.0 : -1.0) * props.pretension / (props.bond_stiffness * tributary);
            D.position.push_back(p);
            D.velocity.push_back({});
            D.force.push_back({});
            D.theta.push_back(0.0);
            D.omega.push_back(0.0);
            D.moment.push_back(0.0);
            D.mass.push_back(0.0);
            D.inertia.push_back(0.0);
            D.length.push_back(tributary);
            D.slip.push_back(slip);
            D.bond.push_back(0.0);
            D.shear.push_back(0.0);
            D.host.push_back(h);
            D.tied.push_back((j == 0 && spec.face_plate) || (j == n && spec.end_anchor));
            D.node_set.push_back(set);
            if (j < n) {
                const Vec2 c = (toe - head) / double(n);
                D.element_node.push_back(first + j);
                D.rest.push_back(segment);
                D.chord0.push_back(std::atan2(c.y, c.x));
                D.axial.push_back(props.pretension);
                D.moment_a.push_back(0.0);
                D.moment_b.push_back(0.0);
                D.plastic_strain.push_back(-props.pretension / props.ea);
                D.plastic_rotation_a.push_back(0.0);
                D.plastic_rotation_b.push_back(0.0);
                D.state.push_back(DowelState::elastic);
            }
        }
        D.first.push_back(D.node_count());
        D.dowel_set.push_back(set);
    }
}

void DowelSupport::force_pass(const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& D = state_;
    std::fill(D.force.begin(), D.force.end(), Vec2{});
    std::fill(D.moment.begin(), D.moment.end(), 0.0);
    for (int e = 0; e < D.element_count(); ++e) {
        if (D.state[e] == DowelState::broken) continue;
        const int a = D.element_node[e], b = a + 1;
        const auto& set = D.sets[D.node_set[a]];
        const support::BeamSection section{set.ea, set.ei, set.yield_force > 0.0, -set.yield_force, set.yield_force,
                                           set.moment_capacity};
        const auto beam = support::beam_forces(D.position[a], D.position[b], D.theta[a], D.theta[b], D.rest[e],
                                               D.chord0[e], section, D.plastic_strain[e], D.plastic_rotation_a[e],
                                               D.plastic_rotation_b[e]);
        if (set.rupture_strain > 0.0 && beam.strain > set.rupture_strain) {
            D.state[e] = DowelState::broken;
            D.axial[e] = D.moment_a[e] = D.moment_b[e] = 0.0;
            continue;
        }
        if (beam.yielded) D.state[e] = DowelState::yielded;
        D.axial[e] = beam.tension;
        D.moment_a[e] = beam.ma;
        D.moment_b[e] = beam.mb;
        D.force[a] += beam.force_on_a;
        D.force[b] -= beam.force_on_a;
        D.moment[a] -= beam.ma;
        D.moment[b] -= beam.mb;
    }
    // The grout (and a plate's or an anchor's tie): along the bar with slip,
    // across it elastic.
    for (int d = 0; d < D.dowel_count(); ++d) {
        const int first = D.first[d], last = D.first[d + 1] - 1;
        for (int k = first; k <= last; ++k) {
            const BoltHost& h = D.host[k];
            if (!rock.holds(h)) {
                D.bond[k] = D.shear[k] = 0.0;
                reaction[k] = {};
                reaction_moment[k] = 0.0;
                continue;
            }
            const auto& set = D.sets[D.node_set[k]];
            const Vec2 x = rock.position(h), t = support::bar_axis(D.position, k, first, last);
            const auto g = support::grout(x - D.position[k], t, set.bond_stiffness, set.bond_strength,
                                          set.normal_stiffness, D.tied[k], D.slip[k]);
            D.bond[k] = g.along;
            D.shear[k] = dot(g.across, perp(t));
            const Vec2 f = D.length[k] * g.per_metre;
            D.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

double DowelSupport::integrate(const SupportMotion& motion, double& work) {
    auto& D = state_;
    const double alpha = motion.damping, dt = motion.dt;
    double unbalanced = 0.0;
    for (int k = 0; k < D.node_count(); ++k) {
        const Vec2 weight = (D.sets[D.node_set[k]].line_mass * D.length[k]) * motion.gravity;
        const Vec2 f = D.force[k] + weight;
        unbalanced = std::max({unbalanced, std::abs(f.x), std::abs(f.y), std::abs(D.moment[k]) / D.length[k]});
        Vec2& v = D.velocity[k];
        v.x += support::damped(f.x, v.x, alpha) / D.mass[k] * dt;
        v.y += support::damped(f.y, v.y, alpha) / D.mass[k] * dt;
        D.omega[k] += support::damped(D.moment[k], D.omega[k], alpha) / D.inertia[k] * dt;
        D.position[k] += dt * v;
        D.theta[k] += dt * D.omega[k];
        work += dot(weight, v) * dt;
    }
    return unbalanced;
}

void DowelSupport::add_stiffness(RockStiffness& rock) {
    auto& D = state_;
    stiffness_.assign(D.node_count(), 0.0);
    rotation_stiffness_.assign(D.node_count(), 0.0);
    for (int e = 0; e < D.element_count(); ++e) {
        if (D.state[e] == DowelState::broken) continue;
        const int a = D.element_node[e];
        const auto& set = D.sets[D.node_set[a]];
        const support::BeamSection section{set.ea, set.ei, false, 0.0, 0.0, 0.0};
        const double kt = support::beam_translation_stiffness(section, D.rest[e]);
        const double kr = support::beam_rotation_stiffness(section, D.rest[e]);
        stiffness_[a] += kt, stiffness_[a + 1] += kt;
        rotation_stiffness_[a] += kr, rotation_stiffness_[a + 1] += kr;
    }
    for (int i = 0; i < D.node_count(); ++i) {
        const auto& set = D.sets[D.node_set[i]];
        const BoltHost& h = D.host[i];
        if (rock.rock.holds(h)) {
            const double kg = D.length[i] * std::max(set.bond_stiffness, set.normal_stiffness);
            stiffness_[i] += kg;
            rock.add_tie(h, kg);
        }
        const double f = rock.mass_factor;
        D.mass[i] = f > 0.0 ? std::max(stiffness_[i] * f, 1e-300) : set.line_mass * D.length[i];
        D.inertia[i] = f > 0.0 ? std::max(rotation_stiffness_[i] * f, 1e-300) : set.line_inertia * D.length[i];
    }
}

double DowelSupport::time_limit() const {
    double limit = INFINITY;
    for (int i = 0; i < state_.node_count(); ++i) {
        if (stiffness_[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(state_.mass[i] / stiffness_[i]));
        if (rotation_stiffness_[i] > 0.0)
            limit = std::min(limit, 2.0 * std::sqrt(state_.inertia[i] / rotation_stiffness_[i]));
    }
    return limit;
}

void DowelSupport::add_force_scale(double& terms, double& squares) const {
    // As a bolt's segments: a dowel may be all that holds a block.
    terms += double(state_.element_count());
    for (double n : state_.axial) squares += n * n;
}

void DowelSupport::model_parameters(std::vector<double>& out) const {
    for (const auto& s : state_.sets)
        out.insert(out.end(), {s.ea, s.ei, s.yield_force, s.moment_capacity, s.rupture_strain, s.bond_stiffness,
                               s.bond_strength, s.normal_stiffness, s.line_mass, s.line_inertia, s.spacing,
                               s.pretension});
}

std::vector<SupportField> DowelSupport::fields() {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    auto& D = state_;
    return {{{"dowels.installed", G::other, E}, &D.installed},
            {{"dowels.position", G::other, E}, &D.position},
            {{"dowels.velocity", G::other, E}, &D.velocity},
            {{"dowels.theta", G::other, E}, &D.theta},
            {{"dowels.omega", G::other, E}, &D.omega},
            {{"dowels.mass", G::other, E}, &D.mass},
            {{"dowels.inertia", G::other, E}, &D.inertia},
            {{"dowels.length", G::other, E}, &D.length},
            {{"dowels.slip", G::other, E}, &D.slip},
            {{"dowels.bond", G::other, E}, &D.bond},
            {{"dowels.shear", G::other, E}, &D.shear},
            {{"dowels.host", G::other, E}, &D.host},
            {{"dowels.tied", G::other, E}, &D.tied},
            {{"dowels.node_set", G::other, E}, &D.node_set},
            {{"dowels.element_node", G::other, E}, &D.element_node},
            {{"dowels.rest", G::other, E}, &D.rest},
            {{"dowels.chord0", G::other, E}, &D.chord0},
            {{"dowels.axial", G::other, E}, &D.axial},
            {{"dowels.moment_a", G::other, E}, &D.moment_a},
            {{"dowels.moment_b", G::other, E}, &D.moment_b},
            {{"dowels.plastic_strain", G::other, E}, &D.plastic_strain},
            {{"dowels.plastic_rotation_a", G::other, E}, &D.plastic_rotation_a},
            {{"dowels.plastic_rotation_b", G::other, E}, &D.plastic_rotation_b},
            {{"dowels.state", G::other, E}, &D.state},
            {{"dowels.first", G::other, E}, &D.first},
            {{"dowels.dowel_set", G::other, E}, &D.dowel_set},
            {{"dowels.force", G::other, R}, &D.force},
            {{"dowels.moment", G::other, R}, &D.moment},
            {{"dowels.stiffness", G::other, R}, &stiffness_},
            {{"dowels.rotation_stiffness", G::other, R}, &rotation_stiffness_}};
}

void DowelSupport::after_load() {
    state_.force.assign(state_.position.size(), {});
    state_.moment.assign(state_.position.size(), 0.0);
}

namespace {
/// An element's shear force from its end moments (per metre of model).
double element_shear(const DowelState& D, int e) { return (D.moment_a[e] + D.moment_b[e]) / D.rest[e]; }
} // namespace

std::vector<SupportSetSummary> DowelSupport::summary() const {
    const auto& D = state_;
    std::vector<SupportSetSummary> out;
    for (std::size_t set = 0; set < D.sets.size(); ++set) {
        if (!D.installed[set]) continue;
        const double S = D.sets[set].spacing;
        double tension = 0.0, shear = 0.0, moment = 0.0, bond = 0.0, across = 0.0;
        int dowels = 0, yielded = 0, broken = 0;
        for (int d = 0; d < D.dowel_count(); ++d) dowels += D.dowel_set[d] == int(set);
        for (int e = 0; e < D.element_count(); ++e) {
            if (D.node_set[D.element_node[e]] != int(set)) continue;
            tension = std::max(tension, D.axial[e] * S);
            shear = std::max(shear, std::abs(element_shear(D, e)) * S);
            moment = std::max({moment, std::abs(D.moment_a[e]) * S, std::abs(D.moment_b[e]) * S});
            yielded += D.state[e] == DowelState::yielded;
            broken += D.state[e] == DowelState::broken;
        }
        for (int k = 0; k < D.node_count(); ++k)
            if (D.node_set[k] == int(set) && !D.tied[k])
                bond = std::max(bond, std::abs(D.bond[k]) * S), across = std::max(across, std::abs(D.shear[k]) * S);
        out.push_back({names_[set],
                       {{"dowels", double(dowels), true},
                        {"max_axial_kN", tension / 1e3},
                        {"max_shear_kN", shear / 1e3},
                        {"max_moment_kNm", moment / 1e3},
                        {"max_bond_kN_per_m", bond / 1e3},
                        {"max_transverse_kN_per_m", across / 1e3},
                        {"yielded_elements", double(yielded), true},
                        {"broken_elements", double(broken), true}}});
    }
    return out;
}

SupportLines DowelSupport::lines() const {
    const auto& D = state_;
    SupportLines out;
    out.points = D.position;
    SupportLines::Array axial{"axial_force_kN", {}, false}, shear{"shear_force_kN", {}, false},
        moment{"moment_kNm", {}, false}, state{"state", {}, true}, set{"set", {}, true}, dowel{"dowel", {}, true};
    int d = 0;
    for (int e = 0; e < D.element_count(); ++e) {
        const int a = D.element_node[e];
        while (a >= D.first[d + 1]) ++d;
        const double S = D.sets[D.node_set[a]].spacing;
        out.cells.push_back({a, a + 1});
        axial.values.push_back(D.axial[e] * S / 1e3);
        shear.values.push_back(element_shear(D, e) * S / 1e3);
        moment.values.push_back(
            (std::abs(D.moment_a[e]) >= std::abs(D.moment_b[e]) ? D.moment_a[e] : -D.moment_b[e]) * S / 1e3);
        state.values.push_back(D.state[e]);
        set.values.push_back(D.node_set[a]);
        dowel.values.push_back(d);
        out.mark.push_back(D.state[e] == DowelState::broken ? 2 : D.state[e] == DowelState::yielded ? 1 : 0);
    }
    out.cell_data = {axial, shear, moment, state, set, dowel};
    SupportLines::Array bond{"bond_kN_per_m", {}, false}, across{"transverse_kN_per_m", {}, false},
        slip{"slip", {}, false};
    for (int k = 0; k < D.node_count(); ++k) {
        const double S = D.sets[D.node_set[k]].spacing;
        bond.values.push_back(D.bond[k] * S / 1e3);
        across.values.push_back(D.shear[k] * S / 1e3);
        slip.values.push_back(D.slip[k]);
    }
    out.point_data = {bond, across, slip};
    out.names = {{"state_names", {"elastic", "yielded", "broken"}}, {"set_names", names_}};
    out.look = SupportLines::Look::bar;
    out.shade = 1; // the shear force: what a dowel is for
    out.shade_label = "kN shear";
    return out;
}

} // namespace bbm
