// bbm base: 2D vector and polygon primitives shared by every layer.
//
// Everything in bbm is plane strain with unit thickness, so a point, a force
// and a displacement are all a pair of doubles. This header is the lowest layer
// of the code: it includes nothing of bbm, and meshing/, fem/, contact/ and the
// solver in core/ all build on it. Polygon integrals (area, centroid, polar
// moment) are the exact closed forms for a simple polygon (Green's theorem),
// since rigid-block mass properties are taken from them (SPEC §3).
#pragma once

#include <cmath>
#include <span>

namespace bbm {

struct Vec2 {
    double x = 0.0;
    double y = 0.0;

    constexpr Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
    constexpr Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
    constexpr Vec2& operator*=(double s) { x *= s; y *= s; return *this; }
    friend constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
    friend constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
    friend constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
    friend constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
    friend constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
    friend constexpr Vec2 operator/(Vec2 a, double s) { return {a.x / s, a.y / s}; }
    friend constexpr bool operator==(Vec2 a, Vec2 b) = default;
};

constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
/// z-component of the 3D cross product: positive when b is counter-clockwise from a.
constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
// sqrt of the square, not std::hypot: hypot's overflow care costs ~4x in the
// contact loop, and bbm's lengths (m) and forces (N/m) are far from the limits.
inline double norm(Vec2 a) { return std::sqrt(a.x * a.x + a.y * a.y); }
constexpr double norm2(Vec2 a) { return a.x * a.x + a.y * a.y; }
/// Rotates a by +90 degrees (counter-clockwise).
constexpr Vec2 perp(Vec2 a) { return {-a.y, a.x}; }

/// cos θ and sin θ of a block's rotation. Every block's vertices are placed from
/// them every step, and a libm sincos was a tenth of a failing tunnel's run time:
/// for |θ| ≤ π/4 (block rotations almost always are) the Taylor series to x¹⁷ and
/// x¹⁸ — truncation below 1e-19 there, so the result is within an ulp or two of
/// libm's (tests/test_geometry.cpp) — and libm beyond.
struct Rotation {
    double c, s;
    Vec2 operator()(Vec2 r) const { return {c * r.x - s * r.y, s * r.x + c * r.y}; }
};
namespace detail {
/// ±1/k! for the Taylor terms of sin (k odd, 3..17) and cos (k even, 2..18), with
/// their signs; 18! < 2⁵³ is exact in a double, so each is correctly rounded.
constexpr double signed_inv_factorial(int k) {
    double f = 1.0;
    for (int j = 2; j <= k; ++j) f *= j;
    return ((k / 2) % 2 ? -1.0 : 1.0) / f;
}
} // namespace detail

inline Rotation rotation(double theta) {
    using detail::signed_inv_factorial;
    if (!(std::abs(theta) <= 0.7853981633974483)) return {std::cos(theta), std::sin(theta)};
    const double z = theta * theta;
    // sin θ = θ (1 + z P(z)), cos θ = 1 + z Q(z), by Horner from the highest term.
    constexpr double s17 = signed_inv_factorial(17), s15 = signed_inv_factorial(15), s13 = signed_inv_factorial(13),
                     s11 = signed_inv_factorial(11), s9 = signed_inv_factorial(9), s7 = signed_inv_factorial(7),
                     s5 = signed_inv_factorial(5), s3 = signed_inv_factorial(3);
    constexpr double c18 = signed_inv_factorial(18), c16 = signed_inv_factorial(16), c14 = signed_inv_factorial(14),
                     c12 = signed_inv_factorial(12), c10 = signed_inv_factorial(10), c8 = signed_inv_factorial(8),
                     c6 = signed_inv_factorial(6), c4 = signed_inv_factorial(4), c2 = signed_inv_factorial(2);
    const double p = s3 + z * (s5 + z * (s7 + z * (s9 + z * (s11 + z * (s13 + z * (s15 + z * s17))))));
    const double q = c2 + z * (c4 + z * (c6 + z * (c8 + z * (c10 + z * (c12 + z * (c14 + z * (c16 + z * c18)))))));
    return {1.0 + z * q, theta + theta * (z * p)};
}

/// Signed area; positive for a counter-clockwise polygon.
inline double signed_area(std::span<const Vec2> p) {
    double a2 = 0.0;
    const std::size_t n = p.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) a2 += cross(p[j], p[i]);
    return 0.5 * a2;
}

/// Area centroid of a simple polygon of either orientation.
inline Vec2 centroid(std::span<const Vec2> p) {
    // Shift to the first vertex so that the sums stay well conditioned far from the origin.
    const Vec2 o = p[0];
    double a2 = 0.0;
    Vec2 c{};
    const std::size_t n = p.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const Vec2 pj = p[j] - o, pi = p[i] - o;
        const double w = cross(pj, pi);
        a2 += w;
        c += w * (pj + pi);
    }
    return o + c / (3.0 * a2);
}

/// Polar second moment of area about the centroid, ∫(x² + y²) dA (unit density),
/// for a counter-clockwise polygon; multiply by density for the rotational inertia.
inline double polar_moment_about_centroid(std::span<const Vec2> p) {
    const Vec2 c = centroid(p);
    double j12 = 0.0;
    const std::size_t n = p.size();
    for (std::size_t i = 0, k = n - 1; i < n; k = i++) {
        const Vec2 a = p[k] - c, b = p[i] - c;
        j12 += cross(a, b) * (dot(a, a) + dot(a, b) + dot(b, b));
    }
    return j12 / 12.0;
}

struct Box2 {
    Vec2 lo{+INFINITY, +INFINITY};
    Vec2 hi{-INFINITY, -INFINITY};
    void add(Vec2 p) {
        lo = {p.x < lo.x ? p.x : lo.x, p.y < lo.y ? p.y : lo.y};
        hi = {p.x > hi.x ? p.x : hi.x, p.y > hi.y ? p.y : hi.y};
    }
    bool empty() const { return lo.x > hi.x; }
    double width() const { return hi.x - lo.x; }
    double height() const { return hi.y - lo.y; }
};

inline Box2 bounding_box(std::span<const Vec2> p) {
    Box2 b;
    for (Vec2 q : p) b.add(q);
    return b;
}

/// Even-odd point-in-polygon test; points on the boundary may go either way.
inline bool point_in_polygon(Vec2 q, std::span<const Vec2> p) {
    bool inside = false;
    const std::size_t n = p.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        if ((p[i].y > q.y) != (p[j].y > q.y)) {
            const double xc = p[j].x + (q.y - p[j].y) * (p[i].x - p[j].x) / (p[i].y - p[j].y);
            if (q.x < xc) inside = !inside;
        }
    }
    return inside;
}

/// Distance from q to the segment [a, b].
inline double distance_to_segment(Vec2 q, Vec2 a, Vec2 b) {
    const Vec2 ab = b - a;
    const double l2 = norm2(ab);
    double t = l2 > 0.0 ? dot(q - a, ab) / l2 : 0.0;
    t = std::fmin(1.0, std::fmax(0.0, t));
    return norm(q - (a + t * ab));
}

} // namespace bbm
