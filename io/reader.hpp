// bbm io: the helpers every section reader of the model file uses (internal).
//
// A section of the model file ([[region]], [[stage]], ...) is read by its own
// file on these: a Path beside every node (its full dotted key for messages and
// its key inside a region for ModelSource), a Ctx that fails with file, line and
// key, typed conversions with ranges, key checks with "did you mean", and the
// names of tables with the references between them. Only io/ includes it.
#pragma once

#include "base/bounds.hpp"
#include "base/keys.hpp"
#include "base/table_reader.hpp"
#include "io/model_input.hpp"

// toml++ 3.3 asserts in its parser a condition that input can break (toml::parse_key
// entered on a table header "[[:" — found by fuzz_model) and then reports the
// syntax error itself. Release builds compile its asserts out (NDEBUG); so does the
// checking build, for toml++ alone, so that such a file gets the same error there
// ("TOML syntax error: ... saw ':'", file and line) instead of an abort. bbm's and
// CGAL's assertions stay on.
#ifndef TOML_ASSERT
#define TOML_ASSERT(expr) static_assert(true)
#endif
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bbm::io::reader {

using Keys = std::span<const std::string_view>;

// --- text helpers ----------------------------------------------------------------

/// Shortest text that reads back as the same double, so "-0.3" stays "-0.3".
inline std::string fmt(double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return {buf, r.ptr};
}

/// A computed value, to 6 significant digits: 2.1 - 0.6 shows as 1.5.
inline std::string fmt6(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

inline std::string fmt(Vec2 p) {
    return "[" + fmt(p.x) + ", " + fmt(p.y) + "]";
}

inline std::string quoted(std::string_view s) {
    return "'" + std::string(s) + "'";
}

inline std::string join(Keys words) {
    std::string s;
    for (std::string_view w : words)
        s += (s.empty() ? "" : ", ") + std::string(w);
    return s;
}

/// Optimal string alignment distance: Levenshtein plus adjacent transpositions,
/// so that "szie" is one edit from "size".
inline int edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::vector<int>> d(a.size() + 1, std::vector<int>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i)
        d[i][0] = static_cast<int>(i);
    for (std::size_t j = 0; j <= b.size(); ++j)
        d[0][j] = static_cast<int>(j);
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    }
    return d[a.size()][b.size()];
}

/// " (did you mean 'size'?)" for the closest option within two edits, else "".
/// A word must be longer than the distance, or any short word would match.
inline std::string did_you_mean(std::string_view word, Keys options) {
    int best = 3;
    std::string_view match;
    for (std::string_view o : options) {
        const int d = edit_distance(word, o);
        if (d < best && d < static_cast<int>(word.size())) best = d, match = o;
    }
    return match.empty() ? "" : " (did you mean " + quoted(match) + "?)";
}

inline std::string describe(const toml::node& n) {
    switch (n.type()) {
    case toml::node_type::string:
        return "string \"" + n.as_string()->get() + "\"";
    case toml::node_type::integer:
        return "integer " + std::to_string(n.as_integer()->get());
    case toml::node_type::floating_point:
        return "float " + fmt(n.as_floating_point()->get());
    case toml::node_type::boolean:
        return n.as_boolean()->get() ? "boolean true" : "boolean false";
    case toml::node_type::array:
        return "an array";
    case toml::node_type::table:
        return "a table";
    default:
        return "a date or time";
    }
}

inline int line(const toml::node& n) {
    return static_cast<int>(n.source().begin.line);
}

// --- where we are ----------------------------------------------------------------

struct Path {
    std::string full; ///< for messages: "region[1].pattern.size"
    std::string rel;  ///< inside the region, for ModelSource: "pattern.size"

    Path key(std::string_view k) const {
        const std::string s(k);
        return {full.empty() ? s : full + "." + s, rel.empty() ? s : rel + "." + s};
    }
    Path at(std::size_t i) const {
        const std::string s = "[" + std::to_string(i) + "]";
        return {full + s, rel + s};
    }
};

struct Ctx {
    std::string file;
    ModelSource* source = nullptr;
    int region = -1; ///< region being read, -1 outside regions
    /// The named table being read, for messages: "region 'bonded'", "boundary 'top'".
    std::string owner;
    /// The model's extent and block size once its regions are read: every point
    /// and box of the analysis tables is checked against it (ModelScale::near).
    const ModelScale* scale = nullptr;

