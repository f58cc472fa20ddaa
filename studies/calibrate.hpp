// bbm core: calibration of joint micro-properties against macro targets
// (`bbm calibrate`; paper §4.2 calls systematic calibration an open problem).
//
// Targets: Young's modulus E, Poisson's ratio ν, uniaxial compressive strength
// and direct tensile strength of the rock mass, for a given block pattern and
// size. Unknowns: kn, ks, σt, c (friction and the softening curves stay as given).
//
// Start (no test run): the hexagonal-lattice inversion of E and ν (the exact
// elastic constants of a regular Voronoi assembly, docs/calibration.md):
//   r = ks/kn = (1 − 3ν)/(1 + ν),  kn = E (3 + r) / (2 a (1 + r)),  a = 0.9523 d,
// d the diameter of the blocks' mean area; σt = tensile / 0.66 and
// c = 9.5 MPa × UCS / 22.9 MPa (the ratios bbm measures with the paper's
// parameters), unless the user gave kn, ks, σt or c: those start
// from the given values. Then each iteration runs `realizations` UCS and
// direct-tension tests (seeds seed, seed+1, ..., in parallel; E and ν from an
// implicit elastic solve of each specimen, as the initial slope and lateral strain
// of a cracking specimen are too noisy to steer kn and ks/kn by) and corrects each
// unknown by the quantity it mainly controls:
//   kn ← kn × E*/E,   r: shifted by the lattice value of r at ν* minus that at ν,
//   σt ← σt × T*/T,   c ← c × UCS*/UCS,
// and, with a biaxial target σ1* at confinement σ3, φ by the slope of the
// strength envelope k = (σ1 − UCS)/σ3 (k* from the targets): tan φ scaled by
// (k* − 1)/(k − 1) at first, then by the secant through the last two iterations,
// steps within ±10°, φ within 5–60°;
// stopping when all the means are within tolerance or after max_iterations.
// The means are over realizations, so the result carries their scatter: a new
// set of seeds reproduces the targets only to within the realization scatter
// (reported as the standard deviation).
#pragma once

#include "studies/labtest.hpp"

#include <functional>
#include <vector>

namespace bbm {

struct CalibrationTargets {
    double E = 20e9, nu = 0.2, ucs = 20e6, tensile = 2.5e6;
    /// Optional: the strength σ1 of a biaxial test at lateral stress `confinement`
    /// (both Pa, compression positive); with it the friction angle φ is calibrated
    /// too. 0 = φ stays as given.
    double biaxial = 0.0, confinement = 0.0;
};

struct CalibrationOptions {
    LabTestOptions base = LabTestOptions::paper_ucs(); ///< pattern, size, specimen, friction, softening
    int realizations = 3;
    int threads = 2;          ///< realizations run in parallel on these
    int max_iterations = 6;
    double tolerance_E = 0.02, tolerance_nu = 0.05, tolerance_ucs = 0.03, tolerance_tensile = 0.05;
    double tolerance_biaxial = 0.03;
    /// Starting values the user gave (kn, ks, tensile, cohesion of base.joint);
    /// the others start from the lattice inversion.
    bool start_kn = false, start_ks = false, start_tensile = false, start_cohesion = false;
};

struct CalibrationIteration {
    JointPropertySpec joint;
    double E = 0, nu = 0, ucs = 0, tensile = 0;             ///< means over realizations
    double E_std = 0, nu_std = 0, ucs_std = 0, tensile_std = 0;
    double biaxial = 0, biaxial_std = 0; ///< σ1 of the biaxial tests (with a biaxial target)
    double E_test = 0, E_test_std = 0; ///< E of the UCS curves (initial slope), for comparison
    double seconds = 0;
    bool converged = false;
};

/// The starting joint properties from the lattice inversion (see above).
JointPropertySpec calibration_start(const CalibrationTargets& t, const CalibrationOptions& o);

/// Runs the iteration; `report` (optional) sees each iteration as it ends.
/// Returns all iterations; the last holds the calibrated set.
std::vector<CalibrationIteration> calibrate(const CalibrationTargets& t, const CalibrationOptions& o,
                                            const std::function<void(const CalibrationIteration&)>& report = {});

/// E and ν of the specimen of `base` with elastic joints (kn, ks of `joint`): one
/// implicit solve under 1 MPa on top, strains from its middle (away from the ends).
struct ElasticMeasure {
    double E = 0, nu = 0;
};
ElasticMeasure elastic_measure(const JointPropertySpec& joint, const LabTestOptions& base);

/// Mean and sample standard deviation of the measures for a joint set (E and ν
/// from elastic_measure, the strengths from the UCS and tension tests, and from
/// biaxial tests at `confinement` if it is > 0).
CalibrationIteration measure_macro_properties(const JointPropertySpec& joint, const CalibrationOptions& o,
                                              std::uint64_t first_seed, double confinement = 0.0);

} // namespace bbm
