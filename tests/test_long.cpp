// The long validation runs (minutes each; CTest label `long`, so `ctest -LE long`
// leaves them out): the paper's trigon specimen, the calibration of issue 5 and
// the post-peak targets of issue 12 over three seeds, exact restart of the
// deformable tunnel (issue 27), the Mine-by notches (issue 24), the residual
// strength of Lac du Bonnet's rubble against broken rock's friction.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"
#include "studies/calibration/calibrate.hpp"
#include "studies/lab/labtest.hpp"
#include "studies/model/opening.hpp"
#include "tests/restart.hpp"
#include "tests/specimens.hpp"
#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

using namespace bbm;

TEST_CASE("uniaxial compression, paper trigon specimen, 3 realizations: the paper's modulus, a quasi-static strength 15-29% below the paper's") {
    // Trigon with the paper's stiffnesses (SPEC §8): triangles of 0.3 m average
    // dimension, from the cells of random points. Realizations in parallel, one
    // thread each. After failure the fragments may jam between the platens and the
    // stress climb again: the run stops there and reports the peak before failure.
    double E = 0, peak = 0;
    std::vector<LabTestResult> r(3);
    std::vector<std::thread> pool;
    for (int k = 0; k < 3; ++k)
        pool.emplace_back([&r, k] {
            auto o = test::paper_trigon_ucs();
            o.rock.pattern.seed = std::uint64_t(k + 1);
            r[k] = run_labtest(o);
        });
    for (auto& t : pool) t.join();
    for (int k = 0; k < 3; ++k) {
        MESSAGE("trigon, seed " << k + 1 << ": " << r[k].blocks << " triangles, E " << r[k].E / 1e9 << " GPa, peak "
                                << r[k].peak_stress / 1e6 << " MPa, locking after the peak " << r[k].post_peak_locking
                                << ", " << r[k].steps << " steps");
        CHECK(r[k].peak_passed);
        CHECK(r[k].strain_at_peak < 0.003);
        E += r[k].E / 3, peak += r[k].peak_stress / 3;
    }
    MESSAGE("trigon, mean of 3: E " << E / 1e9 << " GPa (paper 20.0), UCS " << peak / 1e6 << " MPa (paper 20.3)");
    // Issue 5 asks for E within 10% and the UCS within 15% of the paper. E is met
    // (measured +2.4%); the UCS is not: loaded quasi-statically (the servo holds
    // the platen forces balanced once cracking starts) the trigon peaks at
    // 15.69 MPa, 22.7% under the paper's (15.79 / 15.27 / 16.02); at the former
    // crack-keyed servo it read 17.25 (−15%), a rate effect (the test below).
    // docs/calibration.md says so; this guards the measured figure.
    CHECK(E == doctest::Approx(20.0e9).epsilon(0.10));
    CHECK(peak < 0.85 * 20.3e6);
    CHECK(peak > 0.71 * 20.3e6);
}

TEST_CASE("uniaxial compression, paper trigon specimen: the default loading gives the quasi-static peak") {
    // The trigon fails in a cascade from its first sustained cracking: loaded
    // faster than it can redistribute, it carries more than its strength (constant
    // 5e-8 per step: 17.2 MPa; 2.5e-8: 16.6; 1e-8: 15.8; 4e-9: 15.56). The default
    // servo, which holds the top and bottom platen forces within 2% of each other
    // once cracking starts, must give the slow answer (measured 15.79, +1.5%) in a
    // fraction of its steps (26,000 against 173,860).
    const auto o = test::paper_trigon_ucs();
    LabTestResult fast, slow;
    std::thread other([&] { fast = run_labtest(o); });
    auto q = o;
    q.servo.on = false;
    q.strain_per_step = 4e-9;
    slow = run_labtest(q);
    other.join();
    MESSAGE("trigon seed 1: default loading " << fast.peak_stress / 1e6 << " MPa in " << fast.steps << " steps, constant 4e-9 "
                                              << slow.peak_stress / 1e6 << " MPa in " << slow.steps << " steps");
    REQUIRE(fast.peak_passed);
    REQUIRE(slow.peak_passed);
    CHECK(fast.peak_stress == doctest::Approx(slow.peak_stress).epsilon(0.03));
    CHECK(fast.steps < slow.steps / 3);
}