    [[noreturn]] void fail(int at_line, const Path& p, const std::string& message) const {
        throw InputError(file, at_line, p.full, message);
    }
    [[noreturn]] void fail(const toml::node& n, const Path& p, const std::string& message) const {
        fail(line(n), p, message);
    }
    void note(const Path& p, const toml::node& n) const {
        if (region >= 0) {
            if (!p.rel.empty()) source->key_line[region][p.rel] = line(n);
        } else if (!p.full.empty()) {
            source->analysis_line[p.full] = line(n);
        }
    }
    /// "region 'bonded': " inside a named table, for messages where the index alone
    /// would make the user count tables.
    std::string in_owner() const { return owner.empty() ? "" : owner + ": "; }
};

// --- value conversions: a node at path p to a C++ value, or an error at its line ----

inline double to_number(const Ctx& c, const toml::node& n, const Path& p) {
    double v;
    if (const auto* i = n.as_integer())
        v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point())
        v = f->get();
    else
        c.fail(n, p, "expected a number, got " + describe(n));
    if (!std::isfinite(v)) c.fail(n, p, "expected a finite number, got " + fmt(v));
    return v;
}

inline Vec2 to_vec2(const Ctx& c, const toml::node& n, const Path& p) {
    const auto* a = n.as_array();
    if (!a) c.fail(n, p, "expected a point [x, y], got " + describe(n));
    if (a->size() != 2)
        c.fail(n, p,
               "expected a point [x, y] of 2 numbers, got an array of " +
                   std::to_string(a->size()));
    return {to_number(c, (*a)[0], p.at(0)), to_number(c, (*a)[1], p.at(1))};
}

inline const toml::table& to_table(const Ctx& c, const toml::node& n, const Path& p,
                            std::string_view expected) {
    const auto* t = n.as_table();
    if (!t) c.fail(n, p, "expected " + std::string(expected) + ", got " + describe(n));
    return *t;
}

inline const toml::array& to_array(const Ctx& c, const toml::node& n, const Path& p,
                            std::string_view expected) {
    const auto* a = n.as_array();
    if (!a) c.fail(n, p, "expected " + std::string(expected) + ", got " + describe(n));
    return *a;
}

inline std::string to_str(const Ctx& c, const toml::node& n, const Path& p) {
    const auto* s = n.as_string();
    if (!s) c.fail(n, p, "expected a string, got " + describe(n));
    return s->get();
}

// --- keys of a table ---------------------------------------------------------------

/// Rejects keys outside `allowed`. A key in `elsewhere` (valid for another kind of
/// the same table) is reported as not applying to `kind`. The key reported is the
/// first in the file, as toml++ iterates a table in key order.
inline void check_keys(const Ctx& c, const toml::table& t, const Path& p, Keys allowed,
                Keys elsewhere = {}, std::string_view kind = {}) {
    const toml::key* bad = nullptr;
    for (auto&& [k, v] : t) {
        if (std::ranges::find(allowed, k.str()) != allowed.end()) continue;
        if (!bad || k.source().begin.line < bad->source().begin.line) bad = &k;
    }
    if (!bad) return;
    const std::string_view k = bad->str();
    const int at = static_cast<int>(bad->source().begin.line);
    if (std::ranges::find(elsewhere, k) != elsewhere.end())
        c.fail(at, p.key(k),
               "key " + quoted(k) + " does not apply to " + std::string(kind) +
                   "; its keys are: " + join(allowed));
    const std::string where = p.full.empty() ? "at top level" : "in " + p.full;
    c.fail(at, p.key(k),
           "unknown key " + quoted(k) + " " + where + did_you_mean(k, allowed) +
               "; allowed keys: " + join(allowed));
}

/// The child `key` of t, its line noted; nullptr when absent.
inline const toml::node* find(const Ctx& c, const toml::table& t, const Path& p, std::string_view key) {
    const toml::node* n = t.get(key);
    if (n) c.note(p.key(key), *n);
    return n;
}

inline const toml::node& need(const Ctx& c, const toml::table& t, const Path& p, std::string_view key,
                       std::string_view expected) {
    const toml::node* n = find(c, t, p, key);
    if (!n)
        c.fail(t, p.key(key),
               c.in_owner() + "missing required key " + quoted(key) + ": expected " +
                   std::string(expected));
    return *n;
}

