// bbm contact: one joint property set as a model file gives it (SPEC §4) — the
// law, stiffnesses, strengths and the post-peak softening points. Plain data,
// checked by the input layer; joint_law.hpp turns it into a law.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bbm {

/// One joint property set (SPEC §4). Which law is used follows `law`: the name of
/// one of contact::JointLaw's laws (contact/joint_law.hpp, the registry).
struct JointPropertySpec {
    std::string name;
    std::string law = "softening";
    double kn = 0.0;              ///< normal stiffness, Pa/m (> 0)
    double ks = 0.0;              ///< shear stiffness, Pa/m (> 0)
    /// Between a rigid block and a deformable one: the contacts of the rigid
    /// block's face share the face's mean shear slip (contact/contacts.hpp,
    /// face_slip_pass) — the interface of a bonded region with an elastic far field.
    bool face_shear = false;
    double friction = 30.0;       ///< friction angle φ, degrees
    double residual_friction = -1; ///< φr after failure, degrees; < 0 = friction
    /// A bonded joint's friction above a normal stress: above σn =
    /// `confined_friction_from` the bond's Coulomb cap rises with tan
    /// `confined_friction` instead of tan φ. Flatter than φ, the envelope bends
    /// down under confinement as rock's does (Hoek–Brown's concave curve; what
    /// `bbm calibrate --fit-curvature` fits); steeper, it is S-shaped (brittle
    /// rock's cohesion-controlled crack initiation near an opening, a strength
    /// that climbs steeply with confinement beyond it). Softening law only;
    /// broken joints keep φr. < 0 = none.
    double confined_friction = -1;           ///< φ2, degrees
    double confined_friction_from = 0.0;     ///< σ*, Pa (> 0 with confined_friction)
    double cohesion = 0.0;        ///< c, Pa (coulomb: brittle bond; softening: peak cohesion)
    /// Barton–Bandis (contact/laws/barton_bandis.hpp; `friction` is its φr): the joint
    /// roughness coefficient, the joint wall compressive strength (Pa) and the
    /// joint length (m) that sets the peak shear displacement (≤ 0: none, the
    /// strength stays at its peak).
    double jrc = 0.0;
    double jcs = 0.0;
    double joint_length = -1.0;
    double tensile = 0.0;         ///< σt, Pa
    /// Post-peak points (α, β) of the softening curves, normalised as in SPEC §4
    /// (α: displacement over the elastic displacement at peak, β: stress over peak),
    /// in increasing α, the last with β = 0. Empty = brittle (drops to 0 at once).
    std::vector<std::pair<double, double>> tension_softening;
    std::vector<std::pair<double, double>> shear_softening;
    /// Fracture energies (J/m²): the work to break a bond in pure tension and in
    /// pure shear, the areas under its curves. Given, the curve's plastic
    /// displacements are stretched (its shape kept) to dissipate that energy
    /// whatever kn, ks and the strengths are: the softening displacements are
    /// then lengths of the rock, not multiples of σt/kn, and do not shrink as
    /// calibration at a finer block size stiffens the joints (docs/theory.md §4.2).
    /// ≤ 0 = none: the curve's α are multiples of σt/kn and c/ks (SPEC §4).
    double tension_fracture_energy = -1.0;
    double shear_fracture_energy = -1.0;
    /// Heterogeneity of the strengths (grain boundaries of unequal strength, as
    /// grain-based models of granite have): with a Weibull modulus m > 0 each joint
    /// of the set gets its tensile strength and cohesion times a factor drawn from
    /// a Weibull distribution of modulus m scaled to mean 1 — discretised into
    /// `strength_classes` classes of equal probability (one derived property set
    /// each), the class picked per joint from `strength_seed` and the joint's
    /// index. Small m: very heterogeneous (m 2: a coefficient of variation of
    /// 0.52); large m: uniform (m 10: 0.12). 0 = every joint the same.
    double weibull_modulus = 0.0;
    int strength_classes = 16;
    std::uint64_t strength_seed = 1;
    /// The values of keys a law declares in its own file (a law added by the
    /// recipe keeps its parameters here, not as fields of this struct), by key.
    std::vector<std::pair<std::string, double>> values;
};

/// A law-declared value (JointPropertySpec::values), or `absent` if not given.
inline double law_value(const JointPropertySpec& j, std::string_view key, double absent) {
    for (const auto& [k, v] : j.values)
        if (k == key) return v;
    return absent;
}
inline void set_law_value(JointPropertySpec& j, std::string_view key, double v) {
    for (auto& [k, x] : j.values)
        if (k == key) {
            x = v;
            return;
        }
    j.values.emplace_back(std::string(key), v);
}

/// The strength factors of the classes of a heterogeneous set: the Weibull
/// quantiles at (k + ½)/n, k = 0..n−1, scaled to mean 1.
std::vector<double> strength_class_factors(double weibull_modulus, int classes);

} // namespace bbm
