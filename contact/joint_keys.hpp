// bbm contact: the keys of a [[joint_property]], gathered from the laws of the
// registry (contact/joint_law.hpp) — each declared once, in the file of the law
// that reads it or, shared, in contact/laws/bond.hpp.
//
// Everything that describes a rock's joints is made from them: the model file's
// reader (io/model_input.cpp checks, bounds and reads them), the rock's flags of
// the lab tests, `bbm calibrate` and `bbm shear` (the declarations marked `flag`;
// `--friction` is the key `friction`, with its bounds and words; the Python
// keywords are the flags' names), the rules between keys (each law's check), and
// the key reference docs/reference/joint_property.md (joint_keys_markdown(); a
// test fails when the file is stale).
#pragma once

#include "contact/joint_law.hpp"

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bbm::contact {

/// Every declared key, once, in the order the laws of the registry list them.
std::span<const JointKey* const> joint_keys();
/// The names of joint_keys(), for the reader's check of a table's keys.
std::span<const std::string_view> joint_key_names();
/// The declaration of a key; nullptr if there is none.
const JointKey* find_joint_key(std::string_view key);

/// The keys a law reads (empty for an unknown law).
std::span<const JointKey* const> law_keys(std::string_view law);
std::vector<std::string_view> law_key_names(std::string_view law);

/// A set's values that break a rule between its keys, by its law (the law's
/// check): the key to blame and what is wrong. An unknown law is a problem of `law`.
std::optional<KeyProblem> check_joint_property(const JointPropertySpec& j);

/// Every parameter of a set, as numbers (the model fingerprint: a checkpoint of
/// another set's model is refused): its law, every declared key's value, its curves.
void law_parameters(const JointPropertySpec& j, std::vector<double>& out);

/// The flag of a key (base/keys.hpp).
inline std::string joint_flag(std::string_view key, std::string_view prefix = "") { return key_flag(key, prefix); }

/// docs/reference/joint_property.md: the table of keys and which law reads each.
std::string joint_keys_markdown();

} // namespace bbm::contact
