// Viscous boundaries and incident waves (core/viscous.hpp) against one-dimensional
// wave theory: a P pulse sent in at the base of an elastic column (rollers on its
// sides: plane strain, constrained modulus) travels at c_p = √((λ + 2G)/ρ) with its
// particle velocity, carries the energy ρ c_p ∫v² dt per unit area, and leaves
// through an absorbing top; a free top reflects it with twice the velocity there.
#include "core/measures.hpp"
#include "core/state.hpp"
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "core/step.hpp"

#include "model_text.hpp"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>

using namespace bbm;

namespace {

constexpr double young = 10e9, poisson = 0.25, density = 2500.0, height = 40.0;
constexpr double v_in = 0.1, frequency = 200.0, start = 1e-3;

double p_wave_speed() {
    const double pm = young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    return std::sqrt(pm / density);
}

std::string column(bool absorbing_top) {
    std::ostringstream s;
    s << R"(
[solver]
mode = "dynamic"
damping = 0.0

[[material]]
name = "rock"
density = 2500.0
young = 10e9
poisson = 0.25

[[region]]
name = "column"
outline = { type = "rectangle", min = [0.0, 0.0], max = [1.0, 40.0] }
pattern = { type = "single" }
mesh = { size = 0.25 }

[[boundary]]
name = "sides"
type = "velocity"
box = { min = [-0.01, -1.0], max = [0.01, 41.0] }
vx = 0.0

[[boundary]]
name = "right side"
type = "velocity"
box = { min = [0.99, -1.0], max = [1.01, 41.0] }
vx = 0.0

[[boundary]]
name = "base"
type = "viscous"
box = { min = [-1.0, -0.01], max = [2.0, 0.01] }
pulse = "half_sine"
velocity = 0.1
frequency = 200.0
start = 1e-3
)";
    if (absorbing_top) s << R"(
[[boundary]]
name = "top"
type = "viscous"
box = { min = [-1.0, 39.99], max = [2.0, 40.01] }
)";
    return s.str();
}

int node_near(const World& w, Vec2 p) {
    int best = 0;
    for (int n = 1; n < w.nodes.count(); ++n)
        if (norm(w.nodes.position0[n] - p) < norm(w.nodes.position0[best] - p)) best = n;
    return best;
}

struct Record {
    double mid_y = 0.0; ///< the height of the node recorded half-way up
    double peak_mid = 0.0, peak_mid_at = 0.0, peak_top = 0.0;
    /// At y = 10 and 30 m: Σ t v² and Σ v², for the pulse's energy-weighted arrival
    /// time t̄ = ∫ t v² dt / ∫ v² dt (robust where a crest's sample is not).
    std::array<double, 2> tv2{}, v2{};
    double in_transit = 0.0;    ///< kinetic + strain energy with the pulse half-way up
    double left_after = 0.0;    ///< ... once it has reached the top and had time to leave
    double supplied = 0.0, absorbed = 0.0, worst_balance = 0.0;
    double base_absorbed_in_transit = 0.0;
};

Record send_pulse(const std::string& text, const std::string& name) {
    const auto m = test::build_model(text, name);
    Solver s(m.blocks, m.file.analysis);
    World& w = s.world();
    const int mid = node_near(w, {0.5, 20.0}), top = node_near(w, {0.5, height});
    const std::array<int, 2> gauges{node_near(w, {0.5, 10.0}), node_near(w, {0.5, 30.0})};
    const double c = p_wave_speed();
    const double transit = start + 20.0 / c + 0.5 / frequency, after = start + 1.5 * height / c;
    Record r;
    r.mid_y = w.nodes.position0[mid].y;
    bool transit_taken = false;
    while (w.clock.time < after) {
        s.step();
        const double t = w.clock.time;
        if (std::abs(w.nodes.velocity[mid].y) > r.peak_mid) r.peak_mid = std::abs(w.nodes.velocity[mid].y), r.peak_mid_at = t;
        r.peak_top = std::max(r.peak_top, std::abs(w.nodes.velocity[top].y));
        for (int g = 0; g < 2; ++g) {
            const double v = w.nodes.velocity[gauges[g]].y;
            r.tv2[g] += t * v * v, r.v2[g] += v * v;
        }
        // The account history.csv records (absorbed_energy, wave_energy: core/measures.hpp).
        const double supplied = wave_energy(w), absorbed = absorbed_energy(w);
        const double inside = kinetic_energy(w) + strain_energy(w);
        if (supplied > 0.0) r.worst_balance = std::max(r.worst_balance, std::abs(supplied - absorbed - inside));
        if (!transit_taken && t >= transit) {
            r.in_transit = inside, r.base_absorbed_in_transit = w.viscous.absorbed[0], transit_taken = true;
        }
        r.supplied = supplied, r.absorbed = absorbed, r.left_after = inside;
    }
    return r;
}

