// bbm studies: the broken joints' friction calibrated on broken rock's, as the
// laboratory measures it (`bbm calibrate --target-residual-friction`; issue 48).
//
// Once a bonded joint has broken it slides at its residual friction φr. No
// laboratory test measures φr; what the laboratory measures is the friction of
// the rubble a failed specimen becomes: a confined test run far past its peak
// settles at a residual strength σr, whose friction angle with no cohesion left
// is φ = asin((σr − σ3)/(σr + σ3)) (LabTestResult::residual_friction_angle;
// docs/calibration.md, "The residual strength"). Rigid rubble interlocks, so it
// slides at far more than its joints' φr (Lac du Bonnet's in-situ set: 41° at
// φr = 10°, 1–1.7° of rubble friction per degree of φr). The iteration finds the
// φr whose rubble slides at the target φ (broken crystalline rock: Byerlee's
// τ = 0.85 σn, 40.4°): `realizations` biaxial tests at σ3, each to
// max_strain (2%) whatever the stress does, their mean φ against the target;
// the next φr by the secant of the last two iterations (a slope within 0.3–5),
// else by 1.4° of rubble friction per degree; steps within ±10°, φr within
// [0°, 60°]; done within `tolerance` degrees.
#pragma once

#include "studies/calibration/calibrate.hpp"

#include <functional>
#include <vector>

namespace bbm {

/// What the broken rock slides at, and how it is measured.
struct ResidualFrictionTarget {
    double friction = 0.0;    ///< the rubble's friction angle, degrees (0: not calibrated)
    double confinement = 0.0; ///< σ3 of the tests, Pa (compression positive)
    double tolerance = 1.0;   ///< degrees
    int max_iterations = 5;
    double max_strain = 0.02; ///< each test runs to this axial strain
};

/// One iteration: the broken joints' friction and what its rubble measured.
struct ResidualFrictionStep {
    double residual_friction = 0.0;                 ///< φr of the broken joints, degrees
    double rubble_friction = 0.0, rubble_std = 0.0; ///< mean and sample std over the measured runs, degrees
    double residual_stress = 0.0;                   ///< mean σr, Pa
    double peak_stress = 0.0;                       ///< mean peak, Pa
    int unmeasured = 0; ///< runs that ended too soon after their peak to measure (not in the means)
    double seconds = 0.0;
    bool converged = false;
};

/// The rubble's friction of `joint` on the seeds first_seed, first_seed + 1, ...
/// (o.realizations of them, over o.threads and the ranks).
ResidualFrictionStep measure_rubble_friction(const JointPropertySpec& joint, const ResidualFrictionTarget& t,
                                             const CalibrationOptions& o, std::uint64_t first_seed);

/// The next φr from the last two iterations (phi_prev < 0: none before).
double next_residual_friction(double phi_prev, double measured_prev, double phi, double measured, double target);

/// Iterates the broken joints' friction of `joint` (its residual_friction, or its
/// friction if none, is the start) until its rubble slides at t.friction; `report`
/// sees each iteration. The calibrated φr is the converged iteration's, or else
/// the one nearest the target (best_residual_step).
std::vector<ResidualFrictionStep> calibrate_residual_friction(JointPropertySpec joint, const ResidualFrictionTarget& t,
                                                              const CalibrationOptions& o,
                                                              const std::function<void(const ResidualFrictionStep&)>& report = {});

/// The converged iteration, or else the one whose rubble came nearest the target.
const ResidualFrictionStep& best_residual_step(const std::vector<ResidualFrictionStep>& steps, double target);

} // namespace bbm
