// Yielding, energy-absorbing rockbolts as a support type (core/supports/yielding_bolt.hpp).
#include "core/supports/yielding_bolt.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

std::string YieldingBolts::reference() {
    return "# [[yielding_bolt]] keys\n\n"
           "Generated from core/supports/yielding_bolt.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` "
           "rewrites it; the test fails when it is stale). A yielding bolt is a bar free in its hole between its "
           "face plate and its anchor: elastic to its yield force, held there over its slip capacity, then "
           "ruptured; the energy it absorbs is reported per set and per bolt (summary.json `yielding_bolts`, "
           "`bbm compare`, yielding_bolts.pvd, Python). A set exists from the `install` stage that names it.\n\n" +
           key_table_markdown(yielding_bolt_keys);
}

YieldingBoltSpec YieldingBolts::read(TableReader& t) {
    std::vector<std::string_view> keys;
    for (const auto& k : yielding_bolt_keys) keys.push_back(k.key);
    t.check_keys(keys, "a yielding bolt set");
    YieldingBoltSpec y;
    y.name = t.name();
    read_bars(t, "bolts", y.bolts, y.ring);
    t.declared(yielding_bolt_keys, y);
    const auto area = t.number("area", find_key(yielding_bolt_keys, "area")->bounds);
    const auto diameter = t.number("diameter", find_key(yielding_bolt_keys, "diameter")->bounds);
    if (area && diameter) t.fail("diameter", "give the bar's 'area' or its 'diameter', not both");
    if (area) y.area = *area;
    if (diameter) y.area = 0.25 * std::numbers::pi * *diameter * *diameter;
    if (diameter) t.check_length_resolves("diameter", *diameter, 1e-4);
    // A slip in mm read as metres would be a bolt that never ruptures; one far
    // below the blocks, a bolt that ruptures at once.
    t.check_length_resolves("slip_capacity", y.slip_capacity, 1e-4);
    return y;
}

YieldingBoltState YieldingBolts::make(const std::vector<YieldingBoltSpec>& specs) {
    YieldingBoltState Y;
    Y.specs = specs;
    for (const auto& spec : specs) {
        const double S = spec.spacing;
        Y.names.push_back(spec.name);
        Y.sets.push_back({spec.young * spec.area / S, spec.yield_force / S, spec.slip_capacity, S});
    }
    Y.installed.assign(Y.sets.size(), 0);
    return Y;
}

void YieldingBolts::install(YieldingBoltState& Y, int set, const HostFinder& find) {
    const YieldingBoltSpec& spec = Y.specs[set];
    Y.installed[set] = 1;
    const auto bolts = expand_bars(spec.bolts, spec.ring);
    for (std::size_t b = 0; b < bolts.size(); ++b) {
        const double length = norm(bolts[b][1] - bolts[b][0]);
        for (int end = 0; end < 2; ++end) {
            // A plate on the wall of a polygonal opening may sit a hair outside its rock.
            const Vec2 p = bolts[b][end];
            const TieHost h = find(p, 0.05 * length);
            if (h.block < 0)
                throw InputError("", 0, "yielding_bolt[" + std::to_string(set) + "]",
                                 "bolt " + std::to_string(b) + " of set '" + spec.name + "': its " +
                                     (end == 0 ? "plate" : "anchor") + " (" + std::to_string(p.x) + ", " +
                                     std::to_string(p.y) +
                                     ") lies in no rock (inside an opening, or outside the model)");
            Y.host.push_back(h);
            Y.end.push_back(p);
        }
        Y.bolt_set.push_back(set);
        Y.rest.push_back(length);
        Y.elongation.push_back(0.0);
        Y.slip.push_back(0.0);
        Y.axial.push_back(0.0);
        Y.energy.push_back(0.0);
        Y.state.push_back(YieldingBoltState::elastic);
    }
}

void YieldingBolts::force_pass(YieldingBoltState& Y, const SupportRock& rock, Vec2* reaction, double* moment) {
    for (int b = 0; b < Y.bolt_count(); ++b) {
        const TieHost &plate = Y.host[2 * b], &anchor = Y.host[2 * b + 1];
        reaction[2 * b] = reaction[2 * b + 1] = {};
        moment[2 * b] = moment[2 * b + 1] = 0.0;
        // Its rock gone (excavated) or the bar ruptured: it carries nothing.
        if (Y.state[b] == YieldingBoltState::ruptured || !rock.holds(plate) || !rock.holds(anchor)) {
            Y.axial[b] = 0.0;
            continue;
        }
        const Vec2 head = rock.position(plate), toe = rock.position(anchor);
        Y.end[2 * b] = head, Y.end[2 * b + 1] = toe;
        const auto& set = Y.sets[Y.bolt_set[b]];
        const double length = norm(toe - head), delta = length - Y.rest[b], k = set.ea / Y.rest[b];
        double n = std::max(0.0, k * (delta - Y.slip[b]));
        if (n > set.yield_force) {
            Y.slip[b] = delta - set.yield_force / k;
            n = set.yield_force;
            Y.state[b] = YieldingBoltState::yielding;
        }
        Y.energy[b] += 0.5 * (Y.axial[b] + n) * (delta - Y.elongation[b]);
        Y.elongation[b] = delta;
        if (Y.slip[b] > set.slip_capacity) { // past its capacity: ruptured for good
            Y.state[b] = YieldingBoltState::ruptured;
            Y.axial[b] = 0.0;
            continue;
        }
        Y.axial[b] = n;
        // The bar pulls its plate toward its anchor and the anchor toward the plate.
        const Vec2 t = (toe - head) / length;
        rock.reaction(plate, head, -n * t, reaction[2 * b], moment[2 * b]);
        rock.reaction(anchor, toe, n * t, reaction[2 * b + 1], moment[2 * b + 1]);
    }
}

