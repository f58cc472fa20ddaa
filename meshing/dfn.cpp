// Discrete fracture networks (dfn.hpp): sampling, termination, clipping, statistics.
#include "meshing/dfn.hpp"

#include "meshing/detail.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace bbm::meshing {

namespace {

constexpr double deg = std::numbers::pi / 180.0;

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::numbers::sqrt2); }

/// A standard normal number (Box–Muller, one of the pair).
double standard_normal(detail::Random& rng) {
    double u = rng.uniform();
    while (u <= 0.0) u = rng.uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * rng.uniform());
}

struct LogNormal {
    double mu, sigma;
};
LogNormal lognormal_of(const FractureLengthSpec& s) {
    const double v = std::log(1.0 + (s.std_dev * s.std_dev) / (s.mean * s.mean));
    return {std::log(s.mean) - 0.5 * v, std::sqrt(v)};
}

double upper(const FractureLengthSpec& s, double diagonal) {
    using K = FractureLengthSpec::Kind;
    if (s.kind == K::fixed) return s.value;
    return s.max > 0.0 ? s.max : diagonal;
}

/// The probability mass of the untruncated law inside [min, max].
double kept_mass(const FractureLengthSpec& s, double diagonal) {
    using K = FractureLengthSpec::Kind;
    const double hi = upper(s, diagonal);
    if (s.kind == K::lognormal) {
        const auto [mu, sigma] = lognormal_of(s);
        const double lo = s.min > 0.0 ? normal_cdf((std::log(s.min) - mu) / sigma) : 0.0;
        return normal_cdf((std::log(hi) - mu) / sigma) - lo;
    }
    if (s.kind == K::exponential) return std::exp(-s.min / s.mean) - std::exp(-hi / s.mean);
    return 1.0;
}

double sample_length(const FractureLengthSpec& s, double diagonal, detail::Random& rng) {
    using K = FractureLengthSpec::Kind;
    const double hi = upper(s, diagonal);
    switch (s.kind) {
    case K::fixed: return s.value;
    case K::power_law: {
        const double u = rng.uniform(), a = s.exponent;
        if (std::abs(a - 1.0) < 1e-12) return s.min * std::pow(hi / s.min, u);
        const double p = std::pow(s.min, 1.0 - a), q = std::pow(hi, 1.0 - a);
        return std::pow(p + u * (q - p), 1.0 / (1.0 - a));
    }
    case K::exponential: { // inverse CDF of the truncated law
        const double ea = std::exp(-s.min / s.mean), eb = std::exp(-hi / s.mean);
        return -s.mean * std::log(ea - rng.uniform() * (ea - eb));
    }
    case K::lognormal: { // rejection: kept_mass() >= 0.1% was checked
        const auto [mu, sigma] = lognormal_of(s);
        for (;;) {
            const double l = std::exp(mu + sigma * standard_normal(rng));
            if (l >= s.min && l <= hi) return l;
        }
    }
    }
    return s.value;
}

/// Best & Fisher (1979): θ − mean from the von Mises law of concentration κ > 0,
/// in (−π, π].
double sample_von_mises(double kappa, detail::Random& rng) {
    const double a = 1.0 + std::sqrt(1.0 + 4.0 * kappa * kappa);
    const double b = (a - std::sqrt(2.0 * a)) / (2.0 * kappa);
    const double r = (1.0 + b * b) / (2.0 * b);
    for (;;) {
        const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        const double z = std::cos(std::numbers::pi * u1);
        const double f = (1.0 + r * z) / (r + z);
        const double c = kappa * (r - f);
        if (c * (2.0 - c) - u2 > 0.0 || (u2 > 0.0 && std::log(c / u2) + 1.0 - c >= 0.0))
            return (u3 > 0.5 ? 1.0 : -1.0) * std::acos(std::clamp(f, -1.0, 1.0));
    }
}

