// bbm studies: `bbm calibrate` as a library call — its values (the lab tests'
// specimen and rock, the targets and what to fit), the run, its report and its
// files (joint_property.toml, calibration.json). The iteration itself is
// studies/calibration/calibrate.hpp; the flags are the program's (apps/flags.hpp).
#pragma once

#include "studies/calibration/calibrate.hpp"
#include "studies/lab/labtest_values.hpp"

#include <string>
#include <vector>

namespace bbm::studies {

/// `bbm calibrate`'s values.
struct CalibrateValues {
    LabTestValues lab;
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
    CalibrateValues() { lab.realizations = 3; }
};

/// Runs the calibration; writes joint_property.toml and calibration.json in
/// values.lab.out when values.lab.write_files; returns 0, or 4 if not converged.
/// `calibration_json` gets the calibration.json text when not null.
int run_calibrate(CalibrateValues& values, bool quiet, bool check_only, std::string* calibration_json = nullptr);

} // namespace bbm::studies
