// bbm contact: what the joint laws share — the keys more than one law reads
// (declared once here; a law's own keys are in its file), and the pieces of a
// bonded joint: the frictional part of its Coulomb cap, its post-peak softening
// curves, the elastic step of an intact bond and the frictional update of a
// broken one (SPEC §4).
//
// A key's declaration (base/keys.hpp) carries its kind, unit and bounds, meaning
// and default, the field of JointPropertySpec it fills, and whether a lab test's
// rock takes it as a flag (`flag`): the model file's reader, the command-line
// flags, the Python keywords and docs/reference/joint_property.md are made from
// the declarations the laws list (contact/joint_law.hpp gathers them).
#pragma once

#include "base/keys.hpp"
#include "contact/joint_history.hpp"
#include "contact/joint_property.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bbm::contact {

using JointKey = Key<JointPropertySpec>;
using bbm::KeyKind;

/// A set's values that break a rule between its keys: the key to blame and what
/// is wrong (the reader names the key's line, the flags its flag).
struct KeyProblem {
    std::string_view key;
    std::string message;
};

#define BBM_JOINT_FIELD(field) BBM_KEY_FIELD(JointPropertySpec, field)
// Each row names only the members it sets; the rest keep their defaults.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every set's keys.
inline constexpr JointKey key_name{.key = "name", .kind = KeyKind::text, .required = true,
                                   .meaning = "The set's name, referred to by [[joint_assignment]]"};
inline constexpr JointKey key_law{.key = "law", .kind = KeyKind::choice, .required = true,
                                  .meaning = "The joint law (the laws of contact/joint_law.hpp; the table's last "
                                             "column: which law reads each key)"};
inline constexpr JointKey key_kn{.key = "kn", .bounds = above(0, pascals_per_metre), .required = true,
                                 .meaning = "Normal stiffness", BBM_JOINT_FIELD(kn), .flag = true};
inline constexpr JointKey key_ks{.key = "ks", .bounds = above(0, pascals_per_metre), .required = true,
                                 .meaning = "Shear stiffness", BBM_JOINT_FIELD(ks), .flag = true};
inline constexpr JointKey key_face_shear{
    .key = "face_shear", .kind = KeyKind::boolean,
    .meaning = "Between a rigid block and a deformable one: the contacts of a rigid face share its mean shear slip "
               "(the interface of a bonded region with an elastic far field)",
    .absent = "false", BBM_JOINT_FIELD(face_shear)};
/// The friction of every law that has one.
inline constexpr JointKey key_friction{.key = "friction", .bounds = below(0, 90, degrees),
                                       .meaning = "Friction angle φ (Barton-Bandis: the residual friction φr; cwfs: "
                                                  "the friction mobilised at the start)",
                                       .absent = "30", BBM_JOINT_FIELD(friction), .flag = true};
/// A bond's keys (the bonded laws': a strength to break, then friction).
inline constexpr JointKey key_residual_friction{.key = "residual_friction", .bounds = below(0, 90, degrees),
                                                .meaning = "Friction angle φr once the bond has failed",
                                                .absent = "friction", BBM_JOINT_FIELD(residual_friction), .flag = true};
inline constexpr JointKey key_cohesion{.key = "cohesion", .bounds = at_least(0, pascals),
                                       .meaning = "Cohesion c (softening: the peak, > 0, the shear curve is normalised by)",
                                       .absent = "0 (coulomb)", BBM_JOINT_FIELD(cohesion), .flag = true};
inline constexpr JointKey key_tensile{.key = "tensile", .bounds = at_least(0, pascals),
                                      .meaning = "Tensile strength σt (softening: the peak, > 0, the tension curve is "
                                                 "normalised by)",
                                      .absent = "0 (coulomb)", BBM_JOINT_FIELD(tensile), .flag = true};
inline constexpr JointKey key_weibull_modulus{
    .key = "weibull_modulus", .bounds = at_least(0, ""),
    .meaning = "Heterogeneous bonds: each joint's tensile strength and cohesion times a Weibull factor of this "
               "modulus and mean 1 (2: very heterogeneous, 10: nearly uniform); needs a bond",
    .absent = "0, every joint the same", BBM_JOINT_FIELD(weibull_modulus), .flag = true};
inline constexpr JointKey key_strength_classes{
    .key = "strength_classes", .kind = KeyKind::integer, .bounds = between(1, 1000, ""),
    .meaning = "Heterogeneous bonds: the classes of equal probability the Weibull law is discretised into",
    .absent = "16", BBM_JOINT_FIELD(strength_classes), .flag = true};
