// bbm contact: the registry of joint constitutive laws (SPEC §4) — one row each.
//
// A law maps the relative displacement increments of one point contact (Δun,
// opening positive; Δus) to its stresses (σn compression positive; τ, per unit
// joint area), updating the contact's history in place. Laws are values
// validated once from the model file, and the contact pass calls them per batch
// of contacts sharing a property set (contact_pass: one dispatch per batch, not a
// virtual call per contact).
//
// A law is its own files (contact/laws/<law>.hpp, .cpp): a struct with
//   name                 the model file's `law`;
//   keys                 the [[joint_property]] keys it reads (declarations, with
//                        unit, bounds, meaning, default and whether a lab test's
//                        rock takes it as a flag: shared ones in laws/bond.hpp,
//                        its own in its file; a law added by the recipe keeps its
//                        values in JointPropertySpec::values);
//   check(spec)          the rules between its keys;
//   kn, ks, a constructor from JointPropertySpec, update(history, dun, dus),
//   starts_bonded() and elastic_limit();
// and one alternative of JointLaw below. The model file's reader, the flags of
// the lab tests and `bbm shear`, the Python keywords and
// docs/reference/joint_property.md all walk this list (contact/joint_keys.hpp).
#pragma once

#include "contact/laws/barton_bandis.hpp"
#include "contact/laws/coulomb.hpp"
#include "contact/laws/cwfs.hpp"
#include "contact/laws/elastic.hpp"
#include "contact/laws/softening.hpp"
#include "contact/laws/stress_corrosion.hpp"

#include <array>
#include <cstddef>
#include <string_view>
#include <variant>

namespace bbm::contact {

/// Every joint law, one alternative each.
using JointLaw = std::variant<ElasticLaw, CoulombLaw, SofteningLaw, BartonBandisLaw, CwfsLaw, StressCorrosionLaw>;

/// The laws' names, in the order of JointLaw (the model file's `law`).
inline constexpr auto law_names = []<std::size_t... I>(std::index_sequence<I...>) {
    return std::array<std::string_view, sizeof...(I)>{std::variant_alternative_t<I, JointLaw>::name...};
}(std::make_index_sequence<std::variant_size_v<JointLaw>>{});

/// The index in JointLaw of the law of that name; law_names.size() if none.
constexpr std::size_t law_index(std::string_view name) {
    for (std::size_t k = 0; k < law_names.size(); ++k)
        if (law_names[k] == name) return k;
    return law_names.size();
}

/// The law of a set (its `law` must name one: the reader and the flags check).
JointLaw make_law(const JointPropertySpec& p);
double normal_stiffness(const JointLaw& law);
double shear_stiffness(const JointLaw& law);
/// Does a contact with this law start bonded (can it carry tension)?
bool starts_bonded(const JointLaw& law);

/// Output state of a contact.
JointState state_of(const JointHistory& h);

/// The largest λ ≥ 0 (at most `cap`) for which the stresses before + λ (trial −
/// before) stay within the intact strength of the law — tension cut-off and
/// Coulomb cap with the full tensile strength and cohesion; unbounded (`cap`) for
/// an elastic law or an unloaded contact. With elastic joints the state of a
/// model scales with its load, so the smallest λ over the contacts is how far a
/// load can go before the first joint yields (a lab test's elastic preload).
double elastic_limit(const JointLaw& law, const JointHistory& before, const JointHistory& trial, double cap);

} // namespace bbm::contact