/// Allowed values of a number and its unit (base/bounds.hpp: the flags share them).
using Range = Bounds;
using bbm::above, bbm::at_least, bbm::below, bbm::between, bbm::unbounded;
using bbm::degrees, bbm::metres, bbm::pascals, bbm::pascals_per_metre;

inline double checked_number(const Ctx& c, const toml::node& n, const Path& p, const Range& r) {
    const double v = to_number(c, n, p);
    if (!r.contains(v)) c.fail(n, p, "must be " + r.text() + ", got " + fmt(v));
    return v;
}

inline std::optional<double> number(const Ctx& c, const toml::table& t, const Path& p,
                             std::string_view key, const Range& r) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    return checked_number(c, *n, p.key(key), r);
}

inline double required_number(const Ctx& c, const toml::table& t, const Path& p, std::string_view key,
                       const Range& r) {
    const std::string expected = "a number" + (r.text().empty() ? "" : " " + r.text());
    return checked_number(c, need(c, t, p, key, expected), p.key(key), r);
}

/// An integer >= lo; `hi` only guards the C++ type it is stored in.
inline std::int64_t to_integer(const Ctx& c, const toml::node& n, const Path& p, std::int64_t lo,
                        std::int64_t hi) {
    const auto* i = n.as_integer();
    if (!i) c.fail(n, p, "expected an integer >= " + std::to_string(lo) + ", got " + describe(n));
    if (i->get() < lo)
        c.fail(n, p,
               "must be an integer >= " + std::to_string(lo) + ", got " + std::to_string(i->get()));
    if (i->get() > hi)
        c.fail(n, p,
               "must be an integer <= " + std::to_string(hi) + ", got " + std::to_string(i->get()));
    return i->get();
}

/// A whole number within declared bounds (a key of contact/joint_keys.hpp): "must
/// be a whole number in [1, 1000], got 0", as its flag says it.
inline std::int64_t to_whole_number(const Ctx& c, const toml::node& n, const Path& p, const Bounds& b) {
    const auto* i = n.as_integer();
    if (!i) c.fail(n, p, "expected a whole number " + b.text() + ", got " + describe(n));
    if (!b.contains(double(i->get())))
        c.fail(n, p, "must be a whole number " + b.text() + ", got " + std::to_string(i->get()));
    return i->get();
}

/// A whole number within `b`, if the key is there.
inline std::optional<std::int64_t> whole_number(const Ctx& c, const toml::table& t, const Path& p, std::string_view key,
                                                const Bounds& b) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    return to_whole_number(c, *n, p.key(key), b);
}

inline std::optional<std::int64_t> integer(const Ctx& c, const toml::table& t, const Path& p,
                                    std::string_view key, std::int64_t lo, std::int64_t hi) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    return to_integer(c, *n, p.key(key), lo, hi);
}

inline std::int64_t required_integer(const Ctx& c, const toml::table& t, const Path& p,
                              std::string_view key, std::int64_t lo, std::int64_t hi) {
    const toml::node& n = need(c, t, p, key, "an integer >= " + std::to_string(lo));
    return to_integer(c, n, p.key(key), lo, hi);
}

inline std::optional<std::uint64_t> seed(const Ctx& c, const toml::table& t, const Path& p) {
    const auto s = integer(c, t, p, "seed", 0, std::numeric_limits<std::int64_t>::max());
    if (!s) return std::nullopt;
    return static_cast<std::uint64_t>(*s);
}

inline std::optional<bool> boolean(const Ctx& c, const toml::table& t, const Path& p,
                            std::string_view key) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    const auto* b = n->as_boolean();
    if (!b) c.fail(*n, p.key(key), "expected true or false, got " + describe(*n));
    return b->get();
}

/// "the point (x, y) lies far outside the model ...": a position in another unit.
inline std::string far_from_model(const ModelScale& scale, const std::string& what) {
    return what + " lies far outside the model (its regions span " + fmt(scale.extent.lo) + " to " +
           fmt(scale.extent.hi) + "): a position in another unit? Give it in metres";
}

/// A position [x, y]: near the model once its regions are read (Ctx::scale).
inline Vec2 to_position(const Ctx& c, const toml::node& n, const Path& p) {
    const Vec2 v = to_vec2(c, n, p);
    if (c.scale && !c.scale->near(v)) c.fail(n, p, far_from_model(*c.scale, "the point " + fmt(v)));
    return v;
}

