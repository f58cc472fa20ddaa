// Dowels (core/supports/dowel.hpp) against closed forms: a dowel across a sliding joint
// as a beam on an elastic foundation (Hetényi 1946), and a pretensioned dowel
// clamping two blocks together; both exact on restart and on any thread count.
#include "contact/contacts.hpp"
#include "core/solver.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"

#include "model_text.hpp"
#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <sstream>

using namespace bbm;

namespace {

// Two blocks meeting along y = 0; a vertical dowel through both, its elements
// 1 cm long, the joint at the middle of one of them.
constexpr double young = 200e9, diameter = 0.025, k_grout = 2e9, segment = 0.01;

std::string two_blocks(const std::string& joint, const std::string& upper_boundary, const std::string& dowel) {
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
name = "joint"
law = "coulomb"
)" + joint + R"(
[[joint_assignment]]
property = "joint"

[[boundary]]
name = "base"
type = "velocity"
regions = ["lower"]
vx = 0.0
vy = 0.0
omega = 0.0
)" + upper_boundary + R"(
[[dowel]]
name = "dowel"
segment_length = 0.01
diameter = 0.025
young = 200e9
bond_stiffness = 2e9
)" + dowel;
}

using Built = test::BuiltModel;
Built build(const std::string& text) { return test::build_model(text, "dowel.toml"); }

const Built& sheared_model() {
    static const Built m = build(two_blocks("kn = 1e11\nks = 1e11\nfriction = 0.0\n",
                                            R"(
[[boundary]]
name = "shear"
type = "velocity"
regions = ["upper"]
vx = 0.0
vy = 0.0
omega = 0.0
)",
                                            "bolts = [[[0.0, -0.605], [0.0, 0.605]]]\n"));
    return m;
}

/// The upper block slid by `slip` along x (in 200 steps), then held until the
/// dowel's shear at the joint settles.
struct Sheared {
    double shear = 0, max_moment = 0, max_moment_at = 0;
    long steps = 0;
    std::uint64_t hash = 0;
};
Sheared shear_dowel(double slip, int threads, long save_at = -1) {
    const Built& m = sheared_model();
    AnalysisSpec an = m.file.analysis;
    an.solver.threads = threads;
    auto s = std::make_unique<Solver>(m.blocks, an);
    install_supports(s->world(), {"dowel"});
    const int upper = block_at(s->world(), {0.0, 0.5});
    REQUIRE(upper >= 0);
    const long ramp = 200;
    s->world().loads.block_velocity[upper] = {slip / ramp, 0.0};
    const auto& D = support_state<Dowels>(s->world().supports);
    REQUIRE(D.element_count() == 121);
    const int joint = 60; // the element from y = −0.005 to 0.005
    double last = 0.0;
    for (long k = 0; k < 400000; ++k) {
        if (k == ramp) s->world().loads.block_velocity[upper] = {};
        if (k == save_at) { // continue from a checkpoint in a new solver
            std::stringstream state;
            save_state(s->world(), state);
            auto resumed = std::make_unique<Solver>(m.blocks, an);
            install_supports(resumed->world(), {"dowel"});
            load_state(resumed->world(), state);
            s = std::move(resumed);
        }
        s->step();
        if (k > ramp && k % 2000 == 0) {
            const auto& d = support_state<Dowels>(s->world().supports);
            const double v = (d.moment_a[joint] + d.moment_b[joint]) / d.rest[joint];
            if (std::abs(v - last) < 1e-7 * std::abs(v)) break;
            last = v;
        }
    }
    const auto& E = support_state<Dowels>(s->world().supports);
    Sheared r;
    r.steps = s->world().clock.steps;
    r.hash = state_hash(s->world());
    r.shear = std::abs((E.moment_a[joint] + E.moment_b[joint]) / E.rest[joint]);
    for (int e = 0; e < E.element_count(); ++e)
        for (double mo : {E.moment_a[e], E.moment_b[e]})
            if (std::abs(mo) > r.max_moment) {
                r.max_moment = std::abs(mo);
                r.max_moment_at = std::abs(E.nodes.position[mo == E.moment_a[e] ? e : e + 1].y);
            }
    return r;
}

} // namespace