/// A trace angle in degrees: von Mises folded into mean ± 90°, uniform in [0, 180),
/// or from the list.
double sample_angle(const FractureOrientationSpec& s, detail::Random& rng) {
    using K = FractureOrientationSpec::Kind;
    if (s.kind == K::uniform || (s.kind == K::von_mises && s.concentration <= 0.0)) {
        const double lo = s.kind == K::uniform ? 0.0 : s.mean - 90.0;
        return lo + 180.0 * rng.uniform();
    }
    if (s.kind == K::list) {
        double total = 0.0;
        for (std::size_t i = 0; i < s.angles.size(); ++i) total += s.weights.empty() ? 1.0 : s.weights[i];
        double u = rng.uniform() * total;
        for (std::size_t i = 0; i < s.angles.size(); ++i) {
            u -= s.weights.empty() ? 1.0 : s.weights[i];
            if (u < 0.0) return s.angles[i];
        }
        return s.angles.back();
    }
    double d = sample_von_mises(s.concentration, rng) / deg; // (−180, 180]
    if (d >= 90.0) d -= 180.0;
    if (d < -90.0) d += 180.0;
    return s.mean + d;
}

/// Parameter t in (0, 1) where segment pq crosses segment ab (proper crossing), or −1.
double crossing(Vec2 a, Vec2 b, Vec2 p, Vec2 q) {
    const Vec2 d = b - a, e = q - p;
    const double den = cross(d, e);
    if (std::abs(den) <= 1e-300) return -1.0;
    const double t = cross(p - a, e) / den, u = cross(p - a, d) / den;
    return (t > 0.0 && t < 1.0 && u >= 0.0 && u <= 1.0) ? t : -1.0;
}

/// κ of the von Mises law whose mean resultant length is r (Best & Fisher's
/// approximation of A1⁻¹).
double concentration_of(double r) {
    if (r < 0.53) return 2.0 * r + r * r * r + 5.0 * std::pow(r, 5) / 6.0;
    if (r < 0.85) return -0.4 + 1.39 * r + 0.43 / (1.0 - r);
    return 1.0 / (r * r * r - 4.0 * r * r + 3.0 * r);
}

Box2 box_of(const cgal::Domain& d) {
    Box2 b;
    for (const auto& p : d)
        for (Vec2 q : p.outer) b.add(q);
    return b;
}

/// Crossings per metre of `lines` scanlines along direction `along` (0: x, 1: y)
/// evenly spread over the box, each clipped to the domain.
double scanline_p10(const std::vector<SegmentSpec>& traces, const cgal::Domain& domain, const Box2& box, int along) {
    constexpr int lines = 24;
    double length = 0.0;
    long hits = 0;
    for (int k = 0; k < lines; ++k) {
        const double f = (k + 0.5) / lines;
        const Vec2 a = along == 0 ? Vec2{box.lo.x, box.lo.y + f * box.height()} : Vec2{box.lo.x + f * box.width(), box.lo.y};
        const Vec2 b = along == 0 ? Vec2{box.hi.x, a.y} : Vec2{a.x, box.hi.y};
        for (const auto& piece : dfn::clip_to_domain(a, b, domain)) {
            length += norm(piece.b - piece.a);
            for (const auto& t : traces) hits += crossing(piece.a, piece.b, t.a, t.b) >= 0.0;
        }
    }
    return length > 0.0 ? double(hits) / length : 0.0;
}

