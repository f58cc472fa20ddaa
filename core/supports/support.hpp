// bbm core: what every support type shares — structural elements tied to the rock
// — and what a type must declare to be one (registry.hpp lists the types).
//
// A support type owns its nodes and elements in flat arrays (its State, plain
// data) and is tied to the rock at its nodes ("ties"): each tie sits in a rigid
// block (a body-frame point) or a zone (barycentric weights), found when the
// support is installed. A type is a struct of static members and one row of the
// registry (core/supports/registry.hpp); the rest of the program iterates the
// registry and names no type. What a type declares:
//   name, table          its plural (the state list's prefix, summary.json's
//                        key, the VTK files' stem) and its model-file table
//                        (`table` = "x": [[x]] tables);
//   Spec, State          one table's values, and the installed state;
//   keys, read(...)      its keys (base/keys.hpp: units, bounds, meaning) and its
//                        reader (base/table_reader.hpp);
//   reference()          docs/reference/<table>.md, its keys' page (a type whose
//                        keys are another's page, the dowel's, has none);
//   make(specs)          its State from its tables, nothing installed;
//   set_names, installed, install(set, find), tie_count, host(tie);
//   force_pass           its element and tie forces, what each tie puts on the
//                        rock (a force, and its moment about a rigid host's
//                        centroid) into the world's tie arrays at its offset;
//   integrate            its nodes moved with the blocks' damping; returns its
//                        largest free force component (the unbalanced force);
//   add_stiffness, time_limit   when the time step is recomputed;
//   add_force_scale, add_applied_loads   the force scale's terms;
//   parameters           its sets' properties, for the model fingerprint;
//   visit_fields         its arrays in the state list (saved, hashed, counted);
//   after_load           per-step scratch sized again after a checkpoint;
//   summary, lines       its figures per set (summary.json) and its polylines
//                        with named arrays (VTK, the picture, Python);
//   compare              the figures `bbm compare` tabulates, over its sets;
//   energy               the work the rock has done on it so far (stored,
//                        dissipated and its nodes' kinetic energy, J/m: the
//                        energy account's supports, core/measures.hpp).
// The solver calls them once per type per step (a compile-time loop over the
// registry, no virtual call at all) and gathers the ties' reactions in tie
// order, a fixed order on any thread count. The node integration, the masses and
// the time limit every type's nodes need are SupportNodes' functions below.
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"
#include "contact/contacts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace bbm {

/// Where a support node is tied into the rock: a rigid block (body-frame offset)
/// or a zone (barycentric weights of its nodes); block −1 = in no rock.
struct TieHost {
    int block = -1, zone = -1;
    Vec2 local{};
    std::array<double, 3> weight{};
};
static_assert(sizeof(TieHost) == 2 * sizeof(int) + sizeof(Vec2) + 3 * sizeof(double)); // hashed as raw bytes

template <>
struct ElementTraits<TieHost> : PackedRecordTraits<TieHost> {};

/// The rock as a support sees it during a step: where its ties are now, and
/// which blocks are gone.
struct SupportRock {
    const contact::BodyState* body = nullptr;
    const std::uint8_t* removed = nullptr;
    const Vec2* node_position = nullptr;
    const std::array<int, 3>* zone_node = nullptr;

    /// The tie's rock is there (not excavated, and the node lies in rock at all).
    bool holds(const TieHost& h) const { return h.block >= 0 && !removed[h.block]; }
    /// The rock point the tie follows, now.
    Vec2 position(const TieHost& h) const {
        if (h.zone < 0) return body[h.block].centroid + rotation(body[h.block].theta)(h.local);
        const auto& t = zone_node[h.zone];
        return h.weight[0] * node_position[t[0]] + h.weight[1] * node_position[t[1]] + h.weight[2] * node_position[t[2]];
    }
    /// A tie's force f on its support node at rock point x: the opposite on the
    /// rock, and its moment about a rigid host's centroid.
    void reaction(const TieHost& h, Vec2 x, Vec2 f, Vec2& force, double& moment) const {
        force = -f;
        moment = h.zone < 0 ? -cross(x - body[h.block].centroid, f) : 0.0;
    }
};

/// The rock's stiffness being summed by update_timestep(): a tie adds its own.
struct RockStiffness {
    const SupportRock& rock;
    std::vector<double>& block;    ///< translation, per block
    std::vector<double>& rotation; ///< per block
    std::vector<double>& node;     ///< per FE node
    /// Quasi-static: a node's mass is its stiffness times this; 0 = real masses.
    double mass_factor = 0.0;
    void add_tie(const TieHost& h, double stiffness) {
        if (h.zone < 0) {
            block[h.block] += stiffness;
            rotation[h.block] += stiffness * norm2(rock.position(h) - rock.body[h.block].centroid);
        } else {
            for (int j = 0; j < 3; ++j) node[rock.zone_node[h.zone][j]] += std::abs(h.weight[j]) * stiffness;
        }
    }
};

/// What integration needs of the solver's settings.
struct SupportMotion {
    double dt = 0.0, damping = 0.0;
    Vec2 gravity{};
};

