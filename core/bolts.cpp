// Rock bolts and cables as a support type (core/bolts.hpp for the model).
#include "core/bolts.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

std::vector<std::array<Vec2, 2>> expand_bolts(const BoltSetSpec& spec) {
    std::vector<std::array<Vec2, 2>> out = spec.bolts;
    if (!spec.ring) return out;
    const auto& r = *spec.ring;
    const double span = r.to - r.from;
    const bool full = std::abs(std::abs(span) - 360.0) < 1e-9;
    int count = r.count;
    if (count <= 0 && r.spacing > 0.0) {
        const double arc = std::abs(span) * std::numbers::pi / 180.0 * r.radius;
        count = std::max(1, int(std::floor(arc / r.spacing + 1e-9)) + (full ? 0 : 1));
    }
    for (int k = 0; k < count; ++k) {
        // A full circle: count intervals; an arc: bolts at both of its ends.
        const double f = full ? double(k) / count : (count > 1 ? double(k) / (count - 1) : 0.5);
        const double a = (r.from + f * span) * std::numbers::pi / 180.0;
        const Vec2 u{std::cos(a), std::sin(a)};
        out.push_back({r.center + r.radius * u, r.center + (r.radius + r.length) * u});
    }
    return out;
}

BoltSupport::BoltSupport(const std::vector<BoltSetSpec>& specs) : specs_(specs) {
    // Properties per metre of model; sets installed by stages.
    for (const auto& spec : specs) {
        const double S = spec.spacing;
        names_.push_back(spec.name);
        state_.sets.push_back({spec.young * spec.area / S, spec.yield_force / S, spec.rupture_strain,
                               spec.bond_stiffness / S, spec.bond_strength / S,
                               (spec.normal_stiffness > 0.0 ? spec.normal_stiffness : spec.bond_stiffness) / S,
                               spec.density * spec.area / S, S, std::uint8_t(spec.cable)});
    }
    state_.installed.assign(state_.sets.size(), 0);
}

