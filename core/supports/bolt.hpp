// bbm core: rock bolts and cables — fully grouted structural elements (issue 25),
// a support type (core/supports/support.hpp) of one registry row.
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

#include "base/keys.hpp"
#include "base/table_reader.hpp"
#include "core/supports/bars.hpp"
#include "core/supports/support.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bbm {

/// A [[bolt]] table of the model file: one set of bolts with one property set
/// (a [[dowel]] table has the same keys and a pretension: core/supports/dowel.hpp).
struct BoltSetSpec {
    std::string name;
    /// Bolts given one by one: head (at the wall) and toe.
    std::vector<std::array<Vec2, 2>> bolts;
    /// Radial bolts around a circular opening (core/supports/bars.hpp).
    std::optional<BarRing> ring;
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
    double pretension = 0.0;       ///< N per bolt: a dowel's, against its plate and anchor (bolts: none)
};

/// The bolts of a set as (head, toe) pairs, the ring expanded.
std::vector<std::array<Vec2, 2>> expand_bolts(const BoltSetSpec& spec);

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[bolt]] and [[dowel]], in the order the reference lists them;
/// `only` marks the two that belong to one of them. Forces are per bolt; a set
/// acts on the 1 m thick model divided by its out-of-plane spacing.
inline constexpr Key<BoltSetSpec> bolt_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique among bolt sets, dowel sets and liners; install stages name it"},
    {.key = "bolts", .kind = KeyKind::segments, .bounds = unbounded(" m"),
     .meaning = "Each bolt's head (at the wall) and toe; head ≠ toe; with a ring or instead of it",
     .absent = "none"},
    {.key = "ring", .kind = KeyKind::table,
     .meaning = "Radial bolts around a circular opening, a table: center [x, y], radius (of the wall, > 0 m), "
                "length (> 0 m), count (≥ 1) or spacing along the wall (> 0 m), from and to (degrees "
                "counter-clockwise from +x; a full circle if absent; an arc gets bolts at both ends)",
     .absent = "none"},
    {.key = "segment_length", .bounds = above(0, " m"),
     .meaning = "Nodes along a bolt at most this far apart (fine beside the blocks it crosses)", .absent = "0.25",
     BBM_KEY_FIELD(BoltSetSpec, segment_length)},
    {.key = "young", .bounds = above(0, " Pa"), .meaning = "The steel's Young's modulus", .absent = "200e9",
     BBM_KEY_FIELD(BoltSetSpec, young)},
    {.key = "area", .bounds = above(0, " m²"), .meaning = "The steel's cross-section; not with diameter",
     .absent = "4.91e-4 (25 mm)"},
    {.key = "diameter", .bounds = above(0, " m"), .meaning = "The bar's diameter, for its area; not with area",
     .absent = "25 mm"},
    {.key = "density", .bounds = above(0, " kg/m³"), .meaning = "The steel's density (its weight; its mass in "
                                                                "dynamic mode)",
     .absent = "7850", BBM_KEY_FIELD(BoltSetSpec, density)},
    {.key = "yield_force", .bounds = above(0, " N"),
     .meaning = "Axial force at which the steel yields, in tension and compression (perfectly plastic); a dowel's "
                "plastic moment f_y d³/6 with f_y = yield_force / A",
     .absent = "elastic", BBM_KEY_FIELD(BoltSetSpec, yield_force)},
    {.key = "rupture_strain", .bounds = above(0, ""), .meaning = "A segment stretched past it breaks for good",
     .absent = "never", BBM_KEY_FIELD(BoltSetSpec, rupture_strain)},
    {.key = "cable", .kind = KeyKind::boolean, .only = "bolt", .meaning = "No compression: a cable goes slack",
     .absent = "false", BBM_KEY_FIELD(BoltSetSpec, cable)},
    {.key = "pretension", .bounds = at_least(0, " N"), .only = "dowel",
     .meaning = "Tension against the face plate and end anchor before grouting: every element starts at it, the "
                "rock between plate and anchor pressed by it; below yield_force; needs face_plate and end_anchor",
     .absent = "0", BBM_KEY_FIELD(BoltSetSpec, pretension)},
    {.key = "bond_stiffness", .bounds = above(0, " N/m per m"), .required = true,
     .meaning = "The grout's shear stiffness along the bolt, per metre of bolt", BBM_KEY_FIELD(BoltSetSpec, bond_stiffness)},
    {.key = "bond_strength", .bounds = above(0, " N/m"),
     .meaning = "The grout's shear strength along the bolt, per metre of bolt; past it the grout slips (plastic)",
     .absent = "no slip", BBM_KEY_FIELD(BoltSetSpec, bond_strength)},
    {.key = "normal_stiffness", .bounds = above(0, " N/m per m"),
     .meaning = "Stiffness across the bolt (its hole in the rock; a dowel's elastic foundation), no limit",
     .absent = "bond_stiffness", BBM_KEY_FIELD(BoltSetSpec, normal_stiffness)},
    {.key = "spacing", .bounds = above(0, " m"), .meaning = "Out of plane, between the rows of bolts", .absent = "1",
     BBM_KEY_FIELD(BoltSetSpec, spacing)},
    {.key = "face_plate", .kind = KeyKind::boolean, .meaning = "The head tied to its rock with no slip limit",
     .absent = "false", BBM_KEY_FIELD(BoltSetSpec, face_plate)},
    {.key = "end_anchor", .kind = KeyKind::boolean, .meaning = "The toe tied to its rock with no slip limit",
     .absent = "false", BBM_KEY_FIELD(BoltSetSpec, end_anchor)},
};
#pragma GCC diagnostic pop