Record send_pulse(bool absorbing_top) { return send_pulse(column(absorbing_top), "column.toml"); }

} // namespace

TEST_CASE("a P pulse through a viscous base travels up an elastic column at c_p with its velocity and energy, and "
          "leaves through a viscous top") {
    const double c = p_wave_speed(); // 2190.9 m/s
    // The energy of the incident half-sine per metre of width: ρ c ∫v² dt = ρ c v² / (4 f).
    const double carried = density * c * v_in * v_in / (4.0 * frequency);
    const Record r = send_pulse(true);
    MESSAGE("peak ", r.peak_mid, " m/s at ", r.peak_mid_at, " s (y = ", r.mid_y, ", c_p = ", c, ")", " s; energy in transit ", r.in_transit, " J/m of ",
            carried, "; supplied ", r.supplied, ", absorbed ", r.absorbed, ", left ", r.left_after,
            "; worst balance ", r.worst_balance);
    // Its particle velocity half-way up, and when its crest passes there.
    // (0.25 m triangles, 44 a wavelength: 0.5% below; 0.5 m ones overshoot by 6.5%.)
    CHECK(std::abs(r.peak_mid / v_in - 1.0) < 0.02);
    // From y = 10 to y = 30 m at c_p (its energy-weighted arrival times); its crest
    // passes half-way about when one leaving the base at start + 1/(4f) would.
    const double speed = 20.0 / (r.tv2[1] / r.v2[1] - r.tv2[0] / r.v2[0]);
    MESSAGE("pulse speed ", speed, " m/s");
    CHECK(std::abs(speed / c - 1.0) < 0.01);
    CHECK(std::abs(r.peak_mid_at / (start + 0.25 / frequency + r.mid_y / c) - 1.0) < 0.02);
    // The wave's energy inside the column while it travels; the base's dashpot took
    // as much as the wave carries in, its input force doing twice that.
    CHECK(std::abs(r.in_transit / carried - 1.0) < 0.01);
    CHECK(std::abs(r.base_absorbed_in_transit / carried - 1.0) < 0.01);
    // Gone through the top: less than 1% of it is left, and the account balances.
    CHECK(r.left_after < 0.01 * carried);
    CHECK(std::abs(r.supplied / (2.0 * carried) - 1.0) < 0.01);
    // Supplied = absorbed + kinetic + strain at every step, to the O(Δt) of the
    // kinetic energy of half-step velocities (it halves with the time step).
    CHECK(r.worst_balance < 0.01 * carried);
    CHECK(std::abs(r.supplied - r.absorbed - r.left_after) < 1e-3 * carried);
}

TEST_CASE("a free top reflects the pulse with twice its particle velocity, and keeps its energy in the column") {
    const double c = p_wave_speed();
    const double carried = density * c * v_in * v_in / (4.0 * frequency);
    const Record r = send_pulse(false);
    MESSAGE("peak at the top ", r.peak_top, " m/s; left ", r.left_after, " J/m of ", carried);
    CHECK(std::abs(r.peak_top / (2.0 * v_in) - 1.0) < 0.02);
    // On its way back down at 1.5 transit times: still all inside.
    CHECK(std::abs(r.left_after / carried - 1.0) < 0.01);
}

TEST_CASE("a viscous boundary needs the dynamic mode and deformable blocks, and says so with its key") {
    std::string text = column(true);
    text.replace(text.find("mode = \"dynamic\""), 16, "mode = \"quasi_static\"");
    const auto m = test::build_model(text, "column.toml");
    try {
        Solver s(m.blocks, m.file.analysis);
        FAIL("accepted");
    } catch (const InputError& e) {
        CHECK(e.key() == "boundary[2].type");
        CHECK(std::string(e.what()).find("mode = \"dynamic\"") != std::string::npos);
    }
}

