// The paper's softening bond (contact/laws/softening.hpp).
#include "contact/laws/softening.hpp"

#include <tuple>

namespace bbm::contact {

namespace {
/// σn tan φ, steepening to tan φ2 above σ* with a confined friction.
BondFriction softening_friction(const JointPropertySpec& p) {
    BondFriction f(tan_deg(p.friction));
    if (p.confined_friction >= 0.0) {
        f.from = p.confined_friction_from;
        f.extra_tan = tan_deg(p.confined_friction) - f.tan_phi;
        f.tan_lower = std::min(f.tan_phi, tan_deg(p.confined_friction));
    }
    return f;
}
double sign(double x) { return x < 0 ? -1.0 : 1.0; }
} // namespace

std::optional<KeyProblem> SofteningLaw::check(const JointPropertySpec& j) {
    for (const auto& [key, value, curve] : {std::tuple{"cohesion", j.cohesion, "shear softening"},
                                            std::tuple{"tensile", j.tensile, "tension softening"}})
        if (!(value > 0))
            return KeyProblem{key, "a softening law needs " + std::string(key) + " > 0 Pa, the peak the " + curve +
                                       " curve is normalised by; got " + shortest_text(value)};
    for (const auto& [key, energy, curve, name] :
         {std::tuple{"tension_fracture_energy", j.tension_fracture_energy, &j.tension_softening, "tension_softening"},
          std::tuple{"shear_fracture_energy", j.shear_fracture_energy, &j.shear_softening, "shear_softening"}})
        if (energy > 0.0 && curve->empty())
            return KeyProblem{key, std::string("a fracture energy stretches a softening curve and needs ") + name +
                                       " (a brittle bond dissipates nothing after its peak)"};
    if ((j.confined_friction >= 0.0) != (j.confined_friction_from > 0.0))
        return KeyProblem{j.confined_friction >= 0.0 ? "confined_friction" : "confined_friction_from",
                          "confined_friction (the steeper friction angle, degrees) and confined_friction_from "
                          "(the normal stress it starts at, Pa) go together"};
    return check_bond_keys(j);
}

SofteningLaw::SofteningLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), tan_phi(tan_deg(p.friction)), tan_phi_r(tan_deg(residual_friction_of(p))),
      cohesion(p.cohesion), tensile(p.tensile), friction(softening_friction(p)),
      tension(p.tension_softening, p.tensile / p.kn, p.tensile, p.tension_fracture_energy),
      shear(p.shear_softening, p.cohesion / p.ks, p.cohesion, p.shear_fracture_energy) {}

void SofteningLaw::update_inelastic(JointHistory& h, double dus) const {
    if (!h.bonded) {
        unbonded_update(h, kn, ks, h.broken == JointState::intact ? tan_phi : tan_phi_r, dus);
        return;
    }
    h.sn = -kn * (h.un - h.upn);
    h.tau += ks * dus;
    double sn_strength = tension(h.upn), ss_strength = shear(h.ups);

    // Tension cut-off: −σn <= σt·min(Sn, Ss).
    const double t = -h.sn, cap_t = tensile * std::min(sn_strength, ss_strength);
    if (t > cap_t) {
        const double d = tension.plastic_increment(t, kn, tensile, h.upn, ss_strength, 0.0);
        const double t_after = t - kn * d;
        h.dissipated += 0.5 * (std::min(t, cap_t) + t_after) * d;
        h.upn += d;
        h.sn = -t_after;
        sn_strength = tension(h.upn);
    }
    // Coulomb cap with softened cohesion: |τ| <= c·min(Sn, Ss) + max(σn, 0) tan φ
    // (steepening above σ* with a confined friction).
    const double friction_part = friction(h.sn);
    const double cap_s = cohesion * std::min(sn_strength, ss_strength) + friction_part;
    const double a = std::abs(h.tau);
    h.slipping = a > cap_s;
    if (h.slipping) {
        const double d = shear.plastic_increment(a, ks, cohesion, h.ups, sn_strength, friction_part);
        const double a_after = a - ks * d;
        h.dissipated += 0.5 * (cap_s + a_after) * d;
        h.ups += d;
        h.tau = sign(h.tau) * a_after;
        ss_strength = shear(h.ups);
    }
    const double damage = 1.0 - std::min(sn_strength, ss_strength);
    h.damage = float(damage);
    if (damage >= 1.0) {
        h.damage = 1.0f;
        h.bonded = false;
        h.broken = sn_strength <= ss_strength ? JointState::broken_tension : JointState::broken_shear;
        h.upn = 0.0;
        h.sn = std::max(0.0, -kn * h.un);
        const double cap = h.sn * tan_phi_r;
        if (std::abs(h.tau) > cap) h.tau = sign(h.tau) * cap;
    }
}

} // namespace bbm::contact
