// Cohesion weakening and friction strengthening (contact/laws/cwfs.hpp).
#include "contact/laws/cwfs.hpp"

#include <cmath>
#include <limits>

namespace bbm::contact {

std::optional<KeyProblem> CwfsLaw::check(const JointPropertySpec& j) {
    if (!(j.cohesion > 0.0)) return KeyProblem{"cohesion", "a cwfs bond needs the cohesion c0 it weakens from (> 0)"};
    if (key_residual_cohesion.get(j) > j.cohesion)
        return KeyProblem{"residual_cohesion", "must be at most cohesion (the cohesion weakens)"};
    if (key_mobilised_friction.get(j) < j.friction)
        return KeyProblem{"mobilised_friction", "must be at least friction (the friction strengthens)"};
    return std::nullopt;
}

CwfsLaw::CwfsLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), c0(p.cohesion), cr(key_residual_cohesion.get(p)), uc(key_cohesion_slip.get(p)),
      tan0(tan_deg(p.friction)), tanm(tan_deg(key_mobilised_friction.get(p))), uf(key_friction_slip.get(p)),
      tensile(p.tensile), friction0(tan0) {}

void CwfsLaw::update_inelastic(JointHistory& h, double dus) const {
    if (h.bonded) {
        const double sn = -kn * h.un;
        if (-sn > tensile * cohesion(h.ups) / c0) { // the tensile strength goes with the cohesion
            h.bonded = false;
            h.broken = JointState::broken_tension;
            h.damage = 1.0f;
        } else {
            h.sn = sn;
            const double trial = h.tau + ks * dus, a = std::abs(trial), s = std::max(sn, 0.0);
            auto cap = [&](double ups) { return cohesion(ups) + s * tan_friction(ups); };
            h.slipping = a > cap(h.ups);
            if (!h.slipping) {
                h.tau = trial;
                return;
            }
            // The slip δ with a − ks δ = cap(ups + δ), piece by piece of the cap
            // (linear between the breakpoints uc and uf; a piece that softens
            // faster than ks unloads is passed through: no root on it).
            double u = h.ups, work = 0.0;
            for (;;) {
                const double next = std::min(u < uc ? uc : INFINITY, u < uf ? uf : INFINITY);
                const double slope = (u < uc ? (cr - c0) / uc : 0.0) + s * (u < uf ? (tanm - tan0) / uf : 0.0);
                const double excess = a - ks * (u - h.ups) - cap(u);
                const double d = ks + slope > 0.0 ? excess / (ks + slope) : INFINITY;
                const double to = std::min(u + d, next);
                work += 0.5 * (cap(u) + cap(to)) * (to - u);
                u = to;
                if (u < next || std::isinf(next)) break;
            }
            h.dissipated += work;
            h.tau = std::copysign(a - ks * (u - h.ups), trial);
            h.ups = u;
            h.damage = float(1.0 - cohesion(u) / c0);
            if (!(cr > 0.0) && u >= uc) { // the cohesion is gone: a shear crack
                h.bonded = false;
                h.broken = JointState::broken_shear;
                h.damage = 1.0f;
            }
            return;
        }
    }
    unbonded_update(h, kn, ks, tan_friction(h.ups), dus);
}

} // namespace bbm::contact
