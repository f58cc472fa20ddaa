// bbm studies: the values of a lab-test command — the specimen, the rock and the
// run as the flags give them (LabTestCli), with the checks that turn them into
// LabTestOptions. Plain values: the studies built on lab tests (envelope, shear,
// calibrate, a model's rock) take them without the command-line layer
// (studies/commands.hpp, where the flags are defined).
#pragma once

#include "studies/labtest.hpp"

#include <functional>
#include <string>
#include <vector>

namespace bbm::studies {

/// Command-line values of the lab tests, defaults = the paper's calibration run.
struct LabTestCli {
    LabTestOptions o = LabTestOptions::paper_ucs();
    std::string pattern = "voronoi";
    std::vector<double> tension_softening{0.5, 1.7, 4.0}, shear_softening{0.5, 1.3, 2.1};
    std::string platens = "rough";
    std::string size_measure = "feret";
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
LabTestCli labtest_defaults(LabTestOptions::Kind kind);

/// For the studies built on lab tests (calibrate, envelope): the flags' values
/// applied to c.o for a test of this kind (pattern, softening curves, platens),
/// and the specimen checked before anything is generated. Throws InputError
/// naming the flag.
void prepare_labtest(LabTestCli& c, LabTestOptions::Kind kind);
/// --pattern, --size-measure and the softening flags applied to c.o (checked).
void apply_specimen_flags(LabTestCli& c);
/// --pattern and --size-measure applied to c.o.
void apply_pattern_flags(LabTestCli& c);
/// --tension-softening / --shear-softening b1,a1,a2 -> the points (a1, b1), (a2,
/// 0) of the joint's curves, checked with the rules between the joint's keys.
void apply_softening_flags(LabTestCli& c);
/// Refuses, before anything is generated, a specimen narrower than a few blocks or
/// asking for more blocks and triangles than the limit.
void check_specimen_size(const LabTestCli& c);
/// A number to 6 significant digits, for messages and reports.
std::string fmt_number(double v);
/// A result as it travels between ranks (JSON text; doubles round-trip exactly), and back.
std::string labtest_record_text(const LabTestResult& r);
LabTestResult labtest_from_record_text(const std::string& text);

} // namespace bbm::studies
