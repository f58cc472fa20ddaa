// bbm core: liners — shotcrete or concrete lining along an opening (issue 25), a
// support type (core/supports/support.hpp) of one registry row.
//
// A liner is a chain of beam elements (Euler–Bernoulli, corotational) along the
// wall of a circular opening: nodes with two displacements and a rotation, each
// element carrying a thrust N = E'A (l − l0)/l0 and end moments
//   M1 = (E'I/l0)(4θ1 + 2θ2),  M2 = (E'I/l0)(2θ1 + 4θ2),
// θi the node rotations less the chord's rigid rotation, E' = E/(1 − ν²) (the
// lining is continuous along the tunnel: plane strain), A = t and I = t³/12 per
// metre. Each node is tied to the rock it touches by interface springs along the
// wall's normal n (towards the rock) and tangent t, per metre of liner:
//   normal:  σ = k_n d_n  (d_n > 0 opens the gap), bonded up to the tensile
//            strength, then separated for good: σ = min(k_n d_n, 0);
//   shear:   τ = k_s (d_s − d_sp),  |τ| ≤ c + tan φ · max(−σ, 0)  (c = 0 once
//            separated), plastic slip d_sp;
// with d = x_rock − x_node since installation. The node gets L (σ n + τ t),
// the rock the opposite (as bolts: core/supports/bolt.hpp). A liner whose ends lie on
// symmetry planes (a half or quarter model) holds the ends' displacement along
// the liner and their rotation. Optionally the lining yields, perfectly plastic:
// the thrust within [−tension capacity, thrust capacity] (plastic strain) and each
// end moment within ± the moment capacity (plastic rotations), independently (no
// interaction diagram).
//
// The liner pass runs with the bolt pass (one thread beside the contact
// batches); nodes are integrated with the blocks' damping and, quasi-static,
// masses scaled to their stiffness. Nothing is allocated per step.
#pragma once

#include "base/keys.hpp"
#include "base/table_reader.hpp"
#include "core/supports/support.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace bbm {

struct LinerSpec {
    std::string name;
    Vec2 center{};                 ///< of the circular opening
    double radius = 0.0;           ///< m, of the wall (the liner's line)
    double from = 0.0, to = 360.0; ///< degrees counter-clockwise from +x
    double segment_length = 0.2;   ///< m: elements at most this long
    double young = 30e9;           ///< Pa (shotcrete, concrete)
    double poisson = 0.2;
    double thickness = 0.1;        ///< m
    double density = 2400.0;       ///< kg/m³
    /// Yield of the lining (perfectly plastic, thrust and moment independently; 0 = elastic).
    double thrust_capacity = 0.0;  ///< N/m in compression (σc t)
    double tension_capacity = 0.0; ///< N/m in tension (σt t); 0 with a thrust capacity = none
    double moment_capacity = 0.0;  ///< N·m/m (σc t²/6 at first yield, /4 fully plastic)
    // The interface with the rock, as a joint: stresses on the wall.
    double normal_stiffness = 0.0; ///< Pa/m; 0 = 10 × the liner's ring stiffness E't/R²
    double shear_stiffness = 0.0;  ///< Pa/m; 0 = the normal stiffness
    double tensile_strength = 0.0; ///< Pa the bond holds in tension; 0 = none (separates at once)
    double cohesion = 0.0;         ///< Pa, interface shear
    double friction = 35.0;        ///< degrees, interface shear
    bool symmetric_ends = false;   ///< ends on symmetry planes
};