/// A vector [x, y] (gravity): any direction and size.
inline std::optional<Vec2> vector(const Ctx& c, const toml::table& t, const Path& p, std::string_view key) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    return to_vec2(c, *n, p.key(key));
}

inline std::optional<Vec2> point(const Ctx& c, const toml::table& t, const Path& p, std::string_view key) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return std::nullopt;
    return to_position(c, *n, p.key(key));
}

inline Vec2 required_point(const Ctx& c, const toml::table& t, const Path& p, std::string_view key) {
    return to_position(c, need(c, t, p, key, "a point [x, y]"), p.key(key));
}

/// Index of the string at node n in `options`; `what` names the choice.
inline std::size_t to_choice(const Ctx& c, const toml::node& n, const Path& p, Keys options,
                      std::string_view what) {
    const std::string s = to_str(c, n, p);
    const auto it = std::ranges::find(options, s);
    if (it == options.end())
        c.fail(n, p,
               "unknown " + std::string(what) + " " + quoted(s) + did_you_mean(s, options) +
                   "; expected one of: " + join(options));
    return static_cast<std::size_t>(it - options.begin());
}

/// Index of the string value of the required `key` in `options`.
inline std::size_t choice(const Ctx& c, const toml::table& t, const Path& p, std::string_view key,
                   Keys options, std::string_view what) {
    return to_choice(c, need(c, t, p, key, "one of " + join(options)), p.key(key), options, what);
}

/// Each element of an array-valued key, with its path and its line noted.
template <class F> void for_each_element(const Ctx& c, const toml::array& a, const Path& p, F&& f) {
    for (std::size_t i = 0; i < a.size(); ++i) {
        c.note(p.at(i), a[i]);
        f(a[i], p.at(i));
    }
}


// --- names of tables -----------------------------------------------------------

inline std::string article(std::string_view word) {
    return std::string(std::string_view("aeiou").find(word.front()) == std::string_view::npos
                           ? "a "
                           : "an ") +
           std::string(word);
}

/// The names of one kind of table, for uniqueness and for references to them.
struct Names {
    std::string_view what;   ///< "joint property"
    std::string_view plural; ///< "joint properties"
    std::string_view table;  ///< "joint_property": the key of its tables
    std::vector<std::string> names;
    std::vector<int> lines; ///< line of each table

    std::vector<std::string_view> views() const { return {names.begin(), names.end()}; }
    bool has(std::string_view s) const { return std::ranges::find(names, s) != names.end(); }
};

/// A new name for `names`: not used before. `at` is the line of its key.
inline void add_name(const Ctx& c, Names& names, const std::string& name, int at, const Path& np,
              int table_line) {
    for (std::size_t j = 0; j < names.names.size(); ++j)
        if (names.names[j] == name)
            c.fail(at, np,
                   std::string(names.what) + " name " + quoted(name) + " is already used by " +
                       std::string(names.table) + "[" + std::to_string(j) + "] (line " +
                       std::to_string(names.lines[j]) + ")");
    names.names.push_back(name);
    names.lines.push_back(table_line);
}

/// The required, non-empty, unique `name` of a table; it becomes the owner in messages.
inline std::string read_name(Ctx& c, const toml::table& t, const Path& p, Names& names) {
    const Path np = p.key("name");
    const toml::node& n = need(c, t, p, "name", "a non-empty string");
    std::string s = to_str(c, n, np);
    if (s.empty()) c.fail(n, np, "must be a non-empty string, got \"\"");
    add_name(c, names, s, line(n), np, line(t));
    c.owner = std::string(names.what) + " " + quoted(s);
    return s;
}

/// `name` must be one of `known`.
inline void check_ref(const Ctx& c, int at, const Path& p, std::string_view name, const Names& known) {
    if (known.has(name)) return;
    const std::string head = "unknown " + std::string(known.what) + " " + quoted(name);
    const auto v = known.views();
    if (v.empty())
        c.fail(at, p, head + ": the file has no [[" + std::string(known.table) + "]] tables");
    c.fail(at, p,
           head + did_you_mean(name, v) + "; " + std::string(known.plural) + " are: " + join(v));
}