inline constexpr JointKey key_strength_seed{.key = "strength_seed", .kind = KeyKind::integer,
                                            .bounds = between(0, 9007199254740992.0, ""),
                                            .meaning = "Heterogeneous bonds: the seed of the classes' draw",
                                            .absent = "1", BBM_JOINT_FIELD(strength_seed)};
#pragma GCC diagnostic pop

/// The rules of a bond's keys: a Weibull modulus needs a bond (cohesion or
/// tensile > 0); strength_classes and strength_seed go with it (`given`: the key
/// was set, the reader's or the flags' knowledge).
std::optional<KeyProblem> check_bond_keys(const JointPropertySpec& j);

/// Piecewise-linear normalised strength S(up) over plastic displacement up:
/// S(0) = 1, linear between breakpoints, 0 beyond the last. No breakpoint after 0
/// = brittle (S = 0 for any up > 0).
class SofteningCurve {
public:
    SofteningCurve() = default;
    /// points (α, β) as in SPEC §4, u0 the elastic displacement at peak. With a
    /// fracture energy (> 0, J/m²) the plastic displacements are stretched so the
    /// area under peak·S(up) is that energy; `peak` is then the strength.
    SofteningCurve(const std::vector<std::pair<double, double>>& points, double u0, double peak = 0.0,
                   double fracture_energy = -1.0);
    /// The area under S over up / u0 of the normalised points: the fracture energy
    /// over peak·u0 (1.6 for the paper's tension curve, 0.925 for its shear curve).
    static double normalised_energy(const std::vector<std::pair<double, double>>& points);
    double operator()(double up) const;
    /// Smallest δ >= 0 with  excess − k δ <= peak·min(S(up + δ), other)  (the
    /// return of a trial stress `excess` above the cap, stiffness k). `other` is
    /// the normalised strength of the other mode (coupled damage), `extra` a
    /// constant added to the cap (the frictional part of the shear cap).
    double plastic_increment(double excess, double k, double peak, double up, double other,
                             double extra) const;
    bool brittle() const { return up_.size() <= 1; }

private:
    std::vector<double> up_{0.0}; ///< breakpoints in plastic displacement
    std::vector<double> s_{1.0};  ///< normalised strength at them
};

/// The frictional part of a bonded joint's Coulomb cap at normal stress σn
/// (compression positive): σn tan φ, steepening to tan φ2 above σ* when the set
/// has a confined friction (the softening law's). Without one σ* is +∞ and the
/// second term 0.
struct BondFriction {
    double tan_phi = 0.0;
    double from = INFINITY;  ///< σ*
    double extra_tan = 0.0;  ///< tan φ2 − tan φ
    /// min(tan φ, tan φ2): max(σn, 0) times it is a lower bound of the term, the
    /// elastic path's first test (one multiply, as without a confined friction).
    double tan_lower = 0.0;
    BondFriction() = default;
    explicit BondFriction(double tan_friction) : tan_phi(tan_friction), tan_lower(tan_friction) {}
    double operator()(double sn) const { return std::max(sn, 0.0) * tan_phi + std::max(sn - from, 0.0) * extra_tan; }
};

/// The largest λ in [0, cap] for which before + λ (trial − before) stays within an
/// intact bond's tension cut-off and Coulomb cap (cap if it was not bonded).
double bond_elastic_limit(double tensile, double cohesion, const BondFriction& friction, const JointHistory& before,
                          const JointHistory& trial, double cap);

/// The elastic step of an intact bond below both peaks, shared by the bonded laws:
/// true (and the stresses committed) if neither the tension cut-off nor the
/// Coulomb cap is reached; un, us already incremented.
inline bool intact_elastic_update(JointHistory& h, double kn, double ks, double tensile, double cohesion,
                                  const BondFriction& friction, double dus) {
    const double sn = -kn * h.un, tau = h.tau + ks * dus;
    if (-sn > tensile) return false;
    const double a = std::abs(tau);
    if (a > cohesion + std::max(sn, 0.0) * friction.tan_lower && a > cohesion + friction(sn)) return false;
    h.sn = sn, h.tau = tau, h.slipping = false;
    return true;
}

/// Frictional contact without a bond: no tension, |τ| <= σn tan φ, σn = −kn (un − upn).
/// upn is zero (crack faces meet again at their original position) except for a
/// contact born overlapped in a dynamic run, whose birth overlap is its rest until
/// it opens (DetectionInput::overlap_at_rest).
void unbonded_update(JointHistory& h, double kn, double ks, double tan_phi, double dus);

double tan_deg(double degrees);
/// φr of a set: residual_friction if given, else friction.
double residual_friction_of(const JointPropertySpec& p);

} // namespace bbm::contact
