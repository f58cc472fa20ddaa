// bbm studies: calibration of joint micro-properties against macro targets
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
//   kn ← kn × E*/E,   r: shifted by the lattice value of r at ν* minus that at ν
//                     (from the second iteration on, by the secant of the last two),
//   σt ← σt × T*/T,   c ← c × UCS*/UCS,
// and, with confined targets (the record's triaxial or biaxial strengths, or
// points of its Hoek–Brown curve), c and φ together (next_cohesion_friction):
// the strengths (ln UCS, ln σ1 at each σ3) as planes in (ln c, φ) fitted to
// every iteration so far, solved for the targets. One friction angle sets one
// slope: the curvature of a record's envelope is not fitted, and the misfit at
// each σ3 is reported — unless fit_curvature fits a cap in two pieces, φ below a
// normal stress σ* and φ2 above it (next_bond_cap).
// Converged when every mean is within its tolerance; otherwise, after
// max_iterations, the best set (the smallest largest misfit) is the result.
// The means are over realizations, so the result carries their scatter: a new
// set of seeds reproduces the targets only to within the realization scatter
// (reported as the standard deviation). The record's σci/UCS, when given, is
// reported beside the model's; with fit_ci it is calibrated too, by the
// heterogeneity of the bond strengths (docs/calibration.md, "Heterogeneous
// bonds": the weakest bonds break first, so σci/UCS falls as the strengths
// scatter): the unknown is h = 1/m, m the Weibull modulus of σt and c (h = 0:
// every joint the same), moved by next_heterogeneity() — a fixed step of 0.2
// toward the target until two iterations show the slope, then the secant — with
// σt and c scaled by the mean strength loss measured on the paper's rock
// (UCS / (1 + 0.7 h), tension / (1 + 2 h)) so that the strengths do not lag a step.
#pragma once

#include "studies/lab/labtest.hpp"

#include <functional>
#include <utility>
#include <vector>