/// docs/reference/bolt.md: the table of keys.
std::string bolt_keys_markdown();

/// A [[bolt]] (`type` "bolt") or [[dowel]] table: the keys of bolt_keys that
/// belong to it, the bars given or a ring, the steel's area or diameter; every
/// bar's nodes no farther apart than a tenth of the smallest blocks' size can
/// resolve (refused below a thousandth of it: a length in another unit).
BoltSetSpec read_bar_set(TableReader& t, std::string_view type);

/// Installed bolts in flat arrays (nodes, segments, bolts). Properties per metre
/// of model (divided by the out-of-plane spacing).
struct BoltState {
    struct Set {
        double ea, yield_force, rupture_strain, bond_stiffness, bond_strength, normal_stiffness, line_mass, spacing;
        std::uint8_t cable;
    };
    std::vector<Set> sets; ///< one per [[bolt]] table, in file order (whether installed or not)
    std::vector<BoltSetSpec> specs;
    std::vector<std::string> names;
    SupportNodes nodes;
    std::vector<Vec2> applied;           ///< per node: a load, N/m (a pull-out test's jack)
    std::vector<double> slip, bond;      ///< per node: plastic grout slip; last grout force per metre along the bolt
    std::vector<std::uint8_t> tied;      ///< per node: a face plate's or end anchor's tie (no slip)
    // segments: between nodes segment_node[s] and segment_node[s] + 1
    enum : std::uint8_t { elastic = 0, yielded = 1, broken = 2 };
    std::vector<int> segment_node;
    std::vector<double> rest, plastic, axial;
    std::vector<std::uint8_t> state;
    // bolts: nodes [first[b], first[b + 1])
    std::vector<int> first{0}, bolt_set;
    std::vector<std::uint8_t> installed; ///< per set
    /// Per set, dissipated so far: the steel's plastic work, the grout's slip, and
    /// a segment's elastic energy when it ruptures, J/m (the energy account's).
    std::vector<double> dissipated;
    /// Per node, the energy in its grout's springs across the hole at the last force pass, J/m.
    std::vector<double> across_energy;

    int node_count() const { return nodes.count(); }
    int segment_count() const { return static_cast<int>(rest.size()); }
    int bolt_count() const { return static_cast<int>(bolt_set.size()); }
};

