// Ground support against closed forms (issue 25): a grouted bolt pulled out of
// rock (shear-lag theory, elastic and with a slipping grout), and a block hanging
// from a bolt (the bolt carries its weight). Each is also a check that the bolts
// are exact on restart and the same on any thread count.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <sstream>

using namespace bbm;

namespace {

struct Built {
    io::ModelFile file;
    meshing::BlockAssembly blocks;
};

Built build(const std::string& text) {
    Built b{io::parse_model(text, "support.toml"), {}};
    b.blocks = meshing::generate_blocks(b.file.geometry);
    return b;
}

// A grouted bolt along y = 0 from x = 0 (head, on the rock's face) to x = L, in
// rock that does not move (one fixed block); grout stiffness k per metre, steel EA.
constexpr double L = 3.0, young = 200e9, area = 4.91e-4, k_bond = 1e9, segment = 0.025;
std::string pull_out_model(double bond_strength) {
    std::ostringstream s;
    s << R"(
[[region]]
name = "rock"
outline = { type = "rectangle", min = [0.0, -1.0], max = [4.0, 1.0] }
pattern = { type = "single" }

[[boundary]]
name = "fixed"
type = "velocity"
box = { min = [-1.0, -2.0], max = [5.0, 2.0] }
vx = 0.0
vy = 0.0
omega = 0.0

[[bolt]]
name = "bolt"
bolts = [[[0.0, 0.0], [3.0, 0.0]]]
segment_length = )" << segment << R"(
young = )" << young << R"(
area = )" << area << R"(
bond_stiffness = )" << k_bond << "\n";
    if (bond_strength > 0) s << "bond_strength = " << bond_strength << "\n";
    s << R"(
[[stage]]
type = "install"
supports = ["bolt"]
)";
    return s.str();
}

/// Pulls the head with P (N/m) until the ratio is 1e-7; the axial force at each segment's middle.
struct Pulled {
    std::vector<double> x, axial;
    double head_displacement = 0;
    long steps = 0;
};
Pulled pull(const Built& m, double P, int threads) {
    AnalysisSpec an = m.file.analysis;
    an.solver.threads = threads;
    Solver s(m.blocks, an);
    s.install_bolts({"bolt"});
    auto& B = s.bolts();
    REQUIRE(B.node_count() == int(std::lround(L / segment)) + 1);
    B.applied[0] = {-P, 0.0};
    Pulled r;
    for (long k = 0; k < 400000; ++k) {
        s.step();
        if (k > 100 && s.unbalanced_ratio() < 1e-9) break;
    }
    r.steps = s.steps();
    for (int seg = 0; seg < B.segment_count(); ++seg) {
        const int a = B.segment_node[seg];
        r.x.push_back(0.5 * (B.position[a].x + B.position[a + 1].x));
        r.axial.push_back(B.axial[seg]);
    }
    r.head_displacement = -B.position[0].x;
    return r;
}

} // namespace

TEST_CASE("a grouted bolt pulled out of fixed rock: axial force decays as sinh(beta (L - x)) / sinh(beta L)") {
    // Shear lag (Farmer 1975): EA N'' = k N, N(0) = P, N(L) = 0, so
    // N(x) = P sinh(β(L − x)) / sinh(βL), β = √(k / EA), and the head moves
    // u0 = P coth(βL) / (EA β). Discretised with 0.025 m segments (βh = 0.08:
    // a central-difference error of (βh)²/12 ≈ 0.05%).
    const auto m = build(pull_out_model(0.0));
    const double ea = young * area, beta = std::sqrt(k_bond / ea), P = 100e3;
    const auto r = pull(m, P, 1);
    MESSAGE("elastic pull-out: " << r.steps << " steps");
    for (double x : {0.1, 0.3, 0.6, 1.0}) {
        const int seg = int(x / segment);
        const double exact = P * std::sinh(beta * (L - r.x[seg])) / std::sinh(beta * L);
        MESSAGE("x = " << r.x[seg] << " m: N = " << r.axial[seg] << " N/m, closed form " << exact);
        CHECK(r.axial[seg] == doctest::Approx(exact).epsilon(0.005));
    }
    const double u0 = P / (ea * beta * std::tanh(beta * L));
    MESSAGE("head displacement " << r.head_displacement << " m, closed form " << u0);
    CHECK(r.head_displacement == doctest::Approx(u0).epsilon(0.005));
    // The same bits on two threads (the bolt pass is serial, in the bolts' order).
    const auto r2 = pull(m, P, 2);
    CHECK(r2.steps == r.steps);
    CHECK(r2.axial == r.axial);
}

