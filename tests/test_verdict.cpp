// The verdict of a run (core/verdict.hpp): the rules on recorded samples, then
// real models — a block that comes to rest, one sliding down a plane steeper than
// its friction angle (a collapse), a block falling free above a supported base
// (a fragment: the rock mass is at rest although the model's ratio is not), a
// stage that stops at rest, one that waits for equilibrium, and a resumed run
// that gives the same verdict.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"
#include "tests/validation.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <sstream>
#include <string>

using namespace bbm;

namespace {

using K = Verdict::Kind;

/// Samples every 100 steps from step 0 to `steps`, built by `at(step)`.
template <class F> std::vector<MonitorSample> samples(long steps, F&& at) {
    std::vector<MonitorSample> v;
    for (long k = 0; k <= steps; k += StageMonitor::sample_every) {
        MonitorSample m = at(k);
        m.step = k;
        v.push_back(m);
    }
    return v;
}

struct Silent : StageObserver {};

struct Built {
    io::ModelFile file;
    meshing::BlockAssembly blocks;
};

Built build(const std::string& text) {
    Built b;
    b.file = io::parse_model(text, "verdict.toml");
    b.blocks = meshing::generate_blocks(b.file.geometry);
    return b;
}

Built load(const std::string& name) {
    Built l;
    l.file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/verification/" + name);
    l.blocks = meshing::generate_blocks(l.file.geometry);
    return l;
}

/// examples/verification/dropped_block.toml (a bonded Voronoi base held at its
/// foot, a 1 m block above it) with the block `gap` m above the base, so that it
/// falls freely until it lands, and `stage` in place of its stages.
std::string base_and_block(double gap, const std::string& stage) {
    std::ifstream in(std::string(BBM_SOURCE_DIR) + "/examples/verification/dropped_block.toml");
    std::string text{std::istreambuf_iterator<char>(in), {}};
    const std::string block = "min = [1.5, 1.5], max = [2.5, 2.5]";
    REQUIRE(text.find(block) != std::string::npos);
    std::ostringstream moved;
    moved << "min = [1.5, " << 1.0 + gap << "], max = [2.5, " << 2.0 + gap << "]";
    text.replace(text.find(block), block.size(), moved.str());
    return text.substr(0, text.find("[[stage]]")) + stage;
}

} // namespace

TEST_CASE("verdict rules on recorded samples: equilibrium, fragments, failing, a burst, a collapse, not converged") {
    const double target = 1e-5;
    // At rest: no crack, the ratio at its target.
    auto v = judge(samples(10000, [](long) { return MonitorSample{.cracks = 40, .ratio = 1e-6, .rock_ratio = 1e-6}; }), target);
    CHECK(v.kind == K::equilibrium);
    CHECK(v.window_steps == 2500); // a quarter of the stage, within 1,000-5,000
    // A block falling freely keeps the model's ratio up; the rock mass is at rest.
    v = judge(samples(10000, [](long) {
                  return MonitorSample{.cracks = 40, .ratio = 3.0, .rock_ratio = 1e-6, .fragments = 1,
                                       .fragment_blocks = 2, .fragment_mass = 5400.0};
              }),
              target);
    CHECK(v.kind == K::equilibrium_with_fragments);
    CHECK(v.fragments == 1);
    CHECK(v.fragment_mass == 5400.0);
    // Cracks at a steady rate, the rock moving at a steady speed: failing.
    v = judge(samples(20000, [](long k) { return MonitorSample{.cracks = k / 50, .ratio = 1e-3, .rock_ratio = 1e-3,
                                                               .rock_kinetic = 1.0, .rock_speed = 1e-6}; }),
              target);
    CHECK(v.kind == K::failing);
    CHECK(v.window_steps == 5000);
    CHECK(v.crack_rate == doctest::Approx(20.0));
    // A burst of cracks at the end of a quiet stage: its speed rises and falls.
    v = judge(samples(20000, [](long k) {
                  const double burst = std::exp(-std::pow((k - 17500.0) / 800.0, 2));
                  return MonitorSample{.cracks = k > 17000 ? 10 : 0, .ratio = 1e-3, .rock_ratio = 1e-3,
                                       .rock_kinetic = 1.0 + burst, .rock_speed = 1e-7 * (1.0 + 10.0 * burst)};
              }),
              target);
    CHECK(v.kind == K::failing);
    // The rock mass accelerating from rest at a constant rate, no crack: a collapse,
    // though its speed gains only 25% over the window.
    v = judge(samples(20000, [](long k) {
                  const double speed = 1e-9 * double(k);
                  return MonitorSample{.cracks = 5, .ratio = 0.5, .rock_ratio = 0.5, .rock_kinetic = speed * speed,
                                       .rock_speed = speed};
              }),
              target);
    CHECK(v.kind == K::collapsing);
    CHECK(v.speed_trend > 1.1);
    CHECK(v.speed_trend < 1.3);
    // Slowing down without cracking, the ratio not yet at its target.
    v = judge(samples(20000, [](long k) {
                  const double speed = 1e-6 * std::exp(-double(k) / 5000.0);
                  return MonitorSample{.ratio = 1e-4, .rock_ratio = 1e-4, .rock_kinetic = speed * speed, .rock_speed = speed};
              }),
              target);
    CHECK(v.kind == K::not_converged);
    // Too short to judge.
    CHECK(judge(samples(300, [](long) { return MonitorSample{}; }), target).kind == K::none);
}

