// Stress corrosion (contact/laws/stress_corrosion.hpp, core/creep.hpp) against its
// closed form: one bonded joint pulled by a constant traction loses section at
// dω/dt = −ω̇1 exp(−β (1 − s)), s = s0/ω under the load held, and breaks when ω
// reaches s0, at
//     t_f = (e^β / ω̇1) ∫_{s0}^{1} exp(−β s0 / ω) dω
//         = (e^β / ω̇1) a [H(β) − H(a)],   a = β s0,  H(u) = E1(u) − e^{−u}/u;
// below its threshold it never breaks; halving the creep step's loss moves the
// time to failure by less than 2%; a creep stage resumed from a checkpoint ends
// in the same bits on 1 or 2 threads.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "core/state.hpp"
#include "base/error.hpp"
#include "studies/lab/creep_test.hpp"
#include "studies/model/model.hpp"

#include "model_text.hpp"
#include "restart.hpp"

#include <doctest/doctest.h>

#include "contact/laws/stress_corrosion.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

using namespace bbm;

namespace {

constexpr double tensile = 1e6, exponent = 20.0, rate_at_strength = 1e-6;

/// Two rigid blocks bonded along y = 0 (2 m), the lower one held, the upper one
/// pulled up by syy = ratio σt on its top: the bond's nominal stress ratio s0,
/// put on by one elastic solve (no dynamic overshoot).
std::string bonded_pair(double ratio, double threshold, double duration, double loss, long max_steps = 400000) {
    return R"(
[solver]
mode = "quasi_static"

[[region]]
name = "lower"
outline = { type = "rectangle", min = [-1.0, -1.0], max = [1.0, 0.0] }
pattern = { type = "single" }

[[region]]
name = "upper"
outline = { type = "rectangle", min = [-1.0, 0.0], max = [1.0, 1.0] }
pattern = { type = "single" }

[[joint_property]]
name = "bond"
law = "stress_corrosion"
kn = 1e10
ks = 1e10
tensile = 1e6
cohesion = 4e6
friction = 30.0
corrosion_rate = 1e-6
corrosion_exponent = 20.0
corrosion_threshold = )" +
           std::to_string(threshold) + R"(

[[joint_assignment]]
property = "bond"

[[boundary]]
name = "base"
type = "velocity"
regions = ["lower"]
vx = 0.0
vy = 0.0
omega = 0.0

[[boundary]]
name = "pull"
type = "stress"
box = { min = [-1.01, 0.99], max = [1.01, 1.01] }
syy = )" + std::to_string(ratio * tensile) +
           R"(

[[stage]]
name = "load"
type = "elastic"

[[stage]]
name = "hold"
type = "creep"
duration = )" + std::to_string(duration) +
           "\nloss = " + std::to_string(loss) + "\nratio = 1e-7\nmax_steps = " + std::to_string(max_steps) + "\n";
}

/// E1(u) − e^{−u}/u, the antiderivative of e^{−u}/u².
double h(double u) { return -std::expint(-u) - std::exp(-u) / u; }

double time_to_failure(double s0) {
    const double a = exponent * s0;
    return std::exp(exponent) / rate_at_strength * a * (h(exponent) - h(a));
}

/// Stops a run once its bond has broken, noting the creep time it broke at.
struct Breakage : StageObserver {
    std::optional<double> at;
    long after = 0;
    void step_done(const Solver& s, const StageSpec&, long) override {
        const World& w = s.world();
        if (!at && cracks(w, contact::JointState::broken_tension) > 0) at = w.creep->time;
        if (at) ++after;
    }
    bool stop_requested() override { return after > 50; }
};

struct Held {
    std::optional<double> broke_at;
    double creep_time = 0.0, least_section = 1.0;
    long creep_steps = 0;
};

Held hold(double ratio, double threshold, double duration, double loss) {
    const auto m = test::build_model(bonded_pair(ratio, threshold, duration, loss), "creep.toml");
    Solver s(m.blocks, m.file.analysis);
    Breakage b;
    run_stages(s, m.file.analysis.stages, b);
    const World& w = s.world();
    Held r{b.at, w.creep->time, 1.0, w.creep->steps};
    for (int i = 0; i < w.contacts.size(); ++i) r.least_section = std::min(r.least_section, w.contacts.bond_section[i]);
    return r;
}

} // namespace

