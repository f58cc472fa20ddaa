// bbm core: dowels — fully grouted rock bolts that also resist shear and
// bending where a joint slides across them, optionally pretensioned.
//
// A dowel is a chain of beam elements (core/beam.hpp: corotational Euler–
// Bernoulli, nodes with two displacements and a rotation) of a solid steel bar:
// EA, EI = E·A²/(4π); axially N within ±F_y (plastic strain) and broken past the
// rupture strain; in bending each end moment within the bar's plastic moment
// M_p = f_y d³/6 (f_y = F_y/A, d its diameter; a hinge). Each node is tied to its
// rock by the grout as a bolt's is (core/bolts.hpp): along the bar
// q = k_bond (s − s_p), |q| ≤ q_max; across it q⊥ = k_normal w, the Winkler
// foundation the bar bends on. Where a joint slides by δ across an elastic dowel
// the bar bends over a length of order 1/β, β = (k_normal / 4EI)^¼, and carries a
// shear force k_normal δ / (4β) at the joint with its largest moment 0.32 V/β at
// π/(4β) from it (a beam on an elastic foundation: Hetényi 1946; tests/
// test_dowel.cpp).
//
// Pretension T: a dowel is tensioned against its face plate and end anchor and
// then grouted, so it starts with N = T in every element, the grout unstressed,
// and the plate and the anchor pressing the rock between them together with T
// (both are required with a pretension).
//
// Plane strain: per bolt at an out-of-plane spacing S, as bolts. The pass runs
// with the other supports', nothing is allocated per step.
#pragma once

#include "core/bolts.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm {

/// A [[dowel]] table of the model file: a [[bolt]] set's keys (no cable) and a pretension.
struct DowelSetSpec : BoltSetSpec {
    double pretension = 0.0; ///< N per bolt
};

/// Installed dowels in flat arrays, per metre of model.
struct DowelState {
    struct Set {
        double ea, ei, yield_force, moment_capacity, rupture_strain, bond_stiffness, bond_strength, normal_stiffness;
        double line_mass, line_inertia, spacing, pretension;
    };
    std::vector<Set> sets;
    // nodes
    std::vector<Vec2> position, velocity, force;
    std::vector<double> theta, omega, moment, mass, inertia, length, slip, bond, shear;
    std::vector<BoltHost> host;
    std::vector<std::uint8_t> tied;
    std::vector<int> node_set;
    // elements: between nodes element_node[e] and element_node[e] + 1
    enum : std::uint8_t { elastic = 0, yielded = 1, broken = 2 };
    std::vector<int> element_node;
    std::vector<double> rest, chord0, axial, moment_a, moment_b, plastic_strain, plastic_rotation_a, plastic_rotation_b;
    std::vector<std::uint8_t> state;
    // dowels: nodes [first[d], first[d + 1]) (empty until one is installed: a
    // model without dowels holds no dowel state)
    std::vector<int> first, dowel_set;
    std::vector<std::uint8_t> installed;

    int node_count() const { return static_cast<int>(position.size()); }
    int element_count() const { return static_cast<int>(rest.size()); }
    int dowel_count() const { return static_cast<int>(dowel_set.size()); }
};

class DowelSupport final : public Support {
public:
    explicit DowelSupport(const std::vector<DowelSetSpec>& specs);
    const char* name() const override { return "dowels"; }
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
    void model_parameters(std::vector<double>& out) const override;
    std::vector<SupportField> fields() override;
    void after_load() override;
    /// Per set: dowels, largest tension and shear force (kN per bolt), largest
    /// moment (kN·m per bolt), largest grout force along and across the bar
    /// (kN/m per bolt), elements yielded and broken.
    std::vector<SupportSetSummary> summary() const override;
    /// One line cell per element, cell data axial_force_kN, shear_force_kN,
    /// moment_kNm (the larger end moment, per bolt), state (0 elastic, 1 yielded,
    /// 2 broken), set, dowel; point data bond_kN_per_m, transverse_kN_per_m, slip.
    SupportLines lines() const override;

    const DowelState& state() const { return state_; }

private:
    DowelState state_;
    std::vector<std::string> names_;
    std::vector<DowelSetSpec> specs_;
    std::vector<double> stiffness_, rotation_stiffness_; ///< per node, scratch of add_stiffness()
};

} // namespace bbm