TEST_CASE("a dowel across a sliding joint bends as a beam on an elastic foundation: shear k delta / (4 beta)") {
    // An elastic bar (EI = E A²/4π) on the grout's transverse springs k (N/m per
    // m) across a frictionless joint that slides by δ: antisymmetric about the
    // joint, each half a semi-infinite beam on a Winkler foundation whose end
    // (moment-free) is displaced δ/2 against it: y = (2Vβ/k) e^{−βx} cos βx, so
    // V = k δ / (4β), β = (k / 4EI)^¼, and the largest moment
    // M = (V/β) e^{−π/4} sin(π/4) = 0.3224 V/β at x = π/(4β) (Hetényi 1946).
    const double area = 0.25 * std::numbers::pi * diameter * diameter;
    const double ei = young * area * area / (4.0 * std::numbers::pi);
    const double beta = std::pow(k_grout / (4.0 * ei), 0.25), slip = 1e-3;
    const double shear = k_grout * slip / (4.0 * beta);
    const double moment = shear / beta * std::exp(-0.25 * std::numbers::pi) * std::sin(0.25 * std::numbers::pi);
    const double at = 0.25 * std::numbers::pi / beta;
    const auto r = shear_dowel(slip, 1);
    MESSAGE("beta " << beta << " /m (h beta = " << segment * beta << "); shear at the joint " << r.shear
                    << " N/m, closed form " << shear << "; largest moment " << r.max_moment << " N·m/m at "
                    << r.max_moment_at << " m from the joint, closed form " << moment << " at " << at << "; "
                    << r.steps << " steps");
    CHECK(r.shear == doctest::Approx(shear).epsilon(0.02));
    test::record_check(test::Against::closed_form, "shear force in the dowel at the joint, slip 1 mm",
                       "V = k delta / (4 beta) = " + test::figure(shear / 1e3) + " kN/m (Hetényi 1946)", "within 2%",
                       test::figure(r.shear / 1e3) + " kN/m (" + test::percent(r.shear, shear) + ")",
                       r.shear == doctest::Approx(shear).epsilon(0.02));
    CHECK(r.max_moment == doctest::Approx(moment).epsilon(0.03));
    test::record_check(test::Against::closed_form, "largest bending moment in the dowel",
                       "M = (V/beta) e^(-pi/4) sin(pi/4) = " + test::figure(moment) + " N·m/m (Hetényi 1946)",
                       "within 3%", test::figure(r.max_moment) + " N·m/m (" + test::percent(r.max_moment, moment) + ")",
                       r.max_moment == doctest::Approx(moment).epsilon(0.03));
    CHECK(std::abs(r.max_moment_at - at) < segment);
    test::record_check(test::Against::closed_form, "distance of the largest moment from the joint",
                       "x = pi / (4 beta) = " + test::figure(at) + " m (Hetényi 1946)",
                       "within one element (" + test::figure(segment) + " m)",
                       test::figure(r.max_moment_at) + " m (" + test::figure(r.max_moment_at - at) + " m off)",
                       std::abs(r.max_moment_at - at) < segment);
    // The same bits on two threads, and through a checkpoint.
    const auto two = shear_dowel(slip, 2);
    CHECK(two.steps == r.steps);
    CHECK(two.hash == r.hash);
    const auto resumed = shear_dowel(slip, 1, 1000);
    CHECK(resumed.steps == r.steps);
    CHECK(resumed.hash == r.hash);
}

TEST_CASE("a pretensioned dowel clamps two blocks: the joint carries the dowel's tension") {
    // The upper block is free; the dowel is tensioned to T against its plate (in
    // the lower block) and its anchor (in the upper) and grouted. At rest the
    // joint's normal force equals the dowel's tension where it crosses the joint
    // (statics of the upper block), and the tension is T less what the rock's
    // compression gives back: the joint closes by N/kn·L, the bar shortens by as
    // much, a loss of EA/ℓ times it over the free length ℓ ≈ the segments
    // between the plate and the anchor that the grout does not hold (small here).
    const double T = 50e3;
    const auto m = build(two_blocks("kn = 1e11\nks = 1e11\nfriction = 30.0\n", "",
                                    "bolts = [[[0.0, -0.505], [0.0, 0.505]]]\nface_plate = true\nend_anchor = true\n"
                                    "pretension = 50e3\n"));
    Solver s(m.blocks, m.file.analysis);
    install_supports(s.world(), {"dowel"});
    const auto& D = support_state<Dowels>(s.world().supports);
    REQUIRE(D.element_count() == 101);
    for (double n : D.axial) CHECK(n == T); // installed with its pretension
    const int upper = block_at(s.world(), {0.0, 0.5});
    for (long k = 0; k < 200000; ++k) {
        s.step();
        if (k > 1000 && s.world().clock.ratio < 1e-10) break;
    }
    Vec2 joint{};
    double moment = 0.0;
    contact::block_contact_force(contacts(s.world()), upper, joint, moment);
    const double tension = D.axial[50]; // the element across the joint
    MESSAGE("pretension " << T << " N/m: tension at the joint " << tension << " N/m, joint normal force " << joint.y
                          << " N/m, " << s.world().clock.steps << " steps");
    CHECK(joint.y == doctest::Approx(tension).epsilon(1e-4));
    CHECK(tension == doctest::Approx(T).epsilon(0.02));
    CHECK(tension < T);
    const auto summary = Dowels::summary(support_state<Dowels>(s.world().supports));
    REQUIRE(summary.size() == 1);
    CHECK(summary[0].figure("max_axial_kN") == doctest::Approx(T / 1e3).epsilon(0.02));
}

TEST_CASE("dowel input: a pretension needs a plate and an anchor — names are shared with bolts and liners") {
    const std::string base = two_blocks("kn = 1e11\nks = 1e11\nfriction = 30.0\n", "",
                                        "bolts = [[[0.0, -0.5], [0.0, 0.5]]]\n");
    CHECK_THROWS_WITH_AS(io::parse_model(base + "pretension = 1e4\n", "d.toml"),
                         doctest::Contains("dowel[0].pretension"), InputError);
    // A bolt's own key in a dowel, and a dowel's in a bolt: named as another table's (core/supports/bolt.hpp).
    CHECK_THROWS_WITH_AS(io::parse_model(base + "cable = true\n", "d.toml"),
                         doctest::Contains("key 'cable' does not apply to a dowel set"), InputError);
    CHECK_THROWS_WITH_AS(
        io::parse_model(base + "\n[[bolt]]\nname = \"b\"\nbolts = [[[0.0, -0.5], [0.0, 0.5]]]\nbond_stiffness = 1e9\n"
                               "pretension = 1e4\n",
                        "d.toml"),
        doctest::Contains("key 'pretension' does not apply to a bolt set"), InputError);
    CHECK_THROWS_WITH_AS(
        io::parse_model(base + "\n[[bolt]]\nname = \"dowel\"\nbolts = [[[0.0, -0.5], [0.0, 0.5]]]\nbond_stiffness = 1e9\n",
                        "d.toml"),
        doctest::Contains("already used by bolt[0]"), InputError);
}
