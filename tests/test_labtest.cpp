// Numerical lab tests (core/labtest.hpp) on the paper's 8 m × 16 m specimen of
// Voronoi blocks with its joint properties (SPEC §8). (A smaller specimen is
// several per cent softer: its free sides are a boundary layer of clipped cells of
// relative width ~ d/W.)
#include "core/calibrate.hpp"
#include "core/labtest.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

using namespace bbm;

TEST_CASE("direct tension, paper specimen: mean strength of 3 realizations within 0.5 to 1.1 sigma_t") {
    // Tension peaks at a strain of ~1e-4, so it is loaded ten times slower than
    // compression to stay quasi-static (halving this rate changes it by < 1%; at
    // the compression rate the peak overshoots by ~15%).
    double mean = 0.0;
    for (std::uint64_t seed : {1, 2, 3}) {
        auto o = LabTestOptions::paper_ucs();
        o.kind = LabTestOptions::Kind::tension;
        o.strain_per_step = 5e-9;
        o.seed = seed;
        const auto r = run_labtest(o);
        INFO("seed " << seed << ": tensile strength " << r.peak_stress / 1e6 << " MPa");
        CHECK(r.peak_passed);
        CHECK(r.cracks_tensile > r.cracks_shear);
        mean += r.peak_stress / 3;
    }
    INFO("mean tensile strength " << mean / 1e6 << " MPa");
    CHECK(mean > 0.5 * 3e6);
    CHECK(mean < 1.1 * 3e6);
}

TEST_CASE("uniaxial compression, paper specimen: elastic modulus of the lattice theory, axial splitting") {
    const auto o = LabTestOptions::paper_ucs();
    const auto r = run_labtest(o);
    // Rigid blocks on elastic joints: the hexagonal-lattice closed form
    // E = 2 a kn (kn + ks)/(3 kn + ks), a = d √(π/(2√3)) (examples/verification/
    // hexagonal_lattice.toml); a random Voronoi assembly is close to it.
    const double kn = o.joint.kn, ks = o.joint.ks;
    const double a = o.size * std::sqrt(std::numbers::pi / (2 * std::sqrt(3.0)));
    const double lattice = 2 * a * kn * (kn + ks) / (3 * kn + ks);
    INFO("E " << r.E / 1e9 << " GPa (lattice " << lattice / 1e9 << "), nu " << r.nu << ", peak " << r.peak_stress / 1e6
              << " MPa, cracks vertical " << r.cracks_near_vertical << " horizontal " << r.cracks_near_horizontal);
    CHECK(r.peak_passed);
    CHECK(r.E == doctest::Approx(lattice).epsilon(0.05));
    CHECK(r.nu > 0.1);
    CHECK(r.nu < 0.3);
    // Voronoi failure dominated by axial splitting (issue 5: at least 2 to 1).
    CHECK(r.cracks_near_vertical >= 2 * r.cracks_near_horizontal);
    CHECK(r.cracks_tensile > r.cracks_shear);
}

TEST_CASE("calibrate: targets E 20 GPa, nu 0.2, UCS 20 MPa, tensile 2.5 MPa are met; elastic targets hold on fresh seeds") {
    // A 3 m × 6 m specimen keeps the test short (the paper's 8 m × 16 m takes ~6 min).
    CalibrationOptions o;
    o.base.width = 3.0;
    o.base.height = 6.0;
    o.realizations = 3;
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
    // New seeds: the elastic constants are properties of the pattern, not of one
    // realization (the strengths scatter with the realization: reported, not checked).
    const auto fresh = measure_macro_properties(last.joint, o, 1001);
    MESSAGE("fresh seeds: E " << fresh.E / 1e9 << " GPa (UCS curve " << fresh.E_test / 1e9 << "), nu " << fresh.nu
                              << ", UCS " << fresh.ucs / 1e6 << " MPa, tensile " << fresh.tensile / 1e6 << " MPa");
    CHECK(fresh.E == doctest::Approx(t.E).epsilon(0.05));
    CHECK(fresh.nu == doctest::Approx(t.nu).epsilon(0.10));
}
