// bbm studies: numerical laboratory tests for micro-property calibration (paper §4.2,
// SPEC §8): uniaxial compression, direct tension, biaxial compression and the
// Brazilian test on a bonded-block specimen.
//
// Loading (documented choice): the platens are the specimen blocks with an edge on
// a loaded face (a disc: the blocks within half a block size of its poles); their
// velocities are prescribed (the top ones move, the bottom ones are held, no
// rotation). With `rough_platens` (the default) their horizontal velocity is held at
// zero too, like a platen bonded to the specimen; otherwise it is free, and only
// the bottom face's middle blocks are held horizontally against drift. With
// `platen_friction` ≥ 0 the platens are separate rigid blocks instead, pressing on
// the faces through frictional contacts (finite friction between the two).
// Confinement (biaxial) is a constant stress on the side faces, ramped up with the
// platens held and settled before the axial loading starts. Quasi-static mode,
// Δt = 1, mass scaling and local damping 0.8, so the platen velocity is a
// displacement per step.
//
// Measures, from the platen reaction and displacement:
//   axial stress  = −(reaction on the top platen) / width (compression positive)
//   axial strain  = platen displacement / height (compression positive)
//   lateral strain = mean horizontal displacement of the blocks of the right side
//                    band minus that of the left band, over the width
//   E  = least-squares slope of stress against strain over the pre-peak points
//        with stress between 10% and 50% of the peak (the initial linear part)
//   ν  = −(least-squares slope of lateral against axial strain) over the same points
// Brazilian: indirect tensile strength σt = 2P / (π D), P the peak line load.
// The run stops when the stress has dropped below `stop.fraction` of the peak
// after it, at `max_strain` (a specimen not yet failed there loads on, up to
// `strain_cap`: its strength is not measured yet), or when after failure (a drop by `failure_drop`, or
// a stall of the stress over 2e-4 of strain) it stays above the peak for 10
// records with broken and new contacts carrying at least half of the contact
// compression: fragments locked between the platens (post_peak_locking). Above
// the peak with the bonds carrying the load, the "failure" was a local burst of
// cracks, and loading goes on (unconfined tests; docs/calibration.md, After the
// peak). Confined tests read the laboratory's peak: a stall is yielding (kept as
// first_stall_stress), only a drop is failure, and a climb back above a dropped
// peak is loading on (stop.peak_at_first_stall: the former rule, the first stall
// is the strength; docs/calibration.md, The confined peak).
#pragma once

#include "core/model_spec.hpp"
#include "core/rock.hpp"
#include "meshing/spec.hpp"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace bbm {

/// Strain past a failed confined peak at which the envelope's and the
/// calibration's biaxial tests stop: the peak is final by then, and the tail shows
/// the drop (the stall rule looks back 2e-4 of strain).
inline constexpr double envelope_post_peak_strain = 2e-4;
/// The residual strength (LabTestResult::residual_stress): averaged over the last
/// residual_window_strain of a run that went on at least residual_run_strain past
/// its peak.
inline constexpr double residual_window_strain = 2e-3, residual_run_strain = 5e-3;

/// Servo-controlled platens: at every record the platen speed is multiplied by
/// `cracks` / (new cracks of the record), per 5,000 contacts, within [0.5, 1.1]
/// (×1.1 without new cracks) and kept within [min_factor, max_factor] ×
/// strain_per_step — slow while cracks redistribute load; once the specimen has
/// failed (LabTestStops::failure_drop) it rises to post_peak_factor ×
/// strain_per_step. The elastic part needs no speed: the implicit preload does it
/// at once. Once cracking has started the servo also holds the specimen in
/// equilibrium: the top and bottom platen forces may differ by at most `balance`
/// of the load (rate × balance / mismatch, within the same [0.5, 1.1]). A network
/// that fails in a cascade gives the crack count no warning, and loaded faster
/// than it can redistribute it carries more than its strength (trigon: +12%); the
/// force balance shows it. Measured on the paper's specimen:
/// docs/notes/2026-11-28-calibration-history.md, "Loading rate" and "Measured
/// against the paper".
struct LabTestServo {
    bool on = true;
    double cracks = 2.0;
    double balance = 0.02;
    double min_factor = 0.05, max_factor = 1.5, post_peak_factor = 0.5;
};