FractureSetStats measure(const DfnSetSpec& spec, const std::vector<Fracture>& fractures, int set,
                         const std::vector<SegmentSpec>& traces, const cgal::Domain& domain, double area,
                         double diagonal) {
    FractureSetStats st;
    st.name = spec.name;
    st.source = spec.file.empty() ? "generated" : spec.file + (spec.import_note.empty() ? "" : " (" + spec.import_note + ")");
    st.area = area;
    const Box2 box = box_of(domain);
    double c2 = 0.0, s2 = 0.0, sum = 0.0, sum2 = 0.0;
    std::vector<double> angles;
    for (const auto& f : fractures) {
        if (f.set != set || !detail::domain_contains(domain, 0.5 * (f.a + f.b))) continue;
        ++st.fractures;
        const double l = norm(f.b - f.a), th = std::atan2(f.b.y - f.a.y, f.b.x - f.a.x);
        sum += l, sum2 += l * l;
        c2 += std::cos(2.0 * th), s2 += std::sin(2.0 * th);
        angles.push_back(th);
    }
    if (st.fractures > 0) {
        const double n = st.fractures;
        st.mean_length = sum / n;
        st.std_length = n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * st.mean_length * st.mean_length) / (n - 1))) : 0.0;
        const double mean = 0.5 * std::atan2(s2, c2);
        st.mean_angle = std::fmod(mean / deg + 180.0, 180.0);
        double r = 0.0; // the deviations folded into ±90° (axial data)
        for (double th : angles) {
            double d = std::remainder(th - mean, std::numbers::pi);
            r += std::cos(d);
        }
        st.concentration = concentration_of(std::clamp(r / n, 0.0, 0.999999));
    }
    st.p20 = area > 0.0 ? st.fractures / area : 0.0;
    double total = 0.0;
    for (const auto& t : traces) total += norm(t.b - t.a);
    st.traces = int(traces.size());
    st.p21 = area > 0.0 ? total / area : 0.0;
    st.mean_trace = traces.empty() ? 0.0 : total / double(traces.size());
    st.p10_x = scanline_p10(traces, domain, box, 0);
    st.p10_y = scanline_p10(traces, domain, box, 1);
    if (spec.traces.empty()) {
        st.mean_length_target = dfn::mean_length(spec.length, diagonal);
        // Given as a count, the asked P21 is λ E[L] with λ = count / area.
        st.p21_target = spec.p21 > 0.0 ? spec.p21 : double(spec.count) / area * st.mean_length_target;
    }
    return st;
}

} // namespace

