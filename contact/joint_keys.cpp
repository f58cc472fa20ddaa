#include "contact/joint_keys.hpp"

#include "contact/joint_law.hpp"

#include <algorithm>
#include <array>
#include <tuple>
#include <utility>

namespace bbm::contact {

namespace {
/// Each law's keys, in the order of JointLaw's alternatives.
constexpr auto keys_of_laws = []<std::size_t... I>(std::index_sequence<I...>) {
    return std::array<std::span<const std::string_view>, sizeof...(I)>{
        std::span<const std::string_view>(std::variant_alternative_t<I, JointLaw>::keys)...};
}(std::make_index_sequence<std::variant_size_v<JointLaw>>{});

/// Every key a law reads is declared.
constexpr bool every_law_key_declared() {
    for (const auto keys : keys_of_laws)
        for (const std::string_view k : keys)
            if (!find_joint_key(k)) return false;
    return true;
}
static_assert(every_law_key_declared(), "a law reads a key joint_keys does not declare");

} // namespace

std::span<const std::string_view> law_keys(JointPropertySpec::Law law) {
    return keys_of_laws[static_cast<std::size_t>(law)];
}

std::optional<KeyProblem> check_joint_property(const JointPropertySpec& j) {
    using Law = JointPropertySpec::Law;
    if (j.law == Law::softening) {
        for (const auto& [key, value, curve] : {std::tuple{"cohesion", j.cohesion, "shear softening"},
                                                std::tuple{"tensile", j.tensile, "tension softening"}})
            if (!(value > 0))
                return KeyProblem{key, "a softening law needs " + std::string(key) + " > 0 Pa, the peak the " + curve +
                                           " curve is normalised by; got " + shortest_text(value)};
        for (const auto& [key, energy, curve, name] :
             {std::tuple{"tension_fracture_energy", j.tension_fracture_energy, &j.tension_softening, "tension_softening"},
              std::tuple{"shear_fracture_energy", j.shear_fracture_energy, &j.shear_softening, "shear_softening"}})
            if (energy > 0.0 && curve->empty())
                return KeyProblem{key, std::string("a fracture energy stretches a softening curve and needs ") + name +
                                           " (a brittle bond dissipates nothing after its peak)"};
        if ((j.confined_friction >= 0.0) != (j.confined_friction_from > 0.0))
            return KeyProblem{j.confined_friction >= 0.0 ? "confined_friction" : "confined_friction_from",
                              "confined_friction (the steeper friction angle, degrees) and confined_friction_from "
                              "(the normal stress it starts at, Pa) go together"};
    }
    if ((j.law == Law::coulomb || j.law == Law::softening) && j.weibull_modulus > 0.0 &&
        !(j.cohesion > 0 || j.tensile > 0))
        return KeyProblem{"weibull_modulus", "heterogeneous strengths need a bond: cohesion or tensile > 0"};
    return std::nullopt;
}

void law_parameters(const JointPropertySpec& j, std::vector<double>& out) {
    out.push_back(double(j.law));
    out.push_back(double(j.face_shear));
    for (const JointKey& k : joint_keys)
        if (k.get) out.push_back(k.get(j));
    for (const auto* curve : {&j.tension_softening, &j.shear_softening}) {
        out.push_back(double(curve->size()));
        for (const auto& [alpha, beta] : *curve) out.insert(out.end(), {alpha, beta});
    }
}

std::string joint_keys_markdown() {
    std::string md =
        "# [[joint_property]] keys\n\n"
        "Generated from contact/joint_keys.hpp and the laws' key lists by tests/test_reference.cpp "
        "(`BBM_WRITE_REFERENCE=1` rewrites it; the test fails when it is stale). The lab tests', `bbm calibrate`'s and "
        "`bbm shear`'s rock flags are the same keys (`friction` is `--friction`, with the same bounds), and so "
        "are the Python module's keywords.\n\n"
        "| key | value | if absent | laws | meaning |\n|---|---|---|---|---|\n";
    for (const JointKey& k : joint_keys) {
        std::string laws;
        for (std::size_t l = 0; l < law_names.size(); ++l)
            for (const std::string_view lk : keys_of_laws[l])
                if (lk == k.key) laws += (laws.empty() ? "" : ", ") + std::string(law_names[l]);
        md += "| `" + std::string(k.key) + "` | " + key_value_text(k.kind, k.bounds) + " | " +
              (k.required ? std::string("required") : std::string(k.absent)) + " | " + laws + " | " +
              std::string(k.meaning) + " |\n";
    }
    return md;
}

} // namespace bbm::contact
