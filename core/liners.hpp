// bbm core: liners — shotcrete or concrete lining along an opening (issue 25).
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
// the rock the opposite (as bolts: core/bolts.hpp). A liner whose ends lie on
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

#include "core/bolts.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm {

/// A [[liner]] table of the model file.
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
struct LinerState {
    struct Set {
        double ea, ei, line_mass, line_inertia, kn, ks, tensile, cohesion, tan_friction;
        double thrust_capacity, tension_capacity, moment_capacity;
        std::uint8_t symmetric_ends;
    };
    std::vector<Set> sets; ///< one per [[liner]] table, in file order
    // nodes
    std::vector<Vec2> position, velocity, force;
    std::vector<double> theta, omega, moment, mass, inertia, length, shear_slip;
    std::vector<BoltHost> host;
    std::vector<std::uint8_t> separated; ///< the interface's tensile bond is gone
    std::vector<double> normal_stress;   ///< last interface normal stress, Pa (> 0 tension)
    std::vector<int> node_set;
    std::vector<Vec2> held;               ///< an end on a symmetry plane: the direction held (else zero)
    // elements: between nodes element_node[e] and element_node[e] + 1
    std::vector<int> element_node;
    std::vector<double> rest, chord0, thrust, moment_a, moment_b; ///< thrust > 0 compression
    std::vector<double> plastic_strain, plastic_rotation_a, plastic_rotation_b;
    std::vector<std::uint8_t> yielded; ///< bit 0 in thrust or tension, bit 1 in bending
    // liners: nodes [first[l], first[l + 1])
    std::vector<int> first{0}, liner_set;
    std::vector<std::uint8_t> closed; ///< per liner: a full ring (its last node joins its first)
    std::vector<std::uint8_t> installed; ///< per set

    int node_count() const { return static_cast<int>(position.size()); }
    int element_count() const { return static_cast<int>(rest.size()); }
};

/// Per installed set: thrust (compression positive) and moment extremes, N/m and N·m/m.
struct LinerSetSummary {
    std::string name;
    double max_thrust = 0.0, min_thrust = 0.0, max_moment = 0.0;
    int nodes = 0;
    int open = 0; ///< nodes whose interface gap is open now (bond broken, no contact)
    int yielded = 0; ///< elements that have yielded (thrust or moment)
    int elements = 0;
};

/// The [[liner]]s of a model as a support type (core/support.hpp).
class LinerSupport final : public Support {
public:
    explicit LinerSupport(const std::vector<LinerSpec>& specs);
    const char* name() const override { return "liners"; }
    const std::vector<std::string>& set_names() const override { return names_; }
    bool installed(int set) const override { return state_.installed[set] != 0; }
    void install(int set, const HostFinder& find) override;
    int tie_count() const override { return state_.node_count(); }
    const BoltHost& host(int tie) const override { return state_.host[tie]; }
    void force_pass(const SupportRock& rock, Vec2* reaction, double* moment) override;
    double integrate(const SupportMotion& motion, double& work) override;
    void add_stiffness(RockStiffness& k) override;
    double time_limit() const override;
    void model_parameters(std::vector<double>& out) const override;
    std::vector<SupportField> fields() override;
    void after_load() override;
    std::vector<SupportSetSummary> summary() const override;
    /// One line cell per beam element, cell data thrust_kN_per_m (compression
    /// positive), moment_kNm_per_m (the larger end moment by magnitude, with its
    /// sign), liner, yielded (bit 0 thrust, bit 1 bending); point data
    /// interface_normal_MPa (tension positive), interface_open. Field data liner_names.
    SupportLines lines() const override;

    const LinerState& state() const { return state_; }
    /// Per installed liner: thrust and moment extremes, separated interface nodes.
    std::vector<LinerSetSummary> set_summary() const;

private:
    LinerState state_;
    std::vector<std::string> names_;
    std::vector<LinerSpec> specs_;
    std::vector<double> stiffness_, rotation_stiffness_; ///< per node, scratch of add_stiffness()
};

} // namespace bbm