/// Installed liners in flat arrays, part of the solver's state.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[liner]], in the order the reference lists them. Per metre of
/// tunnel (plane strain).
inline constexpr Key<LinerSpec> liner_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique among the support sets; install stages name it"},
    {.key = "center", .kind = KeyKind::point, .bounds = unbounded(" m"), .required = true,
     .meaning = "The opening's center"},
    {.key = "radius", .bounds = above(0, " m"), .required = true,
     .meaning = "The wall's radius: the liner's line (each node must touch rock within half an element)",
     BBM_KEY_FIELD(LinerSpec, radius)},
    {.key = "from", .bounds = unbounded(" degrees"), .meaning = "Where the liner starts, counter-clockwise from +x",
     .absent = "0", BBM_KEY_FIELD(LinerSpec, from)},
    {.key = "to", .bounds = unbounded(" degrees"),
     .meaning = "Where it ends: above from by at most 360 (360: a closed ring)", .absent = "from + 360"},
    {.key = "segment_length", .bounds = above(0, " m"), .meaning = "Elements at most this long", .absent = "0.2",
     BBM_KEY_FIELD(LinerSpec, segment_length)},
    {.key = "young", .bounds = above(0, " Pa"), .meaning = "The lining's Young's modulus; E' = E / (1 − ν²)",
     .absent = "30e9", BBM_KEY_FIELD(LinerSpec, young)},
    {.key = "poisson", .bounds = below(0, 0.5, ""), .meaning = "The lining's Poisson's ratio", .absent = "0.2",
     BBM_KEY_FIELD(LinerSpec, poisson)},
    {.key = "thickness", .bounds = above(0, " m"), .required = true, .meaning = "A = t, I = t³/12 per metre",
     BBM_KEY_FIELD(LinerSpec, thickness)},
    {.key = "density", .bounds = above(0, " kg/m³"), .meaning = "The lining's density", .absent = "2400",
     BBM_KEY_FIELD(LinerSpec, density)},
    {.key = "normal_stiffness", .bounds = above(0, " Pa/m"),
     .meaning = "The interface's stiffness across the wall", .absent = "10 E't/R²",
     BBM_KEY_FIELD(LinerSpec, normal_stiffness)},
    {.key = "shear_stiffness", .bounds = above(0, " Pa/m"), .meaning = "The interface's stiffness along the wall",
     .absent = "normal_stiffness", BBM_KEY_FIELD(LinerSpec, shear_stiffness)},
    {.key = "tensile_strength", .bounds = above(0, " Pa"),
     .meaning = "The interface's bond in tension; once exceeded it separates for good", .absent = "no tension",
     BBM_KEY_FIELD(LinerSpec, tensile_strength)},
    {.key = "cohesion", .bounds = at_least(0, " Pa"),
     .meaning = "The interface's shear strength c + σ tan φ (c lost once separated)", .absent = "0",
     BBM_KEY_FIELD(LinerSpec, cohesion)},
    {.key = "friction", .bounds = below(0, 90, " degrees"), .meaning = "The interface's friction angle φ",
     .absent = "35", BBM_KEY_FIELD(LinerSpec, friction)},
    {.key = "symmetric_ends", .kind = KeyKind::boolean,
     .meaning = "The ends lie on symmetry planes (a half or quarter model): their displacement along the liner and "
                "their rotation are held; not for a closed ring",
     .absent = "false", BBM_KEY_FIELD(LinerSpec, symmetric_ends)},
    {.key = "thrust_capacity", .bounds = above(0, " N/m"),
     .meaning = "The thrust at which the lining yields in compression (σc t), perfectly plastic", .absent = "elastic",
     BBM_KEY_FIELD(LinerSpec, thrust_capacity)},
    {.key = "tension_capacity", .bounds = above(0, " N/m"),
     .meaning = "Yield in tension (σt t); needs a thrust capacity", .absent = "none",
     BBM_KEY_FIELD(LinerSpec, tension_capacity)},
    {.key = "moment_capacity", .bounds = above(0, " N·m/m"),
     .meaning = "Yield in bending at each end of an element (σc t²/6 at first yield, /4 fully plastic); "
                "independent of the thrust (no interaction diagram)",
     .absent = "elastic", BBM_KEY_FIELD(LinerSpec, moment_capacity)},
};
#pragma GCC diagnostic pop


/// docs/reference/liner.md: the table of keys.
std::string liner_keys_markdown();

struct LinerState {
    struct Set {
        double ea, ei, line_mass, line_inertia, kn, ks, tensile, cohesion, tan_friction;
        double thrust_capacity, tension_capacity, moment_capacity;
        std::uint8_t symmetric_ends;
    };
    std::vector<Set> sets; ///< one per [[liner]] table, in file order
    std::vector<LinerSpec> specs;
    std::vector<std::string> names;
    SupportNodes nodes; ///< with rotations
    std::vector<double> shear_slip;
    std::vector<std::uint8_t> separated; ///< the interface's tensile bond is gone
    std::vector<double> normal_stress;   ///< last interface normal stress, Pa (> 0 tension)
    std::vector<Vec2> held;              ///< an end on a symmetry plane: the direction held (else zero)
    // elements: between nodes element_node[e] and the next node of its liner
    std::vector<int> element_node;
    std::vector<double> rest, chord0, thrust, moment_a, moment_b; ///< thrust > 0 compression
    std::vector<double> plastic_strain, plastic_rotation_a, plastic_rotation_b;
    std::vector<std::uint8_t> yielded; ///< bit 0 in thrust or tension, bit 1 in bending
    // liners: nodes [first[l], first[l + 1])
    std::vector<int> first{0}, liner_set;
    std::vector<std::uint8_t> closed; ///< per liner: a full ring (its last node joins its first)
    std::vector<std::uint8_t> installed; ///< per set

    int node_count() const { return nodes.count(); }
    int element_count() const { return static_cast<int>(rest.size()); }
};

