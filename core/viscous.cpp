// Viscous boundaries and incident waves (core/viscous.hpp for the method).
#include "core/viscous.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>

namespace bbm {

double incident_velocity(const IncidentWaveSpec& wave, double t) {
    using Pulse = IncidentWaveSpec::Pulse;
    const double tau = t - wave.start, f = wave.frequency, pi = std::numbers::pi;
    if (wave.pulse == Pulse::none || tau < 0.0) return 0.0;
    switch (wave.pulse) {
    case Pulse::ricker: {
        // Its peak 1.2/f after the start, where the wavelet has grown from 1e-6 of it.
        const double a = pi * f * (tau - 1.2 / f), a2 = a * a;
        return wave.velocity * (1.0 - 2.0 * a2) * std::exp(-a2);
    }
    case Pulse::half_sine: return tau <= 0.5 / f ? wave.velocity * std::sin(2.0 * pi * f * tau) : 0.0;
    case Pulse::harmonic: return tau <= wave.cycles / f ? wave.velocity * std::sin(2.0 * pi * f * tau) : 0.0;
    case Pulse::file: {
        const auto& r = wave.record;
        if (r.empty() || tau < r.front().first || tau > r.back().first) return 0.0;
        const auto after = std::upper_bound(r.begin(), r.end(), tau,
                                            [](double x, const std::pair<double, double>& row) { return x < row.first; });
        if (after == r.end()) return wave.velocity * r.back().second;
        const auto before = after - 1;
        const double s = (tau - before->first) / (after->first - before->first);
        return wave.velocity * ((1.0 - s) * before->second + s * after->second);
    }
    case Pulse::none: break;
    }
    return 0.0;
}

double incident_end(const IncidentWaveSpec& wave) {
    using Pulse = IncidentWaveSpec::Pulse;
    const double f = wave.frequency;
    switch (wave.pulse) {
    case Pulse::ricker: return wave.start + 2.4 / f;
    case Pulse::half_sine: return wave.start + 0.5 / f;
    case Pulse::harmonic: return wave.start + wave.cycles / f;
    case Pulse::file: return wave.start + (wave.record.empty() ? 0.0 : wave.record.back().first);
    case Pulse::none: break;
    }
    return 0.0;
}

namespace {

/// A dashpot's C = ρ c L (n nᵀ, t tᵀ) and its input force per m/s of incident velocity.
std::pair<std::array<double, 3>, Vec2> dashpot(const IncidentWaveSpec& wave, double length, Vec2 n, double density,
                                               double p_modulus, double shear_modulus) {
    const double cp = std::sqrt(p_modulus / density), cs = std::sqrt(shear_modulus / density);
    const double kn = density * cp * length, ks = density * cs * length;
    const Vec2 t{-n.y, n.x}; // counter-clockwise about the model
    const std::array<double, 3> c{kn * n.x * n.x + ks * t.x * t.x, kn * n.x * n.y + ks * t.x * t.y,
                                  kn * n.y * n.y + ks * t.y * t.y};
    // The traction 2 ρ c v_in along the incident motion: a P wave's inward, an S wave's along t.
    return {c, wave.wave == IncidentWaveSpec::Wave::p ? -2.0 * kn * n : 2.0 * ks * t};
}

} // namespace

void add_dashpot(ViscousBoundaries& b, int boundary, int node, double length, Vec2 n, double density,
                 double p_modulus, double shear_modulus) {
    const auto [c, input] = dashpot(b.waves[std::size_t(boundary)], length, n, density, p_modulus, shear_modulus);
    b.node.push_back(node), b.boundary.push_back(boundary), b.damping.push_back(c), b.input.push_back(input);
}

void add_face_dashpot(ViscousBoundaries& b, int boundary, int body, Vec2 offset, double length, Vec2 n,
                      double density, double p_modulus, double shear_modulus) {
    const auto [c, input] = dashpot(b.waves[std::size_t(boundary)], length, n, density, p_modulus, shear_modulus);
    b.face_body.push_back(body), b.face_boundary.push_back(boundary), b.face_offset.push_back(offset);
    b.face_damping.push_back(c), b.face_input.push_back(input);
}

namespace {

/// The entries' order by `key` (stable: a node's or body's entries keep theirs).
std::vector<int> order_by(const std::vector<int>& key) {
    std::vector<int> order(key.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return key[x] < key[y]; });
    return order;
}

template <class V>
void put_in_order(const std::vector<int>& order, V& v) {
    const V copy = v;
    for (std::size_t k = 0; k < order.size(); ++k) v[k] = copy[std::size_t(order[k])];
}

} // namespace

void sort_dashpots(ViscousBoundaries& b) {
    const auto nodes = order_by(b.node);
    put_in_order(nodes, b.node), put_in_order(nodes, b.boundary), put_in_order(nodes, b.damping);
    put_in_order(nodes, b.input);
    const auto faces = order_by(b.face_body);
    put_in_order(faces, b.face_body), put_in_order(faces, b.face_boundary), put_in_order(faces, b.face_offset);
    put_in_order(faces, b.face_damping), put_in_order(faces, b.face_input);
}

} // namespace bbm
