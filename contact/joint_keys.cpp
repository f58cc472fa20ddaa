// The keys of a [[joint_property]], gathered from the laws (contact/joint_keys.hpp).
#include "contact/joint_keys.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace bbm::contact {

namespace {

/// Each law's keys, in the order of JointLaw's alternatives.
constexpr auto keys_of_laws = []<std::size_t... I>(std::index_sequence<I...>) {
    return std::array<std::span<const JointKey* const>, sizeof...(I)>{
        std::span<const JointKey* const>(std::variant_alternative_t<I, JointLaw>::keys)...};
}(std::make_index_sequence<std::variant_size_v<JointLaw>>{});

struct Gathered {
    std::vector<const JointKey*> keys;
    std::vector<std::string_view> names;
    Gathered() {
        for (const auto law : keys_of_laws)
            for (const JointKey* k : law)
                if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k), names.push_back(k->key);
    }
};
const Gathered& gathered() {
    static const Gathered g;
    return g;
}

} // namespace

std::span<const JointKey* const> joint_keys() { return gathered().keys; }
std::span<const std::string_view> joint_key_names() { return gathered().names; }

const JointKey* find_joint_key(std::string_view key) {
    for (const JointKey* k : joint_keys())
        if (k->key == key) return k;
    return nullptr;
}

std::span<const JointKey* const> law_keys(std::string_view law) {
    const std::size_t k = law_index(law);
    return k < keys_of_laws.size() ? keys_of_laws[k] : std::span<const JointKey* const>{};
}

std::vector<std::string_view> law_key_names(std::string_view law) {
    std::vector<std::string_view> out;
    for (const JointKey* k : law_keys(law)) out.push_back(k->key);
    return out;
}

std::optional<KeyProblem> check_joint_property(const JointPropertySpec& j) {
    constexpr auto checks = []<std::size_t... I>(std::index_sequence<I...>) {
        return std::array<std::optional<KeyProblem> (*)(const JointPropertySpec&), sizeof...(I)>{
            &std::variant_alternative_t<I, JointLaw>::check...};
    }(std::make_index_sequence<std::variant_size_v<JointLaw>>{});
    const std::size_t k = law_index(j.law);
    if (k >= checks.size()) return KeyProblem{"law", "unknown joint law '" + j.law + "'"};
    return checks[k](j);
}

void law_parameters(const JointPropertySpec& j, std::vector<double>& out) {
    out.push_back(double(law_index(j.law)));
    for (const JointKey* k : law_keys(j.law)) {
        if (k->get) out.push_back(k->get(j));
        if (k->get_curve) {
            const auto& curve = k->get_curve(j);
            out.push_back(double(curve.size()));
            for (const auto& [alpha, beta] : curve) out.insert(out.end(), {alpha, beta});
        }
    }
}

std::string joint_keys_markdown() {
    std::string md =
        "# [[joint_property]] keys\n\n"
        "Generated from the laws' key declarations (contact/laws/, gathered by contact/joint_keys.hpp) by "
        "tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the test fails when it is stale). The keys "
        "marked as flags are the lab tests', `bbm calibrate`'s and `bbm shear`'s rock flags (`friction` is "
        "`--friction`, with the same bounds), and so are the Python module's keywords.\n\n"
        "| key | value | if absent | flag | laws | meaning |\n|---|---|---|---|---|---|\n";
    for (const JointKey* k : joint_keys()) {
        std::string laws;
        for (std::size_t l = 0; l < law_names.size(); ++l)
            if (std::find(keys_of_laws[l].begin(), keys_of_laws[l].end(), k) != keys_of_laws[l].end())
                laws += (laws.empty() ? "" : ", ") + std::string(law_names[l]);
        const std::string value = k->kind == KeyKind::choice && k->key == "law"
                                      ? [] {
                                            std::string w = "word:";
                                            for (auto n : law_names) w += " " + std::string(n);
                                            return w;
                                        }()
                                      : key_value_text(k->kind, k->bounds);
        md += "| `" + std::string(k->key) + "` | " + value + " | " +
              (k->required ? std::string("required") : std::string(k->absent)) + " | " +
              (k->flag ? key_flag(k->key) : std::string()) + " | " + laws + " | " + std::string(k->meaning) + " |\n";
    }
    return md;
}

} // namespace bbm::contact
