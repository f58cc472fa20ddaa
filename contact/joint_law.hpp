// bbm contact: joint constitutive laws (SPEC §4), stress per unit joint area.
//
// A law maps the relative displacement increments of one point contact (Δun,
// opening positive; Δus) to its stresses (σn compression positive; τ), updating
// the contact's history in place. Laws are values validated once from the model
// file, and the solver calls them per batch of contacts sharing a property set
// (contact::step_contacts: one dispatch per batch, not a virtual call per contact).
//
// Lemos–Sarhosis softening (paper §3.3, SPEC §4), as implemented:
//   normal:  σn = −kn (un − upn)                     (total form; compression elastic)
//   shear:   τ ← τ + ks Δus                           (incremental)
//   strengths soften with plastic displacement: σt·Sn(upn), c·Ss(ups), where Sn, Ss
//   are the normalised post-peak curves written in plastic displacement, through
//   (0, 1), ((α_k − β_k)·u0, β_k) with u0 = σt/kn (tension) or c/ks (shear);
//   coupled damage D = 1 − min(Sn(upn), Ss(ups)); strengths used σt(1−D), c(1−D);
//   tension cut-off −σn ≤ σt(1−D) and Coulomb cap |τ| ≤ c(1−D) + max(σn, 0) tan φ are
//   enforced by an exact return on the piecewise-linear curves (so monotonic
//   loading passes through the curve points whatever the step size).
//   With `confined_friction` φ2 from σ* (joint_property.hpp) the bonded friction
//   term is σn tan φ up to σ* and σ* tan φ + (σn − σ*) tan φ2 beyond it.
//   At D = 1 the bond is broken: a crack, tensile if the tensile curve drove D to
//   1, shear otherwise; from then on Coulomb friction with φr and no tension, the
//   crack faces meeting again at their original position (upn reset to 0).
//   Unloading is elastic with the initial stiffness.
#pragma once

#include "contact/barton_bandis.hpp"
#include "contact/joint_history.hpp"
#include "contact/joint_property.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace bbm::contact {


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
/// has a confined friction. Without one σ* is +∞ and the second term 0.
struct BondFriction {
    double tan_phi = 0.0;
    double from = INFINITY;  ///< σ*
    double extra_tan = 0.0;  ///< tan φ2 − tan φ
    /// min(tan φ, tan φ2): max(σn, 0) times it is a lower bound of the term, the
    /// elastic path's first test (one multiply, as without a confined friction).
    double tan_lower = 0.0;
    BondFriction() = default;
    explicit BondFriction(const JointPropertySpec& p);
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

// Each law's update() is inline for the elastic path every contact takes most of
// the time; plastic returns and failures go out of line.
struct ElasticLaw {
    static constexpr std::string_view name = "elastic";
    /// The [[joint_property]] keys it reads (declared in joint_keys.hpp).
    static constexpr std::array<std::string_view, 5> keys{"name", "law", "kn", "ks", "face_shear"};
    double kn, ks;
    explicit ElasticLaw(const JointPropertySpec& p) : kn(p.kn), ks(p.ks) {}
    bool starts_bonded() const { return true; }
    /// Never yields: any load is within its strength.
    double elastic_limit(const JointHistory&, const JointHistory&, double cap) const { return cap; }
    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        h.sn = -kn * h.un;
        h.tau += ks * dus;
    }
};

/// Coulomb slip with an optional brittle bond (tensile strength and cohesion that
/// vanish at the first failure).
struct CoulombLaw {
    static constexpr std::string_view name = "coulomb";
    static constexpr std::array<std::string_view, 12> keys{
        "name",     "law",    "kn",  "ks", "face_shear", "friction", "residual_friction", "cohesion", "tensile",
        "weibull_modulus", "strength_classes", "strength_seed"};
    double kn, ks, tan_phi, tan_phi_r, cohesion, tensile;
    BondFriction friction; ///< plain tan φ: the confined friction is the softening law's
    explicit CoulombLaw(const JointPropertySpec& p);
    /// Bonded only with a (brittle) bond to break.
    bool starts_bonded() const { return tensile > 0 || cohesion > 0; }
    double elastic_limit(const JointHistory& before, const JointHistory& trial, double cap) const {
        return bond_elastic_limit(tensile, cohesion, friction, before, trial, cap);
    }
    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        if (h.bonded && intact_elastic_update(h, kn, ks, tensile, cohesion, friction, dus)) return;
        update_inelastic(h, dus);
    }
    /// Bond failure or frictional contact; un, us already incremented.
    void update_inelastic(JointHistory& h, double dus) const;
};

struct SofteningLaw {
    static constexpr std::string_view name = "softening";
    static constexpr std::array<std::string_view, 18> keys{
        "name",     "law",    "kn",  "ks", "face_shear", "friction", "residual_friction", "cohesion", "tensile",
        "weibull_modulus", "strength_classes", "strength_seed", "tension_softening", "shear_softening",
        "tension_fracture_energy", "shear_fracture_energy", "confined_friction", "confined_friction_from"};
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

/// Every joint law, one alternative each, in the order of JointPropertySpec::Law.
/// A law is a type with its `name` (the model file's `law`), the `keys` it reads
/// (each declared in joint_keys.hpp), kn and ks, update(),
/// starts_bonded() and elastic_limit(); the contact pass dispatches once per batch
/// of contacts that share a property set (no virtual call per contact).
using JointLaw = std::variant<ElasticLaw, CoulombLaw, SofteningLaw, BartonBandisLaw>;
static_assert(std::variant_size_v<JointLaw> == std::size_t(JointPropertySpec::Law::barton_bandis) + 1);

/// The laws' names, in the order of JointPropertySpec::Law (the model file's `law`).
inline constexpr auto law_names = []<std::size_t... I>(std::index_sequence<I...>) {
    return std::array<std::string_view, sizeof...(I)>{std::variant_alternative_t<I, JointLaw>::name...};
}(std::make_index_sequence<std::variant_size_v<JointLaw>>{});

JointLaw make_law(const JointPropertySpec& p);
double normal_stiffness(const JointLaw& law);
double shear_stiffness(const JointLaw& law);
/// Does a contact with this law start bonded (can it carry tension)?
bool starts_bonded(const JointLaw& law);

/// Output state of a contact.
JointState state_of(const JointHistory& h);

/// The largest λ ≥ 0 (at most `cap`) for which the stresses before + λ (trial −
/// before) stay within the intact strength of the law — tension cut-off and
/// Coulomb cap with the full tensile strength and cohesion; unbounded (`cap`) for
/// an elastic law or an unloaded contact. With elastic joints the state of a
/// model scales with its load, so the smallest λ over the contacts is how far a
/// load can go before the first joint yields (a lab test's elastic preload).
double elastic_limit(const JointLaw& law, const JointHistory& before, const JointHistory& trial, double cap);

} // namespace bbm::contact