TEST_CASE("a dynamic stage's verdict: a wave that has passed settles, one still ringing moves, cracks fail") {
    // A pulse's kinetic energy: rising to a peak of 1 J/m at 0.01 s, then decaying
    // with a time constant `tau` (a step of 1e-6 s).
    auto pulse = [](double tau, long cracks_from) {
        return samples(20000, [=](long k) {
            const double t = 1e-6 * double(k);
            const double ke = t < 0.01 ? t / 0.01 : std::exp(-(t - 0.01) / tau);
            return MonitorSample{.cracks = k >= cracks_from ? k / 100 : 0, .ratio = 0.3, .rock_ratio = 0.3,
                                 .rock_kinetic = ke, .rock_speed = 1e-6 * std::sqrt(ke), .time = t};
        });
    };
    // Absorbed in a millisecond: at most e^-5 of its peak in the window (the last
    // 5,000 steps), below 1%.
    auto v = judge_dynamic(pulse(1e-3, 1L << 40));
    CHECK(v.kind == K::settled);
    CHECK(v.at_rest());
    CHECK(v.model_time == doctest::Approx(0.02));
    CHECK(v.kinetic_fraction == doctest::Approx(std::exp(-5.0)).epsilon(1e-9));
    // Ringing on (a 0.1 s decay): 95% of its peak in the window, the ratio no matter.
    v = judge_dynamic(pulse(0.1, 1L << 40));
    CHECK(v.kind == K::moving);
    CHECK(!v.at_rest());
    CHECK(v.kinetic_fraction == doctest::Approx(std::exp(-0.05)).epsilon(1e-9));
    // The energy gone but bonds still breaking in the window's last quarter: failing.
    CHECK(judge_dynamic(pulse(1e-3, 19000)).kind == K::failing);
    // The unbalanced ratio's verdict of the same samples would have said "failing"
    // or "not converged" for a passed wave: its ratio is a wave's, not a load's.
    CHECK(judge(pulse(1e-3, 1L << 40), 1e-5).kind == K::not_converged);
    CHECK(judge_dynamic(samples(300, [](long) { return MonitorSample{}; })).kind == K::none);
}

