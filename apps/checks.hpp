// bbm apps: validators for numeric command-line options that a person can read.
//
// CLI11's PositiveNumber and Range let NaN through (every comparison with NaN is
// false) and print their bounds as 300-digit numbers; an unsigned option takes
// "-3" as 2^64 - 3. These refuse NaN, infinities and signs that do not belong, and
// say what the option must be in the option's own terms: "--ks: must be a finite
// number > 0, got nan". CLI11 prefixes the option name; main() exits with status 2.
#pragma once

#include "base/bounds.hpp"
#include "base/error.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace bbm::cli {

namespace detail {
/// The text as a finite double; false for NaN, infinities and what is not a number.
inline bool parse_finite(const std::string& text, double& value) {
    std::istringstream in(text);
    in >> value;
    std::string rest;
    return !in.fail() && !(in >> rest) && std::isfinite(value);
}

inline std::string shortest(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

/// A finite number for which `ok` holds, else "must be a finite number <what>, got <text>".
template <class Ok>
CLI::Validator finite_number(std::string what, Ok ok) {
    return CLI::Validator(
        [what, ok](std::string& text) -> std::string {
            double v = 0;
            if (parse_finite(text, v) && ok(v)) return {};
            return "must be a finite number " + what + ", got " + text;
        },
        what);
}
} // namespace detail

/// A finite number > 0.
inline CLI::Validator positive() {
    return detail::finite_number("> 0", [](double v) { return v > 0; });
}

/// A finite number >= 0.
inline CLI::Validator non_negative() {
    return detail::finite_number(">= 0", [](double v) { return v >= 0; });
}

/// A finite number in [lo, hi].
inline CLI::Validator in_range(double lo, double hi) {
    return detail::finite_number("in [" + detail::shortest(lo) + ", " + detail::shortest(hi) + "]",
                                 [lo, hi](double v) { return v >= lo && v <= hi; });
}

/// A finite number within the bounds a model-file key declares (base/bounds.hpp):
/// "must be a finite number in [0, 90) degrees, got 95".
inline CLI::Validator within(const Bounds& b) {
    return detail::finite_number(b.text(), [b](double v) { return b.contains(v); });
}

/// A whole number within the bounds.
inline CLI::Validator whole_within(const Bounds& b) {
    return CLI::Validator(
        [b](std::string& text) -> std::string {
            std::size_t used = 0;
            long long v = 0;
            try {
                v = std::stoll(text, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used == text.size() && !text.empty() && b.contains(double(v))) return {};
            return "must be a whole number " + b.text() + ", got " + text;
        },
        b.text());
}

/// A whole number >= lo (for counts and seeds held in unsigned or int options:
/// refuses "-3" before an unsigned parse wraps it around).
inline CLI::Validator whole_at_least(long long lo) {
    return whole_within(at_least(double(lo), ""));
}

/// Parses option strings (the Python module's keywords) with a command's option
/// definitions; a parse error becomes an InputError naming the command and what
/// CLI11 said (the flag). Returns whether an output folder was asked for.
inline bool parse_args(CLI::App& app, const std::string& command, const std::vector<std::string>& args) {
    std::vector<std::string> reversed(args.rbegin(), args.rend()); // CLI11 takes them last first
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw InputError(command, 0, "", e.what());
    }
    bool has_out = false;
    for (const auto& a : args) has_out = has_out || a == "--out" || a == "-o";
    return has_out;
}

} // namespace bbm::cli
