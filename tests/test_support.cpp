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

namespace {

// A circular opening of radius a = 1 m in elastic ground (E 5 GPa, ν 0.25) under an
// isotropic 10 MPa, a quarter model (symmetry on x = 0 and y = 0, rollers at 10 m);
// the opening is a block excavated with its support relaxed over 2,000 steps.
std::string lined_opening(bool lined, double thrust_capacity = 0.0) {
    std::string text = R"(
[solver]
mode = "quasi_static"

[[material]]
name = "rock"
young = 5.0e9
poisson = 0.25

[[region]]
name = "ground"
outline = { type = "path", start = [1.0, 0.0], steps = [
  { to = [10.0, 0.0] }, { to = [10.0, 10.0] }, { to = [0.0, 10.0] }, { to = [0.0, 1.0] },
  { to = [1.0, 0.0], center = [0.0, 0.0], clockwise = true } ] }
minus = ["opening"]
pattern = { type = "single" }
mesh = { size = 0.08, size_far = 1.5, grading = 0.3, toward = ["opening"] }

[[region]]
name = "opening"
outline = { type = "path", start = [0.0, 0.0], steps = [
  { to = [1.0, 0.0] }, { to = [0.0, 1.0], center = [0.0, 0.0] }, { to = [0.0, 0.0] } ] }
pattern = { type = "single" }

[[joint_property]]
name = "glue"
law = "elastic"
kn = 1e12
ks = 1e12

[[joint_assignment]]
property = "glue"

[[boundary]]
name = "x0"
type = "velocity"
box = { min = [-0.01, -0.01], max = [0.01, 10.01] }
touching = true
vx = 0.0
omega = 0.0

[[boundary]]
name = "y0"
type = "velocity"
box = { min = [-0.01, -0.01], max = [10.01, 0.01] }
touching = true
vy = 0.0
omega = 0.0

[[boundary]]
name = "right"
type = "velocity"
box = { min = [9.99, -0.01], max = [10.01, 10.01] }
vx = 0.0

[[boundary]]
name = "top"
type = "velocity"
box = { min = [-0.01, 9.99], max = [10.01, 10.01] }
vy = 0.0

[[liner]]
name = "shotcrete"
center = [0.0, 0.0]
radius = 1.0
from = 0.0
to = 90.0
segment_length = 0.05
young = 30e9
poisson = 0.2
thickness = 0.2
normal_stiffness = 1e12
symmetric_ends = true

[[stage]]
type = "initialize"
sxx = -10e6
syy = -10e6

[[stage]]
type = "excavate"
regions = ["opening"]
relax_steps = 2000
steps = 0
)";
    if (thrust_capacity > 0.0) {
        const auto at = text.find("symmetric_ends = true");
        text.insert(at, "thrust_capacity = " + std::to_string(thrust_capacity) + "\n");
        const auto relax = text.find("relax_steps = 2000");
        text.replace(relax, 18, "relax_steps = 20000");
    }
    if (lined) text += "\n[[stage]]\ntype = \"install\"\nsupports = [\"shotcrete\"]\n";
    text += "\n[[stage]]\ntype = \"cycle\"\nsteps = " + std::string(thrust_capacity > 0.0 ? "20000" : "2000") +
            "\n\n[[stage]]\ntype = \"solve\"\nratio = 1e-7\nmax_steps = 100000\n";
    return text;
}

struct Quiet : StageObserver {};

/// Mean inward displacement of the ground's nodes on the wall (r = 1).
double wall_convergence(const Solver& s) {
    const auto& n = s.nodes();
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i < n.count(); ++i)
        if (std::abs(norm(n.position0[i]) - 1.0) < 1e-6) {
            sum -= dot(n.position[i] - n.position0[i], n.position0[i]);
            ++count;
        }
    REQUIRE(count > 10);
    return sum / count;
}

} // namespace