TEST_CASE("a pulse's run resumed from a checkpoint, on 1 or 2 threads, ends in the same state bit for bit") {
    const auto m = test::build_model(column(true), "column.toml");
    auto run = [&](int threads, long save_at) {
        AnalysisSpec an = m.file.analysis;
        an.solver.threads = threads;
        auto s = std::make_unique<Solver>(m.blocks, an);
        for (long k = 0; k < 400; ++k) {
            if (k == save_at) {
                std::stringstream state;
                save_state(s->world(), state);
                auto resumed = std::make_unique<Solver>(m.blocks, an);
                load_state(resumed->world(), state);
                s = std::move(resumed);
            }
            s->step();
        }
        CHECK(s->world().viscous.supplied[0] > 0.0); // the pulse has entered
        return state_hash(s->world());
    };
    const std::uint64_t straight = run(1, -1);
    CHECK(run(1, 150) == straight);
    CHECK(run(2, 150) == straight);
    CHECK(run(2, -1) == straight);
}

TEST_CASE("local damping is 0 by default in the dynamic mode, 0.8 in the quasi-static one") {
    std::string text = column(true);
    text.erase(text.find("damping = 0.0\n"), 14);
    CHECK(test::build_model(text, "column.toml").file.analysis.solver.damping == 0.0);
    text.replace(text.find("mode = \"dynamic\""), 16, "mode = \"quasi_static\"");
    // (a viscous boundary then is refused when the world is built, not when read)
    CHECK(test::build_model(text, "column.toml").file.analysis.solver.damping == 0.8);
}

namespace {

/// examples/verification/oscillator.toml (a 1 m block on a joint, ω = 1000 rad/s)
/// with Rayleigh damping of ratio ξ at `frequency` Hz.
std::string damped_oscillator(double ratio, double frequency) {
    std::ifstream in(std::string(BBM_SOURCE_DIR) + "/examples/verification/oscillator.toml");
    std::stringstream text;
    text << in.rdbuf();
    std::string t = text.str();
    t.replace(t.find("damping = 0.0\n"), 14,
              "damping = 0.0\nrayleigh_ratio = " + std::to_string(ratio) + "\nrayleigh_frequency = " +
                  std::to_string(frequency) + "\n");
    return t;
}

/// The damping ratio of the block's free vibration from the decay of its
/// displacement peaks over `periods` periods (the logarithmic decrement δ:
/// ξ = δ / √(4π² + δ²)), and the time step.
std::pair<double, double> measured_ratio(double ratio, double frequency, int periods) {
    const auto m = test::build_model(damped_oscillator(ratio, frequency), "oscillator.toml");
    Solver s(m.blocks, m.file.analysis);
    StageObserver quiet;
    run_stages(s, {m.file.analysis.stages[0]}, quiet);
    const World& w = s.world();
    const int block = w.blocks.centroid0[0].y > w.blocks.centroid0[1].y ? 0 : 1;
    // About its rest position: the pre-compression's σ/kn = 1 mm above where it started.
    auto u = [&] { return w.bodies.state[block].centroid.y - w.blocks.centroid0[block].y - 1e-3; };
    std::vector<double> peaks;
    double before = u(), now = u();
    s.step();
    now = u();
    while (int(peaks.size()) <= periods) {
        s.step();
        const double next = u();
        if (now > before && now >= next && now > 0.0) peaks.push_back(now);
        before = now, now = next;
    }
    const double delta = std::log(peaks.front() / peaks.back()) / periods;
    return {delta / std::sqrt(4.0 * std::numbers::pi * std::numbers::pi + delta * delta), w.clock.dt};
}

} // namespace

TEST_CASE("Rayleigh damping gives its ratio at its centre frequency, and ξ(ω) = (α/ω + β ω)/2 away from it") {
    const double omega = 1000.0, f0 = omega / (2.0 * std::numbers::pi), xi = 0.05;
    // At the block's own frequency: ξ; at twice it (ω = ω0/2): ξ/2 (2 + 1/2); at half (ω = 2 ω0): the same.
    for (const auto [centre, expected] : {std::pair{f0, xi}, std::pair{2.0 * f0, 1.25 * xi}, std::pair{0.5 * f0, 1.25 * xi}}) {
        const auto [measured, dt] = measured_ratio(xi, centre, 8);
        MESSAGE("centre ", centre, " Hz: ratio ", measured, " (expected ", expected, "), dt ", dt);
        CHECK(measured == doctest::Approx(expected).epsilon(0.01));
    }
    // The stable step shrinks as the stiffness part needs: by √(1 + ξ²) − ξ,
    // ξ = β ω_max / 2 with ω_max = 2 / Δt_crit.
    const double dt0 = measured_ratio(0.0, 1.0, 1).second;
    const double beta = 0.5 / (2.0 * std::numbers::pi * 1.0); // ξ 0.5 at 1 Hz: β = 0.0796 s, ω_max β / 2 ≫ 1
    const auto m = test::build_model(damped_oscillator(0.5, 1.0), "oscillator.toml");
    Solver s(m.blocks, m.file.analysis);
    const double limit = dt0 / 0.1, x = beta / limit;
    CHECK(s.world().clock.dt == doctest::Approx(dt0 * (std::sqrt(1.0 + x * x) - x)).epsilon(1e-9));
}