void YieldingBolts::add_stiffness(YieldingBoltState& Y, RockStiffness& k) {
    for (int b = 0; b < Y.bolt_count(); ++b) {
        if (Y.state[b] == YieldingBoltState::ruptured) continue;
        const double stiffness = Y.sets[Y.bolt_set[b]].ea / Y.rest[b];
        for (int end = 0; end < 2; ++end)
            if (k.rock.holds(Y.host[2 * b + end])) k.add_tie(Y.host[2 * b + end], stiffness);
    }
}

void YieldingBolts::add_force_scale(const YieldingBoltState& Y, double& terms, double& squares) {
    terms += double(Y.bolt_count());
    for (double n : Y.axial) squares += n * n;
}

void YieldingBolts::parameters(const YieldingBoltState& Y, std::vector<double>& out) {
    for (const auto& set : Y.sets) out.insert(out.end(), {set.ea, set.yield_force, set.slip_capacity, set.spacing});
    for (const auto& spec : Y.specs)
        for (const auto& [head, toe] : expand_bars(spec.bolts, spec.ring)) out.insert(out.end(), {head.x, head.y, toe.x, toe.y});
}

std::vector<SupportSetSummary> YieldingBolts::summary(const YieldingBoltState& Y) {
    std::vector<SupportSetSummary> out;
    for (std::size_t set = 0; set < Y.sets.size(); ++set) {
        if (!Y.installed[set]) continue;
        const double S = Y.sets[set].spacing;
        int bolts = 0, yielding = 0, ruptured = 0;
        double max_axial = 0.0, max_slip = 0.0, energy = 0.0, max_energy = 0.0;
        for (int b = 0; b < Y.bolt_count(); ++b) {
            if (Y.bolt_set[b] != int(set)) continue;
            ++bolts;
            yielding += Y.state[b] == YieldingBoltState::yielding;
            ruptured += Y.state[b] == YieldingBoltState::ruptured;
            max_axial = std::max(max_axial, Y.axial[b] * S);
            max_slip = std::max(max_slip, Y.slip[b]);
            energy += Y.energy[b] * S;
            max_energy = std::max(max_energy, Y.energy[b] * S);
        }
        out.push_back({Y.names[set],
                       {{"bolts", double(bolts), true},
                        {"max_axial_kN", max_axial / 1e3},
                        {"max_slip_mm", max_slip * 1e3},
                        {"energy_kJ", energy / 1e3},
                        {"max_energy_kJ", max_energy / 1e3},
                        {"yielding", double(yielding), true},
                        {"ruptured", double(ruptured), true}}});
    }
    return out;
}

SupportLines YieldingBolts::lines(const YieldingBoltState& Y) {
    SupportLines out;
    out.points = Y.end;
    SupportLines::Array axial{"axial_force_kN", {}, false}, slip{"slip_mm", {}, false}, energy{"energy_kJ", {}, false},
        state{"state", {}, true}, set{"set", {}, true};
    for (int b = 0; b < Y.bolt_count(); ++b) {
        const double S = Y.sets[Y.bolt_set[b]].spacing;
        out.cells.push_back({2 * b, 2 * b + 1});
        axial.values.push_back(Y.axial[b] * S / 1e3);
        slip.values.push_back(Y.slip[b] * 1e3);
        energy.values.push_back(Y.energy[b] * S / 1e3);
        state.values.push_back(Y.state[b]);
        set.values.push_back(Y.bolt_set[b]);
        out.mark.push_back(Y.state[b] == YieldingBoltState::ruptured ? 2 : Y.state[b] == YieldingBoltState::yielding ? 1 : 0);
    }
    out.cell_data = {axial, slip, energy, state, set};
    out.names = {{"state_names", {"elastic", "yielding", "ruptured"}}, {"set_names", Y.names}};
    out.look = SupportLines::Look::bar;
    out.shade = 0;
    out.shade_label = "kN";
    return out;
}

} // namespace bbm
