// bbm studies: a lab-test command (`ucs`, `tension`, `biaxial`, `brazilian`) as a
// library call — its realizations spread over threads and ranks, their console
// lines, their files (stress_strain.csv/.png, failure.png/.svg, result.pvd,
// summary.json) and the summary of several. The flags that fill its values are
// the program's (apps/flags.hpp); the Python module runs the same code.
#pragma once

#include "studies/lab/labtest_values.hpp"

#include <string>
#include <vector>

namespace bbm::studies {

/// What a lab-test command produced: one result per realization, and the summary.
struct LabTestStudy {
    std::vector<LabTestResult> results;
    std::string summary_json;
};

/// Runs a lab test (realizations spread over threads), writing its files in
/// values.out when values.write_files. check_only: validate and stop.
/// Returns 0; bad values throw InputError naming the flag.
int run_labtest_command(LabTestValues& values, LabTestOptions::Kind kind, bool quiet, bool check_only,
                        LabTestStudy* study = nullptr);

/// The name of a lab test's kind: "ucs", "tension", "biaxial", "brazilian".
const char* labtest_name(LabTestOptions::Kind kind);

} // namespace bbm::studies