namespace bbm {

struct CalibrationTargets {
    double E = 20e9, nu = 0.2, ucs = 20e6, tensile = 2.5e6;
    /// Optional: the record's confined strengths, (σ3, σ1) pairs in Pa,
    /// compression positive (triaxial or biaxial tests, or points of its
    /// Hoek–Brown curve: hoek_brown_targets). With them the friction angle φ is
    /// calibrated too; empty = φ stays as given.
    std::vector<std::pair<double, double>> envelope;
    /// Optional: the record's crack-initiation stress over its UCS; reported beside
    /// the model's, not calibrated. 0 = none.
    double ci_ratio = 0.0;
};

/// Points (σ3, σ1) of the Hoek–Brown intact-rock criterion σ1 = σ3 + σci √(mi σ3/σci + 1).
std::vector<std::pair<double, double>> hoek_brown_targets(double sigma_ci, double mi, const std::vector<double>& sigma3);

struct CalibrationOptions {
    LabTestOptions base = LabTestOptions::paper_ucs(); ///< pattern, size, specimen, friction, softening
    int realizations = 3;
    int threads = 2;          ///< realizations run in parallel on these
    int max_iterations = 6;
    double tolerance_E = 0.02, tolerance_nu = 0.05, tolerance_ucs = 0.03, tolerance_tensile = 0.05;
    double tolerance_envelope = 0.05; ///< on σ1 at every confined target
    /// Starting values the user gave (kn, ks, tensile, cohesion of base.rock.bonds);
    /// the others start from the lattice inversion.
    bool start_kn = false, start_ks = false, start_tensile = false, start_cohesion = false;
    /// Calibrate σci/UCS (CalibrationTargets::ci_ratio) by the bonds' strength
    /// heterogeneity, within tolerance_ci (absolute, on the ratio).
    bool fit_ci = false;
    double tolerance_ci = 0.05;
    /// Calibrate the bonds' confined friction φ2 (JointPropertySpec::
    /// confined_friction) on the confined targets, from a σ* held (the set's
    /// confined_friction_from; none: the UCS target), the friction φ held and the
    /// cohesion steered by the UCS alone.
    bool fit_confined_friction = false;
    /// Calibrate the bonds' cap in two straight pieces, c and φ below σ* and φ2
    /// above it, together on the UCS and at least two confined targets
    /// (next_bond_cap): σ* held (the set's confined_friction_from; none: the UCS
    /// target), φ2 starting at the set's (none: φ, a straight cap).
    bool fit_curvature = false;
};

/// One iteration's strengths against the bonds' cohesion and friction.
struct StrengthSample {
    /// ln of the cohesion the UCS sees: c × ucs_loss(h), the loss of the
    /// weakest bonds of heterogeneity h taken out (the σci step moves c for it).
    double log_cohesion = 0.0;
    double friction = 0.0;              ///< degrees
    std::vector<double> log_strength;   ///< ln UCS, then ln σ1 at each confinement
    double confined_friction = -1.0;    ///< φ2 above σ*, degrees (next_bond_cap only)
};

/// The next (ln c, φ) for the strength targets (ln UCS, then ln σ1 at each of
/// `sigma3`). Each strength is taken as a plane, ln s = a + b ln c + g φ, fitted
/// by least squares to every sample, its slopes held near the Coulomb ones
/// (UCS = 2c√Nφ, σ1 = UCS + Nφ σ3 at the last sample) by prior rows worth a
/// log-unit of 0.5 in ln c and 3° in φ: with one sample the step is Newton's on
/// the Coulomb slopes, with more the measured slopes take over. Why not one
/// secant per unknown: the UCS of bonded blocks rises with φ about three times
/// as fast as the Coulomb UCS (Lac du Bonnet, 6 iterations: d ln UCS/dφ =
/// 0.055/° against 0.023/°), so each friction step threw the UCS off (134–345
/// MPa against 213) and φ swung (25° → 35° → 43° → 33° → 43° → 41°). The targets
/// are met in least squares, the UCS row weighted twice (its tolerance is half
/// the envelope's); steps within ±0.7 in ln c and ±8° in φ, φ within 5–55°, and
/// when φ's step is cut so, ln c's is solved again for the φ step taken.
std::pair<double, double> next_cohesion_friction(const std::vector<StrengthSample>& history,
                                                 const std::vector<double>& sigma3,
                                                 const std::vector<double>& log_target);

/// The next bonds' cap in two straight pieces (fit_curvature): ln c, φ below the
/// normal stress σ* and φ2 above it (JointPropertySpec::confined_friction), by the
/// planes of next_cohesion_friction in three unknowns. The prior slope of the
/// friction is shared between φ and φ2 by the normal stress on the Coulomb failure
/// plane at each target against σ*. φ2 steps within ±8°, within 0–75°: below φ the
/// envelope bends down (concave, as rock's), above it up (S-shaped).
struct BondCapStep {
    double log_cohesion, friction, confined_friction;
};
BondCapStep next_bond_cap(const std::vector<StrengthSample>& history, const std::vector<double>& sigma3,
                          const std::vector<double>& log_target, double sigma_star);

/// The next confined friction φ2 (degrees) of a confined-friction calibration,
/// σ* held: from the signed misfit m = mean over the confined targets of
/// ln(σ1 / target), measured at φ2 (and at φ2_prev before it; φ2_prev < 0: none).
/// The secant of the last two iterations when it shows σ1 rising with φ2, else
/// the slope measured on Lac du Bonnet's in-situ set (d m/dφ2 = 0.05 per degree:
/// σ1 427 → 704 MPa at σ3 = 35.5 MPa for φ2 55° → 65°, σ* 74.6 MPa); steps
/// within ±10°, φ2 within [φ, 75°].
double next_confined_friction(double friction, double phi2_prev, double misfit_prev, double phi2, double misfit);

/// The step of the stiffness ratio r = ks/kn toward the target ν: the hexagonal
/// lattice's at first (prev_ratio < 0), then the secant of the last two
/// iterations when it shows ν falling as r rises, within twice the lattice's step.
double stiffness_ratio_step(double ratio, double nu, double prev_ratio, double prev_nu, double target_nu);

/// The next heterogeneity h = 1/m of the σci/UCS calibration from the last two
/// iterations (h_prev < 0: none before): the secant when the two show σci/UCS
/// falling with h, else a step of 0.2 toward the target; steps within ±0.3 and h
/// within [0, 1].
double next_heterogeneity(double h_prev, double ci_prev, double h, double ci, double target);

struct CalibrationIteration {
    JointPropertySpec joint;
    double E = 0, nu = 0, ucs = 0, tensile = 0;             ///< means over realizations
    double E_std = 0, nu_std = 0, ucs_std = 0, tensile_std = 0;
    /// σ1 at the σ3 of each confined target (means over realizations, std).
    std::vector<double> confined, confined_std;
    double E_test = 0, E_test_std = 0; ///< E of the UCS curves (initial slope), for comparison
    double ci_ratio = 0, ci_ratio_std = 0; ///< σci/UCS of the UCS runs
    /// The largest |measure / target − 1| over E, ν, UCS, tension and the confined targets.
    double misfit = 0;
    double seconds = 0;
    bool converged = false;
    /// Runs that reached the lab test's max_strain still loading (LabTestResult::
    /// still_loading): their peaks, and the means with them, are lower bounds.
    int still_loading = 0;
};

/// The calibrated set of an iteration table: the converged iteration, or else the
/// one with the smallest misfit.
const CalibrationIteration& best_iteration(const std::vector<CalibrationIteration>& iterations);

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
/// from elastic_measure, the strengths and σci/UCS from the UCS and tension
/// tests, and σ1 from biaxial tests at each of `confinements`), without misfit.
CalibrationIteration measure_macro_properties(const JointPropertySpec& joint, const CalibrationOptions& o,
                                              std::uint64_t first_seed,
                                              const std::vector<double>& confinements = {});


/// Mean and sample standard deviation (0 for fewer than two values; the mean of
/// none is 0) of the realizations' measures.
void mean_std(const std::vector<double>& v, double& mean, double& sd);

/// The misfit of measured properties against the targets (CalibrationIteration::misfit);
/// with `with_ci`, |σci/UCS / target − 1| too.
double calibration_misfit(const CalibrationIteration& it, const CalibrationTargets& t, bool with_ci = false);

} // namespace bbm
