// The bars of a support table (core/supports/bars.hpp).
#include "core/supports/bars.hpp"

#include "base/bounds.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace bbm {

namespace {

BarRing read_ring(TableReader& t) {
    static constexpr std::array<std::string_view, 7> keys{"center", "radius", "length", "count",
                                                          "spacing", "from",  "to"};
    t.check_keys(keys, "a ring of bolts");
    BarRing r;
    r.center = t.required_point("center");
    r.radius = t.required_number("radius", above(0, metres));
    r.length = t.required_number("length", above(0, metres));
    const auto count = t.integer("count", between(1, 100000, ""));
    const auto spacing = t.number("spacing", above(0, metres));
    if (count.has_value() == spacing.has_value())
        t.fail("", "give the bolts' 'count' or their 'spacing' along the wall (one of them)");
    r.count = int(count.value_or(0));
    r.spacing = spacing.value_or(0.0);
    r.from = t.number("from", unbounded(degrees)).value_or(0.0);
    r.to = t.number("to", unbounded(degrees)).value_or(r.from + 360.0);
    if (!(r.to > r.from) || r.to - r.from > 360.0 + 1e-9)
        t.fail("", "'to' must be above 'from' by at most 360 degrees, got from " + shortest_text(r.from) + " to " +
                       shortest_text(r.to));
    t.check_length_resolves("radius", r.radius);
    t.check_length_resolves("length", r.length);
    return r;
}

} // namespace

void read_bars(TableReader& t, std::string_view what, std::vector<std::array<Vec2, 2>>& bars,
               std::optional<BarRing>& ring) {
    if (auto given = t.segments("bolts", std::string(what) + " [[x1, y1], [x2, y2]] (head, toe)", "head and toe"))
        bars = std::move(*given);
    if (auto table = t.table("ring", "a table {center, radius, length, count or spacing, from, to}"))
        ring = read_ring(*table);
    if (bars.empty() && !ring)
        t.fail("", t.owner() + "no " + std::string(what) + ": give 'bolts' (head and toe of each) or a 'ring' around "
                                                         "an opening");
}

std::vector<std::array<Vec2, 2>> expand_bars(const std::vector<std::array<Vec2, 2>>& bars,
                                             const std::optional<BarRing>& ring) {
    std::vector<std::array<Vec2, 2>> out = bars;
    if (!ring) return out;
    const auto& r = *ring;
    const double span = r.to - r.from;
    const bool full = std::abs(std::abs(span) - 360.0) < 1e-9;
    int count = r.count;
    if (count <= 0 && r.spacing > 0.0) {
        const double arc = std::abs(span) * std::numbers::pi / 180.0 * r.radius;
        count = std::max(1, int(std::floor(arc / r.spacing + 1e-9)) + (full ? 0 : 1));
    }
    for (int k = 0; k < count; ++k) {
        // A full circle: count intervals; an arc: bolts at both of its ends.
        const double f = full ? double(k) / count : (count > 1 ? double(k) / (count - 1) : 0.5);
        const double a = (r.from + f * span) * std::numbers::pi / 180.0;
        const Vec2 u{std::cos(a), std::sin(a)};
        out.push_back({r.center + r.radius * u, r.center + (r.radius + r.length) * u});
    }
    return out;
}

} // namespace bbm