/// Rock bolts and cables: the registry's row (core/supports/support.hpp lists
/// what each member is for).
struct Bolts {
    static constexpr std::string_view name = "bolts", table = "bolt";
    using Spec = BoltSetSpec;
    using State = BoltState;
    static constexpr const auto& keys = bolt_keys;
    /// docs/reference/bolt.md (a dowel's keys are on the same page).
    static std::string reference() { return bolt_keys_markdown(); }
    static Spec read(TableReader& t) { return read_bar_set(t, table); }
    static State make(const std::vector<Spec>& specs);
    static const std::vector<std::string>& set_names(const State& s) { return s.names; }
    static bool installed(const State& s, int set) { return s.installed[set] != 0; }
    static void install(State& s, int set, const HostFinder& find);
    static int tie_count(const State& s) { return s.node_count(); }
    static const TieHost& host(const State& s, int tie) { return s.nodes.host[tie]; }
    static void force_pass(State& s, const SupportRock& rock, Vec2* reaction, double* moment);
    static double integrate(State& s, const SupportMotion& motion, double& work) {
        return support::integrate_nodes(s.nodes, s.sets, motion, work, {&s.applied, nullptr});
    }
    static void add_stiffness(State& s, RockStiffness& k);
    static double time_limit(const State& s) { return support::nodes_time_limit(s.nodes); }
    /// A bolt may be all that holds a block: its segments' axial forces count.
    static void add_force_scale(const State& s, double& terms, double& squares);
    static void add_applied_loads(const State& s, double& sum);
    static void parameters(const State& s, std::vector<double>& out);
    template <class S, class V>
    static void visit_fields(S& B, V&& v);
    static void after_load(State& s) { support::resize_node_scratch(s.nodes); }
    /// Elastic in the segments and the grout, dissipated, the nodes' kinetic energy.
    static double energy(const State& s, const SupportRock& rock);
    /// The same for one set.
    static double set_energy(const State& s, int set);
    /// Per installed set, per bolt: bolts, max_axial_kN, max_compression_kN,
    /// max_bond_kN_per_m, yielded, broken (bolts with a yielded / broken segment);
    /// energy_kJ, the work done on the set's bolts of one row (set_energy × spacing).
    static std::vector<SupportSetSummary> summary(const State& s);
    /// One line cell per segment, cell data axial_force_kN (per bolt, tension
    /// positive), state (0 elastic, 1 yielded, 2 broken), set, bolt; point data
    /// bond_kN_per_m (grout force along the bolt, per bolt) and slip (plastic grout
    /// slip, m). Field data state_names, set_names.
    static SupportLines lines(const State& s);
    static constexpr std::array<CompareColumn, 4> compare{{{"bolts", "bolts", true},
                                                           {"max_axial_kN", "largest load kN", false},
                                                           {"yielded", "yielded", true},
                                                           {"broken", "broken", true}}};
};

template <class S, class V>
void Bolts::visit_fields(S& B, V&& v) {
    // Nodes, their ties to the rock, segments; then the step's scratch (in format A's order).
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"bolts.installed", G::other, E}, B.installed);
    v(FieldInfo{"bolts.position", G::other, E}, B.nodes.position);
    v(FieldInfo{"bolts.velocity", G::other, E}, B.nodes.velocity);
    v(FieldInfo{"bolts.applied", G::other, E}, B.applied);
    v(FieldInfo{"bolts.mass", G::other, E}, B.nodes.mass);
    v(FieldInfo{"bolts.length", G::other, E}, B.nodes.length);
    v(FieldInfo{"bolts.slip", G::other, E}, B.slip);
    v(FieldInfo{"bolts.bond", G::other, E}, B.bond);
    v(FieldInfo{"bolts.host", G::other, E}, B.nodes.host);
    v(FieldInfo{"bolts.tied", G::other, E}, B.tied);
    v(FieldInfo{"bolts.node_set", G::other, E}, B.nodes.set);
    v(FieldInfo{"bolts.segment_node", G::other, E}, B.segment_node);
    v(FieldInfo{"bolts.rest", G::other, E}, B.rest);
    v(FieldInfo{"bolts.plastic", G::other, E}, B.plastic);
    v(FieldInfo{"bolts.axial", G::other, E}, B.axial);
    v(FieldInfo{"bolts.state", G::other, E}, B.state);
    v(FieldInfo{"bolts.first", G::other, E}, B.first);
    v(FieldInfo{"bolts.bolt_set", G::other, E}, B.bolt_set);
    v(FieldInfo{"bolts.dissipated", G::other, field_use::saved}, B.dissipated);
    v(FieldInfo{"bolts.across_energy", G::other, field_use::saved}, B.across_energy);
    v(FieldInfo{"bolts.force", G::other, R}, B.nodes.force);
    v(FieldInfo{"bolts.stiffness", G::other, R}, B.nodes.stiffness);
}

} // namespace bbm
