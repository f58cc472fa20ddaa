// bbm base: the allowed values of a number and how to say them ("in [0, 90)
// degrees", "> 0 Pa"), shared by the model-file reader (io/reader.hpp, its Range)
// and the command-line flags (apps/checks.hpp), so that a key and the flag
// made from it accept the same values and refuse them in the same words.
#pragma once

#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

namespace bbm {

/// Shortest text that reads back as the same double, so "-0.3" stays "-0.3".
inline std::string shortest_text(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return {buf, r.ptr};
}

/// An interval of allowed values, open or closed at each end, and its unit
/// (" Pa", with its leading space, or empty) for messages.
struct Bounds {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false, hi_open = false;
    std::string_view unit;

    constexpr bool contains(double v) const {
        return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    }
    /// "> 0 Pa", ">= 1", "in [0, 90) degrees"; empty when unbounded.
    std::string text() const {
        if (std::isinf(hi))
            return std::isinf(lo) ? "" : (lo_open ? "> " : ">= ") + shortest_text(lo) + std::string(unit);
        return "in " + std::string(lo_open ? "(" : "[") + shortest_text(lo) + ", " + shortest_text(hi) +
               (hi_open ? ")" : "]") + std::string(unit);
    }
};

constexpr Bounds unbounded(std::string_view unit) { return {.unit = unit}; }
constexpr Bounds above(double lo, std::string_view unit) { return {.lo = lo, .lo_open = true, .unit = unit}; }
constexpr Bounds at_least(double lo, std::string_view unit) { return {.lo = lo, .unit = unit}; }
constexpr Bounds below(double lo, double hi, std::string_view unit) {
    return {.lo = lo, .hi = hi, .hi_open = true, .unit = unit};
}
constexpr Bounds between(double lo, double hi, std::string_view unit) {
    return {.lo = lo, .hi = hi, .unit = unit};
}

// The units as messages print them.
constexpr std::string_view pascals = " Pa";
constexpr std::string_view pascals_per_metre = " Pa/m";
constexpr std::string_view metres = " m";
constexpr std::string_view joules_per_square_metre = " J/m2";
constexpr std::string_view degrees = " degrees";

} // namespace bbm
