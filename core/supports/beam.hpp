// bbm core: the corotational Euler–Bernoulli beam element shared by the support
// support types that bend.
//
// An element between nodes a and b (positions, rotations θa, θb) of rest length
// l0 and initial chord angle β0 carries
//   N  = EA (ε − εp),  ε = (l − l0)/l0                 (tension positive)
//   Ma = (EI/l0)(4θ̄a + 2θ̄b),  Mb = (EI/l0)(2θ̄a + 4θ̄b)
// with θ̄ the node rotations less the chord's rigid rotation β − β0 and less the
// ends' plastic rotations. Optionally perfectly plastic: N within [lower, upper]
// (plastic strain εp) and each end moment within ± the moment capacity (a hinge:
// plastic rotations), independently (no interaction diagram).
#pragma once

#include "base/vec2.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace bbm::support {

/// An angle in (−π, π].
inline double wrap(double angle) {
    while (angle > std::numbers::pi) angle -= 2.0 * std::numbers::pi;
    while (angle < -std::numbers::pi) angle += 2.0 * std::numbers::pi;
    return angle;
}

struct BeamSection {
    double ea, ei;
    bool axial_limited;          ///< N clamped to [lower, upper]
    double lower, upper;         ///< N limits (tension positive)
    double moment_capacity;      ///< 0 = elastic
};

/// What an element puts on its nodes: force on a (b gets the opposite), end moments.
struct BeamForces {
    double tension, ma, mb, length, strain;
    Vec2 force_on_a;
    std::uint8_t yielded; ///< bit 0 axially, bit 1 in bending (this evaluation)
};

/// The element's forces now; the plastic strain and rotations move when it yields.
inline BeamForces beam_forces(Vec2 pa, Vec2 pb, double theta_a, double theta_b, double l0, double chord0,
                              const BeamSection& s, double& plastic_strain, double& plastic_a, double& plastic_b) {
    BeamForces out{};
    const Vec2 c = pb - pa;
    const double l = norm(c);
    const Vec2 ex = c / l, ey = perp(ex);
    const double beta = wrap(std::atan2(c.y, c.x) - chord0);
    const double ta = theta_a - beta, tb = theta_b - beta;
    const double strain = (l - l0) / l0;
    double tension = s.ea * (strain - plastic_strain);
    if (s.axial_limited && (tension < s.lower || tension > s.upper)) {
        tension = std::clamp(tension, s.lower, s.upper);
        plastic_strain = strain - tension / s.ea;
        out.yielded |= 1;
    }
    const double ea_ = ta - plastic_a, eb_ = tb - plastic_b;
    double ma = s.ei / l0 * (4.0 * ea_ + 2.0 * eb_), mb = s.ei / l0 * (2.0 * ea_ + 4.0 * eb_);
    if (s.moment_capacity > 0.0 && (std::abs(ma) > s.moment_capacity || std::abs(mb) > s.moment_capacity)) {
        // Plastic rotations at the ends that bring each end moment back to the
        // capacity (a hinge), the other end's elastic rotation unchanged.
        ma = std::clamp(ma, -s.moment_capacity, s.moment_capacity);
        mb = std::clamp(mb, -s.moment_capacity, s.moment_capacity);
        // Elastic end rotations giving (ma, mb): the inverse of [[4, 2], [2, 4]] EI/l0.
        const double ra = l0 / s.ei * (4.0 * ma - 2.0 * mb) / 12.0, rb = l0 / s.ei * (4.0 * mb - 2.0 * ma) / 12.0;
        plastic_a = ta - ra;
        plastic_b = tb - rb;
        out.yielded |= 2;
    }
    const double shear = (ma + mb) / l;
    out.tension = tension, out.ma = ma, out.mb = mb, out.length = l, out.strain = strain;
    out.force_on_a = tension * ex - shear * ey;
    return out;
}

/// Row sums of an element's stiffness (translation, rotation), the rotation's
/// coupling terms taken per radian at its length: an upper bound of the
/// diagonal's share, a safe mass.
inline double beam_translation_stiffness(const BeamSection& s, double l0) {
    return s.ea / l0 + 24.0 * s.ei / (l0 * l0 * l0);
}
inline double beam_rotation_stiffness(const BeamSection& s, double l0) { return 12.0 * s.ei / l0; }

} // namespace bbm::support
