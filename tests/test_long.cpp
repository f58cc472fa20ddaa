// The long validation runs (minutes each; CTest label `long`, so `ctest -LE long`
// leaves them out): the paper's trigon specimen and the calibration of issue 5.
#include "core/calibrate.hpp"
#include "core/labtest.hpp"

#include <doctest/doctest.h>

using namespace bbm;

TEST_CASE("uniaxial compression, paper trigon specimen: strength of the paper within 15%, the rubble's re-stiffening is caught") {
    // Trigon with the paper's stiffnesses (SPEC §8). After failure the fragments
    // jam between the platens and the stress climbs again: the run must stop there
    // and report the peak before failure. (E is 40% softer than the paper's: see
    // docs/calibration.md; it is reported, not checked.)
    auto o = LabTestOptions::paper_ucs();
    o.pattern = meshing::PatternSpec::Kind::trigon;
    o.joint.kn = 162e9;
    o.joint.ks = 68e9;
    o.threads = 2;
    const auto r = run_labtest(o);
    MESSAGE("trigon, seed 1: E " << r.E / 1e9 << " GPa (paper 20.0), peak " << r.peak_stress / 1e6
                                 << " MPa (paper 20.3), locking after the peak " << r.post_peak_locking << ", "
                                 << r.steps << " steps");
    CHECK(r.peak_passed);
    CHECK(r.peak_stress == doctest::Approx(20.3e6).epsilon(0.15));
    CHECK(r.strain_at_peak < 0.003);
}

TEST_CASE("calibrate, paper specimen: targets E 20 GPa, nu 0.2, UCS 20 MPa, tensile 2.5 MPa hold on fresh seeds") {
    // Issue 5's check: the calibrated set, run again on seeds calibration never saw,
    // gives E and UCS within 5%, ν and the tensile strength within 10%. Means of 4
    // realizations of the paper's 8 m × 16 m specimen (the realizations of one set
    // scatter by ~3% in UCS and tension, so 4 keep the mean to ~1.5%).
    CalibrationOptions o;
    o.realizations = 4;
    o.threads = 2;
    const CalibrationTargets t{20e9, 0.2, 20e6, 2.5e6};
    const auto iterations = calibrate(t, o);
    const auto& last = iterations.back();
    MESSAGE(iterations.size() << " iterations: kn " << last.joint.kn / 1e9 << " GPa/m, ks " << last.joint.ks / 1e9
                              << " GPa/m, tensile " << last.joint.tensile / 1e6 << " MPa, cohesion "
                              << last.joint.cohesion / 1e6 << " MPa");
    REQUIRE(last.converged);
    CHECK(last.E == doctest::Approx(t.E).epsilon(o.tolerance_E));
    CHECK(last.nu == doctest::Approx(t.nu).epsilon(o.tolerance_nu));
    CHECK(last.ucs == doctest::Approx(t.ucs).epsilon(o.tolerance_ucs));
    CHECK(last.tensile == doctest::Approx(t.tensile).epsilon(o.tolerance_tensile));
    const auto fresh = measure_macro_properties(last.joint, o, 1001);
    MESSAGE("fresh seeds: E " << fresh.E / 1e9 << " GPa (UCS curve " << fresh.E_test / 1e9 << "), nu " << fresh.nu
                              << ", UCS " << fresh.ucs / 1e6 << " MPa, tensile " << fresh.tensile / 1e6 << " MPa");
    CHECK(fresh.E == doctest::Approx(t.E).epsilon(0.05));
    CHECK(fresh.nu == doctest::Approx(t.nu).epsilon(0.10));
    CHECK(fresh.ucs == doctest::Approx(t.ucs).epsilon(0.05));
    CHECK(fresh.tensile == doctest::Approx(t.tensile).epsilon(0.10));
}