/// When a lab test stops, and how its strength is read from the curve.
struct LabTestStops {
    double fraction = 0.8;              ///< stop after the peak below this fraction of it
    /// A drop by this fraction from the peak marks failure: the peak is then the
    /// strength, and the run stops if the stress climbs back above it (confined,
    /// the laboratory's peak: loading goes on, LabTestResult::reloads).
    double failure_drop = 0.1;
    /// The strain at which a test stops, failed or not, unless it is still
    /// loading: a specimen that has not failed by then (no drop, no stall) loads
    /// on up to strain_cap, and once it fails stops by the same rules, at most
    /// max_strain past its peak.
    double max_strain = 0.01;
    /// Hard limit for a specimen still loading at max_strain (≤ max_strain: stop
    /// there). 3% is three times the elastic strain of a strong rock's confined
    /// peak (Lac du Bonnet at σ3 = 71 MPa: 777 / 70 000 = 1.1%); a specimen still
    /// loading at 3% is jammed, not strong (LabTestResult::still_loading).
    double strain_cap = 0.03;
    /// Confined tests (biaxial): stop this much axial strain past the failure once
    /// the specimen has failed (0: go on to max_strain or `fraction`): past the
    /// drop for the laboratory's peak (a climb back above it within the window is
    /// loading on), past the peak for the first-stall rule (whose failed peak is
    /// final). The envelope and calibration set envelope_post_peak_strain.
    double post_peak_strain = 0.0;
    /// Confined tests: how the strength is read from the curve.
    /// false (the laboratory's peak): the largest stress before a drop by
    /// failure_drop that lasts — a stress climbing back above a dropped peak is
    /// loading on (LabTestResult::reloads), and a specimen that only hardens runs
    /// to strain_cap (still_loading). true (the rule until 2026-11-27): the first
    /// stall after cracking (no net rise over 2e-4 of strain) is failure and a
    /// climb back above its peak stops the run — a strength the specimen may exceed
    /// by half when loaded on (Lac du Bonnet at σ3 = 71 MPa: 518 against 1,208 MPa;
    /// docs/calibration.md, "The confined peak").
    bool peak_at_first_stall = false;
    long max_steps = 2000000;
};

/// A persistent joint set across a rectangular specimen (Jaeger's single plane
/// of weakness when one joint): traces at `angle` degrees from horizontal,
/// `spacing` apart along their normal, one through the specimen's centre (spacing
/// 0: that one alone), cut before the blocks, with the property `joint` (kn, ks:
/// the bond's when 0).
struct LabTestJointSet {
    bool on = false;
    double angle = 60.0, spacing = 0.0;
    JointPropertySpec joint = [] {
        JointPropertySpec plane;
        plane.name = "joint_set";
        plane.law = "coulomb";
        return plane;
    }();
};

/// A lab test: the specimen, the rock, how it is loaded and when it stops.
struct LabTestOptions {
    enum class Kind { ucs, tension, biaxial, brazilian };
    Kind kind = Kind::ucs;
    /// The rock the specimen is cut from: its blocks (a random pattern's
    /// "randomly generated" blocks by default: Lloyd 0, the paper's; relaxed cells
    /// are ~20% stronger, docs/calibration.md), bonds and material.
    RockSpec rock = paper_rock();
    double width = 8.0, height = 16.0; ///< m (brazilian: width = diameter)
    LabTestJointSet joint_set;
    double confinement = 0.0;           ///< biaxial: lateral stress, Pa (positive = compression)
    /// Platen velocity over height, per step: the loading rate without the servo,
    /// the unit of its rates with it.
    double strain_per_step = 5e-8;
    LabTestServo servo;
    /// The linear part by one implicit solve (run_labtest), up to this fraction of
    /// the load at which the first joint yields; not with platen blocks (their
    /// frictional contacts are not linear).
    bool elastic_preload = true;
    /// Record seismic events (core/events.hpp): the test's acoustic emission. Off by
    /// default: marking the bonds costs the contact pass about 18% (paper UCS).
    bool events = false;
    double preload_fraction = 0.9;
    bool rough_platens = true;
    /// ≥ 0: instead of prescribing the face blocks, rigid platen blocks (one block
    /// size thick, as wide as the specimen) press on the faces through Coulomb
    /// contacts of this friction angle (degrees; kn, ks of the bond). Compression
    /// and biaxial tests only. < 0: the face blocks are the platens (rough_platens).
    double platen_friction = -1.0;
    LabTestStops stop;
    int record_every = 20;              ///< steps between stress-strain samples
    long frame_every = 4000;            ///< steps between frames of the failure series (0: none)
    int threads = 1;                    ///< threads of the contact loop
    double max_elements = 0;            ///< limit on blocks + triangles (0: half the machine's memory)

