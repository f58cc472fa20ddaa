// Rock bolts and cables as a support type (core/supports/bolt.hpp for the model).
#include "core/supports/bolt.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

std::vector<std::array<Vec2, 2>> expand_bolts(const BoltSetSpec& spec) { return expand_bars(spec.bolts, spec.ring); }

std::string bolt_keys_markdown() {
    return "# [[bolt]] and [[dowel]] keys\n\n"
           "Generated from core/supports/bolt.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). A set exists from the `install` stage that names it. Its loads are "
           "reported per bolt (summary.json `bolts` and `dowels`, `bbm compare`, bolts.pvd, dowels.pvd, "
           "failure.png, Python `Model.bolts`). The elements and the grout: [theory.md](../theory.md) §13; "
           "examples: [input.md](../input.md) and [the support tutorial](../guide/support.md).\n\n" +
           key_table_markdown(bolt_keys, "tables");
}


BoltSetSpec read_bar_set(TableReader& t, std::string_view type) {
    std::vector<std::string_view> keys;
    for (const auto& k : bolt_keys)
        if (key_applies(k, type)) keys.push_back(k.key);
    std::vector<std::string_view> all;
    for (const auto& k : bolt_keys) all.push_back(k.key);
    t.check_keys(keys, "a " + std::string(type) + " set", all);
    BoltSetSpec b;
    b.name = t.name();
    read_bars(t, "bolts", b.bolts, b.ring);
    t.declared(bolt_keys, b, type);
    const auto area = t.number("area", find_key(bolt_keys, "area")->bounds);
    const auto diameter = t.number("diameter", find_key(bolt_keys, "diameter")->bounds);
    if (area && diameter) t.fail("diameter", "give the steel's 'area' or its 'diameter', not both");
    if (area) b.area = *area;
    if (diameter) b.area = 0.25 * std::numbers::pi * *diameter * *diameter;
    // A node spacing far below the blocks (a length in mm, say) would give each
    // node a sliver of grout and beam elements stiffer by its cube: refused.
    t.check_length_resolves("segment_length", b.segment_length);
    if (diameter) t.check_length_resolves("diameter", *diameter, 1e-4);
    return b;
}

BoltState Bolts::make(const std::vector<BoltSetSpec>& specs) {
    // Properties per metre of model; sets installed by stages.
    BoltState B;
    B.specs = specs;
    for (const auto& spec : specs) {
        const double S = spec.spacing;
        B.names.push_back(spec.name);
        B.sets.push_back({spec.young * spec.area / S, spec.yield_force / S, spec.rupture_strain,
                          spec.bond_stiffness / S, spec.bond_strength / S,
                          (spec.normal_stiffness > 0.0 ? spec.normal_stiffness : spec.bond_stiffness) / S,
                          spec.density * spec.area / S, S, std::uint8_t(spec.cable)});
    }
    B.installed.assign(B.sets.size(), 0);
    B.dissipated.assign(B.sets.size(), 0.0);
    return B;
}

void Bolts::install(BoltState& B, int set, const HostFinder& find) {
    const BoltSetSpec& spec = B.specs[set];
    const std::string& name = spec.name;
    B.installed[set] = 1;
    const auto bolts = expand_bolts(spec);
    for (std::size_t b = 0; b < bolts.size(); ++b) {
        const auto [head, toe] = bolts[b];
        const double length = norm(toe - head);
        const int n = std::max(1, int(std::ceil(length / spec.segment_length - 1e-9)));
        const double segment = length / n;
        const int first = B.node_count();
        for (int j = 0; j <= n; ++j) {
            const Vec2 p = head + (double(j) / n) * (toe - head);
            const TieHost h = find(p, 0.5 * segment);
            // Inner nodes may lie in an open joint (no rock: held by their
            // segments); the head and the toe must be in rock.
            if (h.block < 0 && (j == 0 || j == n))
                throw InputError("", 0, "bolt[" + std::to_string(set) + "]",
                                 "bolt " + std::to_string(b) + " of set '" + name + "': its point (" +
                                     std::to_string(p.x) + ", " + std::to_string(p.y) +
                                     ") lies in no rock (inside an opening, or outside the model): its " +
                                     (j == 0 ? "head" : "toe") + " must be in a block");
            add_node(B.nodes, p, j == 0 || j == n ? 0.5 * segment : segment, h, set, false);
            B.applied.push_back({});
            B.slip.push_back(0.0);
            B.across_energy.push_back(0.0);
            B.bond.push_back(0.0);
            B.tied.push_back((j == 0 && spec.face_plate) || (j == n && spec.end_anchor));
            if (j < n) {
                B.segment_node.push_back(first + j);
                B.rest.push_back(segment);
                B.plastic.push_back(0.0);
                B.axial.push_back(0.0);
                B.state.push_back(BoltState::elastic);
            }
        }
        B.first.push_back(B.node_count());
        B.bolt_set.push_back(set);
    }
}

