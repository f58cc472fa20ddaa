// Seismic events from breaking bonds (core/events.hpp). A column of four rigid
// blocks, the lowest held and the highest moved at a constant velocity, its
// middle joint weak: when that joint breaks, the source region (the two blocks it
// joined) loses the force F = strength × L its neighbours put on it across the
// joints a distance d apart, and the event's moment tensor is the force dipole
//     M = F d  (Myy for a pull, Mxy for a shear),
// a tensile source (Feignier and Young's R > 30) for the pull and a shear source
// for the shear. The magnitude follows Hanks and Kanamori; the b-value estimator
// recovers the b of a synthetic Gutenberg–Richter sample; a lab specimen's events
// account for every broken bond, are the same on 1 and 2 threads and after a
// restart, and read crack initiation where the laboratory reads it.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "core/state.hpp"

#include "model_text.hpp"
#include "restart.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>

using namespace bbm;

namespace {

/// Four blocks of `width` × `height` stacked from y = −2 height; the joint at
/// y = 0 weak (brittle: it breaks at its peak); the top block moved at (vx, vy).
std::string column(double width, double height, double vx, double vy, double weak_tensile, double weak_cohesion,
                   long steps) {
    auto num = [](double v) {
        std::ostringstream o;
        o.precision(17);
        o << v;
        std::string s = o.str();
        if (s.find_first_of(".e") == std::string::npos) s += ".0";
        return s;
    };
    std::string t = "[solver]\nmode = \"quasi_static\"\n\n[events]\njoin_distance = " + num(1.5 * width) + "\n";
    const char* names[] = {"b0", "b1", "b2", "b3"};
    for (int k = 0; k < 4; ++k)
        t += "\n[[region]]\nname = \"" + std::string(names[k]) + "\"\noutline = { type = \"rectangle\", min = [" +
             num(-0.5 * width) + ", " + num((k - 2) * height) + "], max = [" + num(0.5 * width) + ", " +
             num((k - 1) * height) + "] }\npattern = { type = \"single\" }\n";
    t += R"(
[[joint_property]]
name = "strong"
law = "coulomb"
kn = 1e10
ks = 1e10
tensile = 1e9
cohesion = 1e9
friction = 30.0

[[joint_property]]
name = "weak"
law = "coulomb"
kn = 1e10
ks = 1e10
tensile = )" + num(weak_tensile) + "\ncohesion = " + num(weak_cohesion) + R"(
friction = 30.0

[[joint_assignment]]
property = "strong"

[[joint_assignment]]
property = "weak"
regions = ["b1", "b2"]

[[boundary]]
name = "base"
type = "velocity"
regions = ["b0"]
vx = 0.0
vy = 0.0
omega = 0.0

[[boundary]]
name = "top"
type = "velocity"
regions = ["b3"]
vx = )" + num(vx) + "\nvy = " + num(vy) + R"(
omega = 0.0

[[stage]]
name = "load"
type = "cycle"
steps = )" + std::to_string(steps) + "\n";
    return t;
}

std::vector<SeismicEvent> run_column(const std::string& text) {
    const auto m = test::build_model(text, "column.toml");
    Solver s(m.blocks, m.file.analysis);
    StageObserver quiet;
    run_stages(s, m.file.analysis.stages, quiet);
    REQUIRE(s.world().events.has_value());
    return event_catalogue(*s.world().events);
}

} // namespace