TEST_CASE("a pulled bolt whose grout slips: N falls linearly by q_max over the slipping length, then decays") {
    // Elastic-plastic shear lag: over the slipping length l_s from the head the
    // grout carries q_max, N(x) = P − q_max x; beyond it the elastic solution with
    // N(l_s) = q_max tanh(β(L − l_s)) / β. With βL ≈ 10, tanh ≈ 1 and
    // l_s = (P − q_max / β) / q_max. P = 3 q_max / β gives l_s = 2 / β.
    const double ea = young * area, beta = std::sqrt(k_bond / ea), q_max = 50e3, P = 3.0 * q_max / beta;
    const auto m = build(pull_out_model(q_max));
    const auto r = pull(m, P, 1);
    const double ls = (P - q_max / beta) / q_max;
    MESSAGE("slipping pull-out: " << r.steps << " steps, l_s = " << ls << " m");
    for (double x : {0.1, 0.3, 0.5, 0.8, 1.2}) {
        const int seg = int(x / segment);
        const double xs = r.x[seg];
        const double exact = xs < ls ? P - q_max * xs : q_max / beta * std::exp(-beta * (xs - ls));
        MESSAGE("x = " << xs << " m: N = " << r.axial[seg] << " N/m, closed form " << exact);
        CHECK(r.axial[seg] == doctest::Approx(exact).epsilon(0.005));
    }
}

TEST_CASE("a block hanging from a bolt: the bolt carries its weight across the gap, and restarts exactly") {
    const auto m = build(R"(
[solver]
gravity = [0.0, -9.81]

[[material]]
name = "rock"
density = 2700.0

[[region]]
name = "roof"
outline = { type = "rectangle", min = [-2.0, 0.5], max = [2.0, 3.0] }
pattern = { type = "single" }

[[region]]
name = "wedge"
outline = { type = "rectangle", min = [-0.5, -1.0], max = [0.5, 0.4] }
pattern = { type = "single" }

[[boundary]]
name = "roof"
type = "velocity"
regions = ["roof"]
vx = 0.0
vy = 0.0
omega = 0.0

[[bolt]]
name = "bolt"
bolts = [[[0.0, -1.0], [0.0, 2.5]]]
segment_length = 0.05
diameter = 0.025
yield_force = 250e3
bond_stiffness = 2e9
face_plate = true
spacing = 1.5

[[stage]]
type = "install"
supports = ["bolt"]
)");
    Solver s(m.blocks, m.file.analysis);
    s.install_bolts({"bolt"});
    const double weight = 2700.0 * 9.81 * 1.0 * 1.4; // N per metre of model
    std::string saved;
    for (long k = 0; k < 60000; ++k) {
        s.step();
        if (k == 500) {
            std::ostringstream o;
            s.save_state(o);
            saved = o.str();
        }
        if (k > 1000 && s.unbalanced_ratio() < 1e-8) break;
    }
    const auto& B = s.bolts();
    // The segments in the gap (0.4 < y < 0.5) carry the whole weight: the block's
    // and the steel's below them (25 mm bar at 1.5 m: 2.57 kg per metre of model).
    const double steel = 7850.0 * 0.25 * 3.141592653589793 * 0.025 * 0.025 / 1.5 * 9.81;
    int in_gap = 0;
    for (int seg = 0; seg < B.segment_count(); ++seg) {
        const int a = B.segment_node[seg];
        const double y = 0.5 * (B.position[a].y + B.position[a + 1].y);
        if (y > 0.42 && y < 0.48) {
            ++in_gap;
            CHECK(B.axial[seg] == doctest::Approx(weight + steel * (y + 1.0)).epsilon(2e-4));
        }
    }
    CHECK(in_gap >= 1);
    const auto summary = s.bolt_summary();
    REQUIRE(summary.size() == 1);
    MESSAGE("block weight " << weight << " N/m; bolt load " << summary[0].max_axial << " N per bolt at 1.5 m spacing, "
                            << s.steps() << " steps");
    CHECK(summary[0].max_axial == doctest::Approx(1.5 * (weight + steel * 1.5)).epsilon(2e-3));
    CHECK(summary[0].yielded == 0);
    // A checkpoint taken with the bolt installed continues to the same bits.
    Solver again(m.blocks, m.file.analysis);
    std::istringstream in(saved);
    again.load_state(in);
    while (again.steps() < s.steps()) again.step();
    CHECK(again.state_hash() == s.state_hash());
}