    /// The paper's Voronoi calibration run (SPEC §8): its rock, 8 × 16 m.
    static LabTestOptions paper_ucs() { return {}; }
};

struct StressStrainPoint {
    long step;
    double axial_strain, axial_stress, lateral_strain;
    int cracks_tensile, cracks_shear;
    double unbalanced_ratio;  ///< largest over the steps since the last point
    double strain_per_step;   ///< the platens' loading rate over those steps
    int events = 0;           ///< seismic events so far (core/events.hpp): the test's acoustic emission
};

struct LabTestResult {
    /// E and ν of the linear part of the pre-peak curve (measure_rock_mechanics);
    /// E50 the ISRM tangent modulus at 50% of the peak.
    double E = 0.0, nu = 0.0, E50 = 0.0, peak_stress = 0.0, strain_at_peak = 0.0;
    /// The stress at which the linear part used for E ends.
    double linear_limit_stress = 0.0;
    /// σci and σcd (compression tests): onset of sustained cracking, and of dilation.
    double crack_initiation_stress = 0.0, crack_damage_stress = 0.0;
    /// σci as a laboratory reads it from acoustic emission: the axial stress at which
    /// the seismic events so far first reach 2% of those at the peak (at least 3),
    /// the end of the quiet before sustained cracking (labtest_run.cpp). 0: none.
    double crack_initiation_events = 0.0;
    int events = 0, events_at_peak = 0; ///< seismic events of the whole test, and up to its peak
    double b_value = 0.0;               ///< their Gutenberg–Richter b (0: fewer than 10 above completeness)
    double tensile_strength = 0.0; ///< brazilian: 2P/(πD)
    int blocks = 0, contacts = 0;
    long steps = 0;
    double wall_seconds = 0.0;
    int cracks_tensile = 0, cracks_shear = 0;
    /// Cracks by the orientation of their joint when they formed (angle from
    /// horizontal, 0–180°), 12 bins of 15°; cracks removed by detection included.
    std::array<int, 12> crack_orientation{};
    int cracks_near_vertical = 0, cracks_near_horizontal = 0; ///< within 30° of each
    int cracks_near_vertical_at_peak = 0, cracks_near_horizontal_at_peak = 0; ///< the same, up to the peak
    /// With a joint set: the axial stress at which the set's joints first slide
    /// over half, and over 90%, of their length (bond broken or intact, at their
    /// frictional limit): the plane of weakness's strength, read where a
    /// laboratory reads it — the knee where the whole plane slips, before the
    /// pieces jam against the platens. 0: never.
    double joint_slip_stress_half = 0.0, joint_slip_stress = 0.0;
    bool peak_passed = false;
    /// The test reached its hard limit (strain_cap, or max_strain when that is
    /// larger; or max_steps while loading on) with its specimen not failed (no
    /// drop, no stall) and the stress at its peak (within 2%): peak_stress is the
    /// stress at the limit — a lower bound of the strength, not a strength
    /// (docs/calibration.md).
    bool still_loading = false;
    /// The specimen had not failed at max_strain and loaded on past it (a strong
    /// rock's confined test: Lac du Bonnet at σ3 = 35.5 MPa was still rising at
    /// 601 MPa at 1%).
    bool loaded_past_max_strain = false;
    /// After failure the stress climbed back above the peak (a jammed rubble core):
    /// the run stopped there and peak_stress is the peak before failure.
    bool post_peak_locking = false;
    /// Confined tests, the laboratory's peak: drops by failure_drop the stress
    /// climbed back above (bursts of cracks the specimen outlasted; loading went on).
    int reloads = 0;
    /// The peak before the first stall or drop after cracking (the strength the
    /// first-stall rule reads): with peak_stress far above it, a confined specimen
    /// yielded there and then hardened — its broken blocks interlock.
    double first_stall_stress = 0.0;
    /// The residual strength of a post-peak curve run far enough (compression,
    /// on at least residual_run_strain past its peak, the largest stress: e.g. biaxial
    /// --stop-fraction 0 --max-strain 0.02): the mean stress over its last
    /// residual_window_strain of axial strain; 0 when not measured. Confined, the
    /// macro friction it mobilises with no cohesion left, asin((σr − σ3)/(σr + σ3))
    /// in degrees — the rubble's friction, to set beside broken rock's in the
    /// laboratory (docs/calibration.md, "The residual strength").
    double residual_stress = 0.0, residual_friction_angle = 0.0;
    /// A confined specimen whose peak stands more than 20% above its first stall:
    /// it yielded and then hardened (broken blocks interlocking).
    bool hardened_past_yield() const { return first_stall_stress > 0.0 && peak_stress > 1.2 * first_stall_stress; }
    /// The implicit elastic preload could not be solved (the confinement left a
    /// block held at one point, or a loose group): the loading was explicit from
    /// the start, and E comes from the explicit curve.
    bool preload_skipped = false;
    std::vector<StressStrainPoint> curve;
};

