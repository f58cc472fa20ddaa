// The figures of docs/validation.md, as the tests that assert them measure them.
//
// A verification or validation test calls record_check() with what it compares,
// the reference (a closed form, the paper, a laboratory record, a field
// measurement) and its source, the tolerance it asserts and the value it
// measured. In a build without sanitizers (tests/CMakeLists.txt defines
// BBM_VALIDATION_DIR: build/validation; the environment variable of that name
// overrides it) each record is written there as one JSON file named after the
// test case and the quantity; tests/validation_report.py gathers them into docs/validation.md and
// the test `validation.report` fails when the committed page differs from what
// the tests measured. The record is written whether or not the check passed: the
// page says which.
#pragma once

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <functional>

namespace bbm::test {

/// What a figure is checked against: the groups of docs/validation.md.
enum class Against { closed_form, paper, laboratory, field };

/// The test case running now and its file (set by tests/main.cpp's listener).
inline std::string current_test_case, current_test_file;

namespace detail {
inline std::string json_text(std::string_view s) {
    std::string out = "\"";
    for (const char ch : s) {
        if (ch == '"' || ch == '\\') out += '\\';
        if (ch == '\n') {
            out += "\\n";
            continue;
        }
        out += ch;
    }
    return out + "\"";
}
} // namespace detail

/// One row of docs/validation.md. `what`: the quantity and case ("E of the square
/// lattice"); `reference`: the reference value or formula and its source;
/// `tolerance`: the bound the test asserts; `measured`: the figure as measured;
/// `within`: whether it held. A test with several rows gives each its own `what`.
inline void record_check(Against against, std::string_view what, std::string_view reference,
                         std::string_view tolerance, std::string_view measured, bool within) {
    const char* dir = std::getenv("BBM_VALIDATION_DIR");
#ifdef BBM_VALIDATION_DIR
    if (dir == nullptr) dir = BBM_VALIDATION_DIR;
#endif
    if (dir == nullptr || *dir == '\0') return;
    // One file per row: the test case and the row's name, made safe for a file name.
    std::string name;
    for (const char ch : current_test_case + " -- " + std::string(what))
        name += (std::isalnum(static_cast<unsigned char>(ch)) != 0) ? ch : '_';
    if (name.size() > 180) name = name.substr(0, 180) + std::to_string(std::hash<std::string>{}(name) % 100000);
    static constexpr const char* groups[] = {"closed form", "paper", "laboratory", "field"};
    const std::string text =
        "{\"against\": " + detail::json_text(groups[static_cast<int>(against)]) +
        ", \"what\": " + detail::json_text(what) + ", \"reference\": " + detail::json_text(reference) +
        ", \"tolerance\": " + detail::json_text(tolerance) + ", \"measured\": " + detail::json_text(measured) +
        ", \"within\": " + (within ? "true" : "false") + ", \"test\": " + detail::json_text(current_test_case) +
        ", \"file\": " + detail::json_text(current_test_file) + "}\n";
    if (std::FILE* f = std::fopen((std::string(dir) + "/" + name + ".json").c_str(), "w")) {
        std::fputs(text.c_str(), f);
        std::fclose(f);
    }
}

/// A figure with `digits` significant digits ("20.3", "0.0042").
inline std::string figure(double v, int digits = 3) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    return buffer;
}

/// A relative difference as a signed percentage with `digits` significant digits ("+1.2%").
inline std::string percent(double measured, double reference, int digits = 2) {
    const double d = 100.0 * (measured / reference - 1.0);
    return (d >= 0 ? "+" : "") + figure(d, digits) + "%";
}

} // namespace bbm::test
