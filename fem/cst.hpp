// bbm fem: constant-strain triangles for deformable blocks (SPEC §5 stage 3, §6).
//
// A zone is a linear triangle with nodes (x0, x1, x2), counter-clockwise. Its shape
// functions have constant gradients ∇N_i = (b_i, c_i) / (2A) with
//   b_i = y_j − y_k,  c_i = x_k − x_j   (i, j, k cyclic),
// so the velocity gradient L = Σ v_i ⊗ ∇N_i is constant over the zone.
//
// Explicit update (small strain on the current configuration, as in FLAC/UDEC
// deformable blocks, so large rigid motions stay stress-free):
//   Δε  = sym(L) Δt,   ω = ½ (∂v_y/∂x − ∂v_x/∂y) Δt   (the spin of the step)
//   σ  ← σ + (W σ − σ W) + D Δε      (Jaumann rotation, then plane-strain Hooke)
// with D plane strain: σxx = (λ+2G) εxx + λ εyy, σyy = λ εxx + (λ+2G) εyy,
// σxy = 2G εxy (εxy the tensor shear strain). Internal nodal forces from the zone
// stress on the current geometry: f_i = −A σ ∇N_i.
//
// The same gradients give the linear element stiffness K_e = A Bᵀ D B used by the
// implicit solve and by mass scaling. Stress is tension positive (SPEC §2).
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace bbm::fem {

/// Plane-strain isotropic elasticity as Lamé constants.
struct Elasticity {
    double lambda = 0.0, shear = 0.0;
    static Elasticity from_young(double young, double poisson) {
        return {young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)), young / (2.0 * (1.0 + poisson))};
    }
    /// P-wave modulus λ + 2G (plane strain constrained modulus).
    double p_modulus() const { return lambda + 2.0 * shear; }
};

/// Area and shape-function gradient numerators of a triangle: ∂N_i/∂x = b[i]/(2A),
/// ∂N_i/∂y = c[i]/(2A).
struct TriangleGradients {
    double area = 0.0;
    std::array<double, 3> b{}, c{};
};

inline TriangleGradients gradients(Vec2 x0, Vec2 x1, Vec2 x2) {
    TriangleGradients g;
    g.area = 0.5 * cross(x1 - x0, x2 - x0);
    g.b = {x1.y - x2.y, x2.y - x0.y, x0.y - x1.y};
    g.c = {x2.x - x1.x, x0.x - x2.x, x1.x - x0.x};
    return g;
}

/// 6×6 element stiffness (row-major, DOF order x0 y0 x1 y1 x2 y2).
std::array<double, 36> element_stiffness(const TriangleGradients& g, const Elasticity& e);

/// Zones of all deformable blocks, flat.
struct Zones {
    std::vector<std::array<int, 3>> node;
    std::vector<Elasticity> elasticity;
    std::vector<std::array<double, 3>> stress; ///< σxx, σyy, σxy, Pa, tension positive
    std::vector<std::array<double, 3>> strain; ///< εxx, εyy, εxy (tensor shear), accumulated
    std::vector<int> block;
    std::vector<double> density;
    int size() const { return static_cast<int>(node.size()); }

    // Derived by index_zone_nodes() once the zones are complete.
    /// Per node, its zone corners (entry 3·zone + corner) in zone order (CSR).
    std::vector<int> node_first, node_entry;
    static constexpr int work_item_size = 256; ///< zones per partial sum of Σ|f|²
    // Per-step scratch of zone_pass.
    std::vector<std::array<Vec2, 3>> nodal_force;
    std::vector<double> partial_sum;
    std::vector<double> partial_damped; ///< per work item: Rayleigh's stiffness part's work this step, J/m
};
static_assert(sizeof(Elasticity) == 2 * sizeof(double)); // in the model fingerprint as raw bytes
} // namespace bbm::fem
template <>
struct bbm::ElementTraits<bbm::fem::Elasticity> : bbm::PackedRecordTraits<bbm::fem::Elasticity> {};
namespace bbm::fem {

/// Its fields (base/fields.hpp): stresses and strains evolve, the elasticity is
/// the model's, the rest is rebuilt.
template <part_of<Zones> Z, class Visit>
void visit_fields(Z& z, Visit&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"zones.stress", G::zones, E}, z.stress);
    v(FieldInfo{"zones.strain", G::zones, E}, z.strain);
    v(FieldInfo{"zones.elasticity", G::zones, M}, z.elasticity);
    v(FieldInfo{"zones.node", G::zones, R}, z.node);
    v(FieldInfo{"zones.block", G::zones, R}, z.block);
    v(FieldInfo{"zones.density", G::zones, R}, z.density);
    v(FieldInfo{"zones.node_first", G::nodes, R}, z.node_first);
    v(FieldInfo{"zones.node_entry", G::zones, R}, z.node_entry);
    v(FieldInfo{"zones.nodal_force", G::zones, R}, z.nodal_force);
    v(FieldInfo{"zones.partial_sum", G::zones, R}, z.partial_sum);
    v(FieldInfo{"zones.partial_damped", G::zones, R}, z.partial_damped);
}

/// Builds the per-node index and sizes the scratch; `nodes` = number of FE nodes.
void index_zone_nodes(Zones& z, int nodes);

/// Stage 3 of a step, first pass: zone stresses from the node velocities of the
/// step, and each zone's nodal forces into `z.nodal_force`, for the work items
/// [first_item, last_item) (zone_items(z): Zones::work_item_size zones each, one
/// partial sum of Σ|f|² each). Who computes an item does not change its result:
/// a team shares the items and meets at a barrier before gathering with
/// node_zone_force(). Zones of removed blocks are skipped (`skip[block]`
/// non-zero) and contribute nothing. Needs index_zone_nodes(). `stiffness_damping`
/// β > 0 adds Rayleigh's stiffness-proportional viscous stress β D ε̇ to the
/// nodal forces (not to the stored stress).
void zone_pass(Zones& z, const Vec2* position, const Vec2* velocity, double dt, const std::uint8_t* skip,
               int first_item, int last_item, double stiffness_damping = 0.0);
inline int zone_items(const Zones& z) { return static_cast<int>(z.partial_sum.size()); }

/// Second pass, per node: the forces of its zones in zone order (the same sum on
/// any number of threads).
inline Vec2 node_zone_force(const Zones& z, int node) {
    Vec2 f{};
    for (int e = z.node_first[node]; e < z.node_first[node + 1]; ++e) {
        const int entry = z.node_entry[e];
        f += z.nodal_force[entry / 3][entry % 3];
    }
    return f;
}

/// Σ|f|² of the nodal forces of the last pass (the force scale of the
/// unbalanced-force ratio), per fixed group of zones, then over the groups in order.
double zone_force_squares(const Zones& z);

} // namespace bbm::fem