TEST_CASE("a bond under a constant load corrodes and breaks at the time the law's integral gives") {
    for (const double s0 : {0.6, 0.8, 0.9}) {
        const double expected = time_to_failure(s0);
        const Held r = hold(s0, 0.0, 2.0 * expected, 0.02);
        REQUIRE(r.broke_at.has_value());
        MESSAGE("s0 = ", s0, ": broke at ", *r.broke_at, " s, closed form ", expected, " s (", r.creep_steps,
                " creep steps)");
        CHECK(std::abs(*r.broke_at / expected - 1.0) < 0.01);
    }
}

TEST_CASE("halving the creep step's loss moves the time to failure by under 2%") {
    const double expected = time_to_failure(0.8);
    const Held coarse = hold(0.8, 0.0, 2.0 * expected, 0.1), fine = hold(0.8, 0.0, 2.0 * expected, 0.05);
    REQUIRE(coarse.broke_at.has_value());
    REQUIRE(fine.broke_at.has_value());
    MESSAGE("loss 0.1: ", *coarse.broke_at, " s in ", coarse.creep_steps, " creep steps; 0.05: ", *fine.broke_at,
            " s in ", fine.creep_steps);
    CHECK(std::abs(*coarse.broke_at / *fine.broke_at - 1.0) < 0.02);
    CHECK(fine.creep_steps > coarse.creep_steps);
}

TEST_CASE("a bond below its threshold never corrodes: a century passes in one creep step") {
    const double century = 100.0 * seconds_per_year;
    const Held r = hold(0.5, 0.6, century, 0.02);
    CHECK_FALSE(r.broke_at.has_value());
    CHECK(r.creep_time == century);
    CHECK(r.least_section == 1.0);
    CHECK(r.creep_steps == 1);
    // Above it, the same century breaks it.
    CHECK(hold(0.7, 0.6, century, 0.02).broke_at.has_value());
}

TEST_CASE("a creep stage resumed from a checkpoint, on 1 or 2 threads, ends in the same bits") {
    // Held for half its time to failure: corroded, at rest at the stage's end.
    const auto m = test::build_model(bonded_pair(0.8, 0.0, 0.5 * time_to_failure(0.8), 0.02), "creep.toml");
    Solver whole(m.blocks, m.file.analysis);
    StageObserver quiet;
    const auto reports = run_stages(whole, m.file.analysis.stages, quiet);
    REQUIRE(reports.back().converged);
    CHECK(reports.back().creep_steps > 20);
    CHECK(whole.world().contacts.bond_section[0] < 0.99);
    const long steps = whole.world().clock.steps;
    test::check_exact_restart({m.blocks, m.file.analysis}, {steps / 3, 2 * steps / 3}, {1, 2});
}

TEST_CASE("a creep stage that finds no rest within settle_steps of its last creep step ends as a failure") {
    // An equilibrium it cannot reach (a ratio below round-off): without a creep
    // step the model never rests, and after settle_steps mechanical steps the
    // stage ends failed, at the creep time it had (none); with the default
    // 200,000 the same 3,000-step stage just runs out of steps.
    const auto run = [](const std::string& settle) {
        std::string text = bonded_pair(0.8, 0.0, 1.0, 0.02, 3000);
        text.replace(text.find("ratio = 1e-7"), 12, "ratio = 1e-300" + settle);
        const auto m = test::build_model(text, "creep.toml");
        Solver s(m.blocks, m.file.analysis);
        StageObserver quiet;
        return run_stages(s, m.file.analysis.stages, quiet).back();
    };
    const StageReport cut = run("\nsettle_steps = 1000");
    CHECK(cut.failed);
    CHECK(cut.steps == 1001);
    CHECK(cut.creep_steps == 0);
    const StageReport whole = run("");
    CHECK_FALSE(whole.failed);
    CHECK(whole.steps == 3000);
}