TEST_CASE("verdict: a dropped block comes to rest on its base (settled: a dynamic stage's rest)") {
    auto m = load("dropped_block.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    const auto r = run_stages(s, m.file.analysis.stages, quiet);
    const auto& v = r.back().verdict;
    INFO(describe(v));
    CHECK(v.kind == K::settled);
    CHECK(v.at_rest());
    CHECK(v.fragments == 0);
    CHECK(v.cracks_in_window == 0);
}

TEST_CASE("verdict: a block sliding down a plane steeper than its friction angle is collapsing, and below it it sticks") {
    for (double theta : {30.0, 10.0}) {
        auto m = load("sliding_block.toml");
        const double g = 9.81, t = theta * std::numbers::pi / 180.0;
        m.file.analysis.solver.gravity = {g * std::sin(t), -g * std::cos(t)};
        m.file.analysis.stages[0].stress.syy = -2000.0 * g * std::cos(t);
        // Damped, so that the sticking block's elastic oscillation dies out.
        m.file.analysis.solver.damping = 0.3;
        m.file.analysis.stages[1].steps = 6000;
        Solver s(m.blocks, m.file.analysis);
        Silent quiet;
        const auto r = run_stages(s, m.file.analysis.stages, quiet);
        const auto& v = r.back().verdict;
        INFO("theta " << theta << ": " << describe(v));
        // The sliding block touches the plane: it is rock mass, not a fragment.
        CHECK(v.fragments == 0);
        CHECK(v.kind == (theta > 20.0 ? K::collapsing : K::settled));
    }
}

TEST_CASE("verdict: a block falling free above a supported base is a fragment, and a stage can stop at rest") {
    // The block starts 4 m above the base and lands after about 0.9 s.
    auto m = build(base_and_block(4.0, R"(
[[stage]]
name = "settle"
type = "solve"
ratio = 1e-4
until = "rest"
quiet_steps = 1000
max_steps = 100000
)"));
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    const auto r = run_stages(s, m.file.analysis.stages, quiet);
    const auto& v = r.back().verdict;
    INFO(describe(v) << ", stopped at step " << r.back().steps << ", time " << s.world().clock.time << " s");
    CHECK(v.kind == K::equilibrium_with_fragments);
    CHECK(v.fragments == 1);
    CHECK(v.fragment_blocks == 1);
    CHECK(v.fragment_mass == doctest::Approx(2700.0).epsilon(1e-9));
    // The model's ratio is the falling block's weight; the rock mass's is at rest.
    CHECK(v.ratio > 1e-2);
    CHECK(v.rock_ratio <= 1e-4);
    CHECK_FALSE(r.back().converged);
    // It stopped at rest, before the block landed (it is still above the base).
    CHECK(r.back().steps < 100000);
    CHECK(s.world().clock.time < std::sqrt(2.0 * 4.0 / 9.81));
}

TEST_CASE("verdict: a stage can wait for equilibrium where the ratio comes while the rock still cracks" * validation) {
    // The paper's Voronoi tunnel with a loose ratio (1e-3): the model's ratio is
    // reached 620 steps into the failure stage while a crack still forms, and a
    // stage ending there leaves a rock that is failing. until = "equilibrium"
    // runs on until the verdict is equilibrium (no crack over its window).
    Verdict::Kind kinds[2];
    long steps[2];
    int cracks[2];
    for (int mode = 0; mode < 2; ++mode) {
        Built m;
        m.file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/tunnel_voronoi.toml");
        auto& failure = m.file.analysis.stages.back();
        REQUIRE(failure.kind == StageSpec::Kind::solve);
        failure.ratio = 1e-3;
        failure.until = mode == 0 ? StageSpec::Until::ratio : StageSpec::Until::equilibrium;
        m.blocks = meshing::generate_blocks(m.file.geometry);
        Solver s(m.blocks, m.file.analysis);
        Silent quiet;
        const auto r = run_stages(s, m.file.analysis.stages, quiet);
        INFO(std::string(mode == 0 ? "ratio: " : "equilibrium: ") << describe(r.back().verdict) << ", " << r.back().steps
                                                      << " steps");
        CHECK(r.back().converged);
        kinds[mode] = r.back().verdict.kind;
        steps[mode] = r.back().steps;
        cracks[mode] = bbm::cracks(s.world(), contact::JointState::broken_tension) +
                       bbm::cracks(s.world(), contact::JointState::broken_shear);
    }
    CHECK(kinds[0] == K::failing);
    CHECK(kinds[1] == K::equilibrium);
    CHECK(steps[1] > steps[0]);
    CHECK(steps[1] < 30000); // it stopped at the verdict, not at the step limit
    CHECK(cracks[1] >= cracks[0]);
}

TEST_CASE("verdict: a run stopped and resumed gives the uninterrupted run's verdict") {
    const auto text = base_and_block(0.3, R"(
[[stage]]
name = "drop"
type = "cycle"
steps = 4000
)");
    auto m = build(text);
    Solver whole(m.blocks, m.file.analysis);
    Silent quiet;
    const auto reference = run_stages(whole, m.file.analysis.stages, quiet).back().verdict;
    // Stopped at step 1,750 (between samples), checkpointed, resumed in a new solver.
    struct StopAt : StageObserver {
        long stop_step;
        StageCursor cursor;
        explicit StopAt(long k) : stop_step(k) {}
        void at(const Solver&, const StageCursor& c) override { cursor = c; }
        bool stop_requested() override { return cursor.step >= stop_step; }
    } stop(1750);
    Solver first(m.blocks, m.file.analysis);
    run_stages(first, m.file.analysis.stages, stop);
    std::stringstream saved;
    save_state(first.world(), saved);
    Solver resumed(m.blocks, m.file.analysis);
    load_state(resumed.world(), saved);
    const auto v = run_stages(resumed, m.file.analysis.stages, quiet, stop.cursor).back().verdict;
    INFO(describe(reference) << " / resumed: " << describe(v));
    CHECK(v.kind == reference.kind);
    CHECK(v.kind != K::none);
    CHECK(v.cracks_in_window == reference.cracks_in_window);
    CHECK(v.rock_ratio == reference.rock_ratio);
    CHECK(v.speed_trend == reference.speed_trend);
    CHECK(v.kinetic_trend == reference.kinetic_trend);
}