void Bolts::force_pass(BoltState& B, const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& N = B.nodes;
    std::fill(N.force.begin(), N.force.end(), Vec2{});
    for (int s = 0; s < B.segment_count(); ++s) {
        const int a = B.segment_node[s];
        if (B.state[s] == BoltState::broken) continue;
        const auto& set = B.sets[N.set[a]];
        const Vec2 d = N.position[a + 1] - N.position[a];
        const double l = norm(d), strain = l / B.rest[s] - 1.0;
        if (set.rupture_strain > 0.0 && strain > set.rupture_strain) {
            // Its stored energy is released as it snaps.
            B.dissipated[N.set[a]] += 0.5 * B.axial[s] * B.axial[s] * B.rest[s] / set.ea;
            B.state[s] = BoltState::broken;
            B.axial[s] = 0.0;
            continue;
        }
        double axial = set.ea * (strain - B.plastic[s]);
        if (set.cable && axial < 0.0) {
            axial = 0.0;
        } else if (set.yield_force > 0.0 && std::abs(axial) > set.yield_force) {
            const double plastic = B.plastic[s];
            axial = support::plastic_return(axial, set.yield_force, set.ea, strain, B.plastic[s]);
            B.dissipated[N.set[a]] += set.yield_force * std::abs(B.plastic[s] - plastic) * B.rest[s];
            B.state[s] = BoltState::yielded;
        }
        B.axial[s] = axial;
        const Vec2 f = (axial / l) * d;
        N.force[a] += f;
        N.force[a + 1] -= f;
    }
    for (int b = 0; b < B.bolt_count(); ++b) {
        const int first = B.first[b], last = B.first[b + 1] - 1;
        for (int k = first; k <= last; ++k) {
            const TieHost& h = N.host[k];
            if (!rock.holds(h)) {
                B.bond[k] = 0.0;
                B.across_energy[k] = 0.0;
                reaction[k] = {};
                reaction_moment[k] = 0.0;
                continue;
            }
            const auto& set = B.sets[N.set[k]];
            const Vec2 x = rock.position(h);
            const Vec2 t = support::bar_axis(N.position, k, first, last);
            const double slip = B.slip[k];
            const auto g = support::grout(x - N.position[k], t, set.bond_stiffness, set.bond_strength,
                                          set.normal_stiffness, B.tied[k], B.slip[k]);
            B.dissipated[N.set[k]] += std::abs(g.along) * std::abs(B.slip[k] - slip) * N.length[k];
            B.across_energy[k] = 0.5 * norm2(g.across) / set.normal_stiffness * N.length[k];
            B.bond[k] = g.along;
            const Vec2 f = N.length[k] * g.per_metre;
            N.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

double Bolts::set_energy(const BoltState& B, int set) {
    const auto& N = B.nodes;
    const auto& S = B.sets[set];
    double e = B.dissipated[set];
    for (int s = 0; s < B.segment_count(); ++s)
        if (N.set[B.segment_node[s]] == set && B.state[s] != BoltState::broken)
            e += 0.5 * B.axial[s] * B.axial[s] * B.rest[s] / S.ea;
    // The grout's springs along the hole (its last force) and across it; the nodes' motion.
    for (int k = 0; k < N.count(); ++k)
        if (N.set[k] == set)
            e += 0.5 * B.bond[k] * B.bond[k] / S.bond_stiffness * N.length[k] + B.across_energy[k] +
                 0.5 * N.mass[k] * norm2(N.velocity[k]);
    return e;
}

double Bolts::energy(const BoltState& B, const SupportRock&) {
    double e = 0.0;
    for (int set = 0; set < int(B.sets.size()); ++set) e += set_energy(B, set);
    return e;
}

void Bolts::add_stiffness(BoltState& B, RockStiffness& rock) {
    auto& N = B.nodes;
    support::clear_stiffness(N);
    for (int s = 0; s < B.segment_count(); ++s) {
        if (B.state[s] == BoltState::broken) continue;
        const int a = B.segment_node[s];
        const double ks = B.sets[N.set[a]].ea / B.rest[s];
        N.stiffness[a] += ks, N.stiffness[a + 1] += ks;
    }
    support::tie_and_set_masses(N, B.sets, rock, [&](int i) {
        const auto& set = B.sets[N.set[i]];
        return std::max(set.bond_stiffness, set.normal_stiffness);
    });
}

void Bolts::add_force_scale(const BoltState& B, double& terms, double& squares) {
    terms += double(B.segment_count());
    for (double n : B.axial) squares += n * n;
}

void Bolts::add_applied_loads(const BoltState& B, double& sum) {
    for (Vec2 f : B.applied) sum += norm(f);
}

void Bolts::parameters(const BoltState& B, std::vector<double>& out) {
    for (const auto& set : B.sets)
        out.insert(out.end(), {set.ea, set.yield_force, set.rupture_strain, set.bond_stiffness, set.bond_strength,
                               set.normal_stiffness, set.line_mass, set.spacing, double(set.cable)});
    for (const auto& spec : B.specs) {
        for (const auto& [head, toe] : expand_bolts(spec)) out.insert(out.end(), {head.x, head.y, toe.x, toe.y});
        out.insert(out.end(), {spec.segment_length, double(spec.face_plate), double(spec.end_anchor)});
    }
}

std::vector<SupportSetSummary> Bolts::summary(const BoltState& B) {
    // The loads an engineer reads, per bolt.
    std::vector<SupportSetSummary> out;
    for (std::size_t set = 0; set < B.sets.size(); ++set) {
        if (!B.installed[set]) continue;
        const double spacing = B.sets[set].spacing;
        int bolts = 0, yielded_bolts = 0, broken_bolts = 0;
        double max_axial = 0.0, min_axial = 0.0, max_bond = 0.0;
        for (int b = 0; b < B.bolt_count(); ++b) {
            if (B.bolt_set[b] != int(set)) continue;
            ++bolts;
            bool yielded = false, broken = false;
            // The grout's load (a plate's or anchor's tie is not grout).
            for (int k = B.first[b]; k < B.first[b + 1]; ++k)
                if (!B.tied[k]) max_bond = std::max(max_bond, std::abs(B.bond[k]) * spacing);
            for (int seg = 0; seg < B.segment_count(); ++seg) {
                const int a = B.segment_node[seg];
                if (a < B.first[b] || a >= B.first[b + 1]) continue;
                max_axial = std::max(max_axial, B.axial[seg] * spacing);
                min_axial = std::min(min_axial, B.axial[seg] * spacing);
                yielded |= B.state[seg] == BoltState::yielded;
                broken |= B.state[seg] == BoltState::broken;
            }
            yielded_bolts += yielded;
            broken_bolts += broken;
        }
        out.push_back({B.names[set],
                       {{"bolts", double(bolts), true},
                        {"max_axial_kN", max_axial / 1e3},
                        {"max_compression_kN", -min_axial / 1e3},
                        {"max_bond_kN_per_m", max_bond / 1e3},
                        {"yielded", double(yielded_bolts), true},
                        {"broken", double(broken_bolts), true},
                        {"energy_kJ", set_energy(B, int(set)) * spacing / 1e3}}});
    }
    return out;
}

SupportLines Bolts::lines(const BoltState& B) {
    const auto& N = B.nodes;
    SupportLines out;
    out.points = N.position;
    const int n = B.segment_count();
    SupportLines::Array axial{"axial_force_kN", {}, false}, state{"state", {}, true}, set{"set", {}, true},
        bolt{"bolt", {}, true};
    int b = 0;
    for (int i = 0; i < n; ++i) {
        const int a = B.segment_node[i];
        while (a >= B.first[b + 1]) ++b;
        out.cells.push_back({a, a + 1});
        axial.values.push_back(B.axial[i] * B.sets[N.set[a]].spacing / 1e3);
        state.values.push_back(B.state[i]);
        set.values.push_back(N.set[a]);
        bolt.values.push_back(b);
        out.mark.push_back(B.state[i] == BoltState::broken ? 2 : B.state[i] == BoltState::yielded ? 1 : 0);
    }
    out.cell_data = {axial, state, set, bolt};
    SupportLines::Array bond{"bond_kN_per_m", {}, false}, slip{"slip", {}, false};
    for (int k = 0; k < B.node_count(); ++k) {
        bond.values.push_back(B.bond[k] * B.sets[N.set[k]].spacing / 1e3);
        slip.values.push_back(B.slip[k]);
    }
    out.point_data = {bond, slip};
    out.names = {{"state_names", {"elastic", "yielded", "broken"}}, {"set_names", B.names}};
    out.look = SupportLines::Look::bar;
    out.shade = 0;
    out.shade_label = "kN";
    return out;
}

} // namespace bbm