TEST_CASE("stress corrosion's bad input is refused with its key") {
    auto error = [](const std::string& text) -> std::string {
        try {
            const auto m = test::build_model(text, "creep.toml");
            Solver s(m.blocks, m.file.analysis);
        } catch (const InputError& e) {
            return e.key() + ": " + e.what();
        }
        return "accepted";
    };
    std::string text = bonded_pair(0.8, 0.0, 1.0, 0.02);
    auto with = [&](std::string from, std::string to) {
        std::string t = text;
        t.replace(t.find(from), from.size(), to);
        return t;
    };
    CHECK(error(with("corrosion_threshold = 0.000000", "corrosion_threshold = 1.0")).find("corrosion_threshold") !=
          std::string::npos);
    CHECK(error(with("corrosion_rate = 1e-6", "corrosion_rate = -1e-6")).find("corrosion_rate") != std::string::npos);
    CHECK(error(with("duration = 1.000000", "duration = 0.0")).find("duration") != std::string::npos);
    CHECK(error(with("loss = 0.020000", "loss = 0.0")).find("loss") != std::string::npos);
    CHECK(error(with("ratio = 1e-7", "ratio = 1e-7\nsettle_steps = 10")).find("settle_steps") != std::string::npos);
    const std::string no_corrosion = error(with("law = \"stress_corrosion\"", "law = \"softening\""));
    // A softening set does not read the corrosion keys; without them, the creep
    // stage is refused by its type.
    CHECK(no_corrosion.find("corrosion_rate") != std::string::npos);
    text = with("law = \"stress_corrosion\"", "law = \"softening\"");
    for (const char* key : {"corrosion_rate = 1e-6\n", "corrosion_exponent = 20.0\n", "corrosion_threshold = 0.000000\n"})
        text = with(key, "");
    const std::string no_law = error(text);
    CHECK(no_law.find("stage[1].type") == 0);
    CHECK(no_law.find("stress_corrosion") != std::string::npos);
}

// --- bbm creep: the static-fatigue test (studies/lab/creep_test.hpp) ------------

namespace {

/// A small specimen (0.5 m x 1 m of 0.1 m Voronoi blocks) of the default
/// corroding rock: seconds a run.
CreepTestOptions small_creep_test() {
    CreepTestOptions o;
    o.width = 0.5, o.height = 1.0;
    o.ratios = {0.9, 0.8};
    return o;
}

} // namespace

TEST_CASE("bbm creep: the short-term strength is bracketed, a lower held load lasts longer, and each run is its "
          "model file's") {
    const CreepTestOptions o = small_creep_test();
    const CreepTestResult res = run_creep_test(o);
    REQUIRE(res.strengths.size() == 1);
    const ShortTermStrength& s = res.strengths[0];
    CHECK(s.holds > 0.0);
    CHECK(s.fails > s.holds);
    CHECK(s.fails - s.holds <= o.strength_tolerance * s.holds);
    REQUIRE(res.runs.size() == 2);
    const CreepRun &high = res.runs[0], &low = res.runs[1];
    CHECK(high.load == doctest::Approx(0.9 * s.holds).epsilon(1e-12));
    REQUIRE(high.failed);
    REQUIRE(low.failed);
    // The static-fatigue line falls: the lower load lasts longer, by at least the
    // factor one bond's law gives for the same drop in its ratio at its weakest
    // (exp(β Δs) with Δs the macroscopic 0.1, β = 30: e^3 = 20, the assembly's
    // redistribution makes it shallower, docs/time.md: at least 2).
    CHECK(low.time_to_failure > 2.0 * high.time_to_failure);
    CHECK(res.decades_per_ratio < 0.0);
    // Creep strain grows while held, and fastest at the end (tertiary creep).
    REQUIRE(high.curve.size() > 3);
    CHECK(high.creep_strain > 0.0);
    for (std::size_t k = 1; k < high.curve.size(); ++k) CHECK(high.curve[k].time >= high.curve[k - 1].time);
    // The run is what `bbm run` does with the model file it writes: the same time to failure to the bit.
    studies::Model m = studies::Model::from_text(creep_model_text(o, high.seed, high.load, true), "creep.toml");
    m.run();
    CHECK(m.reports().back().failed);
    CHECK(m.reports().back().creep_time == high.time_to_failure);
}