namespace {
/// Runs the calibration, shows the set it ends with, and requires it converged.
CalibrationIteration converged_set(const CalibrationTargets& t, const CalibrationOptions& o) {
    const auto iterations = calibrate(t, o);
    const auto& last = iterations.back();
    MESSAGE(iterations.size() << " iterations: kn " << last.joint.kn / 1e9 << " GPa/m, ks " << last.joint.ks / 1e9
                              << " GPa/m, tensile " << last.joint.tensile / 1e6 << " MPa, cohesion "
                              << last.joint.cohesion / 1e6 << " MPa");
    REQUIRE(last.converged);
    return last;
}

/// "mean of seeds 1001-1003, std 1.2": how a fresh-seed mean was measured (the record's text).
std::string fresh_seeds(const CalibrationOptions& o, double std_dev) {
    return "mean of seeds 1001-" + std::to_string(1000 + o.realizations) + ", std " + test::figure(std_dev);
}
} // namespace

TEST_CASE("calibrate, paper specimen: targets E 20 GPa, nu 0.2, UCS 20 MPa, tensile 2.5 MPa hold on fresh seeds") {
    // Issue 5's check: the calibrated set, run again on seeds calibration never saw,
    // gives E and UCS within 5%, ν and the tensile strength within 10%. Means of 4
    // realizations of the paper's 8 m × 16 m specimen (the realizations of one set
    // scatter by ~3% in UCS and tension, so 4 keep the mean to ~1.5%).
    CalibrationOptions o;
    o.realizations = 4;
    o.threads = 2;
    CalibrationTargets t;
    t.E = 20e9, t.nu = 0.2, t.ucs = 20e6, t.tensile = 2.5e6;
    const auto last = converged_set(t, o);
    CHECK(last.E == doctest::Approx(t.E).epsilon(o.tolerance_E));
    CHECK(last.nu == doctest::Approx(t.nu).epsilon(o.tolerance_nu));
    CHECK(last.ucs == doctest::Approx(t.ucs).epsilon(o.tolerance_ucs));
    CHECK(last.tensile == doctest::Approx(t.tensile).epsilon(o.tolerance_tensile));
    const auto fresh = measure_macro_properties(last.joint, o, 1001);
    MESSAGE("fresh seeds: E " << fresh.E / 1e9 << " GPa (UCS curve " << fresh.E_test / 1e9 << "), nu " << fresh.nu
                              << ", UCS " << fresh.ucs / 1e6 << " MPa, tensile " << fresh.tensile / 1e6 << " MPa");
    CHECK(fresh.E == doctest::Approx(t.E).epsilon(0.05));
    test::record_check(test::Against::paper, "E of the calibrated set on fresh seeds",
                       "issue 5's target E 20 GPa (the paper's modulus, SPEC §8)", "within 5%",
                       test::figure(fresh.E / 1e9) + " GPa (" + test::percent(fresh.E, t.E) + "), " +
                           fresh_seeds(o, fresh.E_std / 1e9),
                       fresh.E == doctest::Approx(t.E).epsilon(0.05));
    CHECK(fresh.nu == doctest::Approx(t.nu).epsilon(0.10));
    test::record_check(test::Against::paper, "nu of the calibrated set on fresh seeds", "issue 5's target nu 0.2",
                       "within 10%",
                       test::figure(fresh.nu) + " (" + test::percent(fresh.nu, t.nu) + "), " +
                           fresh_seeds(o, fresh.nu_std),
                       fresh.nu == doctest::Approx(t.nu).epsilon(0.10));
    CHECK(fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    test::record_check(test::Against::paper, "UCS of the calibrated set on fresh seeds", "issue 5's target UCS 20 MPa",
                       "within 5%",
                       test::figure(fresh.ucs / 1e6) + " MPa (" + test::percent(fresh.ucs, t.ucs) + "), " +
                           fresh_seeds(o, fresh.ucs_std / 1e6),
                       fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    CHECK(fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
    test::record_check(test::Against::paper, "tensile strength of the calibrated set on fresh seeds",
                       "issue 5's target 2.5 MPa", "within 10%",
                       test::figure(fresh.tensile / 1e6) + " MPa (" + test::percent(fresh.tensile, t.tensile) + "), " +
                           fresh_seeds(o, fresh.tensile_std / 1e6),
                       fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
}

TEST_CASE("calibrate --fit-ci, paper specimen: the paper's rock with sigma_ci/UCS 0.35 holds on fresh seeds") {
    // Issue 23's targets for a record with a crack-initiation stress: E, nu and UCS
    // within 5%, tension within 10%, sigma_ci/UCS within 0.05, on seeds the
    // calibration never saw. Uniform bonds give this rock 0.34-0.48 (T/UCS 0.095);
    // heterogeneous ones bring it to the target. Measured 2026-11-26 (1 thread, 5 min
    // 56 s): converged at iteration 7 with m 1.89; fresh seeds 1001-1003 E 20.09 GPa,
    // nu 0.206, UCS 20.85 MPa, T 2.067 MPa, sigma_ci/UCS 0.337.
    CalibrationOptions o;
    o.realizations = 3;
    o.threads = 2;
    o.max_iterations = 8;
    o.fit_ci = true;
    CalibrationTargets t;
    t.E = 20e9, t.nu = 0.2, t.ucs = 20.7e6, t.tensile = 1.97e6, t.ci_ratio = 0.35;
    const auto last = converged_set(t, o);
    CHECK(last.joint.weibull_modulus > 0.0);
    CHECK(std::abs(last.ci_ratio - t.ci_ratio) <= o.tolerance_ci);
    const auto fresh = measure_macro_properties(last.joint, o, 1001);
    MESSAGE("m " << last.joint.weibull_modulus << "; fresh seeds: E " << fresh.E / 1e9 << " GPa, nu " << fresh.nu << ", UCS "
                 << fresh.ucs / 1e6 << " MPa, tensile " << fresh.tensile / 1e6 << " MPa, sigma_ci/UCS " << fresh.ci_ratio);
    CHECK(fresh.E == doctest::Approx(t.E).epsilon(0.05));
    CHECK(fresh.nu == doctest::Approx(t.nu).epsilon(0.05));
    CHECK(fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    CHECK(fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
    CHECK(std::abs(fresh.ci_ratio - t.ci_ratio) <= 0.05);
}

TEST_CASE("residual strength, Lac du Bonnet's in-situ set: broken joints at 10 degrees give the rubble broken rock's friction (Byerlee 40.4 degrees)") {
    // docs/calibration.md, "The residual strength": the in-situ set (the values
    // of examples/lab/lac_du_bonnet_in_situ.toml's calibration with broken joints
    // at 10 degrees), biaxial at sigma3 = 10 MPa run to 2% strain. Measured
    // 2026-11-27: peak 93.1 MPa at 0.13%, residual 48.4 MPa, 41.1 degrees.
    // Crystalline rock's broken surfaces slide at tau = 0.85 sigma_n, 40.4
    // degrees (Byerlee 1978); asserted within 3 degrees.
    LabTestOptions o;
    o.kind = LabTestOptions::Kind::biaxial;
    o.rock.pattern.size = 0.12, o.width = 2.4, o.height = 4.8, o.rock.material.density = 2650, o.rock.pattern.seed = 1001;
    o.rock.bonds.kn = 954.511e9, o.rock.bonds.ks = 257.441e9;
    o.rock.bonds.tensile = 15.1313e6, o.rock.bonds.cohesion = 41.843e6;
    o.rock.bonds.friction = 5, o.rock.bonds.residual_friction = 10;
    o.confinement = 10e6;
    o.stop.fraction = 0.0, o.stop.max_strain = 0.02, o.stop.strain_cap = 0.02;
    o.threads = 2, o.frame_every = 0;
    const auto r = run_labtest(o);
    REQUIRE(!r.curve.empty());
    CHECK(r.curve.back().axial_strain >= 0.0199);
    CHECK(r.strain_at_peak < 0.005);                 // failed early, then slid
    REQUIRE(r.residual_stress > 0.0);
    CHECK(r.residual_stress < 0.7 * r.peak_stress);  // softened, not locked
    CHECK(r.residual_friction_angle == doctest::Approx(40.4).epsilon(3.0 / 40.4));
    test::record_check(test::Against::laboratory, "residual friction angle of the rubble, sigma3 10 MPa, 2% strain",
                       "40.4°, broken crystalline rock's tau = 0.85 sigma_n (Byerlee 1978)",
                       "within 3° (3/40.4 relative)",
                       test::figure(r.residual_friction_angle) + "° (residual " +
                           test::figure(r.residual_stress / 1e6) + " MPa, peak " + test::figure(r.peak_stress / 1e6) +
                           " MPa; seed 1001)",
                       r.residual_friction_angle == doctest::Approx(40.4).epsilon(3.0 / 40.4));
    // Consistent with its definition: sigma1/sigma3 = (1 + sin phi)/(1 - sin phi).
    const double sin_phi = std::sin(r.residual_friction_angle * std::numbers::pi / 180.0);
    CHECK(r.residual_stress / o.confinement == doctest::Approx((1 + sin_phi) / (1 - sin_phi)).epsilon(1e-9));
}

TEST_CASE("confined friction, Lac du Bonnet: sigma_ci unconfined and the laboratory's peak at 35.5 MPa on fresh seeds") {
    // The set of examples/field/mineby_confined.toml (bbm --config
    // examples/lab/lac_du_bonnet_in_situ_confined.toml calibrate, 2026-11-27:
    // fresh seeds 1001-1003 strength 69.5 MPa, sigma1 at 35.5 MPa 640 MPa, std
    // 59). Targets: sigma_ci 74.6 MPa within 10%, the record's 557 MPa within 20%
    // (three seeds of a 9% scatter), no specimen jammed at the strain cap; and the
    // same bonds without the confined friction far below the peak (their joints'
    // Coulomb envelope: 2c sqrt(N) + N sigma3 = 129 MPa).
    CalibrationOptions o;
    o.base.rock.pattern.size = 0.12, o.base.width = 2.4, o.base.height = 4.8;
    o.base.rock.material.density = 2650;
    auto& j = o.base.rock.bonds;
    j.kn = 957593745133.4312, j.ks = 266384954237.1118;
    j.tensile = 15296822.579253344, j.cohesion = 39651374.19228245;
    j.friction = 5, j.residual_friction = 10;
    j.confined_friction = 62.36386551427173, j.confined_friction_from = 74.6e6;
    o.realizations = 3;
    o.threads = 2;
    const auto fresh = measure_macro_properties(j, o, 1001, {35.5e6});
    MESSAGE("fresh seeds: strength " << fresh.ucs / 1e6 << " MPa, sigma1 at 35.5 MPa " << fresh.confined[0] / 1e6
                                     << " MPa (std " << fresh.confined_std[0] / 1e6 << ")");
    CHECK(fresh.ucs == doctest::Approx(74.6e6).epsilon(0.10));
    test::record_check(test::Against::laboratory, "unconfined strength on fresh seeds, against sigma_ci",
                       "sigma_ci = 0.35 x 213 MPa = 74.6 MPa (Lac du Bonnet; Martin & Chandler 1994)", "within 10%",
                       test::figure(fresh.ucs / 1e6) + " MPa (" + test::percent(fresh.ucs, 74.6e6) + "), " +
                           fresh_seeds(o, fresh.ucs_std / 1e6),
                       fresh.ucs == doctest::Approx(74.6e6).epsilon(0.10));
    CHECK(fresh.confined[0] == doctest::Approx(557.2e6).epsilon(0.20));
    test::record_check(test::Against::laboratory, "sigma1 at sigma3 = 35.5 MPa on fresh seeds",
                       "557 MPa (Lac du Bonnet; Martin & Chandler 1994, Martin 1997)", "within 20%",
                       test::figure(fresh.confined[0] / 1e6) + " MPa (" + test::percent(fresh.confined[0], 557.2e6) +
                           "), " + fresh_seeds(o, fresh.confined_std[0] / 1e6),
                       fresh.confined[0] == doctest::Approx(557.2e6).epsilon(0.20));
    CHECK(fresh.still_loading == 0);
    LabTestOptions plain = o.base;
    plain.kind = LabTestOptions::Kind::biaxial;
    plain.rock.bonds.confined_friction = -1;
    plain.confinement = 35.5e6, plain.rock.pattern.seed = 1001, plain.threads = 2, plain.frame_every = 0;
    plain.stop.post_peak_strain = envelope_post_peak_strain;
    const auto r = run_labtest(plain);
    MESSAGE("without the confined friction: sigma1 " << r.peak_stress / 1e6 << " MPa");
    CHECK(r.peak_stress < 0.6 * 557.2e6);
}

TEST_CASE("calibrate, Lac du Bonnet on crack initiation: E, nu, sigma_ci and tension hold on fresh seeds") {
    // examples/lab/lac_du_bonnet_in_situ.toml (issue 23 item 4, issue 24): the
    // record's E 69 GPa, nu 0.26, tension 9.3 MPa and sigma_ci = 0.35 x 213 MPa in
    // the UCS's place; 0.12 m Voronoi blocks in a 2.4 m x 4.8 m specimen, bonds of
    // 5 degrees' friction (35 once broken), started from the peak calibration's
    // stiffnesses. Issue 23's targets on fresh seeds: E, nu and the strength within
    // 5%, tension within 10%.
    CalibrationOptions o;
    o.base.rock.pattern.size = 0.12, o.base.width = 2.4, o.base.height = 4.8;
    o.base.rock.material.density = 2650;
    o.base.rock.bonds.kn = 992e9, o.base.rock.bonds.ks = 339e9;
    o.base.rock.bonds.tensile = 17.2e6, o.base.rock.bonds.cohesion = 36e6;
    o.base.rock.bonds.friction = 5, o.base.rock.bonds.residual_friction = 35;
    o.start_kn = o.start_ks = o.start_tensile = o.start_cohesion = true;
    o.realizations = 3;
    o.threads = 2;
    o.max_iterations = 5;
    CalibrationTargets t;
    t.E = 69e9, t.nu = 0.26, t.ucs = 74.6e6, t.tensile = 9.3e6; // sigma_ci = 0.35 x 213 MPa, as the example file
    const auto last = converged_set(t, o);
    const auto fresh = measure_macro_properties(last.joint, o, 1001);
    MESSAGE("fresh seeds: E " << fresh.E / 1e9 << " GPa, nu " << fresh.nu << ", strength " << fresh.ucs / 1e6
                              << " MPa, tensile " << fresh.tensile / 1e6 << " MPa, sigma_ci/peak " << fresh.ci_ratio);
    CHECK(fresh.E == doctest::Approx(t.E).epsilon(0.05));
    const std::string record = "(Lac du Bonnet; Martin & Chandler 1994, Martin 1997)";
    test::record_check(test::Against::laboratory, "E of the calibrated set on fresh seeds", "E 69 GPa " + record,
                       "within 5%",
                       test::figure(fresh.E / 1e9) + " GPa (" + test::percent(fresh.E, t.E) + "), " +
                           fresh_seeds(o, fresh.E_std / 1e9),
                       fresh.E == doctest::Approx(t.E).epsilon(0.05));
    CHECK(fresh.nu == doctest::Approx(t.nu).epsilon(0.05));
    test::record_check(test::Against::laboratory, "nu of the calibrated set on fresh seeds", "nu 0.26 " + record,
                       "within 5%",
                       test::figure(fresh.nu) + " (" + test::percent(fresh.nu, t.nu) + "), " +
                           fresh_seeds(o, fresh.nu_std),
                       fresh.nu == doctest::Approx(t.nu).epsilon(0.05));
    CHECK(fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    test::record_check(test::Against::laboratory, "unconfined strength on fresh seeds, against sigma_ci",
                       "sigma_ci = 0.35 x 213 MPa = 74.6 MPa " + record, "within 5%",
                       test::figure(fresh.ucs / 1e6) + " MPa (" + test::percent(fresh.ucs, t.ucs) + "), " +
                           fresh_seeds(o, fresh.ucs_std / 1e6),
                       fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    CHECK(fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
    test::record_check(test::Against::laboratory, "tensile strength of the calibrated set on fresh seeds",
                       "about 9.3 MPa " + record, "within 10%",
                       test::figure(fresh.tensile / 1e6) + " MPa (" + test::percent(fresh.tensile, t.tensile) + "), " +
                           fresh_seeds(o, fresh.tensile_std / 1e6),
                       fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
}

namespace {

/// Seeds 1–3 of a lab test: in parallel, one thread each; deformable specimens one
/// at a time, two threads each, as `bbm ucs --realizations` runs them (studies/lab/labtest_command.cpp).
std::vector<LabTestResult> three_seeds(const LabTestOptions& base) {
    std::vector<LabTestResult> r(3);
    if (base.rock.material.deformable_fraction > 0.0) {
        for (int k = 0; k < 3; ++k) {
            auto o = base;
            o.rock.pattern.seed = std::uint64_t(k + 1);
            o.threads = 2;
            o.stop.fraction = 0.5;
            r[k] = run_labtest(o);
        }
        return r;
    }
    std::vector<std::thread> pool;
    for (int k = 0; k < 3; ++k)
        pool.emplace_back([&r, &base, k] {
            auto o = base;
            o.rock.pattern.seed = std::uint64_t(k + 1);
            o.threads = 1;
            o.stop.fraction = 0.5; // the checks follow the softening to half the peak
            r[k] = run_labtest(o);
        });
    for (auto& t : pool) t.join();
    return r;
}

/// Issue 12's post-peak target: below half the peak before 1% axial strain, no locking.
void check_softens(const std::vector<LabTestResult>& r, const char* what) {
    for (int k = 0; k < 3; ++k) {
        const auto& end = r[k].curve.back();
        MESSAGE(std::string(what) << ", seed " << k + 1 << ": peak " << r[k].peak_stress / 1e6 << " MPa, end at "
                     << end.axial_stress / r[k].peak_stress << " of it, strain " << end.axial_strain << ", locking "
                     << r[k].post_peak_locking);
        CHECK(r[k].peak_passed);
        CHECK_FALSE(r[k].post_peak_locking);
        CHECK(end.axial_stress <= 0.5 * r[k].peak_stress);
        CHECK(end.axial_strain < 0.01);
    }
}

LabTestOptions small(double deformable_fraction) {
    auto o = LabTestOptions::paper_ucs();
    o.width = 4.0, o.height = 8.0;
    o.rock.material.deformable_fraction = deformable_fraction;
    return o;
}

} // namespace

TEST_CASE("post-peak, 3 seeds: area-sized trigon 3 x 6 m and 8 x 16 m soften without locking") {
    // Issue 12: the area-sized trigon hardened to 176 MPa at 1% strain; after the
    // four fixes of docs/calibration.md ("After the peak") every seed softens.
    // These runs are also the regression tests of mechanisms 2-4 (mechanism 1, a
    // small rigid specimen, is in test_labtest.cpp):
    // - 2 and 3, the 3 x 6 m specimen of seed 3: contacts formed past the end of an
    //   edge started with the gap to the edge's line, not to the rounded corner the
    //   law then measures against: a vertex beside a corner, outside the block, was
    //   born compressed (up to 379 MPa), and new corner contacts came to carry 16% of
    //   the compression, wedging the side fragments; and a single record of a crack
    //   burst's dynamic transient (14.2 -> 18.1 MPa, unbalanced ratio 22) above the
    //   peak stopped the run as "locking". Now new corner contacts start at their
    //   corner gap, and locking must hold for 10 records with the load on broken or
    //   new contacts. Checked: without the corner gap (the lock rules as now) this
    //   specimen still locks; with it but one record enough, it stops on the transient.
    // - 4, the 8 x 16 m specimen of seed 2: the rounded corner a new contact is
    //   measured against past an edge's end is a circle tangent to that edge only,
    //   which beside the triangles' acute corners reaches past the block; vertices
    //   there, outside the block, were born in overlap (344 of 515 contacts born below
    //   -0.1 mm in the 3 x 6 m specimen) and pushed fragments apart with forces nothing
    //   justified. This seed locked at 3.26e-3 strain after 90,860 steps and 23,106
    //   cracks; now such a vertex's contact is with the edge across the corner, which
    //   it faces, and starts open: the specimen softens (23,660 steps) before 0.4%.
    auto o = test::area_trigon_ucs();
    o.width = 3.0, o.height = 6.0;
    check_softens(three_seeds(o), "area trigon 3 x 6 m");
    const auto full = three_seeds(test::area_trigon_ucs());
    check_softens(full, "area trigon 8 x 16 m");
    CHECK(full[1].curve.back().axial_strain < 0.004);
}

TEST_CASE("post-peak, 3 seeds: rigid and deformable blocks (f = 0.5 and 0.95, 4 x 8 m) soften, deformable peaks within 15% of the rigid ones") {
    // Issue 12's target. With the crack-keyed servo alone f = 0.95 seed 2 locked
    // (its rubble climbed back above the peak at 0.7% strain) and seed 1 peaked
    // 10.7% above the rigid specimen; loaded in equilibrium (the force-balance
    // servo) all nine soften and every deformable peak is within 4% of the rigid one.
    const auto rigid = three_seeds(small(0.0));
    check_softens(rigid, "rigid Voronoi 4 x 8 m");
    for (double f : {0.5, 0.95}) {
        const auto deformable = three_seeds(small(f));
        const std::string what = "deformable f = " + std::to_string(f).substr(0, 4) + ", 4 x 8 m";
        check_softens(deformable, what.c_str());
        for (int k = 0; k < 3; ++k)
            CHECK(deformable[k].peak_stress == doctest::Approx(rigid[k].peak_stress).epsilon(0.15));
    }
}

TEST_CASE("restart: the deformable tunnel (f = 0.95) stopped in its excavation and in its failure resumes exactly") {
    // The whole run on 2 threads (33,000 steps), resumed on 1 (issue 27).
    auto file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/compare_rigid_deformable/deformable_f095.toml");
    test::check_exact_restart({meshing::generate_blocks(file.geometry), file.analysis}, {2000, 9000}, {1}, 2);
}

TEST_CASE("field: the Mine-by tunnel in rock calibrated on crack initiation notches its roof and floor, across the largest stress") {
    // examples/field/mineby_in_situ.toml (issue 24, docs/field.md): Lac du Bonnet
    // bonds calibrated on laboratory data only (E, nu, tension and the crack-
    // initiation stress), the field's stresses (60 MPa plunging 14 degrees, 11 MPa),
    // seed as shipped. The field: V-shaped notches at the roof and floor across the
    // largest stress (104 and 284 degrees), nothing comparable at the side walls
    // (14 and 194 degrees), the notch tip at rf/a about 1.45 (docs/field.md).
    auto file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/field/mineby_in_situ.toml");
    file.analysis.solver.threads = 2;
    const auto blocks = meshing::generate_blocks(file.geometry);
    Solver s(blocks, file.analysis);
    struct Quiet : StageObserver {} q;
    const auto reports = run_stages(s, file.analysis.stages, q);
    const auto& rep = file.analysis.report;
    const auto zone = measure_failed_zone(s.world(), rep.center, rep.springline, rep.crown);
    const auto lobes = zone.lobes();
    auto off = [](double deg, double target) { return std::abs(std::remainder(deg - target, 360.0)); };
    // The notches: the largest lobe near each notch direction; the side walls':
    // the largest near each side wall, if any.
    auto largest_near = [&](double direction) {
        FailedZone::Lobe best;
        for (const auto& l : lobes)
            if (off(l.centre_deg, direction) <= 45.0 && l.area > best.area) best = l;
        return best;
    };
    const double a = 1.75;
    double smaller_notch = 1e300;
    std::string side_got; // the record's side-wall lobes
    bool side_held = true;
    for (double notch : {104.0, 284.0}) {
        const auto l = largest_near(notch);
        MESSAGE("notch at " << notch << " deg: centre " << l.centre_deg << " deg, depth " << l.depth << " m (rf/a "
                            << (a + l.depth) / a << ", field 1.45), width " << l.width_deg << " deg, area " << l.area << " m2");
        CHECK(l.area > 0.0);
        CHECK(off(l.centre_deg, notch) <= 10.0);
        const std::string which = notch < 180 ? "roof notch (104°)" : "floor notch (284°)";
        test::record_check(test::Against::field, "centre of the " + which,
                           "the field's notch at " + test::figure(notch) +
                               "°, across the largest stress (Mine-by; Martin 1997, docs/field.md)",
                           "within 10°, a lobe there",
                           l.area > 0.0 ? test::figure(l.centre_deg) + "° (width " + test::figure(l.width_deg) +
                                              "°, area " + test::figure(l.area) + " m²)"
                                        : std::string("no lobe within 45°"),
                           l.area > 0.0 && off(l.centre_deg, notch) <= 10.0);
        // At least three block rows: a notch, not a skin of cracks. (Its depth
        // against the field's is measured over seeds in docs/field.md: 0.43-0.72 m
        // against about 0.79 m.)
        CHECK(l.depth >= 3 * 0.12);
        test::record_check(test::Against::field, "depth of the " + which,
                           "the field's about 0.79 m, rf/a 1.45 (docs/field.md); asserted: a notch, not its depth",
                           ">= 0.36 m (three block rows)",
                           test::figure(l.depth) + " m, rf/a " + test::figure((a + l.depth) / a) + " (seed as shipped)",
                           l.depth >= 3 * 0.12);
        smaller_notch = std::min(smaller_notch, l.area);
    }
    for (double side : {14.0, 194.0}) {
        const auto w = largest_near(side);
        MESSAGE("side wall at " << side << " deg: depth " << w.depth << " m, area " << w.area << " m2");
        CHECK(w.area < 0.5 * smaller_notch);
        side_held = side_held && w.area < 0.5 * smaller_notch;
        side_got += (side_got.empty() ? "" : ", ") + test::figure(w.area) + " m² (" +
                    test::figure(100 * w.area / smaller_notch, 2) + "%)";
    }
    test::record_check(test::Against::field, "largest lobe at each side wall (14°, 194°) against the smaller notch",
                       "no comparable failure at the side walls (Mine-by; Martin 1997, docs/field.md)",
                       "area < 0.5 x the smaller notch's, each side",
                       side_got + " against " + test::figure(smaller_notch) + " m²", side_held);
    // Issue 48: the depth is measured at the broken contacts, finer than a block;
    // its step under 5% of the field's depth (the cells of the zone are 0.144 m).
    MESSAGE("failed-zone depth resolution " << zone.resolution << " m (cells " << zone.cell << " m)");
    CHECK(zone.resolution < 0.05 * 0.79);
    test::record_check(test::Against::field, "step of the failed zone's depth (broken contact points)",
                       "finer than a block: under 5% of the field's notch depth, 0.79 m (issue 48)",
                       "< 0.0395 m", test::figure(zone.resolution) + " m (blocks 0.12 m, cells " + test::figure(zone.cell) + " m)",
                       zone.resolution < 0.05 * 0.79);
    CHECK_FALSE(zone.reaches_region_edge);
    CHECK(reports.back().verdict.kind == Verdict::Kind::equilibrium);
}
