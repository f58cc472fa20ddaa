// bbm contact: the keys of a [[joint_property]] — one declaration each (its kind,
// unit and allowed values, what it means, what its absence means) — and, through
// each law's `keys` (joint_law.hpp, barton_bandis.hpp), which keys a law reads.
//
// Everything that describes a rock's joints is made from this one table: the model
// file's reader (io/model_input.cpp checks, bounds and reads them from it), the
// rock's flags of the lab tests, `bbm calibrate` and `bbm shear` (studies/
// commands.hpp, add_key_flags: `--friction` is the key `friction`, with its bounds and words;
// the Python keywords are the flags' names), and the key reference
// docs/reference/joint_property.md (joint_keys_markdown(); a test fails when the
// file is stale). A new key is one row here and its field in JointPropertySpec.
#pragma once

#include "base/keys.hpp"
#include "contact/joint_property.hpp"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bbm::contact {

using JointKey = Key<JointPropertySpec>;
using bbm::KeyKind;

#define BBM_JOINT_FIELD(field) BBM_KEY_FIELD(JointPropertySpec, field)

// Each row names only the members it sets; the rest keep their defaults.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of a [[joint_property]], in the order the reference lists them.
inline constexpr JointKey joint_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true, .meaning = "The set's name, referred to by [[joint_assignment]]"},
    {.key = "law", .kind = KeyKind::choice, .required = true,
     .meaning = "The joint law: elastic, coulomb, softening (the paper's bilinear softening bond) or barton_bandis"},
    {.key = "kn", .bounds = above(0, pascals_per_metre), .required = true, .meaning = "Normal stiffness", BBM_JOINT_FIELD(kn)},
    {.key = "ks", .bounds = above(0, pascals_per_metre), .required = true, .meaning = "Shear stiffness", BBM_JOINT_FIELD(ks)},
    {.key = "face_shear", .kind = KeyKind::boolean,
     .meaning = "Between a rigid block and a deformable one: the contacts of a rigid face share its mean shear slip "
                "(the interface of a bonded region with an elastic far field)",
     .absent = "false"},
    {.key = "friction", .bounds = below(0, 90, degrees),
     .meaning = "Friction angle φ (Barton-Bandis: the residual friction φr)", .absent = "30", BBM_JOINT_FIELD(friction)},
    {.key = "residual_friction", .bounds = below(0, 90, degrees), .meaning = "Friction angle φr once the bond has failed",
     .absent = "friction", BBM_JOINT_FIELD(residual_friction)},
    {.key = "cohesion", .bounds = at_least(0, pascals),
     .meaning = "Cohesion c (softening: the peak, > 0, the shear curve is normalised by)", .absent = "0 (coulomb)",
     BBM_JOINT_FIELD(cohesion)},
    {.key = "tensile", .bounds = at_least(0, pascals),
     .meaning = "Tensile strength σt (softening: the peak, > 0, the tension curve is normalised by)", .absent = "0 (coulomb)",
     BBM_JOINT_FIELD(tensile)},
    {.key = "tension_softening", .kind = KeyKind::curve,
     .meaning = "Post-peak points [[α, β], ...] of the tension curve (SPEC §4): α the displacement over the elastic "
                "displacement at peak, increasing; β the stress over the peak, the last 0",
     .absent = "brittle"},
    {.key = "shear_softening", .kind = KeyKind::curve, .meaning = "The same for the shear curve", .absent = "brittle"},
    {.key = "tension_fracture_energy", .bounds = above(0, joules_per_square_metre),
     .meaning = "The energy G_I to break a bond in tension, the area under its tension curve: the curve's plastic "
                "displacements are stretched, its shape kept, to dissipate it whatever kn and σt are (softening "
                "lengths held as block size and calibration change kn); needs tension_softening",
     .absent = "none: the curve's α are multiples of σt/kn", BBM_JOINT_FIELD(tension_fracture_energy)},
    {.key = "shear_fracture_energy", .bounds = above(0, joules_per_square_metre),
     .meaning = "The same in shear, G_II, at zero normal stress; needs shear_softening",
     .absent = "none: the curve's α are multiples of c/ks", BBM_JOINT_FIELD(shear_fracture_energy)},
    {.key = "confined_friction", .bounds = below(0, 90, degrees),
     .meaning = "A bond's friction angle φ2 above the normal stress confined_friction_from (below friction: an "
                "envelope flattening as rock's; above it: an S-shaped one); with confined_friction_from",
     .absent = "none", BBM_JOINT_FIELD(confined_friction)},
    {.key = "confined_friction_from", .bounds = above(0, pascals),
     .meaning = "The normal stress σ* above which confined_friction acts", .absent = "none",
     BBM_JOINT_FIELD(confined_friction_from)},
    {.key = "weibull_modulus", .bounds = at_least(0, ""),
     .meaning = "Heterogeneous bonds: each joint's tensile strength and cohesion times a Weibull factor of this "
                "modulus and mean 1 (2: very heterogeneous, 10: nearly uniform); needs a bond",
     .absent = "0, every joint the same", BBM_JOINT_FIELD(weibull_modulus)},
    {.key = "strength_classes", .kind = KeyKind::integer, .bounds = between(1, 1000, ""),
     .meaning = "Heterogeneous bonds: the classes of equal probability the Weibull law is discretised into",
     .absent = "16", BBM_JOINT_FIELD(strength_classes)},
    {.key = "strength_seed", .kind = KeyKind::integer, .bounds = between(0, 9007199254740992.0, ""),
     .meaning = "Heterogeneous bonds: the seed of the classes' draw", .absent = "1", BBM_JOINT_FIELD(strength_seed)},
    {.key = "jrc", .bounds = between(0, 20, ""), .required = true, .meaning = "Barton-Bandis: the joint roughness coefficient JRC",
     BBM_JOINT_FIELD(jrc)},
    {.key = "jcs", .bounds = above(0, pascals), .required = true,
     .meaning = "Barton-Bandis: the joint wall compressive strength JCS", BBM_JOINT_FIELD(jcs)},
    {.key = "joint_length", .bounds = above(0, metres),
     .meaning = "Barton-Bandis: the joint length L of the peak shear displacement (L/500)(JRC/L)^0.33 and of the "
                "post-peak fall of JRC",
     .absent = "none: the strength stays at its peak", BBM_JOINT_FIELD(joint_length)},
};
#pragma GCC diagnostic pop
#undef BBM_JOINT_FIELD

/// The declaration of a key; nullptr if there is none.
constexpr const JointKey* find_joint_key(std::string_view key) { return find_key(joint_keys, key); }

/// The keys a law reads, in the order of JointPropertySpec::Law.
std::span<const std::string_view> law_keys(JointPropertySpec::Law law);

/// A set's values that break a rule between its keys, by law: a softening law's
/// peaks (cohesion, tensile) > 0, confined_friction and confined_friction_from
/// together, a Weibull modulus only with a bond. The key to blame and what is wrong.
struct KeyProblem {
    std::string_view key;
    std::string message;
};
std::optional<KeyProblem> check_joint_property(const JointPropertySpec& j);

/// Every parameter of a set, as numbers (the model fingerprint: a checkpoint of
/// another set's model is refused): its law, every declared key's value, its curves.
void law_parameters(const JointPropertySpec& j, std::vector<double>& out);

/// The flag of a key (base/keys.hpp).
inline std::string joint_flag(std::string_view key, std::string_view prefix = "") { return key_flag(key, prefix); }

/// docs/reference/joint_property.md: the table of keys and which law reads each.
std::string joint_keys_markdown();

} // namespace bbm::contact