TEST_CASE("Rayleigh damping needs its two keys and the dynamic mode, and says so with its key") {
    auto error = [](const std::string& text) -> std::string {
        try {
            test::build_model(text, "oscillator.toml");
        } catch (const InputError& e) {
            return e.key();
        }
        return "accepted";
    };
    std::string t = damped_oscillator(0.05, 100.0);
    CHECK(error(t) == "accepted");
    std::string one = t;
    one.erase(one.find("rayleigh_frequency"), one.find('\n', one.find("rayleigh_frequency")) - one.find("rayleigh_frequency") + 1);
    CHECK(error(one) == "solver.rayleigh_ratio");
    std::string quasi = t;
    quasi.replace(quasi.find("mode = \"dynamic\""), 16, "mode = \"quasi_static\"");
    CHECK(error(quasi) == "solver.rayleigh_ratio");
    std::string bad = t;
    bad.replace(bad.find("rayleigh_ratio = 0.05"), 21, "rayleigh_ratio = 1.5");
    CHECK(error(bad) == "solver.rayleigh_ratio");
}

TEST_CASE("Rayleigh damping of the far field's zones: a column's fundamental mode decays at its ratio") {
    // The elastic column (c_p, 40 m, sides on rollers) fixed at its base, free at
    // its top, released from a uniform 1 MPa compression: its quarter-wave mode
    // f1 = c_p / 4H carries 81% of the top's motion (8/π²), the next (3 f1) 9%.
    // With ξ = 0.05 at f1 the first mode's peaks decay by e^{−2π ξ/√(1−ξ²)} a
    // period; the third, at ξ(3 f1) = ξ (1/3 + 3)/2 = 1.67 ξ, dies sooner.
    std::string t = column(false);
    const std::size_t base = t.find("[[boundary]]\nname = \"base\"");
    t.erase(base, t.find("start = 1e-3\n", base) + 13 - base);
    const double c = p_wave_speed(), f1 = c / (4.0 * height), xi = 0.05;
    t.replace(t.find("damping = 0.0\n"), 14,
              "damping = 0.0\nrayleigh_ratio = 0.05\nrayleigh_frequency = " + std::to_string(f1) + "\n");
    t += R"(
[[boundary]]
name = "base"
type = "velocity"
box = { min = [-1.0, -0.01], max = [2.0, 0.01] }
vy = 0.0

[[stage]]
name = "compressed"
type = "initialize"
syy = -1e6
)";
    const auto m = test::build_model(t, "column.toml");
    Solver s(m.blocks, m.file.analysis);
    StageObserver quiet;
    run_stages(s, m.file.analysis.stages, quiet);
    World& w = s.world();
    const int top = node_near(w, {0.5, height});
    const double modulus = young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    const double rest = 1e6 * height / modulus; // the released column's length change
    auto u = [&] { return w.nodes.position[top].y - w.nodes.position0[top].y - rest; };
    std::vector<double> peaks;
    double before = u();
    s.step();
    double now = u();
    while (peaks.size() < 7) {
        s.step();
        const double next = u();
        if (now > before && now >= next && now > 0.0) peaks.push_back(now);
        before = now, now = next;
    }
    // From the second peak on (the third mode has faded by then) over five periods.
    const double delta = std::log(peaks[1] / peaks[6]) / 5.0;
    const double measured = delta / std::sqrt(4.0 * std::numbers::pi * std::numbers::pi + delta * delta);
    MESSAGE("first mode ", f1, " Hz: damping ratio ", measured, " (", xi, ")");
    CHECK(measured == doctest::Approx(xi).epsilon(0.03));
}

