// bbm base: the declaration of a model-file key — its kind, unit and allowed values,
// what it means and what its absence means, and the field of the spec it fills.
//
// A table of these per section (contact/joint_keys.hpp for [[joint_property]],
// core/material_keys.hpp for [[material]], core/flow_keys.hpp for [flow]) is what the
// reader checks a file by, what
// the command-line flags of the same values are made from (apps/flags.hpp,
// apps/flags.hpp add_key_flags; those marked `flag` are a lab test's rock's) and what the key reference in docs/reference/ is generated from,
// so the three cannot drift apart.
#pragma once

#include "base/bounds.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bbm {

/// How a key's value is written in the model file.
enum class KeyKind {
    text,    ///< a string (the set's name)
    choice,  ///< one of a list of words (the law)
    number,  ///< a number within `bounds`
    integer, ///< a whole number within `bounds`
    boolean, ///< true or false
    curve,   ///< an array of points [[alpha, beta], ...]
    point,   ///< [x, y]
    names,   ///< an array of names of other tables (regions)
    segments, ///< an array of segments [[[x1, y1], [x2, y2]], ...] (bars' two ends)
    numbers, ///< an array of numbers (a list of angles)
    table,   ///< an inline table of its own keys (a ring of bars)
    rows,    ///< an array of rows of numbers [[a, b, c], ...] (a path through a stage)
};

template <class Spec>
struct Key {
    std::string_view key;
    KeyKind kind = KeyKind::number;
    Bounds bounds;
    /// Required by every user of the table that reads it (kn, ks; jrc, jcs of Barton-Bandis).
    bool required = false;
    /// The types of table it belongs to, comma-separated ("excavate, pressurise" of
    /// a [[stage]]); empty: every table of the section.
    std::string_view only;
    std::string_view meaning;
    /// What leaving it out means (the reference's "if absent" column).
    std::string_view absent;
    /// A choice's words, comma-separated, in the order of the spec's enumeration.
    std::string_view words;
    /// The field of a number, integer or boolean key.
    double (*get)(const Spec&) = nullptr;
    void (*set)(Spec&, double) = nullptr;
    /// A lab test's rock takes it as a flag (`--<key>`, and a Python keyword):
    /// said in its declaration, not by a list of the command's.
    bool flag = false;
    /// The flag's name when not `--<key>` (a pattern's `type` is `--pattern`).
    std::string_view flag_name;
    /// The field of a curve key: points [[x, y], ...].
    const std::vector<std::pair<double, double>>& (*get_curve)(const Spec&) = nullptr;
    void (*set_curve)(Spec&, std::vector<std::pair<double, double>>) = nullptr;
};

/// A table's declaration of a key; nullptr if there is none.
template <class Spec, std::size_t N>
constexpr const Key<Spec>* find_key(const Key<Spec> (&table)[N], std::string_view key) {
    for (const Key<Spec>& k : table)
        if (k.key == key) return &k;
    return nullptr;
}

/// The value column of a key reference: "number > 0 Pa", "whole number in [1, 1000]".
inline std::string key_value_text(KeyKind kind, const Bounds& b) {
    switch (kind) {
    case KeyKind::text: return "string";
    case KeyKind::choice: return "word";
    case KeyKind::boolean: return "true / false";
    case KeyKind::curve: return b.unit.empty() ? "[[α, β], ...]" : "[[x, y], ...]" + std::string(b.unit);
    case KeyKind::point: return "[x, y]" + (b.unit.empty() ? std::string() : std::string(b.unit));
    case KeyKind::names: return "array of names";
    case KeyKind::segments: return "[[[x1, y1], [x2, y2]], ...]" + std::string(b.unit);
    case KeyKind::table: return "table";
    case KeyKind::rows: return "[[a, b, c], ...]";
    case KeyKind::numbers: return "array of numbers" + (b.text().empty() ? std::string(b.unit) : " " + b.text());
    case KeyKind::integer: return "whole number " + b.text();
    case KeyKind::number: break;
    }
    // An unbounded number still names its unit ("number, m").
    const std::string range = b.text();
    if (!range.empty()) return "number " + range;
    const std::string_view unit = b.unit.starts_with(' ') ? b.unit.substr(1) : b.unit;
    return unit.empty() ? std::string("number") : "number, " + std::string(unit);
}

/// The words of a comma-separated list ("steady, transient"), in order.
inline std::vector<std::string_view> key_words(std::string_view list) {
    std::vector<std::string_view> words;
    while (!list.empty()) {
        const auto comma = list.find(',');
        words.push_back(list.substr(0, comma));
        list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
        while (list.starts_with(' ')) list.remove_prefix(1);
    }
    return words;
}

/// Does a key belong to a table of type `type` (its `only` names it, or is empty)?
template <class Spec>
bool key_applies(const Key<Spec>& k, std::string_view type) {
    if (k.only.empty()) return true;
    for (const std::string_view w : key_words(k.only))
        if (w == type) return true;
    return false;
}

/// A key reference's table: `| key | value | if absent | meaning |`, with a column
/// `only_heading` of each key's `only` ("every" when empty) after the key if given.
template <class Spec, std::size_t N>
std::string key_table_markdown(const Key<Spec> (&table)[N], std::string_view only_heading = "") {
    const bool only = !only_heading.empty();
    std::string md = only ? "| key | " + std::string(only_heading) + " | value | if absent | meaning |\n|---|---|---|---|---|\n"
                          : std::string("| key | value | if absent | meaning |\n|---|---|---|---|\n");
    for (const Key<Spec>& k : table) {
        md += "| `" + std::string(k.key) + "` | ";
        if (only) md += (k.only.empty() ? std::string("every") : std::string(k.only)) + " | ";
        md += (k.kind == KeyKind::choice && !k.words.empty() ? "word: " + std::string(k.words)
                                                             : key_value_text(k.kind, k.bounds)) +
              " | " + (k.required ? std::string("required") : std::string(k.absent)) + " | " + std::string(k.meaning) +
              " |\n";
    }
    return md;
}

/// The flag of a key: `--` and the key with dashes (`residual_friction` is
/// `--residual-friction`), after `prefix` (`bbm shear`'s plane: `joint-`) unless
/// the key already starts with it.
inline std::string key_flag(std::string_view key, std::string_view prefix = "") {
    std::string k(key);
    for (char& ch : k)
        if (ch == '_') ch = '-';
    return "--" + std::string(k.starts_with(prefix) ? "" : prefix) + k;
}

} // namespace bbm

/// The get and set of a curve key's field.
#define BBM_CURVE_FIELD(Spec, field)                                                                   \
    .get_curve = [](const Spec& s) -> const std::vector<std::pair<double, double>>& { return s.field; }, \
    .set_curve = [](Spec& s, std::vector<std::pair<double, double>> v) { s.field = std::move(v); }

/// The get and set of a key's field, for a table's rows.
#define BBM_KEY_FIELD(Spec, field)                                                                   \
    .get = [](const Spec& s) { return double(s.field); },                                            \
    .set = [](Spec& s, double v) { s.field = static_cast<decltype(s.field)>(v); }
