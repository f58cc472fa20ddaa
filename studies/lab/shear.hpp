// bbm studies: the direct shear test of a rock joint or of a non-persistent joint
// with rock bridges (issue 26), as a rock-mechanics laboratory runs it (ISRM
// suggested method for the direct shear test of rock discontinuities, 2014).
//
// The specimen is a width × height rectangle of bonded blocks; a joint plane at
// mid-height runs across it, persistent (persistence k = 1) or as joint segments
// with `bridges` rock bridges of intact rock between them (k < 1): the joint
// segments are cut into the region before the block pattern, so the bridges are
// bonded blocks that can break (the paper's closing remark). The joint segments
// have their own property (unbonded Coulomb, a weak brittle bond or a softening
// bond); the rock's bonds are the lab tests' bond.
//
// Loading, a shear box of rigid halves: the blocks with an edge on the bottom face
// or on a side face below the plane are the lower box (held still); those with an
// edge on the top face or on a side face above the plane are the upper box, moved
// as one rigid body (no rotation): horizontally at the shear rate, vertically by a
// servo that holds the normal force at
//   N = W (σn0 + K dv)    (dv: the box's upward displacement since shearing began)
// — constant normal load (CNL) with K = 0, constant normal stiffness (CNS, the
// surrounding rock of a joint in the field) with K > 0. The normal stress is
// applied first (ramped, then settled) with the box held horizontally.
//
// Measures, per record: shear displacement u (the box's), shear stress
// τ = (F_lower − F_upper)_x / 2W (the mean of the two boxes' reactions, over the
// nominal area: u stays ≪ W), normal stress σn = N/W, dilation dv; the peak and
// the residual (mean over the last tenth of the displacement), the dilation at
// the peak and the largest dilation angle, cracks. Over several normal stresses a
// Coulomb line τ = c + σn tan φ is fitted to the peaks and to the residuals.
#pragma once

#include "studies/lab/labtest_values.hpp"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace bbm {

struct ShearTestOptions {
    /// The rock of the box: its blocks, the bonds of the intact rock (and the
    /// bridges) and their density (bbm shear's blocks are rigid).
    RockSpec rock = [] {
        RockSpec r = paper_rock();
        r.pattern.size = 0.1;
        return r;
    }();
    double width = 2.0, height = 1.0; ///< m
    JointPropertySpec plane; ///< the joint segments on the shear plane
    double persistence = 1.0; ///< k: joint length over the plane's length
    int bridges = 1;          ///< rock bridges along the plane (k < 1), centred in equal cells
    double normal_stress = 5e6;   ///< σn0, Pa (compression positive)
    double normal_stiffness = 0.0; ///< K of CNS, Pa/m; 0 = constant normal load
    double shear_rate = 2e-8;     ///< box displacement per step, m (quasi-static steps)
    double max_displacement = 2e-3; ///< m
    /// Servo: the box's vertical speed per step is servo_gain × (N − N_target) /
    /// the specimen's normal stiffness (its rows of bonds and the plane in series).
    double servo_gain = 0.05;
    int record_every = 20;
    long frame_every = 0;
    int threads = 1;
    double max_elements = 0;
};

struct ShearPoint {
    long step;
    double displacement, shear_stress, normal_stress, dilation;
    int cracks_tensile, cracks_shear;
};

struct ShearTestResult {
    double normal_stress = 0.0;      ///< σn0 asked
    double peak_shear_stress = 0.0, displacement_at_peak = 0.0, normal_stress_at_peak = 0.0;
    double residual_shear_stress = 0.0, residual_normal_stress = 0.0;
    double dilation_at_peak = 0.0, final_dilation = 0.0;
    double peak_dilation_angle = 0.0; ///< degrees: the steepest dv/du over 5% of the run's displacement
    /// Largest |σn − target| / target while shearing: how well the servo held the boundary condition.
    double normal_stress_error = 0.0;
    int blocks = 0, contacts = 0, plane_joints = 0;
    int cracks_tensile = 0, cracks_shear = 0;
    long steps = 0;
    double wall_seconds = 0.0;
    std::uint64_t seed = 0;
    std::vector<ShearPoint> curve;
};

meshing::ModelGeometrySpec shear_geometry(const ShearTestOptions& o);
AnalysisSpec shear_analysis(const ShearTestOptions& o);

class Solver;
/// Runs one direct shear test. `on_finish` sees the final state (for output),
/// `on_frame` the state every frame_every steps of shearing.
ShearTestResult run_shear_test(const ShearTestOptions& o,
                               const std::function<void(const ShearPoint&)>& progress = {},
                               const std::function<void(const Solver&, const ShearTestResult&)>& on_finish = {},
                               const std::function<void(const Solver&, const ShearPoint&)>& on_frame = {});

namespace studies {

/// `bbm shear`'s values: the box (its rock, plane and loading: `o`), the normal
/// stresses of the series, and as the lab tests take them the rock file,
/// realizations, threads and output (`lab`).
struct ShearValues {
    LabTestValues lab;
    ShearTestOptions o;
    std::vector<double> normal_stresses{5e6}; ///< Pa: one series of tests per value
    ShearValues();
};

struct ShearStudy {
    std::vector<ShearTestResult> results; ///< normal stress by normal stress, realizations within
    std::string summary_json;
};

/// Runs the series (normal stresses × realizations spread over threads and
/// ranks), writes summary.json, shear.csv, shear_stress.png, dilation.png and
/// per run failure.png and VTK in --out. Returns 0. Throws InputError naming a flag.
int run_shear(ShearValues& values, bool quiet, bool check_only, ShearStudy* study = nullptr);

} // namespace studies
} // namespace bbm
