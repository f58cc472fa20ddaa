// The direct shear test (studies/lab/shear.hpp, issue 26): a planar joint slides at
// its Coulomb strength under constant normal load, a weak bond peaks at c + σn tan φ
// and falls to σn tan φr, the servo holds σn0 + K dv under constant normal
// stiffness, and rock bridges make a joint stronger.
#include "apps/flags.hpp"
#include "base/error.hpp"
#include "studies/lab/shear.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"
#include "tests/validation_record.hpp"

#include <cmath>
#include <numbers>
#include <string>

using namespace bbm;

namespace {

double tan_deg(double a) { return std::tan(a * std::numbers::pi / 180.0); }

/// The paper's rock bonds, a 2 m x 1 m specimen, an unbonded 30° joint at mid-height.
ShearTestOptions shear_specimen(meshing::PatternSpec::Kind pattern, double size) {
    ShearTestOptions o;
    o.rock.pattern.kind = pattern;
    o.rock.pattern.size = size;
    o.rock.bonds = paper_rock().bonds;
    o.plane.law = "coulomb";
    o.plane.kn = o.rock.bonds.kn, o.plane.ks = o.rock.bonds.ks;
    o.plane.friction = 30.0;
    return o;
}

} // namespace

TEST_CASE("direct shear: a planar unbonded joint slides at its Coulomb strength, sigma_n tan(phi)" * validation) {
    // Rigid halves (one block each): one contact, exact to the servo's error.
    std::string peak_got, residual_got; // the records' figures at each sigma_n
    bool peak_held = true, residual_held = true;
    for (double sn : {1e6, 5e6, 10e6}) {
        auto o = shear_specimen(meshing::PatternSpec::Kind::single, 0.1);
        o.normal_stress = sn;
        o.max_displacement = 5e-4;
        const auto r = run_shear_test(o);
        CAPTURE(sn);
        CHECK(r.peak_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(1e-3));
        CHECK(r.residual_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(1e-3));
        CHECK(r.normal_stress_error < 1e-3);
        CHECK(std::abs(r.final_dilation) < 1e-8); // a flat joint does not dilate
        const std::string sep = peak_got.empty() ? "" : ", ";
        peak_held = peak_held && (r.peak_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(1e-3));
        residual_held =
            residual_held && (r.residual_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(1e-3));
        peak_got += sep + test::figure(r.peak_shear_stress / 1e6) + " (" +
                    test::percent(r.peak_shear_stress, sn * tan_deg(30.0)) + ")";
        residual_got += sep + test::figure(r.residual_shear_stress / 1e6) + " (" +
                        test::percent(r.residual_shear_stress, sn * tan_deg(30.0)) + ")";
    }
    test::record_check(test::Against::closed_form, "peak shear stress, rigid halves, sigma_n 1, 5, 10 MPa",
                       "Coulomb, sigma_n tan 30° = 0.577, 2.89, 5.77 MPa", "each within 0.1%", peak_got + " MPa",
                       peak_held);
    test::record_check(test::Against::closed_form, "residual shear stress, rigid halves, sigma_n 1, 5, 10 MPa",
                       "Coulomb, sigma_n tan 30° = 0.577, 2.89, 5.77 MPa", "each within 0.1%", residual_got + " MPa",
                       residual_held);
    // Bonded Voronoi halves: 39 joint segments along the plane slide together
    // (measured 0.57737, 0.57722 of sigma_n).
    std::string voronoi_got;
    bool voronoi_held = true;
    for (double sn : {1e6, 5e6}) {
        auto o = shear_specimen(meshing::PatternSpec::Kind::voronoi, 0.1);
        o.normal_stress = sn;
        o.max_displacement = 6e-4;
        const auto r = run_shear_test(o);
        CAPTURE(sn);
        CHECK(r.plane_joints > 20);
        CHECK(r.peak_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(5e-3));
        CHECK(r.normal_stress_error < 2e-3);
        voronoi_held = voronoi_held && (r.peak_shear_stress == doctest::Approx(sn * tan_deg(30.0)).epsilon(5e-3));
        voronoi_got += (voronoi_got.empty() ? "" : ", ") + test::figure(r.peak_shear_stress / 1e6) + " (" +
                       test::percent(r.peak_shear_stress, sn * tan_deg(30.0)) + ")";
    }
    test::record_check(test::Against::closed_form, "peak shear stress, bonded Voronoi halves, sigma_n 1, 5 MPa",
                       "Coulomb, sigma_n tan 30° = 0.577, 2.89 MPa", "each within 0.5%", voronoi_got + " MPa",
                       voronoi_held);
}

