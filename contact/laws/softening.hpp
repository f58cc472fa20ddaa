// bbm contact: the paper's bonded joint — Lemos–Sarhosis piecewise-linear
// softening in tension and shear (paper §3.3, SPEC §4), as implemented:
//   normal:  σn = −kn (un − upn)                     (total form; compression elastic)
//   shear:   τ ← τ + ks Δus                           (incremental)
//   strengths soften with plastic displacement: σt·Sn(upn), c·Ss(ups), where Sn, Ss
//   are the normalised post-peak curves written in plastic displacement, through
//   (0, 1), ((α_k − β_k)·u0, β_k) with u0 = σt/kn (tension) or c/ks (shear);
//   coupled damage D = 1 − min(Sn(upn), Ss(ups)); strengths used σt(1−D), c(1−D);
//   tension cut-off −σn ≤ σt(1−D) and Coulomb cap |τ| ≤ c(1−D) + max(σn, 0) tan φ are
//   enforced by an exact return on the piecewise-linear curves (so monotonic
//   loading passes through the curve points whatever the step size).
//   With `confined_friction` φ2 from σ* the bonded friction term is σn tan φ up
//   to σ* and σ* tan φ + (σn − σ*) tan φ2 beyond it.
//   At D = 1 the bond is broken: a crack, tensile if the tensile curve drove D to
//   1, shear otherwise; from then on Coulomb friction with φr and no tension, the
//   crack faces meeting again at their original position (upn reset to 0).
//   Unloading is elastic with the initial stiffness.
#pragma once

#include "contact/laws/bond.hpp"

#include <array>
#include <string_view>

namespace bbm::contact {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
inline constexpr JointKey key_tension_softening{
    .key = "tension_softening", .kind = KeyKind::curve,
    .meaning = "Post-peak points [[α, β], ...] of the tension curve (SPEC §4): α the displacement over the elastic "
               "displacement at peak, increasing; β the stress over the peak, the last 0",
    .absent = "brittle", .flag = true, BBM_CURVE_FIELD(JointPropertySpec, tension_softening)};
inline constexpr JointKey key_shear_softening{.key = "shear_softening", .kind = KeyKind::curve,
                                              .meaning = "The same for the shear curve", .absent = "brittle",
                                              .flag = true, BBM_CURVE_FIELD(JointPropertySpec, shear_softening)};
inline constexpr JointKey key_tension_fracture_energy{
    .key = "tension_fracture_energy", .bounds = above(0, joules_per_square_metre),
    .meaning = "The energy G_I to break a bond in tension, the area under its tension curve: the curve's plastic "
               "displacements are stretched, its shape kept, to dissipate it whatever kn and σt are (softening "
               "lengths held as block size and calibration change kn); needs tension_softening",
    .absent = "none: the curve's α are multiples of σt/kn", BBM_JOINT_FIELD(tension_fracture_energy), .flag = true};
inline constexpr JointKey key_shear_fracture_energy{
    .key = "shear_fracture_energy", .bounds = above(0, joules_per_square_metre),
    .meaning = "The same in shear, G_II, at zero normal stress; needs shear_softening",
    .absent = "none: the curve's α are multiples of c/ks", BBM_JOINT_FIELD(shear_fracture_energy), .flag = true};
inline constexpr JointKey key_confined_friction{
    .key = "confined_friction", .bounds = below(0, 90, degrees),
    .meaning = "A bond's friction angle φ2 above the normal stress confined_friction_from (below friction: an "
               "envelope flattening as rock's; above it: an S-shaped one); with confined_friction_from",
    .absent = "none", BBM_JOINT_FIELD(confined_friction), .flag = true};
inline constexpr JointKey key_confined_friction_from{.key = "confined_friction_from", .bounds = above(0, pascals),
                                                     .meaning = "The normal stress σ* above which confined_friction acts",
                                                     .absent = "none", BBM_JOINT_FIELD(confined_friction_from),
                                                     .flag = true};
#pragma GCC diagnostic pop

struct SofteningLaw {
    static constexpr std::string_view name = "softening";
    static constexpr std::array<const JointKey*, 18> keys{
        &key_name, &key_law, &key_kn, &key_ks, &key_face_shear, &key_friction, &key_residual_friction,
        &key_cohesion, &key_tensile, &key_weibull_modulus, &key_strength_classes, &key_strength_seed,
        &key_tension_softening, &key_shear_softening, &key_tension_fracture_energy, &key_shear_fracture_energy,
        &key_confined_friction, &key_confined_friction_from};
    /// Its peaks (cohesion, tensile) > 0, a fracture energy with its curve,
    /// confined_friction and confined_friction_from together; the bond's rules.
    static std::optional<KeyProblem> check(const JointPropertySpec& j);
    double kn, ks, tan_phi, tan_phi_r, cohesion, tensile;
    BondFriction friction; ///< the bonded cap's frictional term, confined friction included
    SofteningCurve tension, shear;
    explicit SofteningLaw(const JointPropertySpec& p);
    bool starts_bonded() const { return true; }
    double elastic_limit(const JointHistory& before, const JointHistory& trial, double cap) const {
        return bond_elastic_limit(tensile, cohesion, friction, before, trial, cap);
    }
    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        if (h.bonded && h.upn == 0.0 && h.ups == 0.0 && // never softened
            intact_elastic_update(h, kn, ks, tensile, cohesion, friction, dus))
            return;
        update_inelastic(h, dus);
    }
    /// Softening, failure or friction; un, us already incremented.
    void update_inelastic(JointHistory& h, double dus) const;
};

} // namespace bbm::contact