/// Liners: the registry's row (core/supports/support.hpp lists what each member is for).
struct Liners {
    static constexpr std::string_view name = "liners", table = "liner";
    using Spec = LinerSpec;
    using State = LinerState;
    static constexpr const auto& keys = liner_keys;
    /// docs/reference/liner.md.
    static std::string reference() { return liner_keys_markdown(); }
    static Spec read(TableReader& t);
    static State make(const std::vector<Spec>& specs);
    static const std::vector<std::string>& set_names(const State& s) { return s.names; }
    static bool installed(const State& s, int set) { return s.installed[set] != 0; }
    static void install(State& s, int set, const HostFinder& find);
    static int tie_count(const State& s) { return s.node_count(); }
    static const TieHost& host(const State& s, int tie) { return s.nodes.host[tie]; }
    static void force_pass(State& s, const SupportRock& rock, Vec2* reaction, double* moment);
    static double integrate(State& s, const SupportMotion& motion, double& work) {
        return support::integrate_nodes(s.nodes, s.sets, motion, work, {nullptr, &s.held});
    }
    static void add_stiffness(State& s, RockStiffness& k);
    static double time_limit(const State& s) { return support::nodes_time_limit(s.nodes); }
    static void add_force_scale(const State&, double&, double&) {}
    static void add_applied_loads(const State&, double&) {}
    static void parameters(const State& s, std::vector<double>& out);
    template <class S, class V>
    static void visit_fields(S& L, V&& v);
    static void after_load(State& s) { support::resize_node_scratch(s.nodes); }
    /// Its nodes' kinetic energy only: the elastic and plastic work of its
    /// elements and interface are not yet in the energy account (docs/theory.md §19.1).
    static double energy(const State& s, const SupportRock&) { return support::nodes_kinetic_energy(s.nodes); }
    /// Per installed liner: nodes, max_thrust_kN_per_m, min_thrust_kN_per_m,
    /// max_moment_kNm_per_m, open_interface_nodes, elements, yielded_elements.
    static std::vector<SupportSetSummary> summary(const State& s);
    /// One line cell per beam element, cell data thrust_kN_per_m (compression
    /// positive), moment_kNm_per_m (the larger end moment by magnitude, with its
    /// sign), liner, yielded (bit 0 thrust, bit 1 bending); point data
    /// interface_normal_MPa (tension positive), interface_open. Field data liner_names.
    static SupportLines lines(const State& s);
    static constexpr std::array<CompareColumn, 3> compare{{{"max_thrust_kN_per_m", "thrust kN/m", false},
                                                           {"max_moment_kNm_per_m", "moment kNm/m", false},
                                                           {"yielded_elements", "elements yielded", true}}};
};

template <class S, class V>
void Liners::visit_fields(S& L, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"liners.installed", G::other, E}, L.installed);
    v(FieldInfo{"liners.position", G::other, E}, L.nodes.position);
    v(FieldInfo{"liners.velocity", G::other, E}, L.nodes.velocity);
    v(FieldInfo{"liners.theta", G::other, E}, L.nodes.theta);
    v(FieldInfo{"liners.omega", G::other, E}, L.nodes.omega);
    v(FieldInfo{"liners.mass", G::other, E}, L.nodes.mass);
    v(FieldInfo{"liners.inertia", G::other, E}, L.nodes.inertia);
    v(FieldInfo{"liners.length", G::other, E}, L.nodes.length);
    v(FieldInfo{"liners.shear_slip", G::other, E}, L.shear_slip);
    v(FieldInfo{"liners.host", G::other, E}, L.nodes.host);
    v(FieldInfo{"liners.separated", G::other, E}, L.separated);
    v(FieldInfo{"liners.normal_stress", G::other, E}, L.normal_stress);
    v(FieldInfo{"liners.node_set", G::other, E}, L.nodes.set);
    v(FieldInfo{"liners.held", G::other, E}, L.held);
    v(FieldInfo{"liners.element_node", G::other, E}, L.element_node);
    v(FieldInfo{"liners.rest", G::other, E}, L.rest);
    v(FieldInfo{"liners.chord0", G::other, E}, L.chord0);
    v(FieldInfo{"liners.thrust", G::other, E}, L.thrust);
    v(FieldInfo{"liners.moment_a", G::other, E}, L.moment_a);
    v(FieldInfo{"liners.moment_b", G::other, E}, L.moment_b);
    v(FieldInfo{"liners.plastic_strain", G::other, E}, L.plastic_strain);
    v(FieldInfo{"liners.plastic_rotation_a", G::other, E}, L.plastic_rotation_a);
    v(FieldInfo{"liners.plastic_rotation_b", G::other, E}, L.plastic_rotation_b);
    v(FieldInfo{"liners.yielded", G::other, E}, L.yielded);
    v(FieldInfo{"liners.first", G::other, E}, L.first);
    v(FieldInfo{"liners.liner_set", G::other, E}, L.liner_set);
    v(FieldInfo{"liners.closed", G::other, E}, L.closed);
    v(FieldInfo{"liners.force", G::other, R}, L.nodes.force);
    v(FieldInfo{"liners.moment", G::other, R}, L.nodes.moment);
    v(FieldInfo{"liners.stiffness", G::other, R}, L.nodes.stiffness);
    v(FieldInfo{"liners.rotation_stiffness", G::other, R}, L.nodes.rotation_stiffness);
}

} // namespace bbm