TEST_CASE("a pulled bond's break is one tensile event whose moment is the force dipole it released") {
    const double width = 2.0, height = 0.5, tensile = 1e6;
    const auto events = run_column(column(width, height, 0.0, 1e-7, tensile, 4e6, 6000));
    REQUIRE(events.size() == 1);
    const SeismicEvent& e = events[0];
    const double expected = tensile * width * (2.0 * height); // F d: the joints at ±height
    MESSAGE("Mxx ", e.tensor[0], " Myy ", e.tensor[1], " Mxy ", e.tensor[2], " N m/m (F d = ", expected, "), R ",
            e.r_value, ", Mw ", e.magnitude, ", ", e.bonds, " bonds");
    CHECK(e.bonds == 2);
    CHECK(e.tensile_bonds == 2);
    // Settled, the drop is F d; the largest over the event's window adds the
    // rebound's overshoot of it.
    MESSAGE("settled: Myy ", e.static_tensor[1], " (", e.static_tensor[1] / expected, " F d)");
    CHECK(std::abs(e.static_tensor[1] / expected - 1.0) < 0.03);
    CHECK(e.tensor[1] / expected > 1.0);
    CHECK(e.tensor[1] / expected < 1.4);
    CHECK(std::abs(e.tensor[0]) < 0.05 * expected);
    CHECK(std::abs(e.tensor[2]) < 0.05 * expected);
    CHECK(e.r_value > 30.0);
    CHECK(e.type == "tensile");
    CHECK(std::abs(e.position.y) < 1e-3 * height);
    // M0 = √((m1² + m2²)/2); the thickness its own length (the joint's, 2 m).
    CHECK(e.moment == doctest::Approx(std::abs(e.tensor[1]) / std::sqrt(2.0)).epsilon(0.02));
    CHECK(e.length == doctest::Approx(width).epsilon(1e-9));
    CHECK(e.magnitude == doctest::Approx((std::log10(e.moment * width) - 9.1) / 1.5).epsilon(1e-12));
}

TEST_CASE("a sheared bond's break is a shear event, its moment the shear force's dipole") {
    const double width = 4.0, height = 0.25, cohesion = 1e6;
    const auto events = run_column(column(width, height, 1e-7, 0.0, 2e7, cohesion, 6000));
    REQUIRE(events.size() == 1);
    const SeismicEvent& e = events[0];
    const double expected = cohesion * width * (2.0 * height);
    MESSAGE("Mxx ", e.tensor[0], " Myy ", e.tensor[1], " Mxy ", e.tensor[2], " N m/m (F d = ", expected, "), R ",
            e.r_value);
    CHECK(e.bonds == 2);
    CHECK(e.tensile_bonds == 0);
    MESSAGE("settled: Mxy ", e.static_tensor[2], " (", std::abs(e.static_tensor[2]) / expected, " F d)");
    CHECK(std::abs(std::abs(e.static_tensor[2]) / expected - 1.0) < 0.03);
    CHECK(std::abs(e.tensor[2]) / expected > 1.0);
    CHECK(std::abs(e.tensor[2]) / expected < 1.4);
    CHECK(std::abs(e.tensor[0]) < 0.1 * expected);
    CHECK(std::abs(e.tensor[1]) < 0.1 * expected);
    CHECK(std::abs(e.r_value) < 30.0);
    CHECK(e.type == "shear");
}

TEST_CASE("the failure type and scalar moment of the standard sources") {
    // A pure shear dipole pair: R = 0; a tensile crack in plane strain (λ = μ:
    // M = [3, 1] μ ΔV): R = 100·4/(4 + 2) = 67; its opposite implosive.
    CHECK(isotropic_ratio({0.0, 0.0, 1.0}) == doctest::Approx(0.0));
    CHECK(std::string(failure_type(isotropic_ratio({0.0, 0.0, 1.0}))) == "shear");
    CHECK(isotropic_ratio({3.0, 1.0, 0.0}) == doctest::Approx(100.0 * 4.0 / 6.0));
    CHECK(std::string(failure_type(isotropic_ratio({3.0, 1.0, 0.0}))) == "tensile");
    CHECK(std::string(failure_type(isotropic_ratio({-3.0, -1.0, 0.0}))) == "implosive");
    // M0 of the shear pair: eigenvalues ±1.
    CHECK(scalar_moment({0.0, 0.0, 1.0}) == doctest::Approx(1.0));
    // Hanks and Kanamori: M0 = 10^(1.5 Mw + 9.1) N m.
    CHECK(moment_magnitude(std::pow(10.0, 1.5 * -3.0 + 9.1)) == doctest::Approx(-3.0));
}

