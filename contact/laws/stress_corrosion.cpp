// Stress corrosion of a bond (contact/laws/stress_corrosion.hpp).
#include "contact/laws/stress_corrosion.hpp"

namespace bbm::contact {

std::optional<KeyProblem> StressCorrosionLaw::check(const JointPropertySpec& j) { return SofteningLaw::check(j); }

StressCorrosionLaw::StressCorrosionLaw(const JointPropertySpec& p)
    : SofteningLaw(p), rate_at_strength(key_corrosion_rate.get(p)), exponent(key_corrosion_exponent.get(p)),
      threshold(key_corrosion_threshold.get(p)) {}

void StressCorrosionLaw::corrode_through(JointHistory& h) const {
    const bool tension = std::max(-h.sn, 0.0) / tensile >= std::abs(h.tau) / (cohesion + friction(h.sn));
    h.damage = 1.0f;
    h.bonded = false;
    h.broken = tension ? JointState::broken_tension : JointState::broken_shear;
    h.upn = 0.0;
    h.sn = std::max(0.0, -kn * h.un);
    const double cap = h.sn * tan_phi_r;
    if (std::abs(h.tau) > cap) h.tau = h.tau < 0 ? -cap : cap;
}

} // namespace bbm::contact
