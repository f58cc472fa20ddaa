// What the joint laws share (contact/laws/bond.hpp).
#include "contact/laws/bond.hpp"

#include <numbers>

namespace bbm::contact {

double tan_deg(double degrees) { return std::tan(degrees * std::numbers::pi / 180.0); }

double residual_friction_of(const JointPropertySpec& p) {
    return p.residual_friction >= 0 ? p.residual_friction : p.friction;
}

std::optional<KeyProblem> check_bond_keys(const JointPropertySpec& j) {
    if (j.weibull_modulus > 0.0 && !(j.cohesion > 0 || j.tensile > 0))
        return KeyProblem{"weibull_modulus", "heterogeneous strengths need a bond: cohesion or tensile > 0"};
    return std::nullopt;
}

void unbonded_update(JointHistory& h, double kn, double ks, double tan_phi, double dus) {
    // upn < 0 only for a contact born overlapped in a dynamic run (DetectionInput::
    // overlap_at_rest): the overlap it was born with is its rest, until it opens.
    if (h.upn > 0.0 || h.un >= 0.0) h.upn = 0.0;
    h.sn = std::max(0.0, -kn * (h.un - h.upn));
    h.tau += ks * dus;
    const double cap = h.sn * tan_phi;
    h.slipping = std::abs(h.tau) > cap;
    if (h.slipping) {
        const double excess = (std::abs(h.tau) - cap) / ks;
        h.dissipated += cap * excess;
        h.ups += excess;
        h.tau = h.tau < 0 ? -cap : cap;
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

} // namespace bbm::contact
