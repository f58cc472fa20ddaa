#include "contact/joint_law.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace bbm::contact {

namespace {
double tan_deg(double deg) { return std::tan(deg * std::numbers::pi / 180.0); }
double residual(const JointPropertySpec& p) { return p.residual_friction >= 0 ? p.residual_friction : p.friction; }
double sign(double x) { return x < 0 ? -1.0 : 1.0; }

/// Frictional contact without a bond: no tension, |τ| <= σn tan φ. Upn is zero here:
/// crack faces meet again at their original position.
void unbonded_update(JointHistory& h, double kn, double ks, double tan_phi, double dus) {
    h.upn = 0.0;
    h.sn = std::max(0.0, -kn * h.un);
    h.tau += ks * dus;
    const double cap = h.sn * tan_phi;
    h.slipping = std::abs(h.tau) > cap;
    if (h.slipping) {
        const double excess = (std::abs(h.tau) - cap) / ks;
        h.dissipated += cap * excess;
        h.ups += excess;
        h.tau = sign(h.tau) * cap;
    }
}
} // namespace

BondFriction::BondFriction(const JointPropertySpec& p) : tan_phi(tan_deg(p.friction)), tan_lower(tan_phi) {
    if (p.law == JointPropertySpec::Law::softening && p.confined_friction >= 0.0) {
        from = p.confined_friction_from;
        extra_tan = tan_deg(p.confined_friction) - tan_phi;
        tan_lower = std::min(tan_phi, tan_deg(p.confined_friction));
    }
}

double SofteningCurve::normalised_energy(const std::vector<std::pair<double, double>>& points) {
    double area = 0.0, up = 0.0, s = 1.0;
    for (const auto& [alpha, beta] : points) {
        area += 0.5 * (s + beta) * (alpha - beta - up);
        up = alpha - beta, s = beta;
    }
    return area;
}

SofteningCurve::SofteningCurve(const std::vector<std::pair<double, double>>& points, double u0, double peak,
                               double fracture_energy) {
    // A fracture energy fixes the area: the unit of the plastic displacements is
    // then G / (peak · normalised area) instead of u0 (the key checks keep the
    // curve non-empty, so the area is > 0).
    if (fracture_energy > 0.0 && !points.empty()) u0 = fracture_energy / (peak * normalised_energy(points));
    for (const auto& [alpha, beta] : points) {
        up_.push_back((alpha - beta) * u0);
        s_.push_back(beta);
    }
}

double SofteningCurve::operator()(double up) const {
    if (up <= 0.0) return 1.0;
    if (brittle()) return 0.0;
    for (std::size_t k = 0; k + 1 < up_.size(); ++k)
        if (up < up_[k + 1]) return s_[k] + (s_[k + 1] - s_[k]) * (up - up_[k]) / (up_[k + 1] - up_[k]);
    return s_.back();
}

double SofteningCurve::plastic_increment(double excess, double k, double peak, double up, double other,
                                         double extra) const {
    auto cap = [&](double d) { return peak * std::min((*this)(up + d), other) + extra; };
    if (brittle()) return std::max(0.0, (excess - cap(1e300)) / k);
    // Walk the breakpoints ahead of `up` — each segment's crossing of `other`
    // (inside it), then its end, which is their increasing order: h(δ) = excess −
    // kδ − cap(δ) is linear between them, so its root is exact. No allocation:
    // this runs inside the contact loop.
    double d0 = 0.0, h0 = excess - cap(0.0);
    for (std::size_t i = 0; i + 1 < up_.size(); ++i) {
        double ahead[2];
        int count = 0;
        const double s0 = s_[i] - other, s1 = s_[i + 1] - other;
        if (s0 * s1 < 0) {
            const double x = up_[i] + (up_[i + 1] - up_[i]) * s0 / (s0 - s1);
            if (x > up) ahead[count++] = x - up;
        }
        if (up_[i + 1] > up) ahead[count++] = up_[i + 1] - up;
        for (int j = 0; j < count; ++j) {
            const double d1 = ahead[j], h1 = excess - k * d1 - cap(d1);
            if (h1 <= 0.0) return d0 + h0 * (d1 - d0) / (h0 - h1);
            d0 = d1, h0 = h1;
        }
    }
    return d0 + h0 / k; // beyond the last point the strength is constant
}

CoulombLaw::CoulombLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), tan_phi(tan_deg(p.friction)), tan_phi_r(tan_deg(residual(p))),
      cohesion(p.cohesion), tensile(p.tensile) {
    friction.tan_phi = friction.tan_lower = tan_phi;
}

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

SofteningLaw::SofteningLaw(const JointPropertySpec& p)
    : kn(p.kn), ks(p.ks), tan_phi(tan_deg(p.friction)), tan_phi_r(tan_deg(residual(p))),
      cohesion(p.cohesion), tensile(p.tensile), friction(p),
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

JointLaw make_law(const JointPropertySpec& p) {
    // By index: the alternative of JointLaw that JointPropertySpec::Law names.
    constexpr auto makers = []<std::size_t... I>(std::index_sequence<I...>) {
        return std::array<JointLaw (*)(const JointPropertySpec&), sizeof...(I)>{
            [](const JointPropertySpec& q) -> JointLaw { return std::variant_alternative_t<I, JointLaw>(q); }...};
    }(std::make_index_sequence<std::variant_size_v<JointLaw>>{});
    return makers[static_cast<std::size_t>(p.law)](p);
}

double normal_stiffness(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.kn; }, law);
}
double shear_stiffness(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.ks; }, law);
}

bool starts_bonded(const JointLaw& law) {
    return std::visit([](const auto& l) { return l.starts_bonded(); }, law);
}

double elastic_limit(const JointLaw& law, const JointHistory& before, const JointHistory& trial, double cap) {
    return std::visit([&](const auto& l) { return l.elastic_limit(before, trial, cap); }, law);
}

double bond_elastic_limit(double tensile, double cohesion, const BondFriction& friction, const JointHistory& before,
                          const JointHistory& trial, double cap) {
    if (!before.bonded) return cap;
    auto within = [&](double lambda) {
        const double sn = before.sn + lambda * (trial.sn - before.sn);
        const double tau = before.tau + lambda * (trial.tau - before.tau);
        return -sn <= tensile && std::abs(tau) <= cohesion + friction(sn);
    };
    if (within(cap)) return cap;
    if (!within(0.0)) return 0.0;
    // Each condition holds on an interval of λ that contains 0: bisect its end.
    double lo = 0.0, hi = cap;
    for (int k = 0; k < 100 && hi - lo > 1e-12 * hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        (within(mid) ? lo : hi) = mid;
    }
    return lo;
}

JointState state_of(const JointHistory& h) {
    if (h.broken != JointState::intact) return h.broken;
    if (h.slipping) return JointState::sliding;
    return h.damage > 0 ? JointState::softening : JointState::intact;
}

} // namespace bbm::contact

namespace bbm {

std::vector<double> strength_class_factors(double m, int classes) {
    std::vector<double> f(std::max(classes, 1), 1.0);
    if (!(m > 0.0)) return f;
    double mean = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
        const double q = (double(k) + 0.5) / double(f.size());
        f[k] = std::pow(-std::log1p(-q), 1.0 / m);
        mean += f[k];
    }
    mean /= double(f.size());
    for (double& x : f) x /= mean;
    return f;
}

} // namespace bbm
