// bbm contact: the Barton–Bandis law of a rough rock joint (a fracture of a DFN,
// a mapped joint, the plane of a direct shear test).
//
// The joint is unbonded (no tension, no cohesion). Its peak shear strength at
// normal stress σn > 0 (Barton & Choubey 1977, "The shear strength of rock joints
// in theory and practice", Rock Mech. 10, eq. 8):
//     τp = σn tan(φr + JRC log10(JCS / σn)),
// φr the residual friction angle, JRC the joint roughness coefficient (0-20),
// JCS the joint wall compressive strength. Following Barton's own bounds the
// roughness term i = JRC log10(JCS/σn) is not negative (σn ≥ JCS gives φr) and
// φr + i is at most 70° (the log grows without bound as σn → 0).
//
// With a joint length L (m) the strength is mobilised along the shear
// displacement δ, as Barton's (1982) curve of JRC_mob/JRC against δ/δp gives it:
//     δ/δp      0       0.3   0.6   1     2     4     10    100
//     JRC_mob   −φr/i   0     0.75  1     0.85  0.70  0.50  0     (× JRC)
// linear between, with the peak shear displacement δp = (L/500)(JRC/L)^0.33
// (Barton & Bandis 1982): the mobilised angle φ_mob = φr + (JRC_mob/JRC) i rises
// from 0 at δ = 0 to φr at 0.3 δp and to the peak at δp (pre-peak), then falls
// toward the residual σn tan φr (post-peak). δ is the shear displacement along
// the joint's loading path, elastic and plastic: ups + |τ|/ks. So the curve is
// Barton's, its peak at δp, whatever ks — as long as ks is stiffer than the
// curve's rise (a softer joint stays on its elastic line until it meets the
// curve); ks is the stiffness of unloading, and the asperities' wear (ups) is
// kept: a joint unloaded past its peak reloads to its softened strength.
// Without a length the joint is elastic to its peak and stays there (no
// mobilisation). Sliding dilates at the mobilised dilation angle dn = ½ (φ_mob −
// φr) where it is positive (Barton 1982; Barton, Bandis & Bakhtar 1985): the
// plastic opening upn grows by |Δups| tan dn, and σn = −kn (un − upn) rises
// against a stiff surround (why rough joints are stronger under constant normal
// stiffness). Not modelled: the contraction before 0.3 δp (upn only grows), the
// scale corrections of JRC and JCS (give the values at the block scale).
#pragma once

#include "contact/laws/bond.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

namespace bbm::contact {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
inline constexpr JointKey key_jrc{.key = "jrc", .bounds = between(0, 20, ""), .required = true,
                                  .meaning = "Barton-Bandis: the joint roughness coefficient JRC",
                                  BBM_KEY_FIELD(JointPropertySpec, jrc)};
inline constexpr JointKey key_jcs{.key = "jcs", .bounds = above(0, pascals), .required = true,
                                  .meaning = "Barton-Bandis: the joint wall compressive strength JCS",
                                  BBM_KEY_FIELD(JointPropertySpec, jcs)};
inline constexpr JointKey key_joint_length{
    .key = "joint_length", .bounds = above(0, metres),
    .meaning = "Barton-Bandis: the joint length L of the peak shear displacement (L/500)(JRC/L)^0.33 along which "
               "the strength is mobilised before and after the peak",
    .absent = "none: elastic to the peak, the strength stays there", BBM_KEY_FIELD(JointPropertySpec, joint_length)};
#pragma GCC diagnostic pop

struct BartonBandisLaw {
    static constexpr std::string_view name = "barton_bandis";
    static constexpr std::array<const JointKey*, 9> keys{&key_name, &key_law,      &key_kn,  &key_ks,
                                                         &key_face_shear, &key_friction, &key_jrc, &key_jcs,
                                                         &key_joint_length};
    static std::optional<KeyProblem> check(const JointPropertySpec&) { return std::nullopt; }
    static constexpr double max_angle_deg = 70.0; ///< Barton's bound on φr + JRC log10(JCS/σn)

    double kn, ks;
    double jrc;               ///< joint roughness coefficient
    double log10_jcs;         ///< log10 of the joint wall compressive strength (Pa)
    double residual_deg;      ///< φr, degrees
    double peak_displacement; ///< δp, m; 0 = no mobilisation (elastic to the peak, which stays)

    explicit BartonBandisLaw(const JointPropertySpec& p);

    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        update_stresses(h, dus);
    }
    /// σn from the opening, τ by increment, slip and dilation at the mobilised
    /// strength; un, us already incremented.
    void update_stresses(JointHistory& h, double dus) const;

    /// The peak roughness angle i = JRC log10(JCS/σn), degrees, at σn > 0 (not
    /// negative, and with φr at most 70°).
    double peak_roughness_deg(double sn) const {
        return std::min(jrc * std::max(0.0, log10_jcs - std::log10(sn)), max_angle_deg - residual_deg);
    }
    /// The mobilised friction angle φ_mob, degrees, at the shear displacement
    /// `travelled` (Barton's δ: ups + |τ|/ks; the curve above; the peak angle
    /// without a joint length).
    double mobilised_deg(double sn, double travelled) const;
    /// The shear strength at σn (compression positive) at that displacement.
    double strength(double sn, double travelled) const;

    /// A fracture: open to tension, no bond to break.
    bool starts_bonded() const { return false; }
    /// Nothing bonded to hold an elastic preload back (see joint_law.hpp).
    double elastic_limit(const JointHistory&, const JointHistory&, double cap) const { return cap; }
};

} // namespace bbm::contact
