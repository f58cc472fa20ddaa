// bbm studies: the static-fatigue test (`bbm creep`; issue 74) — a specimen held
// under a constant load below its short-term strength while its bonds corrode
// (law = "stress_corrosion", docs/theory.md §17), as a laboratory runs it on
// granite (Schmidtke and Lajtai 1985; Potyondy 2007 ran it on a bonded-particle
// model): load to a stress ratio of the short-term strength, hold, and measure the
// time to failure, the creep strain and the cracks against time; over several
// ratios and seeds, the static-fatigue line (log time to failure against ratio).
//
// The specimen is a width × height rectangle cut from the rock, its base held (the
// blocks touching y = 0: no motion), a uniform vertical stress on its top face (a
// stress boundary, so the load holds however the top moves), quasi-static mode.
// Each seed's short-term strength is the largest such stress it carries at rest
// with the bonds' own law without corrosion (softening): the load put on at once
// by one elastic solve, then solved to equilibrium — at rest, or not (cracking
// on, failing or collapsing) — bracketed and bisected to `strength_tolerance`.
// This is the strength of the loading the creep test holds (a dead load), not the
// UCS of a strain-controlled test (which passes its peak under control and reads
// a few per cent higher). Then, per ratio r, the same specimen under r times it
// with the corroding law: the load by one elastic solve, then a `creep` stage of
// `max_time` that ends when the rock collapses (its creep time the time to
// failure) or at max_time (no failure: a lower bound). Each run is a model built
// from a generated model file (model_text): what `bbm run` would do with it, the
// same bits, kept in the run's folder.
#pragma once

#include "core/creep.hpp"
#include "core/rock.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bbm {

struct CreepTestOptions {
    /// The rock: its bonds must corrode (law stress_corrosion). The default is
    /// the paper's rock with the illustrative corrosion of examples/time/
    /// static_fatigue.toml (rate 1e-6 /s at s = 1, β = 30, threshold 0.4; not
    /// calibrated) on 0.1 m blocks.
    RockSpec rock = [] {
        RockSpec r = paper_rock();
        r.pattern.size = 0.1;
        r.bonds.law = "stress_corrosion";
        set_law_value(r.bonds, "corrosion_rate", 1e-6);
        set_law_value(r.bonds, "corrosion_exponent", 30.0);
        set_law_value(r.bonds, "corrosion_threshold", 0.4);
        return r;
    }();
    double width = 1.0, height = 2.0;           ///< m
    std::vector<double> ratios{0.9, 0.85, 0.8}; ///< held load over the short-term strength
    int realizations = 1;                       ///< seeds seed, seed + 1, ...
    double max_time = 100.0 * seconds_per_year; ///< s: a run not failed by then holds (a lower bound)
    double loss = 0.02;                         ///< the creep stage's loss per creep step
    /// The short-term strength's bracket, relative: bisection stops when
    /// (fails − holds) ≤ strength_tolerance × holds.
    double strength_tolerance = 0.01;
    long max_steps = 20000000;                  ///< mechanical steps of a creep stage
    long strength_max_steps = 100000;           ///< of a trial of the short-term strength
    int threads = 1;
    double max_elements = 0;
};

/// One sample of a held specimen, at each change of creep time.
struct CreepPoint {
    double time;   ///< creep time, s
    double strain; ///< axial creep strain: the top's shortening since the hold began over the height
    int cracks_tensile, cracks_shear;
};

struct CreepRun {
    std::uint64_t seed = 0;
    double ratio = 0.0, load = 0.0;  ///< load: the held stress, Pa
    bool failed = false;             ///< the rock collapsed within max_time
    /// Neither failed nor held to max_time: the hold reached max_steps mechanical
    /// steps first (time_to_failure is then only a lower bound).
    bool step_limit = false;
    double time_to_failure = 0.0;    ///< s (failed), else the creep time reached
    int cracks_tensile = 0, cracks_shear = 0;
    int cracks_at_load = 0;          ///< cracks when the load was on (before any creep)
    /// The most loaded bond's stress ratio when the load was on: below the bonds'
    /// threshold nothing corrodes and the whole hold is one creep step.
    double highest_ratio_at_load = 0.0;
    long creep_steps = 0, steps = 0;
    double creep_strain = 0.0;       ///< at the end
    double wall_seconds = 0.0;
    std::vector<CreepPoint> curve;
};

/// A seed's short-term strength under a dead load: it holds at `holds`, not at `fails`.
struct ShortTermStrength {
    std::uint64_t seed = 0;
    double holds = 0.0, fails = 0.0; ///< Pa
    int trials = 0;
    int blocks = 0, contacts = 0;
};

struct CreepTestResult {
    std::vector<ShortTermStrength> strengths; ///< by realization
    std::vector<CreepRun> runs;               ///< by realization, then ratio
    /// Per ratio (as given): the geometric mean time to failure over the runs that
    /// failed (0 if none did) and how many did.
    std::vector<double> mean_time;
    std::vector<int> failed;
    /// The static-fatigue line fitted to the failed runs, log10 t = a + b r: the
    /// decades of time per unit of stress ratio (b < 0); 0 with fewer than two
    /// ratios failed.
    double decades_per_ratio = 0.0, line_intercept = 0.0;
};

