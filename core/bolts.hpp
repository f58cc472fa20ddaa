// bbm core: rock bolts and cables — fully grouted structural elements (issue 25).
//
// A bolt is a chain of nodes joined by axial segments (steel E·A, a yield force,
// a rupture strain) as UDEC's and FLAC's cables are. Each node is tied by grout
// springs to the point of rock it sits in (a rigid block, or a zone of a
// deformable block), found when the bolt is installed:
//   along the bolt:  q = k_bond (s − s_p),  |q| ≤ q_max   (N/m per m of bolt)
//   across it:       q⊥ = k_normal w                      (no limit: the hole)
// where d = x_rock − x_node is the relative displacement since installation,
// s = d·t its component along the bolt axis t and w = d − s t the rest, and s_p
// the plastic slip of the grout (shear-lag theory: Farmer 1975). The node gets
// L·(q t + q⊥), L its tributary length, and the rock the opposite at the same
// point (a force and a moment on a rigid block; split by barycentric weights over
// a zone's three nodes). A segment carries N = E·A (ε − ε_p), limited to ±F_y
// (plastic strain ε_p), zero once ε passes the rupture strain (broken for
// good) and, for a cable, zero in compression (it goes slack). A face plate or
// an end anchor ties the head or the toe node to its rock with no slip limit.
//
// Plane strain: a set given per bolt at an out-of-plane spacing S acts with E·A,
// F_y, k_bond, q_max, k_normal and the steel's mass divided by S (per metre of
// model); its figures are reported per bolt (times S).
//
// The bolt pass runs once per step, by one thread while the others start on the
// contacts (a few hundred nodes: no barrier of its own); it writes each node's
// reaction on its rock, which the gather of block and node forces adds in a
// fixed order (the same bits on any thread count). The nodes are integrated
// with the blocks' damping and, quasi-static, their masses scaled to their
// stiffness. Nothing is allocated per step.
#pragma once

#include "base/vec2.hpp"
#include "core/support.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bbm {

/// A [[bolt]] table of the model file: one set of bolts with one property set.
struct BoltSetSpec {
    std::string name;
    /// Bolts given one by one: head (at the wall) and toe.
    std::vector<std::array<Vec2, 2>> bolts;
    /// Radial bolts around a circular opening: heads on the circle, evenly spaced
    /// (`count`, or `spacing` along the wall) from angle `from` to `to`, degrees
    /// counter-clockwise from +x (a full circle when to − from = 360).
    struct Ring {
        Vec2 center{};
        double radius = 0.0, length = 0.0;
        int count = 0;
        double spacing = 0.0;
        double from = 0.0, to = 360.0;
    };
    std::optional<Ring> ring;
    double segment_length = 0.25;  ///< m: nodes along a bolt at most this far apart
    double young = 200e9;          ///< Pa, steel
    double area = 4.91e-4;         ///< m², steel cross-section (25 mm bar)
    double density = 7850.0;       ///< kg/m³, steel
    double yield_force = 0.0;      ///< N per bolt; 0 = elastic
    double rupture_strain = 0.0;   ///< breaks past this axial strain; 0 = never
    bool cable = false;            ///< no compression (goes slack)
    double bond_stiffness = 0.0;   ///< N/m per m of bolt (grout shear stiffness)
    double bond_strength = 0.0;    ///< N per m of bolt; 0 = no slip
    double normal_stiffness = 0.0; ///< N/m per m across the bolt; 0 = bond_stiffness
    double spacing = 1.0;          ///< m, out of plane
    bool face_plate = false;       ///< head tied to its rock without slip
    bool end_anchor = false;       ///< toe tied to its rock without slip
};

/// The bolts of a set as (head, toe) pairs, the ring expanded.
std::vector<std::array<Vec2, 2>> expand_bolts(const BoltSetSpec& spec);

/// Installed bolts in flat arrays (nodes, segments, bolts), part of the solver's
/// state. Properties per metre of model (divided by the out-of-plane spacing).
struct BoltState {
    struct Set {
        double ea, yield_force, rupture_strain, bond_stiffness, bond_strength, normal_stiffness, line_mass, spacing;
        std::uint8_t cable;
    };
    std::vector<Set> sets; ///< one per [[bolt]] table, in file order (whether installed or not)
    // nodes
    std::vector<Vec2> position, velocity, force;
    std::vector<Vec2> applied; ///< a load on a node, N/m (a pull-out test's jack)
    std::vector<double> mass, length, slip, bond; ///< bond: last grout force per metre along the bolt
    std::vector<BoltHost> host;
    std::vector<std::uint8_t> tied;
    std::vector<int> node_set;
    // segments: between nodes segment_node[s] and segment_node[s] + 1
    enum : std::uint8_t { elastic = 0, yielded = 1, broken = 2 };
    std::vector<int> segment_node;
    std::vector<double> rest, plastic, axial;
    std::vector<std::uint8_t> state;
    // bolts: nodes [first[b], first[b + 1])
    std::vector<int> first{0}, bolt_set;
    std::vector<std::uint8_t> installed; ///< per set

    int node_count() const { return static_cast<int>(position.size()); }
    int segment_count() const { return static_cast<int>(rest.size()); }
    int bolt_count() const { return static_cast<int>(bolt_set.size()); }
};

/// Per set, what an engineer reads: loads per bolt (N), counts.
struct BoltSetSummary {
    std::string name;
    int bolts = 0, yielded = 0, broken = 0; ///< bolts with a yielded / broken segment
    double max_axial = 0.0;                 ///< largest tension, N per bolt
    double min_axial = 0.0;                 ///< largest compression (≤ 0), N per bolt
    double max_bond = 0.0;                  ///< largest grout force, N per m of bolt per bolt
};

/// The [[bolt]] sets of a model as a support type (core/support.hpp).
class BoltSupport final : public Support {
public:
    explicit BoltSupport(const std::vector<BoltSetSpec>& specs);
    const char* name() const override { return "bolts"; }
    const std::vector<std::string>& set_names() const override { return names_; }
    bool installed(int set) const override { return state_.installed[set] != 0; }
    void install(int set, const HostFinder& find) override;
    int tie_count() const override { return state_.node_count(); }
    const BoltHost& host(int tie) const override { return state_.host[tie]; }
    void force_pass(const SupportRock& rock, Vec2* reaction, double* moment) override;
    double integrate(const SupportMotion& motion, double& work) override;
    void add_stiffness(RockStiffness& k) override;
    double time_limit() const override;
    void add_force_scale(double& terms, double& squares) const override;
    void add_applied_loads(double& sum) const override;
    void model_parameters(std::vector<double>& out) const override;
    std::vector<SupportField> fields() override;
    void after_load() override;
    std::vector<SupportSetSummary> summary() const override;
    /// One line cell per segment, cell data axial_force_kN (per bolt, tension
    /// positive), state (0 elastic, 1 yielded, 2 broken), set, bolt; point data
    /// bond_kN_per_m (grout force along the bolt, per bolt) and slip (plastic grout
    /// slip, m). Field data state_names, set_names.
    SupportLines lines() const override;

    const BoltState& state() const { return state_; }
    BoltState& state() { return state_; } ///< a study may load a node (BoltState::applied)
    /// Per installed set: loads per bolt and how many yielded or broke.
    std::vector<BoltSetSummary> set_summary() const;

private:
    BoltState state_;
    std::vector<std::string> names_;
    std::vector<BoltSetSpec> specs_;
    std::vector<double> stiffness_; ///< per node, scratch of add_stiffness()
};

} // namespace bbm
