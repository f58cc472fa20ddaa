// bbm core: supports — structural elements tied to the rock (bolts, liners,
// dowels), behind one small interface.
//
// A support type owns its nodes and elements in flat arrays and is tied to the
// rock at its nodes ("ties"): each tie sits in a rigid block (a body-frame point)
// or a zone (barycentric weights), found when the support is installed. Once per
// step the solver asks every installed support type, in registration order, for
//   force_pass — its element and tie forces, and what each tie puts on the rock
//                (a force, and its moment about a rigid host's centroid), written
//                into the solver's tie arrays at the type's offset;
//   integrate  — its nodes moved with the blocks' damping; returns its largest
//                free force component (the unbalanced-force measure);
// and, when the time step is recomputed, for add_stiffness (its ties' stiffness
// added to the rock's, its nodes' masses scaled) and time_limit. It lists its
// arrays in the state list (fields(): saved, hashed, counted like the rest) and
// describes itself for output (summary(): figures per set for summary.json;
// lines(): a polyline grid with named arrays for VTK and the picture).
//
// Virtual calls are per support type per step, never per node or contact; the
// solver gathers the ties' reactions in tie order, a fixed order on any thread
// count. A new support type is one file (a class deriving from Support) and one
// row of the registry in core/support.cpp.
#pragma once

#include "base/vec2.hpp"
#include "core/state_fields.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace bbm {

struct AnalysisSpec;

/// Where a support node is tied into the rock: a rigid block (body-frame offset)
/// or a zone (barycentric weights of its nodes); block −1 = in no rock.
struct BoltHost {
    int block = -1, zone = -1;
    Vec2 local{};
    std::array<double, 3> weight{};
};

/// The rock as a support sees it during a step: where its ties are now, and
/// which blocks are gone.
struct SupportRock {
    const Vec2* centroid = nullptr;
    const double* theta = nullptr;
    const std::uint8_t* removed = nullptr;
    const Vec2* node_position = nullptr;
    const std::array<int, 3>* zone_node = nullptr;

    /// The tie's rock is there (not excavated, and the node lies in rock at all).
    bool holds(const BoltHost& h) const { return h.block >= 0 && !removed[h.block]; }
    /// The rock point the tie follows, now.
    Vec2 position(const BoltHost& h) const;
    /// A tie's force f on its support node at rock point x: the opposite on the
    /// rock, and its moment about a rigid host's centroid.
    void reaction(const BoltHost& h, Vec2 x, Vec2 f, Vec2& force, double& moment) const;
};

/// The rock's stiffness being summed by update_timestep(): a tie adds its own.
struct RockStiffness {
    const SupportRock& rock;
    std::vector<double>& block;    ///< translation, per block
    std::vector<double>& rotation; ///< per block
    std::vector<double>& node;     ///< per FE node
    /// Quasi-static: a node's mass is its stiffness times this; 0 = real masses.
    double mass_factor = 0.0;
    void add_tie(const BoltHost& h, double stiffness);
};

/// What integration needs of the solver's settings.
struct SupportMotion {
    double dt = 0.0, damping = 0.0;
    Vec2 gravity{};
};

/// A support's array in the state list (core/state_fields.hpp).
struct SupportField {
    FieldInfo info;
    std::variant<std::vector<Vec2>*, std::vector<double>*, std::vector<std::uint8_t>*, std::vector<int>*,
                 std::vector<BoltHost>*>
        field;
};

/// Per installed set, the figures an engineer reads (summary.json): name, value,
/// and whether it is a count.
struct SupportSetSummary {
    struct Figure {
        std::string key;
        double value = 0.0;
        bool count = false;
    };
    std::string name;
    std::vector<Figure> figures;
    double figure(const std::string& key) const; ///< throws std::out_of_range for an unknown key
};

/// A support drawn as line cells over its nodes, with named arrays (VTK output,
/// the picture).
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
using HostFinder = std::function<BoltHost(Vec2 point, double reach)>;

class Support {
public:
    virtual ~Support() = default;
    /// The type's plural name: the state list's prefix, summary.json's key, the
    /// VTK files' stem ("bolts", "liners", "dowels").
    virtual const char* name() const = 0;
    /// Its sets (model-file tables) by name, in file order.
    virtual const std::vector<std::string>& set_names() const = 0;
    virtual bool installed(int set) const = 0;
    /// Installs a set: its nodes tied to the rock they lie in now, unstressed (or
    /// pretensioned). Throws InputError for a node that must be in rock and is not.
    virtual void install(int set, const HostFinder& find) = 0;
    virtual int tie_count() const = 0;
    virtual const BoltHost& host(int tie) const = 0;
    /// Element and tie forces; what tie k puts on the rock goes to reaction[k], moment[k].
    virtual void force_pass(const SupportRock& rock, Vec2* reaction, double* moment) = 0;
    /// Moves the nodes one step; adds the loads' work; returns the largest free force component.
    virtual double integrate(const SupportMotion& motion, double& work) = 0;
    virtual void add_stiffness(RockStiffness& k) = 0;
    /// Dynamic mode: the critical time step of its nodes (after add_stiffness).
    virtual double time_limit() const = 0;
    /// Terms of the force scale (core/solver.hpp force_scale): an element that may
    /// be all that holds a block counts.
    virtual void add_force_scale(double& terms, double& squares) const {
        (void)terms, (void)squares;
    }
    /// Adds |applied load| of each node (a pull-out test's jack) to `sum`: the
    /// force scale when nothing else loads the model.
    virtual void add_applied_loads(double& sum) const { (void)sum; }
    /// The sets' properties, for the model fingerprint.
    virtual void model_parameters(std::vector<double>& out) const = 0;
    /// Its arrays, for the state list.
    virtual std::vector<SupportField> fields() = 0;
    /// After a checkpoint is loaded: per-step scratch sized again.
    virtual void after_load() = 0;
    virtual std::vector<SupportSetSummary> summary() const = 0;
    virtual SupportLines lines() const = 0;
};

/// The registered support types, in the order their ties are numbered and their
/// forces gathered, each built from its tables of the model (an empty type when
/// it has none).
std::vector<std::unique_ptr<Support>> make_supports(const AnalysisSpec& analysis);

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
/// neighbours (bolts, dowels).
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
} // namespace support

} // namespace bbm