TEST_CASE("the b-value fit recovers the b of a Gutenberg–Richter sample") {
    // Magnitudes above 0 with log10 N(>= M) = a − b M: M = −log10(U) / b.
    for (const double b : {0.8, 1.0, 1.5}) {
        std::mt19937_64 random(7);
        std::vector<double> m;
        for (int k = 0; k < 20000; ++k) {
            const double u = (double(random() >> 11) + 0.5) * 0x1.0p-53;
            m.push_back(-std::log10(u) / b);
        }
        const GutenbergRichter g = gutenberg_richter(m);
        REQUIRE(g.fitted);
        MESSAGE("b = ", b, ": fitted ", g.b, " ± ", g.b_error, " above Mc ", g.completeness, " (", g.count, " events)");
        CHECK(g.completeness == doctest::Approx(0.0));
        CHECK(std::abs(g.b - b) < 3.0 * g.b_error);
        CHECK(g.b_error == doctest::Approx(g.b / std::sqrt(double(g.count))).epsilon(0.1));
        CHECK(g.a == doctest::Approx(std::log10(double(g.count))).epsilon(1e-9));
    }
    CHECK_FALSE(gutenberg_richter({-2.0, -2.1, -1.9}).fitted);
}

TEST_CASE("a lab specimen's events hold every broken bond, on 1 and 2 threads and after a restart") {
    // The paper's UCS specimen (2 x 4 m) at a constant platen rate: cracking from
    // about step 4,500, the peak near 9,800, failure after (tests/test_restart.cpp).
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.strain_per_step = 2e-7, o.events = true;
    test::RestartModel m = test::labtest_model(o, 11000);
    m.analysis.solver.threads = 1;
    Solver one(m.blocks, m.analysis);
    StageObserver quiet;
    run_stages(one, m.analysis.stages, quiet);
    const auto events = event_catalogue(*one.world().events);
    int bonds = 0;
    for (const auto& e : events) bonds += e.bonds;
    const int broken = cracks(one.world(), contact::JointState::broken_tension) +
                       cracks(one.world(), contact::JointState::broken_shear);
    MESSAGE(events.size(), " events of ", bonds, " bonds; ", broken, " broken bonds");
    REQUIRE(events.size() > 5);
    CHECK(bonds == broken);
    m.analysis.solver.threads = 2;
    Solver two(m.blocks, m.analysis);
    run_stages(two, m.analysis.stages, quiet);
    const auto other = event_catalogue(*two.world().events);
    REQUIRE(other.size() == events.size());
    for (std::size_t k = 0; k < events.size(); ++k) {
        CHECK(other[k].step == events[k].step);
        CHECK(other[k].moment == events[k].moment);
        CHECK(other[k].tensor == events[k].tensor);
    }
    // Resumed from the middle: the same catalogue, to the bit.
    m.analysis.solver.threads = 1;
    Solver whole(m.blocks, m.analysis);
    test::SaveAt save({8500});
    run_stages(whole, m.analysis.stages, save);
    REQUIRE(save.saved.size() == 1);
    Solver resumed(m.blocks, m.analysis);
    std::istringstream in(save.saved[0].state, std::ios::binary);
    load_state(resumed.world(), in);
    run_stages(resumed, m.analysis.stages, quiet, save.saved[0].cursor);
    const auto again = event_catalogue(*resumed.world().events);
    REQUIRE(again.size() == events.size());
    for (std::size_t k = 0; k < events.size(); ++k) {
        CHECK(again[k].step == events[k].step);
        CHECK(again[k].tensor == events[k].tensor);
        CHECK(again[k].energy == events[k].energy);
    }
}

TEST_CASE("[events]' bad input is refused with its key") {
    auto error = [](const std::string& text) -> std::string {
        try {
            test::build_model(text, "column.toml");
        } catch (const InputError& e) {
            return e.key() + ": " + e.what();
        }
        return "accepted";
    };
    const std::string text = column(2.0, 0.5, 0.0, 1e-7, 1e6, 4e6, 10);
    auto with = [&](std::string from, std::string to) {
        std::string t = text;
        t.replace(t.find(from), from.size(), to);
        return t;
    };
    CHECK(error(with("join_distance = 3.0", "join_distance = 3000.0")).find("events.join_distance") != std::string::npos);
    CHECK(error(with("join_distance = 3.0", "join_distance = -1.0")).find("events.join_distance") != std::string::npos);
    CHECK(error(with("join_distance = 3.0", "window = -5")).find("events.window") != std::string::npos);
    CHECK(error(with("join_distance = 3.0", "joint_distance = 3.0")).find("joint_distance") != std::string::npos);
}
