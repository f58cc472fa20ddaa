// bbm apps: the command line's flags — CLI11 in front of the library's values
// (studies/), for the program (apps/cli.cpp), the fuzzer of --config files and the
// Python module, which parses its keyword arguments with the same definitions so
// that a keyword is checked, defaulted and reported exactly as its flag.
//
// Most flags are made from key declarations (base/keys.hpp), not written here:
//   the rock (core/rock.hpp)  its pattern's keys marked `flag` (`--pattern`,
//                             `--size`, `--size-measure`, `--lloyd`, `--seed`),
//                             every joint key marked `flag` (`--kn`, `--tensile`,
//                             `--tension-softening` ...) and every material key
//                             marked `flag` (`--density`, `--young` ...);
//   a joint of its own        `bbm shear`'s plane (`--joint-law`, `--joint-<key>`)
//                             and a lab test's joint set (`--joint-set-law`,
//                             `--joint-set-<key>`): the law from the registry's
//                             names, a flag for every number a law declares, the
//                             keys the chosen law does not read refused by name.
// A key's flag is checked against the key's bounds in the reader's words, and the
// rules between a set's keys are its law's (contact::check_joint_property).
// Softening curves are written as a model file writes them, `[[1.7, 0.5], [4, 0]]`;
// the former `b1,a1,a2` is still read, with a deprecation message.
#pragma once

#include "base/keys.hpp"
#include "core/rock.hpp"
#include "studies/calibration/calibrate_command.hpp"
#include "studies/lab/creep_test.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/lab/labtest_command.hpp"
#include "studies/lab/shear.hpp"

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
}

namespace bbm::cli {

extern const char* const max_elements_help;

/// The flags of keys on a command: `--<key>` (dashes for underscores) after
/// `prefix`, bound to spec's field, checked against the key's bounds, its help
/// the key's meaning (other keys named by their flags) after `help_prefix`.
/// Numbers, whole numbers, words (a choice's) and curves; other kinds are skipped.
template <class Spec>
void add_key_flags(CLI::App* command, Spec& spec, std::span<const Key<Spec>* const> keys, std::string_view prefix = "",
                   std::string_view help_prefix = "");

/// The declarations marked `flag` of a table (a lab test's rock's keys).
template <class Spec, std::size_t N>
std::vector<const Key<Spec>*> flag_keys(const Key<Spec> (&table)[N]) {
    std::vector<const Key<Spec>*> keys;
    for (const Key<Spec>& k : table)
        if (k.flag) keys.push_back(&k);
    return keys;
}

/// The rock's flags: its pattern, bonds and material, and `--mesh-size`.
void add_rock_flags(CLI::App* command, RockSpec& rock);
/// --rock FILE: the file's rock (io::read_rock), then the rock's flags given on
/// `command` beside it over it. Throws InputError naming the file, line and key.
void apply_rock_file(const CLI::App& command, const std::string& file, RockSpec& rock);

/// A joint with a law of its own (`bbm shear`'s plane, a lab test's joint set):
/// `--<prefix>law` and `--<prefix><key>` for every number of every law except the
/// stiffnesses (the rock's unless `--<prefix>kn`, `--<prefix>ks` are given).
void add_joint_law_flags(CLI::App* command, JointPropertySpec& joint, std::string_view prefix,
                         std::string_view help_prefix);
/// After parsing: a given `--<prefix><key>` the chosen law does not read is
/// refused by name; then the law's rules (InputError naming the flag).
void check_joint_law_flags(const CLI::App& command, const JointPropertySpec& joint, std::string_view prefix);

/// The options of a lab test (specimen, rock, loading, stop rules, joint set,
/// realizations, threads, output) on a (sub)command; `quiet` gets -q/--quiet.
void add_labtest_options(CLI::App* command, studies::LabTestValues& values, bool& quiet);
/// The envelope options (lab-test options, confinements, fit) on a (sub)command.
void add_envelope_options(CLI::App* command, studies::EnvelopeOptions& options, bool& quiet);
/// `bbm shear`'s options on a (sub)command.
void add_shear_options(CLI::App* command, studies::ShearValues& values, bool& quiet);
/// `bbm creep`'s options on a (sub)command.
void add_creep_options(CLI::App* command, studies::CreepValues& values, bool& quiet);
/// The calibrate options (lab-test options and targets) on a (sub)command.
void add_calibrate_options(CLI::App* command, studies::CalibrateValues& values, bool& quiet);
/// After parsing: which joint values the user gave (the calibration starts from them).
void note_given_joint_values(const CLI::App& command, studies::CalibrateValues& values);

/// The studies from option strings as the program takes them after the command's
/// name ({"--width", "2", "--seed", "3"}): the Python module's keyword arguments.
/// Files are written only with --out. Throws InputError naming the flag.
/// `on_frame`: as LabTestValues::on_frame (with --frame-every).
studies::LabTestStudy run_labtest_args(
    const std::string& command, const std::vector<std::string>& args, bool quiet,
    const std::function<void(const Solver&, const StressStrainPoint&, int)>& on_frame = {});
studies::EnvelopeStudy run_envelope_args(const std::vector<std::string>& args, bool quiet);
studies::ShearStudy run_shear_args(const std::vector<std::string>& args, bool quiet);
studies::CreepStudy run_creep_args(const std::vector<std::string>& args, bool quiet);
/// Returns calibration.json's text.
std::string run_calibrate_args(const std::vector<std::string>& args, bool quiet);

} // namespace bbm::cli