/// The array of strings `key` (required or not): not empty, no repeats, each
/// checked by f(string, node, path). `if_absent` says what leaving it out means.
template <class F>
inline std::vector<std::string> string_list(const Ctx& c, const toml::table& t, const Path& p,
                                     std::string_view key, std::string_view what,
                                     std::string_view if_absent, F&& f) {
    std::vector<std::string> list;
    const std::string expected = "an array of " + std::string(what) + " names";
    const toml::node* n = if_absent.empty()
                              ? &need(c, t, p, key, "a non-empty " + expected.substr(3))
                              : find(c, t, p, key);
    if (!n) return list;
    const Path kp = p.key(key);
    const toml::array& a = to_array(c, *n, kp, expected);
    if (a.empty())
        c.fail(*n, kp,
               "must list at least one " + std::string(what) + ", got an empty array" +
                   (if_absent.empty()
                        ? ""
                        : "; leave " + quoted(key) + " out " + std::string(if_absent)));
    for_each_element(c, a, kp, [&](const toml::node& e, const Path& ep) {
        std::string s = to_str(c, e, ep);
        f(s, e, ep);
        if (const auto it = std::ranges::find(list, s); it != list.end())
            c.fail(e, ep,
                   quoted(s) + " is already listed as " + std::string(key) + "[" +
                       std::to_string(it - list.begin()) + "]");
        list.push_back(std::move(s));
    });
    return list;
}

inline std::vector<std::string> name_list(const Ctx& c, const toml::table& t, const Path& p,
                                   std::string_view key, const Names& known,
                                   std::string_view if_absent) {
    return string_list(c, t, p, key, known.what, if_absent,
                       [&](const std::string& s, const toml::node& e, const Path& ep) {
                           check_ref(c, line(e), ep, s, known);
                       });
}

/// Each table of the top-level array `key` ([[key]] sections), read by f(table, path).
template <class F> void read_tables(Ctx& c, const toml::table& doc, std::string_view key, F&& f) {
    const Path kp = Path{}.key(key);
    const toml::node* n = find(c, doc, Path{}, key);
    if (!n) return;
    const std::string what = "[[" + std::string(key) + "]]";
    const toml::array& a = to_array(c, *n, kp, "an array of " + what + " tables (double brackets)");
    for (std::size_t i = 0; i < a.size(); ++i) {
        c.note(kp.at(i), a[i]);
        c.owner.clear();
        f(to_table(c, a[i], kp.at(i), "a " + what + " table"), kp.at(i), i);
    }
    c.owner.clear();
}

/// A box { min = [x, y], max = [x, y] } with max above min in x and y.
inline Box2 read_box(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a box { min = [x, y], max = [x, y] }");
    static constexpr std::array<std::string_view, 2> keys{"min", "max"};
    check_keys(c, t, p, keys);
    Box2 b;
    // Its corners may lie far out (a box taking all of one side): the box as a whole is checked.
    b.lo = to_vec2(c, need(c, t, p, "min", "a point [x, y]"), p.key("min"));
    b.hi = to_vec2(c, need(c, t, p, "max", "a point [x, y]"), p.key("max"));
    if (!(b.hi.x > b.lo.x && b.hi.y > b.lo.y))
        c.fail(*t.get("max"), p.key("max"),
               "must exceed min = " + fmt(b.lo) + " in both x and y, got " + fmt(b.hi));
    if (c.scale && !c.scale->near(b))
        c.fail(node, p, far_from_model(*c.scale, "the box " + fmt(b.lo) + " to " + fmt(b.hi)));
    return b;
}

// --- stress fields (boundaries and initialize stages) -----------------------------


constexpr std::array<std::string_view, 7> stress_keys{"sxx",     "syy",     "sxy",    "y_ref",
                                                      "dsxx_dy", "dsyy_dy", "dsxy_dy"};

inline StressFieldSpec read_stress(const Ctx& c, const toml::table& t, const Path& p) {
    StressFieldSpec s;
    s.sxx = number(c, t, p, "sxx", unbounded(pascals)).value_or(0.0);
    s.syy = number(c, t, p, "syy", unbounded(pascals)).value_or(0.0);
    s.sxy = number(c, t, p, "sxy", unbounded(pascals)).value_or(0.0);
    s.y_ref = number(c, t, p, "y_ref", unbounded(metres)).value_or(0.0);
    s.dsxx_dy = number(c, t, p, "dsxx_dy", unbounded(pascals_per_metre)).value_or(0.0);
    s.dsyy_dy = number(c, t, p, "dsyy_dy", unbounded(pascals_per_metre)).value_or(0.0);
    s.dsxy_dy = number(c, t, p, "dsxy_dy", unbounded(pascals_per_metre)).value_or(0.0);
    return s;
}