namespace dfn {

double mean_length(const FractureLengthSpec& s, double diagonal) {
    using K = FractureLengthSpec::Kind;
    const double hi = upper(s, diagonal), lo = s.min;
    switch (s.kind) {
    case K::fixed: return s.value;
    case K::power_law: {
        const double a = s.exponent;
        if (std::abs(a - 1.0) < 1e-12) return (hi - lo) / std::log(hi / lo);
        if (std::abs(a - 2.0) < 1e-12) return std::log(hi / lo) / (1.0 / lo - 1.0 / hi);
        return (1.0 - a) / (2.0 - a) * (std::pow(hi, 2.0 - a) - std::pow(lo, 2.0 - a)) /
               (std::pow(hi, 1.0 - a) - std::pow(lo, 1.0 - a));
    }
    case K::exponential: {
        const double m = s.mean, ea = std::exp(-lo / m), eb = std::exp(-hi / m);
        return ((lo + m) * ea - (hi + m) * eb) / (ea - eb);
    }
    case K::lognormal: {
        const auto [mu, sigma] = lognormal_of(s);
        const double za = lo > 0.0 ? (std::log(lo) - mu) / sigma : -INFINITY, zb = (std::log(hi) - mu) / sigma;
        return std::exp(mu + 0.5 * sigma * sigma) * (normal_cdf(zb - sigma) - normal_cdf(za - sigma)) /
               (normal_cdf(zb) - normal_cdf(za));
    }
    }
    return s.value;
}

double length_cdf(const FractureLengthSpec& s, double diagonal, double x) {
    using K = FractureLengthSpec::Kind;
    const double hi = upper(s, diagonal), lo = s.min;
    if (x < lo) return 0.0;
    if (x >= hi) return 1.0;
    switch (s.kind) {
    case K::fixed: return x >= s.value ? 1.0 : 0.0;
    case K::power_law: {
        const double a = s.exponent;
        if (std::abs(a - 1.0) < 1e-12) return std::log(x / lo) / std::log(hi / lo);
        return (std::pow(x, 1.0 - a) - std::pow(lo, 1.0 - a)) / (std::pow(hi, 1.0 - a) - std::pow(lo, 1.0 - a));
    }
    case K::exponential: {
        const double ea = std::exp(-lo / s.mean);
        return (ea - std::exp(-x / s.mean)) / (ea - std::exp(-hi / s.mean));
    }
    case K::lognormal: {
        const auto [mu, sigma] = lognormal_of(s);
        const double fa = lo > 0.0 ? normal_cdf((std::log(lo) - mu) / sigma) : 0.0;
        return (normal_cdf((std::log(x) - mu) / sigma) - fa) / (normal_cdf((std::log(hi) - mu) / sigma) - fa);
    }
    }
    return 0.0;
}

double angle_cdf(const FractureOrientationSpec& s, double x) {
    using K = FractureOrientationSpec::Kind;
    if (s.kind == K::list) {
        double total = 0.0, below = 0.0;
        for (std::size_t i = 0; i < s.angles.size(); ++i) {
            const double w = s.weights.empty() ? 1.0 : s.weights[i];
            total += w;
            if (s.angles[i] <= x) below += w;
        }
        return below / total;
    }
    const double lo = s.kind == K::uniform ? 0.0 : s.mean - 90.0;
    const double f = std::clamp((x - lo) / 180.0, 0.0, 1.0);
    if (s.kind == K::uniform || s.concentration <= 0.0) return f;
    // The folded density ∝ exp(κ cos d) + exp(−κ cos d) on d in [−90°, 90°):
    // Simpson's rule (the normalisation the same way over the whole range).
    auto integral = [&](double to) {
        constexpr int n = 2000;
        const double a = -0.5 * std::numbers::pi, h = (to - a) / n;
        auto g = [&](double d) { return std::exp(s.concentration * (std::cos(d) - 1.0)) + std::exp(-s.concentration * (std::cos(d) + 1.0)); };
        double sum = g(a) + g(to);
        for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * g(a + i * h);
        return sum * h / 3.0;
    };
    return integral((x - s.mean) * deg) / integral(0.5 * std::numbers::pi);
}

std::vector<SegmentSpec> clip_to_domain(Vec2 a, Vec2 b, const cgal::Domain& domain) {
    std::vector<double> ts{0.0, 1.0};
    auto ring = [&](const std::vector<Vec2>& r) {
        for (std::size_t i = 0; i < r.size(); ++i) {
            const Vec2 p = r[i], q = r[(i + 1) % r.size()];
            const Vec2 d = b - a, e = q - p;
            const double den = cross(d, e);
            if (std::abs(den) <= 1e-300) continue;
            const double t = cross(p - a, e) / den, u = cross(p - a, d) / den;
            if (t > 0.0 && t < 1.0 && u >= 0.0 && u <= 1.0) ts.push_back(t);
        }
    };
    for (const auto& p : domain) {
        ring(p.outer);
        for (const auto& h : p.holes) ring(h);
    }
    std::sort(ts.begin(), ts.end());
    std::vector<SegmentSpec> out;
    for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
        if (ts[i + 1] - ts[i] <= 1e-12) continue;
        const Vec2 p = a + ts[i] * (b - a), q = a + ts[i + 1] * (b - a);
        if (!detail::domain_contains(domain, 0.5 * (p + q))) continue;
        if (!out.empty() && out.back().b == p) out.back().b = q; // a crossing at a vertex
        else out.push_back({p, q});
    }
    return out;
}

} // namespace dfn

