#include "contact/barton_bandis.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <utility>

namespace bbm::contact {

namespace {
constexpr double degree = std::numbers::pi / 180.0;
/// Barton (1982): JRC_mob / JRC against δ/δp past the peak.
constexpr std::array<std::pair<double, double>, 5> mobilisation{
    {{1.0, 1.0}, {2.0, 0.85}, {4.0, 0.70}, {10.0, 0.50}, {100.0, 0.0}}};
} // namespace

BartonBandisLaw::BartonBandisLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), jrc(p.jrc), log10_jcs(std::log10(p.jcs)), residual_deg(p.friction),
      peak_displacement(p.joint_length > 0.0 && p.jrc > 0.0
                            ? p.joint_length / 500.0 * std::pow(p.jrc / p.joint_length, 0.33)
                            : 0.0) {}

double BartonBandisLaw::mobilised_fraction(double ups) const {
    if (!(peak_displacement > 0.0)) return 1.0;
    const double r = 1.0 + ups / peak_displacement;
    for (std::size_t k = 0; k + 1 < mobilisation.size(); ++k) {
        const auto [r0, f0] = mobilisation[k];
        const auto [r1, f1] = mobilisation[k + 1];
        if (r < r1) return f0 + (f1 - f0) * (r - r0) / (r1 - r0);
    }
    return 0.0;
}

double BartonBandisLaw::strength(double sn, double ups) const {
    if (!(sn > 0.0)) return 0.0;
    return sn * std::tan((residual_deg + roughness_deg(sn, ups)) * degree);
}

void BartonBandisLaw::update_stresses(JointHistory& h, double dus) const {
    h.sn = std::max(0.0, -kn * (h.un - h.upn));
    if (h.sn == 0.0) { // apart: no shear stress, no wear of the asperities
        h.tau = 0.0;
        h.slipping = false;
        return;
    }
    h.tau += ks * dus;
    const double roughness = roughness_deg(h.sn, h.ups);
    const double cap = h.sn * std::tan((residual_deg + roughness) * degree);
    h.slipping = std::abs(h.tau) > cap;
    if (h.slipping) {
        const double slip = (std::abs(h.tau) - cap) / ks;
        h.dissipated += cap * slip;
        h.ups += slip;
        h.tau = h.tau < 0.0 ? -cap : cap;
        h.upn += slip * std::tan(0.5 * roughness * degree); // dilation at dn = ½ JRC_mob log10(JCS/σn)
    }
}

} // namespace bbm::contact