TEST_CASE("a liner in elastic ground: the pressure where the ground reaction and support characteristic meet") {
    // The convergence–confinement method. Ground: its reaction curve p(u) is linear,
    // p = p0 − k_g u, with k_g measured on the unlined model and checked against the
    // closed form of a hole of radius a in ground held at b (plane strain):
    //   u = A a + B/a, A = −B/b², 2(λ + μ)A − 2μ B/a² = p0.
    // Support: a thin ring, p = K_ring u, K_ring = E' t / a² (E' = E/(1 − ν²)), in
    // series with the interface springs k_n. They meet at p = K p0 / (K + k_g), and
    // the ring's thrust is T = p a.
    const double p0 = 10e6, a = 1.0, b = 10.0, E = 5e9, nu = 0.25;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const double B = p0 / (-2.0 * (lambda + mu) / (b * b) - 2.0 * mu / (a * a)), A = -B / (b * b);
    const double u_closed = -(A * a + B / a);
    auto run = [&](bool lined, double capacity = 0.0) {
        const auto m = build(lined_opening(lined, capacity));
        auto s = std::make_unique<Solver>(m.blocks, m.file.analysis);
        Quiet quiet;
        const auto reports = run_stages(*s, m.file.analysis.stages, quiet);
        CHECK(reports.back().converged);
        return s;
    };
    const auto unlined = run(false);
    const double u0 = wall_convergence(*unlined);
    MESSAGE("unlined wall convergence " << u0 * 1e3 << " mm, closed form (round boundary at 10 m) " << u_closed * 1e3
                                        << " mm");
    CHECK(u0 == doctest::Approx(u_closed).epsilon(0.02));
    const double k_ground = p0 / u0;

    const auto lined = run(true);
    const auto& L = lined->liners();
    const double e_liner = 30e9 / (1 - 0.04), t = 0.2;
    const double k_ring = e_liner * t / (a * a), k = 1.0 / (1.0 / k_ring + 1.0 / 1e12);
    const double p_expected = k * p0 / (k + k_ground);
    double p_mean = 0.0, thrust = 0.0;
    for (int i = 0; i < L.node_count(); ++i) p_mean -= L.normal_stress[i] / L.node_count();
    for (int e = 0; e < L.element_count(); ++e) thrust += L.thrust[e] / L.element_count();
    const double u1 = wall_convergence(*lined);
    MESSAGE("lined: support pressure " << p_mean / 1e6 << " MPa (GRC-SCC " << p_expected / 1e6 << " MPa), thrust "
                                       << thrust / 1e3 << " kN/m (p a = " << p_mean * a / 1e3 << "), convergence "
                                       << u1 * 1e3 << " mm (" << (p0 - p_expected) / k_ground * 1e3 << ")");
    CHECK(p_mean == doctest::Approx(p_expected).epsilon(0.01));
    CHECK(thrust == doctest::Approx(p_mean * a).epsilon(0.01));
    CHECK(u1 == doctest::Approx((p0 - p_expected) / k_ground).epsilon(0.01));
    // No bending under an isotropic load.
    const auto summary = lined->liner_summary();
    REQUIRE(summary.size() == 1);
    CHECK(summary[0].max_moment < 0.001 * thrust * t);
    CHECK(summary[0].open == 0);
    CHECK(summary[0].yielded == 0);

    // A lining that yields at half that thrust (3 MN/m): it carries its capacity,
    // p = T_y / a, and the ground converges to its reaction curve at that pressure.
    // The support's relaxation is 10 times slower here: the explicit quasi-static
    // loading overshoots a perfectly plastic ring, which then unloads below its
    // capacity (2,000 relaxation steps: 2,459 kN/m, 18% below; 20,000: 0.7%).
    const auto yielding = run(true, 3e6);
    const auto& Y = yielding->liners();
    double p_yield = 0.0, thrust_yield = 0.0;
    for (int i = 0; i < Y.node_count(); ++i) p_yield -= Y.normal_stress[i] / Y.node_count();
    for (int e = 0; e < Y.element_count(); ++e) thrust_yield += Y.thrust[e] / Y.element_count();
    const double u_yield = wall_convergence(*yielding);
    MESSAGE("yielding liner: thrust " << thrust_yield / 1e3 << " kN/m (capacity 3000), pressure " << p_yield / 1e6
                                      << " MPa, convergence " << u_yield * 1e3 << " mm ("
                                      << (p0 - 3e6 / a) / k_ground * 1e3 << ")");
    CHECK(thrust_yield == doctest::Approx(3e6).epsilon(0.01));
    CHECK(p_yield == doctest::Approx(3e6 / a).epsilon(0.01));
    CHECK(u_yield == doctest::Approx((p0 - 3e6 / a) / k_ground).epsilon(0.01));
    CHECK(yielding->liner_summary()[0].yielded == Y.element_count());
}

TEST_CASE("a lined opening resumes exactly from a checkpoint, and runs to the same bits on 2 threads") {
    const auto m = build(lined_opening(true));
    const std::vector<StageSpec> before(m.file.analysis.stages.begin(), m.file.analysis.stages.begin() + 3);
    REQUIRE(before.back().kind == StageSpec::Kind::install);
    auto solver = [&](int threads) {
        AnalysisSpec an = m.file.analysis;
        an.solver.threads = threads;
        auto s = std::make_unique<Solver>(m.blocks, an);
        Quiet quiet;
        run_stages(*s, before, quiet);
        return s;
    };
    auto one = solver(1);
    REQUIRE(one->liners().node_count() > 0);
    for (int k = 0; k < 500; ++k) one->step();
    std::ostringstream saved;
    one->save_state(saved);
    for (int k = 0; k < 1000; ++k) one->step();
    auto resumed = solver(1);
    std::istringstream in(saved.str());
    resumed->load_state(in);
    while (resumed->steps() < one->steps()) resumed->step();
    CHECK(resumed->state_hash() == one->state_hash());
    auto two = solver(2);
    while (two->steps() < one->steps()) two->step();
    CHECK(two->state_hash() == one->state_hash());
}

TEST_CASE("a support pressure: keeping a fraction of the excavated rock's support scales the elastic convergence") {
    // Linear elastic ground: keeping 40% of the in-situ support on the wall (the
    // convergence–confinement method's fictitious pressure (1 − λ) p0 with λ = 0.6)
    // leaves 60% of the free convergence, for good (the support does not relax on).
    const auto free = build(lined_opening(false));
    std::string text = lined_opening(false);
    text.insert(text.find("steps = 0\n"), "keep = 0.4\n");
    const auto held = build(text);
    auto run = [](const Built& m) {
        auto s = std::make_unique<Solver>(m.blocks, m.file.analysis);
        Quiet quiet;
        const auto reports = run_stages(*s, m.file.analysis.stages, quiet);
        CHECK(reports.back().converged);
        return s;
    };
    const auto a = run(free), b = run(held);
    const double u_free = wall_convergence(*a), u_held = wall_convergence(*b);
    MESSAGE("free convergence " << u_free * 1e3 << " mm, with 40% of the support kept " << u_held * 1e3 << " mm");
    CHECK(u_held == doctest::Approx(0.6 * u_free).epsilon(2e-3));
}
