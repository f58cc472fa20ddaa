// bbm base: the declaration of a model-file key — its kind, unit and allowed values,
// what it means and what its absence means, and the field of the spec it fills.
//
// A table of these per section (contact/joint_keys.hpp for [[joint_property]],
// core/material_keys.hpp for [[material]], core/flow_keys.hpp for [flow]) is what the
// reader checks a file by, what
// the command-line flags of the same values are made from (studies/commands.hpp,
// add_key_flags) and what the key reference in docs/reference/ is generated from,
// so the three cannot drift apart.
#pragma once

#include "base/bounds.hpp"

#include <cstddef>
#include <string>
#include <string_view>

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
};

template <class Spec>
struct Key {
    std::string_view key;
    KeyKind kind = KeyKind::number;
    Bounds bounds;
    /// Required by every user of the table that reads it (kn, ks; jrc, jcs of Barton-Bandis).
    bool required = false;
    std::string_view meaning;
    /// What leaving it out means (the reference's "if absent" column).
    std::string_view absent;
    /// A choice's words, comma-separated, in the order of the spec's enumeration.
    std::string_view words;
    /// The field of a number, integer or boolean key.
    double (*get)(const Spec&) = nullptr;
    void (*set)(Spec&, double) = nullptr;
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
    case KeyKind::curve: return "[[α, β], ...]";
    case KeyKind::point: return "[x, y]" + (b.unit.empty() ? std::string() : std::string(b.unit));
    case KeyKind::names: return "array of names";
    case KeyKind::integer: return "whole number " + b.text();
    case KeyKind::number: break;
    }
    // An unbounded number still names its unit ("number, m").
    const std::string range = b.text();
    if (!range.empty()) return "number " + range;
    const std::string_view unit = b.unit.starts_with(' ') ? b.unit.substr(1) : b.unit;
    return unit.empty() ? std::string("number") : "number, " + std::string(unit);
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

/// The get and set of a key's field, for a table's rows.
#define BBM_KEY_FIELD(Spec, field)                                                                   \
    .get = [](const Spec& s) { return double(s.field); },                                            \
    .set = [](Spec& s, double v) { s.field = static_cast<decltype(s.field)>(v); }
