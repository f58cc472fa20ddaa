// Numerical lab tests (core/labtest.hpp) on the paper's 8 m × 16 m specimen of
// Voronoi blocks with its joint properties (SPEC §8). (A smaller specimen is
// several per cent softer: its free sides are a boundary layer of clipped cells of
// relative width ~ d/W.)
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
