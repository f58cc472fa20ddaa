// Coulomb slip with a brittle bond (contact/laws/coulomb.hpp).
#include "contact/laws/coulomb.hpp"

namespace bbm::contact {

CoulombLaw::CoulombLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), tan_phi(tan_deg(p.friction)), tan_phi_r(tan_deg(residual_friction_of(p))),
      cohesion(p.cohesion), tensile(p.tensile), friction(tan_phi) {}

void CoulombLaw::update_inelastic(JointHistory& h, double dus) const {
    if (h.bonded) {
        h.sn = -kn * h.un;
        h.tau += ks * dus;
        if (-h.sn > tensile) {
            h.bonded = false;
            h.broken = JointState::broken_tension;
        } else if (std::abs(h.tau) > cohesion + friction(h.sn)) {
            h.bonded = false;
            h.broken = JointState::broken_shear;
        } else {
            h.slipping = false;
            return;
        }
        h.damage = 1.0f;
        h.tau -= ks * dus; // the unbonded update below re-applies the increment
    }
    unbonded_update(h, kn, ks, h.broken == JointState::intact ? tan_phi : tan_phi_r, dus);
}

} // namespace bbm::contact
