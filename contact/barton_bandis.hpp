// bbm contact: the Barton–Bandis law of a rough rock joint (a fracture of a DFN,
// a mapped joint, the plane of a direct shear test).
//
// The joint is unbonded (no tension, no cohesion) and elastic with kn, ks below
// its peak. The peak shear strength at normal stress σn > 0 (Barton & Choubey
// 1977, "The shear strength of rock joints in theory and practice", Rock Mech.
// 10, eq. 8):
//     τp = σn tan(φr + JRC log10(JCS / σn)),
// φr the residual friction angle, JRC the joint roughness coefficient (0-20),
// JCS the joint wall compressive strength. Following Barton's own bounds the
// roughness term is not negative (σn ≥ JCS gives φr) and the angle φr + JRC
// log10(JCS/σn) is at most 70° (the log grows without bound as σn → 0).
// Sliding dilates at the mobilised dilation angle dn = ½ JRC_mob log10(JCS/σn)
// (Barton 1982; Barton, Bandis & Bakhtar 1985): the plastic opening upn grows by
// |Δups| tan dn, and σn = −kn (un − upn) rises against a stiff surround (why
// rough joints are stronger under constant normal stiffness).
// Past the peak, with a joint length L (m), JRC is mobilised down Barton's (1982)
// curve of JRC_mob/JRC against δ/δp: 1 at 1, 0.85 at 2, 0.70 at 4, 0.50 at 10, 0
// at 100 (linear between), with the peak shear displacement δp = (L/500)(JRC/L)^0.33
// (Barton & Bandis 1982) and δ = δp + ups; toward the residual strength σn tan φr.
// Without a length the strength stays at its peak (no post-peak softening).
// Not modelled: the pre-peak mobilisation (the joint is elastic to its peak), the
// scale corrections of JRC and JCS (give the values at the block scale), and
// contraction on reversal (upn only grows).
#pragma once

#include "contact/joint_history.hpp"
#include "contact/joint_property.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

namespace bbm::contact {

struct BartonBandisLaw {
    static constexpr std::string_view name = "barton_bandis";
    /// The [[joint_property]] keys it reads (declared in joint_keys.hpp).
    static constexpr std::array<std::string_view, 9> keys{"name", "law", "kn", "ks", "face_shear",
                                                          "friction", "jrc", "jcs", "joint_length"};
    static constexpr double max_angle_deg = 70.0; ///< Barton's bound on φr + JRC log10(JCS/σn)

    double kn, ks;
    double jrc;               ///< joint roughness coefficient
    double log10_jcs;         ///< log10 of the joint wall compressive strength (Pa)
    double residual_deg;      ///< φr, degrees
    double peak_displacement; ///< δp, m; 0 = no post-peak softening

    explicit BartonBandisLaw(const JointPropertySpec& p);

    void update(JointHistory& h, double dun, double dus) const {
        h.un += dun;
        h.us += dus;
        update_stresses(h, dus);
    }
    /// σn from the opening, τ by increment, slip and dilation at the peak; un, us
    /// already incremented.
    void update_stresses(JointHistory& h, double dus) const;

    /// JRC_mob / JRC at accumulated plastic shear `ups` past the peak.
    double mobilised_fraction(double ups) const;
    /// JRC_mob log10(JCS/σn), degrees, the roughness term at σn > 0 (not negative,
    /// and with φr at most 70°).
    double roughness_deg(double sn, double ups) const {
        const double term = jrc * mobilised_fraction(ups) * std::max(0.0, log10_jcs - std::log10(sn));
        return std::min(term, max_angle_deg - residual_deg);
    }
    /// The shear strength at σn (compression positive) after `ups` of plastic shear.
    double strength(double sn, double ups) const;

    /// A fracture: open to tension, no bond to break.
    bool starts_bonded() const { return false; }
    /// Nothing bonded to hold an elastic preload back (see joint_law.hpp).
    double elastic_limit(const JointHistory&, const JointHistory&, double cap) const { return cap; }
};

} // namespace bbm::contact