/// Per installed set, the figures an engineer reads (summary.json, `bbm
/// compare`): name, value, and whether it is a count.
struct SupportSetSummary {
    struct Figure {
        std::string key;
        double value = 0.0;
        bool count = false;
    };
    std::string name;
    std::vector<Figure> figures;
    /// Throws std::out_of_range for an unknown key.
    double figure(const std::string& key) const {
        for (const auto& f : figures)
            if (f.key == key) return f.value;
        throw std::out_of_range("support summary of '" + name + "' has no figure '" + key + "'");
    }
};

/// A figure of a type's sets that `bbm compare` tabulates: summed over the sets
/// (a count) or their largest, with its heading in the Markdown table.
struct CompareColumn {
    std::string_view figure;
    std::string_view heading;
    bool sum = false;
};

/// A support drawn as line cells over its nodes, with named arrays (VTK output,
/// the picture, Python's views).
struct SupportLines {
    struct Array {
        std::string name;
        std::vector<double> values;
        bool integer = false;
    };
    std::vector<Vec2> points;
    std::vector<std::array<int, 2>> cells;
    std::vector<Array> cell_data, point_data;
    std::vector<std::pair<std::string, std::vector<std::string>>> names; ///< field data: named string lists
    /// The picture: cells shaded by |cell_data[shade]| against its largest value;
    /// per cell 0 = drawn plain, 1 = yielded (thicker), 2 = broken (dashed).
    enum class Look : std::uint8_t { bar, lining } look = Look::bar;
    int shade = 0;
    std::string shade_label; ///< the legend's unit of that array ("kN", "kN/m thrust")
    std::vector<std::uint8_t> mark;
};

/// Finds the rock a point lies in (or the nearest within `reach`): install time.
using HostFinder = std::function<TieHost(Vec2 point, double reach)>;

/// The nodes of a support, as every type has them: translation (all), rotation
/// (the types that bend), tributary lengths, ties, sets; and add_stiffness's
/// per-node scratch. Its fields are listed by each type in its own order.
struct SupportNodes {
    std::vector<Vec2> position, velocity, force;
    std::vector<double> mass, length;
    std::vector<double> theta, omega, moment, inertia; ///< empty for a type that does not bend
    std::vector<TieHost> host;
    std::vector<int> set;                              ///< per node, its set
    std::vector<double> stiffness, rotation_stiffness; ///< add_stiffness's scratch
    int count() const { return static_cast<int>(position.size()); }
};

/// A new node at p, at rest, of tributary length `length`.
inline void add_node(SupportNodes& n, Vec2 p, double length, const TieHost& host, int set, bool rotates) {
    n.position.push_back(p);
    n.velocity.push_back({});
    n.force.push_back({});
    n.mass.push_back(0.0);
    n.length.push_back(length);
    n.host.push_back(host);
    n.set.push_back(set);
    if (rotates) {
        n.theta.push_back(0.0);
        n.omega.push_back(0.0);
        n.moment.push_back(0.0);
        n.inertia.push_back(0.0);
    }
}

