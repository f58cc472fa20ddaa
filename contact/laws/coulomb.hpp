// bbm contact: Coulomb slip with an optional brittle bond — a tensile strength
// and a cohesion that vanish at the first failure (the contacts formed during a
// run, a joint set of a lab test): |τ| ≤ c + σn tan φ while bonded, σn tan φr
// after, no tension once broken.
#pragma once

#include "contact/laws/bond.hpp"

#include <array>
#include <string_view>

namespace bbm::contact {

struct CoulombLaw {
    static constexpr std::string_view name = "coulomb";
    static constexpr std::array<const JointKey*, 12> keys{
        &key_name,     &key_law,     &key_kn,           &key_ks,           &key_face_shear,        &key_friction,
        &key_residual_friction, &key_cohesion, &key_tensile, &key_weibull_modulus, &key_strength_classes,
        &key_strength_seed};
    static std::optional<KeyProblem> check(const JointPropertySpec& j) { return check_bond_keys(j); }
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

} // namespace bbm::contact