namespace dfn {
SetSize expected_size(const DfnSetSpec& s, const cgal::Domain& domain) {
    if (!s.traces.empty()) return {double(s.traces.size()), 0.0};
    const Box2 box = box_of(domain);
    const double diagonal = norm(box.hi - box.lo), area = cgal::area(domain);
    const double mean = mean_length(s.length, diagonal), longest = upper(s.length, diagonal);
    const double density = s.p21 > 0.0 ? s.p21 / mean : double(s.count) / area;
    return {density * (box.width() + longest) * (box.height() + longest), density * mean};
}
} // namespace dfn

namespace {

/// The centres of a set's fractures in the box `grown`: n Poisson points, or a
/// Thomas process (cluster centres uniform over the box grown by 4σ more, each
/// fracture about a random cluster's centre; those landing outside the grown box
/// are dropped, which keeps the density stationary inside).
std::vector<Vec2> set_centres(const DfnSetSpec& s, const Box2& grown, long n, detail::Random& rng) {
    std::vector<Vec2> centre(n);
    if (s.centres == DfnSetSpec::Centres::poisson) {
        for (auto& c : centre) c = {rng.uniform(grown.lo.x, grown.hi.x), rng.uniform(grown.lo.y, grown.hi.y)};
        return centre;
    }
    const double r = s.cluster_radius;
    Box2 wide = grown;
    wide.lo = wide.lo - Vec2{4 * r, 4 * r};
    wide.hi = wide.hi + Vec2{4 * r, 4 * r};
    const double scale = wide.width() * wide.height() / (grown.width() * grown.height());
    const long clusters = std::max(1L, std::lround(double(n) * scale / s.cluster_size));
    std::vector<Vec2> parent(clusters);
    for (auto& p : parent) p = {rng.uniform(wide.lo.x, wide.hi.x), rng.uniform(wide.lo.y, wide.hi.y)};
    centre.clear();
    const long total = std::lround(double(n) * scale);
    for (long i = 0; i < total; ++i) {
        const Vec2 p = parent[std::min<long>(clusters - 1, long(rng.uniform() * double(clusters)))];
        const Vec2 c = p + r * Vec2{standard_normal(rng), standard_normal(rng)};
        if (c.x >= grown.lo.x && c.x <= grown.hi.x && c.y >= grown.lo.y && c.y <= grown.hi.y) centre.push_back(c);
    }
    return centre;
}

/// Set k's fractures [first, end) terminated at the earlier sets it names: out
/// from each fracture's centre along each half, the crossings in order; at each,
/// the fracture ends there with probability p.
void terminate_at_older_sets(FractureNetwork& net, const DfnSetSpec& s, const std::vector<int>& set_first, int first,
                             double cell, detail::Random& rng) {
    std::vector<std::pair<Vec2, Vec2>> older;
    std::vector<int> older_index; // each one's index in net.fractures
    for (int j : s.terminate_at)
        for (int i = set_first[j]; i < set_first[j + 1]; ++i) {
            older.push_back({net.fractures[i].a, net.fractures[i].b});
            older_index.push_back(i);
        }
    if (older.empty()) return;
    const detail::SegmentGrid grid(std::move(older), cell);
    std::vector<int> near;
    std::vector<std::pair<double, int>> ts; // crossing parameter, the fracture crossed
    for (int i = first; i < int(net.fractures.size()); ++i) {
        Fracture& f = net.fractures[i];
        Box2 fb;
        fb.add(f.a);
        fb.add(f.b);
        near.clear();
        grid.for_each_near(fb, [&](int j) { near.push_back(j); });
        std::sort(near.begin(), near.end());
        near.erase(std::unique(near.begin(), near.end()), near.end());
        ts.clear();
        for (int j : near) {
            const auto& [p, q] = grid.segments()[j];
            if (const double t = crossing(f.a, f.b, p, q); t >= 0.0) ts.push_back({t, older_index[j]});
        }
        std::sort(ts.begin(), ts.end());
        double hi = 1.0, lo = 0.0;
        for (const auto& [t, j] : ts) // the half towards b, outwards from the centre
            if (t > 0.5 && rng.uniform() < s.terminate_probability) { hi = t, f.b_at = j; break; }
        for (auto it = ts.rbegin(); it != ts.rend(); ++it) // the half towards a
            if (it->first < 0.5 && rng.uniform() < s.terminate_probability) { lo = it->first, f.a_at = it->second; break; }
        const Vec2 a = f.a, d = f.b - f.a;
        f.a = a + lo * d, f.b = a + hi * d;
    }
}

/// The traces: each fracture clipped to the region (one crossing no part of it
/// leaves none); per set, its traces.
std::vector<std::vector<SegmentSpec>> clip_network(FractureNetwork& net, std::size_t set_count, const Box2& box,
                                                   const cgal::Domain& domain) {
    std::vector<std::vector<SegmentSpec>> per_set(set_count);
    for (int i = 0; i < int(net.fractures.size()); ++i) {
        const Fracture& f = net.fractures[std::size_t(i)];
        Box2 fb;
        fb.add(f.a);
        fb.add(f.b);
        if (fb.hi.x < box.lo.x || fb.lo.x > box.hi.x || fb.hi.y < box.lo.y || fb.lo.y > box.hi.y) continue;
        for (const auto& piece : dfn::clip_to_domain(f.a, f.b, domain)) {
            net.traces.push_back(piece);
            net.trace_set.push_back(f.set);
            net.trace_fracture.push_back(i);
            per_set[f.set].push_back(piece);
        }
    }
    return per_set;
}

} // namespace

