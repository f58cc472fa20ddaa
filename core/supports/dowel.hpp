// bbm core: dowels — fully grouted rock bolts that also resist shear and
// bending where a joint slides across them, optionally pretensioned; a support
// type (core/supports/support.hpp) of one registry row.
//
// A dowel is a chain of beam elements (core/supports/beam.hpp: corotational Euler–
// Bernoulli, nodes with two displacements and a rotation) of a solid steel bar:
// EA, EI = E·A²/(4π); axially N within ±F_y (plastic strain) and broken past the
// rupture strain; in bending each end moment within the bar's plastic moment
// M_p = f_y d³/6 (f_y = F_y/A, d its diameter; a hinge). Each node is tied to its
// rock by the grout as a bolt's is (core/supports/bolt.hpp): along the bar
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

#include "core/supports/bolt.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm {

/// A [[dowel]] table: a bolt set's keys (core/supports/bolt.hpp) and a pretension.
using DowelSetSpec = BoltSetSpec;

struct DowelState {
    struct Set {
        double ea, ei, yield_force, moment_capacity, rupture_strain, bond_stiffness, bond_strength, normal_stiffness;
        double line_mass, line_inertia, spacing, pretension;
    };
    std::vector<Set> sets;
    std::vector<DowelSetSpec> specs;
    std::vector<std::string> names;
    SupportNodes nodes; ///< with rotations
    std::vector<double> slip, bond, shear; ///< per node: grout slip, grout force along and across the bar per metre
    std::vector<std::uint8_t> tied;
    // elements: between nodes element_node[e] and element_node[e] + 1
    enum : std::uint8_t { elastic = 0, yielded = 1, broken = 2 };
    std::vector<int> element_node;
    std::vector<double> rest, chord0, axial, moment_a, moment_b, plastic_strain, plastic_rotation_a, plastic_rotation_b;
    std::vector<std::uint8_t> state;
    // dowels: nodes [first[d], first[d + 1]) (empty until one is installed: a
    // model without dowels holds no dowel state)
    std::vector<int> first, dowel_set;
    std::vector<std::uint8_t> installed;

    int node_count() const { return nodes.count(); }
    int element_count() const { return static_cast<int>(rest.size()); }
    int dowel_count() const { return static_cast<int>(dowel_set.size()); }
};

/// Dowels: the registry's row (core/supports/support.hpp lists what each member is for).
struct Dowels {
    static constexpr std::string_view name = "dowels", table = "dowel";
    using Spec = DowelSetSpec;
    using State = DowelState;
    static constexpr const auto& keys = bolt_keys;
    /// A bolt set's table, and a pretension held by a face plate and an end anchor, below the yield force.
    static Spec read(TableReader& t);
    static State make(const std::vector<Spec>& specs);
    static const std::vector<std::string>& set_names(const State& s) { return s.names; }
    static bool installed(const State& s, int set) { return s.installed[set] != 0; }
    static void install(State& s, int set, const HostFinder& find);
    static int tie_count(const State& s) { return s.node_count(); }
    static const TieHost& host(const State& s, int tie) { return s.nodes.host[tie]; }
    static void force_pass(State& s, const SupportRock& rock, Vec2* reaction, double* moment);
    static double integrate(State& s, const SupportMotion& motion, double& work) {
        return support::integrate_nodes(s.nodes, s.sets, motion, work);
    }
    static void add_stiffness(State& s, RockStiffness& k);
    static double time_limit(const State& s) { return support::nodes_time_limit(s.nodes); }
    /// As a bolt's segments: a dowel may be all that holds a block.
    static void add_force_scale(const State& s, double& terms, double& squares);
    static void add_applied_loads(const State&, double&) {}
    static void parameters(const State& s, std::vector<double>& out);
    template <class S, class V>
    static void visit_fields(S& D, V&& v);
    static void after_load(State& s) { support::resize_node_scratch(s.nodes); }
    /// Its nodes' kinetic energy only: the elastic and plastic work of its
    /// elements and interface are not yet in the energy account (docs/theory.md §19.1).
    static double energy(const State& s, const SupportRock&) { return support::nodes_kinetic_energy(s.nodes); }
    /// Per set: dowels, largest tension and shear force (kN per bolt), largest
    /// moment (kN·m per bolt), largest grout force along and across the bar
    /// (kN/m per bolt), elements yielded and broken.
    static std::vector<SupportSetSummary> summary(const State& s);
    /// One line cell per element, cell data axial_force_kN, shear_force_kN,
    /// moment_kNm (the larger end moment, per bolt), state (0 elastic, 1 yielded,
    /// 2 broken), set, dowel; point data bond_kN_per_m, transverse_kN_per_m, slip.
    static SupportLines lines(const State& s);
    static constexpr std::array<CompareColumn, 4> compare{{{"dowels", "dowels", true},
                                                           {"max_shear_kN", "largest shear kN", false},
                                                           {"max_axial_kN", "largest tension kN", false},
                                                           {"broken_elements", "elements broken", true}}};
};

template <class S, class V>
void Dowels::visit_fields(S& D, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"dowels.installed", G::other, E}, D.installed);
    v(FieldInfo{"dowels.position", G::other, E}, D.nodes.position);
    v(FieldInfo{"dowels.velocity", G::other, E}, D.nodes.velocity);
    v(FieldInfo{"dowels.theta", G::other, E}, D.nodes.theta);
    v(FieldInfo{"dowels.omega", G::other, E}, D.nodes.omega);
    v(FieldInfo{"dowels.mass", G::other, E}, D.nodes.mass);
    v(FieldInfo{"dowels.inertia", G::other, E}, D.nodes.inertia);
    v(FieldInfo{"dowels.length", G::other, E}, D.nodes.length);
    v(FieldInfo{"dowels.slip", G::other, E}, D.slip);
    v(FieldInfo{"dowels.bond", G::other, E}, D.bond);
    v(FieldInfo{"dowels.shear", G::other, E}, D.shear);
    v(FieldInfo{"dowels.host", G::other, E}, D.nodes.host);
    v(FieldInfo{"dowels.tied", G::other, E}, D.tied);
    v(FieldInfo{"dowels.node_set", G::other, E}, D.nodes.set);
    v(FieldInfo{"dowels.element_node", G::other, E}, D.element_node);
    v(FieldInfo{"dowels.rest", G::other, E}, D.rest);
    v(FieldInfo{"dowels.chord0", G::other, E}, D.chord0);
    v(FieldInfo{"dowels.axial", G::other, E}, D.axial);
    v(FieldInfo{"dowels.moment_a", G::other, E}, D.moment_a);
    v(FieldInfo{"dowels.moment_b", G::other, E}, D.moment_b);
    v(FieldInfo{"dowels.plastic_strain", G::other, E}, D.plastic_strain);
    v(FieldInfo{"dowels.plastic_rotation_a", G::other, E}, D.plastic_rotation_a);
    v(FieldInfo{"dowels.plastic_rotation_b", G::other, E}, D.plastic_rotation_b);
    v(FieldInfo{"dowels.state", G::other, E}, D.state);
    v(FieldInfo{"dowels.first", G::other, E}, D.first);
    v(FieldInfo{"dowels.dowel_set", G::other, E}, D.dowel_set);
    v(FieldInfo{"dowels.force", G::other, R}, D.nodes.force);
    v(FieldInfo{"dowels.moment", G::other, R}, D.nodes.moment);
    v(FieldInfo{"dowels.stiffness", G::other, R}, D.nodes.stiffness);
    v(FieldInfo{"dowels.rotation_stiffness", G::other, R}, D.nodes.rotation_stiffness);
}

} // namespace bbm
