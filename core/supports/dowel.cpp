// Dowels as a support type (core/supports/dowel.hpp for the model).
#include "core/supports/dowel.hpp"

#include "base/error.hpp"
#include "core/supports/beam.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

DowelSetSpec Dowels::read(TableReader& t) {
    const DowelSetSpec d = read_bar_set(t, table);
    if (d.pretension > 0.0 && !(d.face_plate && d.end_anchor))
        t.fail("pretension", "a pretension is held by the face plate and the end anchor: set face_plate = true and "
                             "end_anchor = true");
    if (d.yield_force > 0.0 && d.pretension >= d.yield_force)
        t.fail("pretension", "the pretension " + shortest_text(d.pretension) + " N must be below the yield force " +
                                 shortest_text(d.yield_force) + " N");
    return d;
}

DowelState Dowels::make(const std::vector<DowelSetSpec>& specs) {
    DowelState D;
    D.specs = specs;
    // A solid round bar: I = A²/(4π); plastic moment f_y d³/6. Per metre of model.
    for (const auto& spec : specs) {
        const double S = spec.spacing, A = spec.area, pi = std::numbers::pi;
        const double d = std::sqrt(4.0 * A / pi), inertia = A * A / (4.0 * pi);
        const double moment_capacity = spec.yield_force > 0.0 ? spec.yield_force / A * d * d * d / 6.0 : 0.0;
        D.names.push_back(spec.name);
        D.sets.push_back({spec.young * A / S, spec.young * inertia / S, spec.yield_force / S, moment_capacity / S,
                               spec.rupture_strain, spec.bond_stiffness / S, spec.bond_strength / S,
                               (spec.normal_stiffness > 0.0 ? spec.normal_stiffness : spec.bond_stiffness) / S,
                               spec.density * A / S, spec.density * inertia / S, S, spec.pretension / S});
    }
    D.installed.assign(D.sets.size(), 0);
    return D;
}