TEST_CASE("the energy account closes: a damped oscillator's damping takes what it loses, a pulse's edges what it brings") {
    // The block on its joint released from 1 MPa: 500 J/m of strain energy, no
    // work; damping (Rayleigh's, or local) takes it. The account starts after the
    // initialize stage that sets the stress.
    for (const bool rayleigh : {true, false}) {
        std::string t = damped_oscillator(0.05, 1000.0 / (2.0 * std::numbers::pi));
        if (!rayleigh) {
            t.erase(t.find("rayleigh_ratio"), t.find("\n", t.find("rayleigh_frequency")) + 1 - t.find("rayleigh_ratio"));
            t.replace(t.find("damping = 0.0"), 13, "damping = 0.1");
        }
        const auto m = test::build_model(t, "oscillator.toml");
        Solver s(m.blocks, m.file.analysis);
        StageObserver quiet;
        run_stages(s, {m.file.analysis.stages[0]}, quiet);
        const double e0 = strain_energy(s.world());
        double worst = 0.0;
        for (int k = 0; k < 2000; ++k) {
            s.step();
            worst = std::max(worst, std::abs(energy_account(s.world()).error));
        }
        const EnergyAccount a = energy_account(s.world());
        MESSAGE(std::string(rayleigh ? "Rayleigh" : "local"), ": stored ", a.kinetic + a.strain, " of ", e0, " J/m, damping took ",
                a.damping, ", worst error ", worst, " (", worst / e0, " of it)");
        CHECK(a.damping > 0.5 * e0);
        CHECK(worst < 0.01 * e0);
    }
    // The P pulse through the viscous base into an absorbing top: the waves'
    // work against what the column holds and its edges radiated.
    const auto m = test::build_model(column(true), "column.toml");
    Solver s(m.blocks, m.file.analysis);
    const double end = start + 1.5 * height / p_wave_speed();
    double worst = 0.0;
    while (s.world().clock.time < end) {
        s.step();
        worst = std::max(worst, std::abs(energy_account(s.world()).error));
    }
    const EnergyAccount a = energy_account(s.world());
    MESSAGE("pulse: wave input ", a.wave_input, " J/m, radiated ", a.radiated, ", worst error ", worst);
    CHECK(worst < 0.01 * a.wave_input);
}

TEST_CASE("a pulse read from a CSV record is the named pulse it samples; a record whose times go back is refused") {
    // The half-sine of the column's base, written as 201 rows of time and velocity.
    const auto dir = std::filesystem::temp_directory_path() / "bbm_pulse_record";
    std::filesystem::create_directories(dir);
    {
        std::ofstream csv(dir / "half_sine.csv");
        csv << "time_s,velocity_m_per_s\n";
        for (int k = 0; k <= 200; ++k) {
            const double t = 0.5 / frequency * k / 200.0;
            csv << t << ',' << v_in * std::sin(2.0 * std::numbers::pi * frequency * t) << '\n';
        }
    }
    std::string text = column(true);
    const std::size_t from = text.find("pulse = \"half_sine\"");
    text.replace(from, text.find("start = 1e-3", from) - from, "pulse = \"file\"\nfile = \"half_sine.csv\"\n");
    const Record named = send_pulse(true), recorded = send_pulse(text, (dir / "column.toml").string());
    MESSAGE("peak velocity half-way up: named ", named.peak_mid, " m/s, recorded ", recorded.peak_mid,
            "; wave input ", named.supplied, " and ", recorded.supplied, " J/m");
    CHECK(recorded.peak_mid == doctest::Approx(named.peak_mid).epsilon(0.005));
    CHECK(recorded.supplied == doctest::Approx(named.supplied).epsilon(0.005));
    // Bad records: a time that goes back, a lone row; a frequency with a record.
    {
        std::ofstream csv(dir / "back.csv");
        csv << "0,0\n0.001,0.1\n0.0005,0.05\n";
    }
    auto error = [&](const std::string& t) -> std::string {
        try {
            test::build_model(t, (dir / "column.toml").string());
        } catch (const InputError& e) {
            return e.file() + ":" + std::to_string(e.line()) + ": " + e.key() + ": " + e.what();
        }
        return "accepted";
    };
    std::string back = text;
    back.replace(back.find("half_sine.csv"), 13, "back.csv");
    const std::string said = error(back);
    MESSAGE(said);
    CHECK(said.find("back.csv:3") != std::string::npos);
    CHECK(said.find("go forward") != std::string::npos);
    std::string with_frequency = text;
    with_frequency.replace(with_frequency.find("file = \"half_sine.csv\""), 22, "file = \"half_sine.csv\"\nfrequency = 200.0");
    CHECK(error(with_frequency).find("boundary[2].frequency") != std::string::npos);
}
