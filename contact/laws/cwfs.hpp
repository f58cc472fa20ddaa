// bbm contact: cohesion weakening and friction strengthening (CWFS), the brittle
// rock's strength of Hajiabdolmajid, Kaiser & Martin (2002, "Modelling brittle
// failure of rock", Int. J. Rock Mech. Min. Sci. 39, 731-741), written for a bond:
// the cohesion and the friction are mobilised at different plastic slips ups,
//     c(ups)     = c0 + (cr − c0) min(ups / uc, 1)            the cohesion is lost first,
//     tan φ(ups) = tan φ0 + (tan φm − tan φ0) min(ups / uf, 1) the friction mobilised later,
//     |τ| ≤ c(ups) + max(σn, 0) tan φ(ups),
// so that at low confinement (the wall of an opening) the cohesion is gone before
// the friction can carry the load — the notch-shaped breakout the paper's
// Mine-by model gives — while under confinement the rising friction makes the
// rock stronger. In tension −σn ≤ σt c(ups)/c0: the tensile strength goes with the
// cohesion; beyond it the bond breaks (a tensile crack). With no residual cohesion
// (cr = 0) the bond is broken once ups reaches uc (a shear crack). A broken bond
// slides at σn tan φ(ups), no tension. The return onto the cap is exact on its
// linear pieces (breakpoints uc and uf), so the stresses are on the curve whatever
// the step. No dilation; unloading is elastic with kn, ks.
#pragma once

#include "contact/laws/bond.hpp"

#include <array>
#include <string_view>

namespace bbm::contact {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
// Its own keys keep their values in JointPropertySpec::values (law_value).
inline constexpr JointKey key_residual_cohesion{
    .key = "residual_cohesion", .bounds = at_least(0, pascals),
    .meaning = "cwfs: the cohesion cr left after cohesion_slip of plastic slip (at most cohesion)",
    .absent = "0: the bond is broken once the cohesion is lost",
    .get = [](const JointPropertySpec& j) { return law_value(j, "residual_cohesion", 0.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "residual_cohesion", v); }};
inline constexpr JointKey key_mobilised_friction{
    .key = "mobilised_friction", .bounds = below(0, 90, degrees), .required = true,
    .meaning = "cwfs: the friction angle φm mobilised after friction_slip of plastic slip (at least friction)",
    .get = [](const JointPropertySpec& j) { return law_value(j, "mobilised_friction", -1.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "mobilised_friction", v); }};
inline constexpr JointKey key_cohesion_slip{
    .key = "cohesion_slip", .bounds = above(0, metres), .required = true,
    .meaning = "cwfs: the plastic slip uc over which the cohesion falls linearly from cohesion to residual_cohesion",
    .get = [](const JointPropertySpec& j) { return law_value(j, "cohesion_slip", 0.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "cohesion_slip", v); }};
inline constexpr JointKey key_friction_slip{
    .key = "friction_slip", .bounds = above(0, metres), .required = true,
    .meaning = "cwfs: the plastic slip uf over which tan φ rises linearly from tan friction to tan mobilised_friction",
    .get = [](const JointPropertySpec& j) { return law_value(j, "friction_slip", 0.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "friction_slip", v); }};
#pragma GCC diagnostic pop

struct CwfsLaw {
    static constexpr std::string_view name = "cwfs";
    static constexpr std::array<const JointKey*, 12> keys{
        &key_name,    &key_law,     &key_kn,          &key_ks,           &key_face_shear,         &key_friction,
        &key_cohesion, &key_tensile, &key_residual_cohesion, &key_mobilised_friction, &key_cohesion_slip,
        &key_friction_slip};
    /// A cohesion to weaken (> 0), the residual at most that, φm at least φ0.
    static std::optional<KeyProblem> check(const JointPropertySpec& j);

    double kn, ks;
    double c0, cr, uc;        ///< cohesion: from c0 to cr over uc of plastic slip
    double tan0, tanm, uf;    ///< friction: tan φ from tan φ0 to tan φm over uf
    double tensile;           ///< σt of the intact bond, falling with the cohesion
    BondFriction friction0;   ///< the intact bond's cap: tan φ0

    explicit CwfsLaw(const JointPropertySpec& p);
    double cohesion(double ups) const { return c0 + (cr - c0) * std::min(ups / uc, 1.0); }
    double tan_friction(double ups) const { return tan0 + (tanm - tan0) * std::min(ups / uf, 1.0); }

    bool starts_bonded() const { return true; }
    double elastic_limit(const JointHistory& before, const JointHistory& trial, double cap) const {
        return bond_elastic_limit(tensile, c0, friction0, before, trial, cap);
    }
    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        if (h.bonded && h.ups == 0.0 && intact_elastic_update(h, kn, ks, tensile, c0, friction0, dus)) return;
        update_inelastic(h, dus);
    }
    /// Slip on the moving cap, failure, or friction once broken; un, us already incremented.
    void update_inelastic(JointHistory& h, double dus) const;
};

} // namespace bbm::contact