TEST_CASE("bbm creep: a held load below every bond's threshold passes its century in one creep step") {
    CreepTestOptions o = small_creep_test();
    o.ratios = {0.1, 0.2};
    o.strength_tolerance = 0.05;
    const CreepTestResult res = run_creep_test(o);
    REQUIRE(res.runs.size() == 2);
    // At 0.1 of the strength no bond is at its threshold (0.4): nothing corrodes.
    const CreepRun& idle = res.runs[0];
    REQUIRE(idle.highest_ratio_at_load < 0.4);
    CHECK_FALSE(idle.failed);
    CHECK(idle.time_to_failure == doctest::Approx(o.max_time).epsilon(1e-12));
    CHECK(idle.creep_steps == 1);
    CHECK_FALSE(idle.step_limit);
    CHECK(idle.cracks_tensile + idle.cracks_shear == idle.cracks_at_load);
    CHECK(std::abs(idle.creep_strain) < 1e-9); // the elastic strain under the load is about 1e-4
    // At 0.2 the blocks' corners put a few bonds above it (the assembly's stress
    // concentrations): they corrode and break, the rock holds its century.
    const CreepRun& slow = res.runs[1];
    CHECK(slow.highest_ratio_at_load > 0.4);
    CHECK_FALSE(slow.failed);
    CHECK(slow.creep_steps > 1);
}

TEST_CASE("bbm creep's bad options are refused by flag") {
    CreepTestOptions o = small_creep_test();
    o.rock.bonds.law = "softening";
    CHECK_THROWS_WITH_AS(check_creep_options(o), doctest::Contains("--law"), InputError);
    o = small_creep_test();
    o.ratios = {0.9, 1.2};
    CHECK_THROWS_WITH_AS(check_creep_options(o), doctest::Contains("--ratios"), InputError);
    o = small_creep_test();
    o.rock.pattern.size = 0.4;
    CHECK_THROWS_WITH_AS(check_creep_options(o), doctest::Contains("--size"), InputError);
}

TEST_CASE("bbm creep --fit-record recovers the corrosion law that made a static-fatigue record") {
    // The record: the small specimen's own times at three ratios with beta = 30 and
    // rate 1e-6 /s; the fit starts from beta = 15 and rate 1e-4 /s.
    CreepTestOptions o = small_creep_test();
    o.ratios = {0.9, 0.85, 0.8};
    const CreepTestResult truth = run_creep_test(o);
    std::vector<FatiguePoint> record;
    for (const CreepRun& r : truth.runs) {
        REQUIRE(r.failed);
        record.push_back({r.ratio, r.time_to_failure});
    }
    CreepTestOptions start = o;
    set_law_value(start.rock.bonds, "corrosion_exponent", 15.0);
    set_law_value(start.rock.bonds, "corrosion_rate", 1e-4);
    const FatigueFit fit = fit_static_fatigue(start, record, 0.05, 8);
    REQUIRE(fit.converged);
    CHECK(contact::key_corrosion_exponent.get(fit.bonds) == doctest::Approx(30.0).epsilon(0.15));
    CHECK(std::log10(contact::key_corrosion_rate.get(fit.bonds)) == doctest::Approx(-6.0).epsilon(0.1));
    // The fitted set's times against the record's, ratio by ratio: within a factor 1.5.
    REQUIRE(fit.final_test.runs.size() == record.size());
    for (std::size_t k = 0; k < record.size(); ++k) {
        INFO("ratio " << record[k].ratio);
        CHECK(fit.final_test.runs[k].failed);
        CHECK(std::abs(std::log10(fit.final_test.runs[k].time_to_failure / record[k].time)) < std::log10(1.5));
    }
}

TEST_CASE("a static-fatigue record's defects are refused with their line") {
    const auto path = std::filesystem::temp_directory_path() / "bbm_fatigue_record.csv";
    const auto refused = [&](const std::string& text) {
        std::ofstream(path) << text;
        try {
            read_fatigue_record(path.string());
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    CHECK(refused("ratio,time\n0.9,100\n1.2,1000\n").find(":3") != std::string::npos);
    CHECK(refused("ratio,time\n0.9,100\n0.8,-5\n").find("must be positive") != std::string::npos);
    CHECK(refused("ratio,time\n0.9,100\n").find("two stress ratios") != std::string::npos);
    CHECK(refused("ratio,time\n0.9,1000\n0.8,100\n").find("not static fatigue") != std::string::npos);
    CHECK(refused("ratio,time\n0.9,100\nx,y\n").find(":3") != std::string::npos);
    CHECK(refused("# a comment\nratio,time\n0.9,100\n0.8,1000\n") == "accepted");
    std::filesystem::remove(path);
}