/// Whether the test has separate platen blocks (platen_friction ≥ 0, compression).
bool uses_platen_blocks(const LabTestOptions& o);
/// The loaded height: the specimen's, or a Brazilian disc's diameter.
inline double specimen_height(const LabTestOptions& o) {
    return o.kind == LabTestOptions::Kind::brazilian ? o.width : o.height;
}

/// The traces of the persistent joint set (o.joint_set), clipped to the specimen.
std::vector<meshing::SegmentSpec> joint_set_traces(const LabTestOptions& o);

/// A confined test of `bbm envelope` or `bbm calibrate`: stopped
/// envelope_post_peak_strain past its failure (unless a window is given), and that
/// tail, which only shows the drop, run at the servo's fastest speed (max_factor,
/// or post_peak_factor if faster) instead of post_peak_factor's half speed. Before
/// the failure nothing changes: on four rocks (the paper's Hoek-Brown set, its
/// default joints, Lac du Bonnet's in-situ set with and without the confined
/// friction; 28 biaxial tests, 2026-11-30) the peaks, first stalls, sigma_ci,
/// sigma_cd, E and nu are the same to the last digit, most tests 5,120 steps
/// shorter (docs/performance.md). A climb back above the dropped peak within the
/// window (LabTestResult::reloads) is still loading on; none of those tests had one.
inline void as_envelope_confined_test(LabTestOptions& o) {
    if (o.stop.post_peak_strain <= 0.0) o.stop.post_peak_strain = envelope_post_peak_strain;
    if (o.servo.post_peak_factor < o.servo.max_factor) o.servo.post_peak_factor = o.servo.max_factor;
}

/// Geometry and analysis of a lab test.
meshing::ModelGeometrySpec labtest_geometry(const LabTestOptions& o);
AnalysisSpec labtest_analysis(const LabTestOptions& o);

class Solver;
/// Runs one test. `progress` (optional) is called with every recorded point;
/// `on_finish` (optional) sees the final solver state and the result (for output);
/// `on_frame` (optional) sees the state every `frame_every` steps of loading, with
/// the last recorded point (for a series of the failure).
LabTestResult run_labtest(const LabTestOptions& o,
                          const std::function<void(const StressStrainPoint&)>& progress = {},
                          const std::function<void(const Solver&, const LabTestResult&)>& on_finish = {},
                          const std::function<void(const Solver&, const StressStrainPoint&)>& on_frame = {});

/// The measures of rock mechanics (ISRM; Martin & Chandler 1994; SPEC §8) from a
/// finished curve (peak_stress set): E and ν as the slopes of the linear part —
/// the implicit preload's line (its first `preload_points` points) or, without
/// one, the pre-peak points from 10% of the peak up to the first broken bond or
/// 50% of the peak; E50 the tangent at 50% of the peak; for compression, σci
/// where the crack volumetric strain leaves zero for good and σcd where the
/// volumetric strain reverses.
void measure_rock_mechanics(LabTestResult& r, std::size_t preload_points, bool tension, long peak_step);

/// The residual strength of a finished compression curve (peak_stress and
/// strain_at_peak set): LabTestResult::residual_stress, and with a confinement its
/// residual_friction_angle. Left 0 for a curve that ends too soon after its peak.
void measure_residual_strength(LabTestResult& r, double confinement);

/// Least-squares slope of y on x.
double fit_slope(const std::vector<double>& x, const std::vector<double>& y);

} // namespace bbm