TEST_CASE("direct shear: a weak brittle bond peaks at c + sigma_n tan(phi) and falls to sigma_n tan(phi_r)") {
    auto o = shear_specimen(meshing::PatternSpec::Kind::single, 0.1);
    o.plane.cohesion = 1e6, o.plane.tensile = 0.5e6;
    o.plane.friction = 35.0, o.plane.residual_friction = 25.0;
    o.normal_stress = 2e6;
    o.max_displacement = 5e-4;
    const auto r = run_shear_test(o);
    CHECK(r.peak_shear_stress == doctest::Approx(1e6 + 2e6 * tan_deg(35.0)).epsilon(2e-3));
    CHECK(r.residual_shear_stress == doctest::Approx(2e6 * tan_deg(25.0)).epsilon(1e-3));
}

TEST_CASE("direct shear: constant normal stiffness holds sigma_n0 + K dv, and a dilating joint grows stronger" * validation) {
    // A joint of persistence 0.5: its rock bridge breaks and the plane dilates.
    auto o = shear_specimen(meshing::PatternSpec::Kind::voronoi, 0.2);
    o.height = 1.25;
    o.persistence = 0.5;
    o.normal_stress = 2e6;
    o.shear_rate = 5e-8;
    o.max_displacement = 4e-3;
    const auto cnl = run_shear_test(o);
    o.normal_stiffness = 5e9; // Pa/m: 0.1 mm of dilation adds 0.5 MPa
    const auto cns = run_shear_test(o);
    CHECK(cnl.final_dilation > 5e-5);
    CHECK(cns.final_dilation > 0.0);
    // The servo lags a burst of cracks by a few hundred steps (measured: 16% of
    // sigma_n0 at the bridge's failure, back within 0.1% 200 steps later).
    int held = 0;
    for (const auto& p : cns.curve) {
        const double target = o.normal_stress + o.normal_stiffness * p.dilation;
        held += std::abs(p.normal_stress - target) < 0.01 * o.normal_stress;
    }
    CHECK(held >= 0.95 * double(cns.curve.size()));
    const auto& end = cns.curve.back();
    CHECK(end.normal_stress == doctest::Approx(o.normal_stress + o.normal_stiffness * end.dilation).epsilon(2e-3));
    CHECK(cns.residual_normal_stress > o.normal_stress + 0.5 * o.normal_stiffness * cns.final_dilation);
    CHECK(cns.peak_shear_stress > cnl.peak_shear_stress);
}

TEST_CASE("direct shear: bad options name their flag") {
    auto key_of = [](std::vector<std::string> args) {
        args.insert(args.end(), {"--max-displacement", "1e-4", "-q"});
        try {
            cli::run_shear_args(args, true);
        } catch (const InputError& e) {
            return e.file();
        }
        return std::string("none");
    };
    CHECK(key_of({"--pattern", "single", "--persistence", "0.5"}) == "--persistence");
    CHECK(key_of({"--joint-law", "softening"}) == "--joint-cohesion"); // a softening plane needs its peaks
    CHECK(key_of({"--joint-jrc", "10"}) == "--joint-jrc");              // not a coulomb joint's key
    CHECK(key_of({"--size", "0.5"}) == "--size");
    CHECK(key_of({"--persistence", "1.5"}) == "shear");
    CHECK(key_of({"--normal-stress", "-1e6"}) == "shear");
}