FractureNetwork generate_fracture_network(std::span<const DfnSetSpec> sets, const cgal::Domain& domain) {
    FractureNetwork net;
    const Box2 box = box_of(domain);
    const double diagonal = norm(box.hi - box.lo), area = cgal::area(domain);
    std::vector<int> set_first; // fractures of set k: [set_first[k], set_first[k + 1])
    for (int k = 0; k < int(sets.size()); ++k) {
        const DfnSetSpec& s = sets[k];
        set_first.push_back(int(net.fractures.size()));
        if (!s.traces.empty()) {
            for (const auto& t : s.traces) net.fractures.push_back({t.a, t.b, k, t.a, t.b});
            continue;
        }
        if (kept_mass(s.length, diagonal) < 1e-3)
            throw std::invalid_argument("fracture set '" + s.name +
                                        "': its length law keeps under 0.1% of its mass within [min, max]");
        detail::Random rng(s.seed);
        const double mean = dfn::mean_length(s.length, diagonal);
        const double longest = upper(s.length, diagonal);
        const double density = s.p21 > 0.0 ? s.p21 / mean : double(s.count) / area; // centres per m²
        // Every fracture that can reach the region has its centre in the box grown
        // by half the longest one.
        Box2 grown = box;
        grown.lo = grown.lo - Vec2{0.5 * longest, 0.5 * longest};
        grown.hi = grown.hi + Vec2{0.5 * longest, 0.5 * longest};
        const long n = std::lround(density * grown.width() * grown.height()); // dfn::expected_size
        for (const Vec2 c : set_centres(s, grown, n, rng)) {
            const double th = sample_angle(s.orientation, rng) * deg, l = sample_length(s.length, diagonal, rng);
            const Vec2 h = 0.5 * l * Vec2{std::cos(th), std::sin(th)};
            net.fractures.push_back({c - h, c + h, k, c - h, c + h});
        }
        if (s.terminate_probability > 0.0 && !s.terminate_at.empty())
            terminate_at_older_sets(net, s, set_first, set_first[k], std::max(mean, 1e-6 * diagonal), rng);
    }
    set_first.push_back(int(net.fractures.size()));
    const auto per_set = clip_network(net, sets.size(), box, domain);
    for (int k = 0; k < int(sets.size()); ++k)
        net.stats.push_back(measure(sets[k], net.fractures, k, per_set[k], domain, area, diagonal));
    return net;
}

} // namespace bbm::meshing