namespace support {
/// Perfectly plastic return shared by the support laws: the trial value within
/// ±limit, else clamped there and `plastic` moved so that stiffness ×
/// (total − plastic) gives the clamped value.
inline double plastic_return(double trial, double limit, double stiffness, double total, double& plastic) {
    if (!(std::abs(trial) > limit)) return trial;
    const double clamped = trial > 0.0 ? limit : -limit;
    plastic = total - clamped / stiffness;
    return clamped;
}
/// A bar's unit axis at node k of the bar whose nodes are [first, last]: along its
/// neighbours (the types of bars).
inline Vec2 bar_axis(const std::vector<Vec2>& position, int k, int first, int last) {
    const Vec2 axis = position[std::min(k + 1, last)] - position[std::max(k - 1, first)];
    return axis / norm(axis);
}
/// A bar's grout at one node, the rock point having moved `gap` from the node:
/// along the axis t, q = k_bond (s − s_p) with s = gap·t, limited to ±strength
/// (plastic slip s_p) unless the node is tied (a face plate, an end anchor);
/// across it k_across (gap − s t), elastic. per_metre: the force on the node per
/// metre of bar (times its tributary length: the node's).
struct Grout {
    double along;
    Vec2 across, per_metre;
};
inline Grout grout(Vec2 gap, Vec2 t, double k_bond, double strength, double k_across, bool tied, double& slip) {
    const double s = dot(gap, t);
    double q = k_bond * (s - slip);
    if (!tied && strength > 0.0) q = plastic_return(q, strength, k_bond, s, slip);
    const Vec2 across = k_across * (gap - s * t);
    return {q, across, q * t + across};
}
/// Local non-viscous damping (Cundall), as the blocks get it: f reduced by α|f| against v.
inline double damped(double f, double v, double alpha) {
    return f - alpha * std::abs(f) * double((v > 0.0) - (v < 0.0));
}

/// What loads a type's nodes besides their elements, ties and weight.
struct NodeLoads {
    const std::vector<Vec2>* applied = nullptr; ///< a load per node, N/m (a pull-out test's jack)
    const std::vector<Vec2>* held = nullptr;    ///< per node: a direction held (an end on a symmetry plane), or zero
};

/// Moves every node one step, as the blocks move (damped central differences):
/// its elements' and ties' force, its weight (the set's line mass, kg per metre
/// of support per metre of model, times its tributary length) and its loads;
/// rotation too if the type bends. Adds the loads' work; returns the largest free
/// force component (a moment per metre of its length).
template <class Sets>
double integrate_nodes(SupportNodes& n, const Sets& sets, const SupportMotion& motion, double& work,
                       const NodeLoads& loads = {}) {
    const double alpha = motion.damping, dt = motion.dt;
    const bool rotates = !n.theta.empty();
    double unbalanced = 0.0;
    for (int k = 0; k < n.count(); ++k) {
        const Vec2 weight = (sets[n.set[k]].line_mass * n.length[k]) * motion.gravity;
        Vec2 f = n.force[k] + weight;
        if (loads.applied) f += (*loads.applied)[k];
        const Vec2 held = loads.held ? (*loads.held)[k] : Vec2{};
        if (held != Vec2{}) f -= dot(f, held) * held; // the symmetry plane's reaction
        unbalanced = std::max({unbalanced, std::abs(f.x), std::abs(f.y)});
        Vec2& v = n.velocity[k];
        v.x += damped(f.x, v.x, alpha) / n.mass[k] * dt;
        v.y += damped(f.y, v.y, alpha) / n.mass[k] * dt;
        if (rotates) {
            if (held != Vec2{}) {
                v -= dot(v, held) * held;
                n.omega[k] = 0.0;
            } else {
                unbalanced = std::max(unbalanced, std::abs(n.moment[k]) / std::max(n.length[k], 1e-12));
                n.omega[k] += damped(n.moment[k], n.omega[k], alpha) / n.inertia[k] * dt;
            }
        }
        n.position[k] += dt * v;
        if (rotates) n.theta[k] += dt * n.omega[k];
        work += dot(loads.applied ? weight + (*loads.applied)[k] : weight, v) * dt;
    }
    return unbalanced;
}

/// The kinetic energy of a type's nodes (translation, and rotation if it bends), J/m.
inline double nodes_kinetic_energy(const SupportNodes& n) {
    double e = 0.0;
    for (int k = 0; k < n.count(); ++k) {
        e += 0.5 * n.mass[k] * norm2(n.velocity[k]);
        if (!n.theta.empty()) e += 0.5 * n.inertia[k] * n.omega[k] * n.omega[k];
    }
    return e;
}

/// add_stiffness's start: the per-node stiffness scratch zeroed.
inline void clear_stiffness(SupportNodes& n) {
    n.stiffness.assign(n.count(), 0.0);
    if (!n.theta.empty()) n.rotation_stiffness.assign(n.count(), 0.0);
}

/// add_stiffness's end: each node's tie (its stiffness per metre of support,
/// `per_metre(k)`, times its tributary length) added to its own stiffness and
/// its rock's; then its masses — quasi-static, its stiffness times the mass
/// factor; dynamic, its set's line mass (and line inertia) times its length.
template <class Sets, class PerMetre>
void tie_and_set_masses(SupportNodes& n, const Sets& sets, RockStiffness& rock, PerMetre&& per_metre) {
    for (int i = 0; i < n.count(); ++i) {
        const TieHost& h = n.host[i];
        if (!rock.rock.holds(h)) continue;
        const double kg = n.length[i] * per_metre(i);
        n.stiffness[i] += kg;
        rock.add_tie(h, kg);
    }
    const double f = rock.mass_factor;
    for (int i = 0; i < n.count(); ++i) {
        const auto& set = sets[n.set[i]];
        n.mass[i] = f > 0.0 ? std::max(n.stiffness[i] * f, 1e-300) : set.line_mass * n.length[i];
        if constexpr (requires { set.line_inertia; })
            if (!n.theta.empty())
                n.inertia[i] = f > 0.0 ? std::max(n.rotation_stiffness[i] * f, 1e-300) : set.line_inertia * n.length[i];
    }
}

/// Dynamic mode: the critical time step of the nodes (after add_stiffness).
inline double nodes_time_limit(const SupportNodes& n) {
    double limit = INFINITY;
    for (int i = 0; i < n.count(); ++i) {
        if (n.stiffness[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(n.mass[i] / n.stiffness[i]));
        if (!n.theta.empty() && n.rotation_stiffness[i] > 0.0)
            limit = std::min(limit, 2.0 * std::sqrt(n.inertia[i] / n.rotation_stiffness[i]));
    }
    return limit;
}

/// After a checkpoint is loaded: the per-step force (and moment) sized again.
inline void resize_node_scratch(SupportNodes& n) {
    n.force.assign(n.position.size(), {});
    if (!n.theta.empty()) n.moment.assign(n.position.size(), 0.0);
}
} // namespace support

} // namespace bbm