TEST_CASE("direct shear: rock bridges make a joint stronger, the more of them the stronger" * validation) {
    // Persistence 1, 0.5 and 0 (intact) at 5 MPa, two patterns (seeds). Measured
    // (0.2 m blocks, 6 mm): seed 1 2.89 / 6.68 / 7.70 MPa, seed 2 2.89 / 8.09 / 9.69 MPa.
    for (std::uint64_t seed : {1, 2}) {
        auto strength = [&](double k) {
            auto o = shear_specimen(meshing::PatternSpec::Kind::voronoi, 0.2);
            o.height = 1.25;
            o.rock.pattern.seed = seed;
            o.persistence = k;
            o.shear_rate = 1e-7;
            o.max_displacement = 6e-3;
            return run_shear_test(o).peak_shear_stress;
        };
        const double joint = strength(1.0), half = strength(0.5), intact = strength(0.0);
        CAPTURE(seed);
        CHECK(joint == doctest::Approx(5e6 * tan_deg(30.0)).epsilon(0.02));
        CHECK(half > 2.0 * joint);
        CHECK(intact > half);
    }
}

TEST_CASE("direct shear: a Barton-Bandis joint peaks at sigma_n tan(phi_r + JRC log10(JCS / sigma_n)) and dilates") {
    // Rigid halves (one block each), JRC 10, JCS 100 MPa, phi_r 30 deg, no
    // post-peak fall (no joint length): the peak of Barton & Choubey (1977).
    std::string peak_ref, peak_got, dilation_ref, dilation_got; // the records' figures at each sigma_n
    bool peak_held = true, dilation_held = true;
    for (double sn : {1e6, 5e6}) {
        auto o = shear_specimen(meshing::PatternSpec::Kind::single, 0.1);
        o.plane.law = "barton_bandis";
        o.plane.friction = 30.0, o.plane.jrc = 10.0, o.plane.jcs = 100e6;
        o.normal_stress = sn;
        o.max_displacement = 5e-4;
        const auto r = run_shear_test(o);
        CAPTURE(sn);
        // At the normal stress of the peak (the servo holds σn within 1% while the
        // joint dilates against it): 50° at 1 MPa, 43° at 5 MPa.
        const double at_peak = r.normal_stress_at_peak;
        CHECK(at_peak == doctest::Approx(sn).epsilon(1e-2));
        const double angle = 30.0 + 10.0 * std::log10(100e6 / at_peak);
        CHECK(r.peak_shear_stress == doctest::Approx(at_peak * tan_deg(angle)).epsilon(2e-3));
        CHECK(r.normal_stress_error < 1e-2);
        // Sliding opens the joint at the dilation angle ½ JRC log10(JCS/σn).
        MESSAGE("dilation angle " << r.peak_dilation_angle << " deg, final dilation " << r.final_dilation << " m");
        CHECK(r.peak_dilation_angle == doctest::Approx(0.5 * 10.0 * std::log10(100e6 / sn)).epsilon(0.05));
        const std::string sep = peak_ref.empty() ? "" : ", ";
        const double dilation = 0.5 * 10.0 * std::log10(100e6 / sn);
        peak_held = peak_held && (r.peak_shear_stress == doctest::Approx(at_peak * tan_deg(angle)).epsilon(2e-3));
        dilation_held = dilation_held && (r.peak_dilation_angle == doctest::Approx(dilation).epsilon(0.05));
        peak_ref += sep + test::figure(at_peak * tan_deg(angle) / 1e6);
        peak_got += sep + test::figure(r.peak_shear_stress / 1e6) + " (" +
                    test::percent(r.peak_shear_stress, at_peak * tan_deg(angle)) + ")";
        dilation_ref += sep + test::figure(dilation);
        dilation_got +=
            sep + test::figure(r.peak_dilation_angle) + "° (" + test::percent(r.peak_dilation_angle, dilation) + ")";
    }
    test::record_check(test::Against::closed_form, "peak shear stress at the sigma_n of the peak, sigma_n 1, 5 MPa",
                       "sigma_n tan(phi_r + JRC log10(JCS/sigma_n)), JRC 10, JCS 100 MPa, phi_r 30° "
                       "(Barton & Choubey 1977): " +
                           peak_ref + " MPa",
                       "each within 0.2%", peak_got + " MPa", peak_held);
    test::record_check(test::Against::closed_form, "peak dilation angle, sigma_n 1, 5 MPa",
                       "1/2 JRC log10(JCS/sigma_n) = " + dilation_ref + "° (docs/joints.md)", "each within 5%",
                       dilation_got, dilation_held);
}
