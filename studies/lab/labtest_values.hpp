// bbm studies: the values of a lab-test command — the test (its specimen, rock,
// loading and stop rules), the rock file it was given, the realizations, threads
// and output — with the checks that make them a test. Plain values: the flags
// that fill them are the program's (apps/flags.hpp), and the studies built on lab
// tests (envelope, shear, calibrate) take them as they are.
#pragma once

#include "studies/lab/labtest.hpp"

#include <functional>
#include <string_view>
#include <string>
#include <vector>

namespace bbm::studies {

/// Command-line values of the lab tests, defaults = the paper's calibration run.
struct LabTestValues {
    LabTestOptions o = LabTestOptions::paper_ucs();
    /// --rock: a rock file or a model file whose rock the test takes (flags given
    /// beside it override its values; apply_rock_file).
    std::string rock;
    int realizations = 1;
    int threads = 0;
    std::string out = "out";
    /// false: nothing is written (the Python module without `out`).
    bool write_files = true;
    /// Called with the state every --frame-every steps of loading (and the last
    /// recorded point), from the thread running that realization (0, 1, ...).
    std::function<void(const Solver&, const StressStrainPoint&, int realization)> on_frame;
};

/// The lab-test command names: "ucs", "tension", "biaxial", "brazilian".
LabTestOptions::Kind labtest_kind(const std::string& command);

/// A lab-test command's defaults (tension and brazilian load slower, the disc is 4 m).
LabTestValues labtest_defaults(LabTestOptions::Kind kind);

/// For the studies built on lab tests (calibrate, envelope): the test's kind set
/// and the specimen checked before anything is generated (the platens the kind
/// allows, the joint set, the rock's bonds by their law's rules, its size).
/// Throws InputError naming the flag.
void prepare_labtest(LabTestValues& c, LabTestOptions::Kind kind);
/// The rules between a joint's keys (its law's: contact::check_joint_property), as
/// an InputError naming the flag (`prefix` after the dashes: `--joint-cohesion`).
void check_joint_flags(const JointPropertySpec& joint, std::string_view prefix = "");
/// Refuses, before anything is generated, a specimen narrower than a few blocks or
/// asking for more blocks and triangles than the limit.
void check_specimen_size(const LabTestValues& c);
/// A number to 6 significant digits, for messages and reports.
std::string fmt_number(double v);
/// A result as it travels between ranks (JSON text; doubles round-trip exactly), and back.
std::string labtest_record_text(const LabTestResult& r);
LabTestResult labtest_from_record_text(const std::string& text);

} // namespace bbm::studies