void Dowels::install(DowelState& D, int set, const HostFinder& find) {
    const DowelSetSpec& spec = D.specs[set];
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
            const TieHost h = find(p, 0.5 * segment);
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
            add_node(D.nodes, p, tributary, h, set, true);
            D.slip.push_back(slip);
            D.bond.push_back(0.0);
            D.shear.push_back(0.0);
            D.tied.push_back((j == 0 && spec.face_plate) || (j == n && spec.end_anchor));
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

void Dowels::force_pass(DowelState& D, const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& N = D.nodes;
    std::fill(N.force.begin(), N.force.end(), Vec2{});
    std::fill(N.moment.begin(), N.moment.end(), 0.0);
    for (int e = 0; e < D.element_count(); ++e) {
        if (D.state[e] == DowelState::broken) continue;
        const int a = D.element_node[e], b = a + 1;
        const auto& set = D.sets[N.set[a]];
        const support::BeamSection section{set.ea, set.ei, set.yield_force > 0.0, -set.yield_force, set.yield_force,
                                           set.moment_capacity};
        const auto beam = support::beam_forces(N.position[a], N.position[b], N.theta[a], N.theta[b], D.rest[e],
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
        N.force[a] += beam.force_on_a;
        N.force[b] -= beam.force_on_a;
        N.moment[a] -= beam.ma;
        N.moment[b] -= beam.mb;
    }
    // The grout (and a plate's or an anchor's tie): along the bar with slip,
    // across it elastic.
    for (int d = 0; d < D.dowel_count(); ++d) {
        const int first = D.first[d], last = D.first[d + 1] - 1;
        for (int k = first; k <= last; ++k) {
            const TieHost& h = N.host[k];
            if (!rock.holds(h)) {
                D.bond[k] = D.shear[k] = 0.0;
                reaction[k] = {};
                reaction_moment[k] = 0.0;
                continue;
            }
            const auto& set = D.sets[N.set[k]];
            const Vec2 x = rock.position(h), t = support::bar_axis(N.position, k, first, last);
            const auto g = support::grout(x - N.position[k], t, set.bond_stiffness, set.bond_strength,
                                          set.normal_stiffness, D.tied[k], D.slip[k]);
            D.bond[k] = g.along;
            D.shear[k] = dot(g.across, perp(t));
            const Vec2 f = N.length[k] * g.per_metre;
            N.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

void Dowels::add_stiffness(DowelState& D, RockStiffness& rock) {
    auto& N = D.nodes;
    support::clear_stiffness(N);
    for (int e = 0; e < D.element_count(); ++e) {
        if (D.state[e] == DowelState::broken) continue;
        const int a = D.element_node[e];
        const auto& set = D.sets[N.set[a]];
        const support::BeamSection section{set.ea, set.ei, false, 0.0, 0.0, 0.0};
        const double kt = support::beam_translation_stiffness(section, D.rest[e]);
        const double kr = support::beam_rotation_stiffness(section, D.rest[e]);
        N.stiffness[a] += kt, N.stiffness[a + 1] += kt;
        N.rotation_stiffness[a] += kr, N.rotation_stiffness[a + 1] += kr;
    }
    support::tie_and_set_masses(N, D.sets, rock, [&](int i) {
        const auto& set = D.sets[N.set[i]];
        return std::max(set.bond_stiffness, set.normal_stiffness);
    });
}

void Dowels::add_force_scale(const DowelState& D, double& terms, double& squares) {
    terms += double(D.element_count());
    for (double n : D.axial) squares += n * n;
}

void Dowels::parameters(const DowelState& D, std::vector<double>& out) {
    for (const auto& s : D.sets)
        out.insert(out.end(), {s.ea, s.ei, s.yield_force, s.moment_capacity, s.rupture_strain, s.bond_stiffness,
                               s.bond_strength, s.normal_stiffness, s.line_mass, s.line_inertia, s.spacing,
                               s.pretension});
    for (const auto& spec : D.specs) {
        for (const auto& [head, toe] : expand_bolts(spec)) out.insert(out.end(), {head.x, head.y, toe.x, toe.y});
        out.insert(out.end(), {spec.segment_length, double(spec.face_plate), double(spec.end_anchor)});
    }
}

namespace {
/// An element's shear force from its end moments (per metre of model).
double element_shear(const DowelState& D, int e) { return (D.moment_a[e] + D.moment_b[e]) / D.rest[e]; }
} // namespace

std::vector<SupportSetSummary> Dowels::summary(const DowelState& D) {
    const auto& N = D.nodes;
    std::vector<SupportSetSummary> out;
    for (std::size_t set = 0; set < D.sets.size(); ++set) {
        if (!D.installed[set]) continue;
        const double S = D.sets[set].spacing;
        double tension = 0.0, shear = 0.0, moment = 0.0, bond = 0.0, across = 0.0;
        int dowels = 0, yielded = 0, broken = 0;
        for (int d = 0; d < D.dowel_count(); ++d) dowels += D.dowel_set[d] == int(set);
        for (int e = 0; e < D.element_count(); ++e) {
            if (N.set[D.element_node[e]] != int(set)) continue;
            tension = std::max(tension, D.axial[e] * S);
            shear = std::max(shear, std::abs(element_shear(D, e)) * S);
            moment = std::max({moment, std::abs(D.moment_a[e]) * S, std::abs(D.moment_b[e]) * S});
            yielded += D.state[e] == DowelState::yielded;
            broken += D.state[e] == DowelState::broken;
        }
        for (int k = 0; k < N.count(); ++k)
            if (N.set[k] == int(set) && !D.tied[k])
                bond = std::max(bond, std::abs(D.bond[k]) * S), across = std::max(across, std::abs(D.shear[k]) * S);
        out.push_back({D.names[set],
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

SupportLines Dowels::lines(const DowelState& D) {
    const auto& N = D.nodes;
    SupportLines out;
    out.points = N.position;
    SupportLines::Array axial{"axial_force_kN", {}, false}, shear{"shear_force_kN", {}, false},
        moment{"moment_kNm", {}, false}, state{"state", {}, true}, set{"set", {}, true}, dowel{"dowel", {}, true};
    int d = 0;
    for (int e = 0; e < D.element_count(); ++e) {
        const int a = D.element_node[e];
        while (a >= D.first[d + 1]) ++d;
        const double S = D.sets[N.set[a]].spacing;
        out.cells.push_back({a, a + 1});
        axial.values.push_back(D.axial[e] * S / 1e3);
        shear.values.push_back(element_shear(D, e) * S / 1e3);
        moment.values.push_back(
            (std::abs(D.moment_a[e]) >= std::abs(D.moment_b[e]) ? D.moment_a[e] : -D.moment_b[e]) * S / 1e3);
        state.values.push_back(D.state[e]);
        set.values.push_back(N.set[a]);
        dowel.values.push_back(d);
        out.mark.push_back(D.state[e] == DowelState::broken ? 2 : D.state[e] == DowelState::yielded ? 1 : 0);
    }
    out.cell_data = {axial, shear, moment, state, set, dowel};
    SupportLines::Array bond{"bond_kN_per_m", {}, false}, across{"transverse_kN_per_m", {}, false},
        slip{"slip", {}, false};
    for (int k = 0; k < N.count(); ++k) {
        const double S = D.sets[N.set[k]].spacing;
        bond.values.push_back(D.bond[k] * S / 1e3);
        across.values.push_back(D.shear[k] * S / 1e3);
        slip.values.push_back(D.slip[k]);
    }
    out.point_data = {bond, across, slip};
    out.names = {{"state_names", {"elastic", "yielded", "broken"}}, {"set_names", D.names}};
    out.look = SupportLines::Look::bar;
    out.shade = 1; // the shear force: what a dowel is for
    out.shade_label = "kN shear";
    return out;
}

} // namespace bbm