/// The names of a table's keys (base/keys.hpp), for check_keys.
template <class Spec, std::size_t N>
constexpr std::array<std::string_view, N> key_names(const Key<Spec> (&table)[N]) {
    std::array<std::string_view, N> names;
    for (std::size_t i = 0; i < N; ++i) names[i] = table[i].key;
    return names;
}

/// The keys of `table` that belong to type `type`, for check_keys.
template <class Spec, std::size_t N>
std::vector<std::string_view> keys_of_type(const Key<Spec> (&table)[N], std::string_view type) {
    std::vector<std::string_view> keys;
    for (const Key<Spec>& k : table)
        if (key_applies(k, type)) keys.push_back(k.key);
    return keys;
}

/// The bounds a key is read with: its declaration's.
template <class Spec, std::size_t N>
const Bounds& bounds_of(const Key<Spec> (&table)[N], std::string_view key) {
    return find_key(table, key)->bounds;
}

/// A table whose keys depend on a word in it (a stage's `type`, a length law's
/// `distribution`): the word's index among its row's words, once the table is
/// checked to have only that word's keys ("key 'lloyd' does not apply to a
/// hexagonal pattern"). `what` names the word in an error ("pattern type"), `noun`
/// the table ("pattern").
template <class Spec, std::size_t N>
std::size_t read_typed_keys(const Ctx& c, const toml::table& t, const Path& p, const Key<Spec> (&table)[N],
                            std::string_view type_key, std::string_view what, std::string_view noun) {
    const auto words = key_words(find_key(table, type_key)->words);
    const std::size_t i = choice(c, t, p, type_key, words, what);
    std::vector<std::string_view> all;
    for (const Key<Spec>& k : table) all.push_back(k.key);
    check_keys(c, t, p, keys_of_type(table, words[i]), all, article(words[i]) + " " + std::string(noun));
    return i;
}

/// A number, integer or boolean key as its table declares it: its bounds, required or left
/// at the spec's default.
template <class Spec>
void read_declared_key(const Ctx& c, const toml::table& t, const Path& p, const Key<Spec>& k, Spec& spec) {
    if (k.kind == KeyKind::integer) {
        if (const toml::node* n = k.required ? &need(c, t, p, k.key, "a whole number " + k.bounds.text())
                                             : find(c, t, p, k.key))
            k.set(spec, double(to_whole_number(c, *n, p.key(k.key), k.bounds)));
    } else if (k.kind == KeyKind::boolean) {
        if (const auto v = boolean(c, t, p, k.key)) k.set(spec, *v ? 1.0 : 0.0);
    } else if (k.required) {
        k.set(spec, required_number(c, t, p, k.key, k.bounds));
    } else if (const auto v = number(c, t, p, k.key, k.bounds)) {
        k.set(spec, *v);
    }
}

// --- section readers (one file each) ---------------------------------------------

/// Every registered support type's tables (io/read_supports.cpp), each by its
/// type's own reader; their names, unique over all types, to `names`.
void read_supports(Ctx& c, const toml::table& doc, SupportSpecs& specs, Names& names, const ModelScale& scale);
/// A [[history]] table and a [[stage]] table (io/read_stages.cpp).
HistorySpec read_history(Ctx& c, const toml::table& t, const Path& p, Names& names, const Names& boundaries);
StageSpec read_stage(Ctx& c, const toml::table& t, const Path& p, std::size_t index, Names& names,
                     const Names& regions, const Names& supports);
/// One [[region.dfn]] table (io/read_dfn.cpp); `earlier` holds the names of the
/// region's sets before it, and gets its name.
meshing::DfnSetSpec read_dfn_set(Ctx& c, const toml::node& node, const Path& p, std::vector<std::string>& earlier,
                                 const meshing::OutlineSpec& outline);
/// [flow], [[flow_boundary]] and [[flow_source]] (io/read_flow.cpp).
void read_flow(Ctx& c, const toml::table& doc, FlowSpec& flow, const Names& regions);

} // namespace bbm::io::reader
