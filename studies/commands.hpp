// bbm studies: the commands a user runs — `mesh`, the lab tests (`ucs`, `tension`,
// `biaxial`, `brazilian`) and `calibrate` — as library calls with their options,
// their output files and their summaries, so that the program (apps/cli.cpp) and
// the Python module (python/) are thin front ends that run the same code.
//
// The lab tests' options are CLI11 options (add_labtest_options): the program puts
// them on its subcommands, and run_labtest_args() parses a list of "--key value"
// strings with the same definitions, so a Python keyword argument is checked,
// defaulted and reported exactly as the flag is. Each run returns its exit status
// (0 done, 4 calibration not converged) and, when asked, its summary as JSON text
// (the summary.json a run writes) and the lab-test results with their curves.
// Bad options throw InputError naming the flag.
#pragma once

#include "base/keys.hpp"
#include "studies/calibrate.hpp"
#include "studies/envelope.hpp"
#include "studies/labtest.hpp"
#include "studies/labtest_values.hpp"
#include "studies/model_rock.hpp"
#include "studies/shear.hpp"

#include <filesystem>
#include <functional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace bbm::studies {

extern const char* const max_elements_help;

/// The [[joint_property]] keys (contact/joint_keys.hpp) the lab tests' rock takes
/// as flags: the softening bond's numbers (its curves are --tension-softening and
/// --shear-softening as b1,a1,a2; its seed is the specimen's).
inline constexpr std::string_view labtest_joint_keys[] = {
    "kn", "ks", "tensile", "cohesion", "friction", "residual_friction", "confined_friction",
    "confined_friction_from", "tension_fracture_energy", "shear_fracture_energy", "weibull_modulus",
    "strength_classes"};

/// The [[material]] keys (core/material_keys.hpp) the lab tests take as flags.
inline constexpr std::string_view labtest_material_keys[] = {"density", "deformable_fraction", "young", "poisson"};

/// The flags of a spec's keys on a command, made from their declarations in
/// `table` (base/keys.hpp): `--<key>` with dashes after `prefix`, bound to spec's
/// field, checked against the key's bounds in the reader's words, its help the
/// key's meaning (other keys named by their flags) after `help_prefix`.
template <class Spec>
void add_key_flags(CLI::App* command, Spec& spec, std::span<const Key<Spec>> table,
                   std::span<const std::string_view> keys, std::string_view prefix = "",
                   std::string_view help_prefix = "");

/// The flags of a joint's keys on a command, made from their declarations
/// (contact/joint_keys.hpp): `--residual-friction` is the key residual_friction,
/// bound to joint's field, checked against the key's bounds in the reader's words,
/// its help the key's meaning after `help_prefix`. `prefix` goes after the dashes
/// (`bbm shear`'s plane: `--joint-friction`).
void add_joint_flags(CLI::App* command, JointPropertySpec& joint, std::span<const std::string_view> keys,
                     std::string_view prefix = "", std::string_view help_prefix = "");
/// The rules between a joint's keys (contact::check_joint_property), as an
/// InputError naming the flag.
void check_joint_flags(const JointPropertySpec& joint, std::string_view prefix = "");

/// The envelope options (lab-test options, confinements, fit) on a (sub)command.
void add_envelope_options(CLI::App* command, EnvelopeOptions& options, bool& quiet);
/// `bbm shear`'s options on a (sub)command.
void add_shear_options(CLI::App* command, ShearCli& values, bool& quiet);

/// --rock FILE on a lab-test command (add_labtest_options): the rock file's bonds
/// and material (io::RockFile), or a model file's rock (labtest_of_model), then
/// the rock's flags given on `cmd` beside it over them. Throws InputError naming
/// the file, line and key.
void apply_rock_file(const CLI::App& cmd, LabTestCli& c);

/// The lab-test options on a (sub)command; `quiet` gets -q/--quiet.
void add_labtest_options(CLI::App* command, LabTestCli& values, bool& quiet);

/// What a lab-test command produced: one result per realization, and the summary.
struct LabTestStudy {
    std::vector<LabTestResult> results;
    std::string summary_json;
};

/// Runs a lab test (realizations spread over threads), writing its files in
/// values.out when values.write_files. check_only: validate and stop.
int run_labtest_command(LabTestCli& values, LabTestOptions::Kind kind, bool quiet, bool check_only,
                        LabTestStudy* study = nullptr);

/// The same from option strings as the program takes them after the command name
/// ({"--width", "2", "--seed", "3"}). Throws InputError naming the flag.
/// `on_frame`: as LabTestCli::on_frame (with --frame-every).
LabTestStudy run_labtest_args(const std::string& command, const std::vector<std::string>& args, bool quiet,
                              const std::function<void(const Solver&, const StressStrainPoint&, int)>& on_frame = {});

/// `bbm calibrate`'s values.
struct CalibrateCli {
    LabTestCli lab;
    CalibrationTargets targets;
    /// The confined targets as given; run_calibrate turns them into targets.envelope.
    double biaxial = 0.0, confinement = 0.0; ///< one biaxial test: σ1 at σ3 (Pa)
    std::string record;                      ///< CSV of σ3, σ1 pairs in MPa (the lab's triaxial tests)
    double mi = 0.0;                         ///< Hoek–Brown mi of the record (σci = the UCS target)
    std::vector<double> mi_confinements;     ///< σ3 of the Hoek–Brown points, Pa (default UCS/6, UCS/3)
    int iterations = 6;
    bool fit_ci = false; ///< calibrate σci/UCS too (--fit-ci: by the bonds' strength heterogeneity)
    bool fit_confined_friction = false; ///< --fit-confined-friction: σ*, φ2 on the confined targets
    bool fit_curvature = false;         ///< --fit-curvature: c, φ and φ2 above σ* together
    /// --target-residual-friction (degrees) and --residual-confinement (Pa): the
    /// broken joints' friction calibrated first, on the rubble's (residual_friction.hpp).
    double residual_target = 0.0, residual_confinement = 0.0;
    /// Joint values given (they are the starting point rather than estimates).
    bool given_kn = false, given_ks = false, given_tensile = false, given_cohesion = false;
    CalibrateCli() { lab.realizations = 3; }
};

/// The calibrate options (lab-test options and targets) on a (sub)command.
void add_calibrate_options(CLI::App* command, CalibrateCli& values, bool& quiet);
/// After parsing: which joint values the user gave.
void note_given_joint_values(const CLI::App& command, CalibrateCli& values);

/// Runs the calibration; writes joint_property.toml and calibration.json in
/// values.lab.out when values.lab.write_files; returns 0, or 4 if not converged.
/// `calibration_json` gets the calibration.json text when not null.
int run_calibrate(CalibrateCli& values, bool quiet, bool check_only, std::string* calibration_json = nullptr);

/// run_calibrate from option strings, as run_labtest_args. Returns calibration.json's text.
std::string run_calibrate_args(const std::vector<std::string>& args, bool quiet);

/// `bbm mesh`: generate a model file's blocks, write blocks.vtu, joints.vtu,
/// blocks.png and summary.json in `out`.
struct MeshCommand {
    std::string model;
    std::filesystem::path out = "out";
    std::vector<double> window; ///< XMIN YMIN XMAX YMAX of blocks.png, or empty
    double max_elements = 0;
};
int run_mesh(const MeshCommand& command, bool quiet, bool check_only);

} // namespace bbm::studies