void BoltSupport::install(int set, const HostFinder& find) {
    auto& B = state_;
    const BoltSetSpec& spec = specs_[set];
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
            const BoltHost h = find(p, 0.5 * segment);
            // Inner nodes may lie in an open joint (no rock: held by their
            // segments); the head and the toe must be in rock.
            if (h.block < 0 && (j == 0 || j == n))
                throw InputError("", 0, "bolt[" + std::to_string(set) + "]",
                                 "bolt " + std::to_string(b) + " of set '" + name + "': its point (" +
                                     std::to_string(p.x) + ", " + std::to_string(p.y) +
                                     ") lies in no rock (inside an opening, or outside the model): its " +
                                     (j == 0 ? "head" : "toe") + " must be in a block");
            B.position.push_back(p);
            B.velocity.push_back({});
            B.force.push_back({});
            B.applied.push_back({});
            B.mass.push_back(0.0);
            B.length.push_back(j == 0 || j == n ? 0.5 * segment : segment);
            B.slip.push_back(0.0);
            B.bond.push_back(0.0);
            B.host.push_back(h);
            B.tied.push_back((j == 0 && spec.face_plate) || (j == n && spec.end_anchor));
            B.node_set.push_back(set);
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
void BoltSupport::force_pass(const SupportRock& rock, Vec2* reaction, double* reaction_moment) {
    auto& B = state_;
    std::fill(B.force.begin(), B.force.end(), Vec2{});
    for (int s = 0; s < B.segment_count(); ++s) {
        const int a = B.segment_node[s];
        if (B.state[s] == BoltState::broken) continue;
        const auto& set = B.sets[B.node_set[a]];
        const Vec2 d = B.position[a + 1] - B.position[a];
        const double l = norm(d), strain = l / B.rest[s] - 1.0;
        if (set.rupture_strain > 0.0 && strain > set.rupture_strain) {
            B.state[s] = BoltState::broken;
            B.axial[s] = 0.0;
            continue;
        }
        double axial = set.ea * (strain - B.plastic[s]);
        if (set.cable && axial < 0.0) {
            axial = 0.0;
        } else if (set.yield_force > 0.0 && std::abs(axial) > set.yield_force) {
            axial = support::plastic_return(axial, set.yield_force, set.ea, strain, B.plastic[s]);
            B.state[s] = BoltState::yielded;
        }
        B.axial[s] = axial;
        const Vec2 f = (axial / l) * d;
        B.force[a] += f;
        B.force[a + 1] -= f;
    }
    for (int b = 0; b < B.bolt_count(); ++b) {
        const int first = B.first[b], last = B.first[b + 1] - 1;
        for (int k = first; k <= last; ++k) {
            const BoltHost& h = B.host[k];
            if (!rock.holds(h)) {
                B.bond[k] = 0.0;
                reaction[k] = {};
                reaction_moment[k] = 0.0;
                continue;
            }
            const auto& set = B.sets[B.node_set[k]];
            const Vec2 x = rock.position(h);
            const auto g = support::grout(x - B.position[k], support::bar_axis(B.position, k, first, last),
                                          set.bond_stiffness, set.bond_strength, set.normal_stiffness, B.tied[k], B.slip[k]);
            B.bond[k] = g.along;
            const Vec2 f = B.length[k] * g.per_metre;
            B.force[k] += f;
            rock.reaction(h, x, f, reaction[k], reaction_moment[k]);
        }
    }
}

double BoltSupport::integrate(const SupportMotion& motion, double& work) {
    auto& B = state_;
    const double alpha = motion.damping, dt = motion.dt;
    const Vec2 g = motion.gravity;
    double unbalanced = 0.0;
    for (int k = 0; k < B.node_count(); ++k) {
        const Vec2 weight = (B.sets[B.node_set[k]].line_mass * B.length[k]) * g;
        const Vec2 f = B.force[k] + weight + B.applied[k];
        unbalanced = std::max({unbalanced, std::abs(f.x), std::abs(f.y)});
        Vec2& v = B.velocity[k];
        v.x += support::damped(f.x, v.x, alpha) / B.mass[k] * dt;
        v.y += support::damped(f.y, v.y, alpha) / B.mass[k] * dt;
        B.position[k] += dt * v;
        work += dot(weight + B.applied[k], v) * dt;
    }
    return unbalanced;
}

void BoltSupport::add_stiffness(RockStiffness& rock) {
    auto& B = state_;
    auto& own = stiffness_;
    const double mass_factor = rock.mass_factor;
    own.assign(B.node_count(), 0.0);
    for (int s = 0; s < B.segment_count(); ++s) {
        if (B.state[s] == BoltState::broken) continue;
        const int a = B.segment_node[s];
        const double ks = B.sets[B.node_set[a]].ea / B.rest[s];
        own[a] += ks, own[a + 1] += ks;
    }
    for (int i = 0; i < B.node_count(); ++i) {
        const auto& set = B.sets[B.node_set[i]];
        const BoltHost& h = B.host[i];
        if (!rock.rock.holds(h)) continue;
        const double kg = B.length[i] * std::max(set.bond_stiffness, set.normal_stiffness);
        own[i] += kg;
        rock.add_tie(h, kg);
    }
    for (int i = 0; i < B.node_count(); ++i) {
        const double real = B.sets[B.node_set[i]].line_mass * B.length[i];
        B.mass[i] = mass_factor > 0.0 ? std::max(own[i] * mass_factor, 1e-300) : real;
    }
}

double BoltSupport::time_limit() const {
    double limit = INFINITY;
    for (int i = 0; i < state_.node_count(); ++i)
        if (stiffness_[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(state_.mass[i] / stiffness_[i]));
    return limit;
}

void BoltSupport::add_force_scale(double& terms, double& squares) const {
    // Bolts count with their segments' axial forces (a bolt may be all that holds a block).
    terms += double(state_.segment_count());
    for (double n : state_.axial) squares += n * n;
}

void BoltSupport::add_applied_loads(double& sum) const {
    for (Vec2 f : state_.applied) sum += norm(f);
}

void BoltSupport::model_parameters(std::vector<double>& out) const {
    for (const auto& set : state_.sets)
        out.insert(out.end(), {set.ea, set.yield_force, set.rupture_strain, set.bond_stiffness, set.bond_strength,
                               set.normal_stiffness, set.line_mass, set.spacing, double(set.cable)});
}

std::vector<SupportField> BoltSupport::fields() {
    // Nodes, their ties to the rock, segments; then the step's scratch.
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    auto& B = state_;
    return {{{"bolts.installed", G::other, E}, &B.installed}, {{"bolts.position", G::other, E}, &B.position},
            {{"bolts.velocity", G::other, E}, &B.velocity},   {{"bolts.applied", G::other, E}, &B.applied},
            {{"bolts.mass", G::other, E}, &B.mass},           {{"bolts.length", G::other, E}, &B.length},
            {{"bolts.slip", G::other, E}, &B.slip},           {{"bolts.bond", G::other, E}, &B.bond},
            {{"bolts.host", G::other, E}, &B.host},           {{"bolts.tied", G::other, E}, &B.tied},
            {{"bolts.node_set", G::other, E}, &B.node_set},   {{"bolts.segment_node", G::other, E}, &B.segment_node},
            {{"bolts.rest", G::other, E}, &B.rest},           {{"bolts.plastic", G::other, E}, &B.plastic},
            {{"bolts.axial", G::other, E}, &B.axial},         {{"bolts.state", G::other, E}, &B.state},
            {{"bolts.first", G::other, E}, &B.first},         {{"bolts.bolt_set", G::other, E}, &B.bolt_set},
            {{"bolts.force", G::other, R}, &B.force},         {{"bolts.stiffness", G::other, R}, &stiffness_}};
}

void BoltSupport::after_load() { state_.force.assign(state_.position.size(), {}); }

std::vector<BoltSetSummary> BoltSupport::set_summary() const {
    const auto& B = state_;
    std::vector<BoltSetSummary> out;
    for (std::size_t set = 0; set < B.sets.size(); ++set) {
        if (!B.installed[set]) continue;
        BoltSetSummary s;
        s.name = names_[set];
        const double spacing = B.sets[set].spacing;
        for (int b = 0; b < B.bolt_count(); ++b) {
            if (B.bolt_set[b] != int(set)) continue;
            ++s.bolts;
            bool yielded = false, broken = false;
            // The grout's load (a plate's or anchor's tie is not grout).
            for (int k = B.first[b]; k < B.first[b + 1]; ++k)
                if (!B.tied[k]) s.max_bond = std::max(s.max_bond, std::abs(B.bond[k]) * spacing);
            for (int seg = 0; seg < B.segment_count(); ++seg) {
                const int a = B.segment_node[seg];
                if (a < B.first[b] || a >= B.first[b + 1]) continue;
                s.max_axial = std::max(s.max_axial, B.axial[seg] * spacing);
                s.min_axial = std::min(s.min_axial, B.axial[seg] * spacing);
                yielded |= B.state[seg] == BoltState::yielded;
                broken |= B.state[seg] == BoltState::broken;
            }
            s.yielded += yielded;
            s.broken += broken;
        }
        out.push_back(s);
    }
    return out;
}

std::vector<SupportSetSummary> BoltSupport::summary() const {
    // The loads an engineer reads, per bolt.
    std::vector<SupportSetSummary> out;
    for (const auto& b : set_summary())
        out.push_back({b.name,
                       {{"bolts", double(b.bolts), true},
                        {"max_axial_kN", b.max_axial / 1e3},
                        {"max_compression_kN", -b.min_axial / 1e3},
                        {"max_bond_kN_per_m", b.max_bond / 1e3},
                        {"yielded", double(b.yielded), true},
                        {"broken", double(b.broken), true}}});
    return out;
}

SupportLines BoltSupport::lines() const {
    const auto& B = state_;
    SupportLines out;
    out.points = B.position;
    const int n = B.segment_count();
    SupportLines::Array axial{"axial_force_kN", {}, false}, state{"state", {}, true}, set{"set", {}, true},
        bolt{"bolt", {}, true};
    int b = 0;
    for (int i = 0; i < n; ++i) {
        const int a = B.segment_node[i];
        while (a >= B.first[b + 1]) ++b;
        out.cells.push_back({a, a + 1});
        axial.values.push_back(B.axial[i] * B.sets[B.node_set[a]].spacing / 1e3);
        state.values.push_back(B.state[i]);
        set.values.push_back(B.node_set[a]);
        bolt.values.push_back(b);
        out.mark.push_back(B.state[i] == BoltState::broken ? 2 : B.state[i] == BoltState::yielded ? 1 : 0);
    }
    out.cell_data = {axial, state, set, bolt};
    SupportLines::Array bond{"bond_kN_per_m", {}, false}, slip{"slip", {}, false};
    for (int k = 0; k < B.node_count(); ++k) {
        bond.values.push_back(B.bond[k] * B.sets[B.node_set[k]].spacing / 1e3);
        slip.values.push_back(B.slip[k]);
    }
    out.point_data = {bond, slip};
    out.names = {{"state_names", {"elastic", "yielded", "broken"}}, {"set_names", names_}};
    out.look = SupportLines::Look::bar;
    out.shade = 0;
    out.shade_label = "kN";
    return out;
}

} // namespace bbm