/// The model file of one run: the specimen under `load` (Pa), held with the
/// corroding law (creep) or solved to equilibrium with its law without corrosion
/// (the short-term strength's trial).
std::string creep_model_text(const CreepTestOptions& o, std::uint64_t seed, double load, bool creep);

/// Checks the options (InputError naming the flag): a corroding law, ratios in
/// (0, 1), a specimen of a few blocks.
void check_creep_options(const CreepTestOptions& o);

/// Progress and the runs as they finish: `say` gets one line per seed's strength
/// and per run (and with it, a held run prints its creep time as it goes, on
/// standard error: base/progress.hpp).
/// `on_run` (optional) sees each finished creep run and its model file's text.
/// `strengths` (optional): the realizations' short-term strengths, found before
/// (they do not depend on the corrosion), not bisected again.
CreepTestResult run_creep_test(const CreepTestOptions& o, const std::function<void(const std::string&)>& say = {},
                               const std::function<void(const CreepRun&, const std::string& text)>& on_run = {},
                               const std::vector<ShortTermStrength>* strengths = nullptr);

/// A static-fatigue record: (stress ratio, time to failure in s), one row per test.
struct FatiguePoint {
    double ratio, time;
};
/// Reads a CSV of stress ratio and time to failure (s), a header line and `#`
/// comments allowed. Refused, naming the file and line: a ratio outside (0, 1), a
/// time not positive, fewer than two ratios, or a record whose times do not grow
/// as the load falls (its fitted line's slope ≥ 0).
std::vector<FatiguePoint> read_fatigue_record(const std::string& file);

/// log10 t = a + b r fitted to points by least squares; b = 0 if the ratios do not spread.
struct FatigueLine {
    double a = 0.0, b = 0.0;
    double at(double ratio) const { return a + b * ratio; }
};
FatigueLine fit_fatigue_line(const std::vector<FatiguePoint>& points);

/// One iteration of the fit: the law's β and ω̇1 tried and the line it gave.
struct FatigueFitIteration {
    double exponent = 0.0, rate = 0.0;
    FatigueLine line;
    int failed = 0, runs = 0; ///< runs that failed within max_time, of all
    double misfit = 0.0;      ///< rms of log10(t_model / t_record) at the record's ratios (failed runs)
};

/// The corrosion law fitted to a static-fatigue record on the bonds as given (the
/// short-term calibration's): the specimen is held at the record's ratios over the
/// realizations; β is scaled by the ratio of the record's slope to the model's
/// (the slope grows about in proportion to β) until they agree within
/// `slope_tolerance`, and ω̇1 each time by the mean offset of log t — exact, not
/// fitted: the mechanics has no time, so every time to failure scales as 1/ω̇1 —
/// until the model's times lie within 0.1 decade of the record's line on average;
/// each set is run to measure it. Not converged (max_iterations, or `unreachable`),
/// the set that came nearest. The threshold is the rock's as given.
struct FatigueFit {
    JointPropertySpec bonds;                 ///< the fitted set (not converged: the nearest tried)
    std::vector<FatigueFitIteration> iterations;
    std::vector<CreepTestResult> tests;      ///< each iteration's test
    int best = 0;                            ///< the iteration whose set `bonds` is
    FatigueLine record;
    CreepTestResult final_test;              ///< the test of `bonds`
    bool converged = false;
    /// Stopped because moving β no longer moved the specimen's slope toward the
    /// record's: the line's steepness is held by the assembly, out of the law's reach.
    bool unreachable = false;
};
FatigueFit fit_static_fatigue(const CreepTestOptions& o, const std::vector<FatiguePoint>& record,
                              double slope_tolerance = 0.1, int max_iterations = 6,
                              const std::function<void(const std::string&)>& say = {});

namespace studies {

/// `bbm creep`'s values: the test and where it writes.
struct CreepValues {
    CreepTestOptions o;
    std::string rock; ///< --rock, as the lab tests take it (read by the command line)
    /// --fit-record: fit the corrosion law to this static-fatigue record (CSV of
    /// stress ratio and time to failure, s) and write joint_property.toml.
    std::string fit_record;
    std::string out = "out";
    bool write_files = true;
};

struct CreepStudy {
    CreepTestResult result; ///< the test (with --fit-record: the fitted set's)
    std::string summary_json;
};

/// Runs the test and writes, in --out: summary.json (strengths, runs, the line),
/// creep.csv (one row per run), creep_curves.csv (creep time, strain and cracks of
/// every run), time_to_failure.png (the static-fatigue line), creep_curves.png
/// (creep strain against time over time to failure) and per run its model file;
/// with --fit-record first the fit (fit.json, joint_property.toml: the fitted set,
/// and the record beside the line in time_to_failure.png).
/// Returns 0. Throws InputError naming a flag.
int run_creep(CreepValues& values, bool quiet, bool check_only, CreepStudy* study = nullptr);

} // namespace studies
} // namespace bbm
