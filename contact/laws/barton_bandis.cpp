// The Barton–Bandis joint (contact/laws/barton_bandis.hpp).
#include "contact/laws/barton_bandis.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <utility>

namespace bbm::contact {

namespace {
constexpr double degree = std::numbers::pi / 180.0;
/// Barton (1982): JRC_mob / JRC against δ/δp from the peak on.
constexpr std::array<std::pair<double, double>, 5> post_peak{
    {{1.0, 1.0}, {2.0, 0.85}, {4.0, 0.70}, {10.0, 0.50}, {100.0, 0.0}}};
} // namespace

BartonBandisLaw::BartonBandisLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), jrc(p.jrc), log10_jcs(std::log10(p.jcs)), residual_deg(p.friction),
      peak_displacement(p.joint_length > 0.0 && p.jrc > 0.0
                            ? p.joint_length / 500.0 * std::pow(p.jrc / p.joint_length, 0.33)
                            : 0.0) {}

double BartonBandisLaw::mobilised_deg(double sn, double travelled) const {
    const double i = peak_roughness_deg(sn);
    if (!(peak_displacement > 0.0)) return residual_deg + i;
    const double r = travelled / peak_displacement;
    // Before the peak: φ_mob from 0 to φr at 0.3 δp (JRC_mob from −φr/i to 0), to
    // φr + 0.75 i at 0.6 δp, to the peak φr + i at δp.
    if (r < 0.3) return residual_deg * r / 0.3;
    if (r < 0.6) return residual_deg + i * 0.75 * (r - 0.3) / 0.3;
    if (r < 1.0) return residual_deg + i * (0.75 + 0.25 * (r - 0.6) / 0.4);
    for (std::size_t k = 0; k + 1 < post_peak.size(); ++k) {
        const auto [r0, f0] = post_peak[k];
        const auto [r1, f1] = post_peak[k + 1];
        if (r < r1) return residual_deg + i * (f0 + (f1 - f0) * (r - r0) / (r1 - r0));
    }
    return residual_deg;
}

double BartonBandisLaw::strength(double sn, double travelled) const {
    if (!(sn > 0.0)) return 0.0;
    return sn * std::tan(mobilised_deg(sn, travelled) * degree);
}

void BartonBandisLaw::update_stresses(JointHistory& h, double dus) const {
    // upn < 0 only for a contact born overlapped in a dynamic run (its rest,
    // DetectionInput::overlap_at_rest), until it opens; dilation keeps it >= 0 after.
    if (h.upn < 0.0 && h.un >= 0.0) h.upn = 0.0;
    h.sn = std::max(0.0, -kn * (h.un - h.upn));
    if (h.sn == 0.0) { // apart: no shear stress, no wear of the asperities
        h.tau = 0.0;
        h.slipping = false;
        return;
    }
    // Barton's δ: the shear displacement along the loading path, plastic and
    // elastic (the elastic part at the start of the increment: an increment is a
    // small fraction of δp, so the lag is of its order).
    const double travelled = h.ups + std::abs(h.tau) / ks;
    h.tau += ks * dus;
    const double angle = mobilised_deg(h.sn, travelled);
    const double cap = h.sn * std::tan(angle * degree);
    h.slipping = std::abs(h.tau) > cap;
    if (h.slipping) {
        const double slip = (std::abs(h.tau) - cap) / ks;
        h.dissipated += cap * slip;
        h.ups += slip;
        h.tau = h.tau < 0.0 ? -cap : cap;
        // Dilation at dn = ½ (φ_mob − φr) = ½ JRC_mob log10(JCS/σn), where positive.
        h.upn += slip * std::tan(0.5 * std::max(0.0, angle - residual_deg) * degree);
    }
}

} // namespace bbm::contact
