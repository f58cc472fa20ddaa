// Numerical lab tests (studies/lab/labtest.hpp) on the paper's 8 m × 16 m specimen of
// Voronoi blocks with its joint properties (SPEC §8). The runs of minutes (trigon,
// calibration) are in test_long.cpp.
#include "core/solver.hpp"
#include "studies/calibration/calibrate.hpp"
#include "studies/lab/labtest.hpp"
#include "tests/specimens.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"
#include "tests/validation_record.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

using namespace bbm;

TEST_CASE("direct tension, paper specimen: mean strength of 3 realizations within 0.5 to 1.1 sigma_t" * validation) {
    // Tension peaks at a strain of ~1e-4, so it is loaded ten times slower than
    // compression to stay quasi-static (halving this rate changes it by < 1%; at
    // the compression rate the peak overshoots by ~15%).
    double mean = 0.0;
    std::string seeds; // the record's per-seed strengths
    for (std::uint64_t seed : {1, 2, 3}) {
        auto o = LabTestOptions::paper_ucs();
        o.kind = LabTestOptions::Kind::tension;
        o.strain_per_step = 5e-9;
        o.rock.pattern.seed = seed;
        const auto r = run_labtest(o);
        INFO("seed " << seed << ": tensile strength " << r.peak_stress / 1e6 << " MPa");
        CHECK(r.peak_passed);
        CHECK(r.cracks_tensile > r.cracks_shear);
        mean += r.peak_stress / 3;
        seeds += (seeds.empty() ? "" : ", ") + test::figure(r.peak_stress / 1e6);
    }
    INFO("mean tensile strength " << mean / 1e6 << " MPa");
    CHECK(mean > 0.5 * 3e6);
    CHECK(mean < 1.1 * 3e6);
    test::record_check(test::Against::paper, "direct tensile strength, mean of seeds 1-3",
                       "the paper's bond sigma_t = 3 MPa (SPEC §8)", "in (0.5, 1.1) sigma_t",
                       test::figure(mean / 1e6) + " MPa = " + test::figure(mean / 3e6) + " sigma_t (seeds 1-3: " +
                           seeds + ")",
                       mean > 0.5 * 3e6 && mean < 1.1 * 3e6);
}

TEST_CASE("uniaxial compression, paper specimen, 3 realizations: the paper's modulus and strength, the lattice modulus, little scatter, axial splitting" * validation) {
    // Rigid blocks on elastic joints: the hexagonal-lattice closed form
    // E = 2 a kn (kn + ks)/(3 kn + ks), a = d √(π/(2√3)) with d the diameter of the
    // mean block area (examples/verification/hexagonal_lattice.toml); a random
    // Voronoi assembly is close to it.
    const auto base = LabTestOptions::paper_ucs();
    const double kn = base.rock.bonds.kn, ks = base.rock.bonds.ks;
    double E = 0, peak = 0, peak2 = 0;
    std::string seeds_E, seeds_peak, seeds_lattice; // the records' per-seed figures
    bool lattice_held = true;
    for (std::uint64_t seed : {1, 2, 3}) {
        auto o = base;
        o.rock.pattern.seed = seed;
        const auto r = run_labtest(o);
        const double d = std::sqrt(4.0 * o.width * o.height / (std::numbers::pi * r.blocks));
        const double a = d * std::sqrt(std::numbers::pi / (2 * std::sqrt(3.0)));
        const double lattice = 2 * a * kn * (kn + ks) / (3 * kn + ks);
        INFO("seed " << seed << ": E " << r.E / 1e9 << " GPa (lattice " << lattice / 1e9 << "), nu " << r.nu << ", peak "
                     << r.peak_stress / 1e6 << " MPa, cracks vertical " << r.cracks_near_vertical << " horizontal "
                     << r.cracks_near_horizontal << " (at the peak " << r.cracks_near_vertical_at_peak << " / "
                     << r.cracks_near_horizontal_at_peak << ")");
        CHECK(r.peak_passed);
        CHECK_FALSE(r.post_peak_locking);
        CHECK(r.E == doctest::Approx(lattice).epsilon(0.05));
        lattice_held = lattice_held && (r.E == doctest::Approx(lattice).epsilon(0.05));
        seeds_lattice += (seeds_lattice.empty() ? "" : ", ") + test::percent(r.E, lattice);
        CHECK(r.nu > 0.1);
        CHECK(r.nu < 0.3);
        // Voronoi failure dominated by axial splitting (issue 5: at least 2 to 1 by the
        // peak; the rubble of the post-peak adds cracks of every direction).
        CHECK(r.cracks_near_vertical_at_peak >= 2 * r.cracks_near_horizontal_at_peak);
        CHECK(r.cracks_near_vertical >= r.cracks_near_horizontal * 3 / 2);
        CHECK(r.cracks_tensile > r.cracks_shear);
        E += r.E / 3, peak += r.peak_stress / 3, peak2 += r.peak_stress * r.peak_stress / 3;
        seeds_E += (seeds_E.empty() ? "" : ", ") + test::figure(r.E / 1e9);
        seeds_peak += (seeds_peak.empty() ? "" : ", ") + test::figure(r.peak_stress / 1e6);
    }
    test::record_check(test::Against::closed_form, "E of each seed against the hexagonal lattice's",
                       "E = 2a kn(kn+ks)/(3kn+ks), a from the mean block area (hexagonal lattice)",
                       "each seed within 5%", seeds_lattice + " (seeds 1-3)", lattice_held);
    // The whole loaded face moves with the platens, so the strength is a property
    // of the material, not of where the platen rows happen to end: the
    // realizations agree to a few per cent (measured 3%).
    const double cv = std::sqrt(std::max(0.0, peak2 - peak * peak) * 3.0 / 2.0) / peak;
    MESSAGE("paper specimen, mean of 3: E " << E / 1e9 << " GPa (paper 20.0), UCS " << peak / 1e6
                                            << " MPa (paper 20.7), coefficient of variation of the peak " << cv);
    CHECK(cv < 0.06);
    // Issue 5: the paper's calibration (SPEC §8) reproduced, blocks of 0.3 m average
    // dimension (mean Feret diameter), the cells of random points.
    CHECK(E == doctest::Approx(20.0e9).epsilon(0.10));
    test::record_check(test::Against::paper, "E, mean of seeds 1-3", "E 20.0 GPa (the paper, SPEC §8)", "within 10%",
                       test::figure(E / 1e9) + " GPa (" + test::percent(E, 20.0e9) + "; seeds 1-3: " + seeds_E + ")",
                       E == doctest::Approx(20.0e9).epsilon(0.10));
    CHECK(peak == doctest::Approx(20.7e6).epsilon(0.15));
    test::record_check(test::Against::paper, "UCS, mean of seeds 1-3", "UCS 20.7 MPa (the paper, SPEC §8)",
                       "within 15%",
                       test::figure(peak / 1e6) + " MPa (" + test::percent(peak, 20.7e6) + "; seeds 1-3: " +
                           seeds_peak + ")",
                       peak == doctest::Approx(20.7e6).epsilon(0.15));
}

TEST_CASE("hexagonal lattice UCS with default options: E and nu of the linear part within 3% of the closed form" * validation) {
    // Issue 12: fitted between 10% and 50% of a peak reached after 2,000 cracks the
    // summary once read nu 0.807; from the whole height's side bands, held in by
    // the rough platens, 0.144. The linear part (preload) and mid-height lateral
    // gauges give the lattice's own values: E = 2a kn (kn + ks)/(3kn + ks),
    // nu = (kn - ks)/(3kn + ks), a the spacing (examples/verification/hexagonal_lattice.toml).
    auto o = LabTestOptions::paper_ucs();
    o.rock.pattern.kind = meshing::PatternSpec::Kind::hexagonal;
    o.threads = 2;
    o.frame_every = 1500;
    // Statics after the axial joints split (docs/calibration.md, "The hexagonal
    // lattice"): mean normal stress on the axial joints (normal horizontal) and on
    // the inclined ones (normal 30° from the load) over the applied stress.
    struct Frame { double strain, stress, axial, inclined; };
    std::vector<Frame> frames;
    const auto on_frame = [&](const Solver& s, const StressStrainPoint& p) {
        const auto& c = contacts(s.world());
        double axial = 0, inclined = 0;
        int na = 0, ni = 0;
        for (int i = 0; i < c.size(); ++i) {
            const double from_load = std::atan2(std::abs(c.normal[i].x), std::abs(c.normal[i].y)) * 180 / std::numbers::pi;
            if (from_load > 85) axial += c.history[i].sn, ++na;
            else if (std::abs(from_load - 30) < 5) inclined += c.history[i].sn, ++ni;
        }
        if (na > 0 && ni > 0 && p.axial_stress > 0) frames.push_back({p.axial_strain, p.axial_stress, axial / na / p.axial_stress, inclined / ni / p.axial_stress});
    };
    const auto r = run_labtest(o, {}, {}, on_frame);
    const double kn = o.rock.bonds.kn, ks = o.rock.bonds.ks, a = o.rock.pattern.size;
    const double E = 2 * a * kn * (kn + ks) / (3 * kn + ks), nu = (kn - ks) / (3 * kn + ks);
    INFO("E " << r.E / 1e9 << " GPa (closed form " << E / 1e9 << "), nu " << r.nu << " (" << nu << "), E50 "
              << r.E50 / 1e9 << ", peak " << r.peak_stress / 1e6 << " MPa");
    CHECK(r.E == doctest::Approx(E).epsilon(0.03));
    test::record_check(test::Against::closed_form, "E of the linear part",
                       "E = 2a kn(kn+ks)/(3kn+ks) = " + test::figure(E / 1e9) + " GPa (hexagonal lattice)", "within 3%",
                       test::figure(r.E / 1e9) + " GPa (" + test::percent(r.E, E) + ")",
                       r.E == doctest::Approx(E).epsilon(0.03));
    CHECK(r.nu == doctest::Approx(nu).epsilon(0.03));
    test::record_check(test::Against::closed_form, "nu of the linear part",
                       "nu = (kn-ks)/(3kn+ks) = " + test::figure(nu) + " (hexagonal lattice)", "within 3%",
                       test::figure(r.nu) + " (" + test::percent(r.nu, nu) + ")",
                       r.nu == doctest::Approx(nu).epsilon(0.03));
    // The linear part ends before the first crack, and cracking starts before the peak.
    CHECK(r.linear_limit_stress > 0);
    CHECK(r.linear_limit_stress <= r.crack_initiation_stress);
    CHECK(r.crack_initiation_stress < r.peak_stress);
    // Before cracking the inclined faces wedge the axial joints into tension; once
    // those have split, each hexagon stands on two ±30° faces: σ1·√3a = 2a(σn cos30°
    // + τ sin30°) with τ = σn tan30° gives σn = 0.75 σ1 there, and the lattice carries
    // load far past σci. Then it fails (a shear band from the platen corners) and
    // softens instead of locking.
    int before = 0, after = 0;
    bool inclined_held = true; // the record's summary of the frames after splitting
    double inclined_low = 1e300, inclined_high = -1e300;
    for (const auto& f : frames) {
        if (f.strain >= r.strain_at_peak) continue; // after the peak the band unloads it
        INFO("sigma1 " << f.stress / 1e6 << " MPa: axial joints " << f.axial << " sigma1, inclined " << f.inclined);
        if (f.stress < r.crack_initiation_stress) {
            ++before;
            CHECK(f.axial < -0.1);
        } else if (f.stress > 2.0 * r.crack_initiation_stress) {
            ++after;
            CHECK(std::abs(f.axial) < 0.02);
            CHECK(f.inclined == doctest::Approx(0.75).epsilon(0.04));
            inclined_held = inclined_held && (f.inclined == doctest::Approx(0.75).epsilon(0.04));
            inclined_low = std::min(inclined_low, f.inclined), inclined_high = std::max(inclined_high, f.inclined);
        }
    }
    CHECK(before >= 1);
    CHECK(after >= 3);
    test::record_check(test::Against::closed_form, "normal stress on the ±30° joints once the axial joints split",
                       "sigma_n = 0.75 sigma1 (statics of a hexagon on two faces; docs/calibration.md)",
                       "each frame within 4%, at least 3 frames",
                       (after > 0 ? test::figure(inclined_low) + " to " + test::figure(inclined_high)
                                  : std::string("-")) +
                           " sigma1 over " + std::to_string(after) + " frames",
                       inclined_held && after >= 3);
    CHECK(r.peak_stress > 2.5 * r.crack_initiation_stress);
    CHECK_FALSE(r.post_peak_locking);
}

namespace {

/// A UCS run, and the stress at its end as a fraction of the peak.
struct PostPeak {
    LabTestResult r;
    double end_fraction = 0, end_strain = 0;
};
PostPeak post_peak_run(LabTestOptions o) {
    o.threads = 2;
    o.stop.fraction = 0.5; // the checks follow the softening to half the peak
    PostPeak p{run_labtest(o)};
    REQUIRE(!p.r.curve.empty());
    p.end_fraction = p.r.curve.back().axial_stress / p.r.peak_stress;
    p.end_strain = p.r.curve.back().axial_strain;
    return p;
}

#define POST_PEAK_INFO(p)                                                                                          \
    INFO("peak " << p.r.peak_stress / 1e6 << " MPa at strain " << p.r.strain_at_peak << ", end at "               \
                 << p.end_fraction << " of it, strain " << p.end_strain << ", locking " << p.r.post_peak_locking \
                 << ", cracks " << p.r.cracks_tensile << " T " << p.r.cracks_shear << " S")

/// Below half the peak by `max_strain`, without locking.
void check_softens(const PostPeak& p, double max_strain) {
    POST_PEAK_INFO(p);
    CHECK_FALSE(p.r.post_peak_locking);
    CHECK(p.end_fraction <= 0.5);
    CHECK(p.end_strain < max_strain);
}

} // namespace

TEST_CASE("post-peak, mechanism 1: local crack bursts of a small rigid specimen are not failure (2 x 4 m, seed 1)" * validation) {
    // Before (issue 12): a stall after a burst of cracks was taken for failure,
    // the intact skeleton (97% of the contact compression in intact bonds) loaded
    // on above 30.10 MPa and the run stopped as "locking" at strain 1.83e-3. Now
    // the load carriers are asked: bonds still carry it, loading goes on, and the
    // specimen fails for real. Checked: without asking, it still locks.
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.rock.pattern.seed = 1;
    const auto p = post_peak_run(o);
    CHECK(p.r.peak_passed);
    CHECK_FALSE(p.r.still_loading);
    check_softens(p, 0.01);
}

TEST_CASE("a test not failed at its strain limit loads on to its strength and at the hard cap says its peak is a lower bound" * validation) {
    // The same specimen with max_strain at half its peak's strain. With the cap at
    // max_strain the stress is still rising there, so the "peak" is the stress at
    // the limit, and the result says so (a strong rock's confined test at the
    // default 1% did this silently). With the default cap it loads on, fails, and
    // its peak is the one of a run limited at 1%: the same steps up to the peak.
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.rock.pattern.seed = 1;
    o.threads = 2;
    o.stop.max_strain = 5e-4;
    o.stop.strain_cap = 0.0;
    const auto capped = run_labtest(o);
    REQUIRE(!capped.curve.empty());
    CHECK(capped.still_loading);
    CHECK_FALSE(capped.loaded_past_max_strain);
    CHECK_FALSE(capped.peak_passed);
    CHECK(capped.curve.back().axial_strain >= 5e-4);
    CHECK(capped.peak_stress == doctest::Approx(capped.curve.back().axial_stress).epsilon(0.02));
    CHECK(capped.peak_stress < 0.8 * 22e6); // below the specimen's strength, about 22 MPa

    o.stop.strain_cap = LabTestOptions{}.stop.strain_cap;
    const auto on = run_labtest(o);
    o.stop.max_strain = LabTestOptions{}.stop.max_strain;
    const auto full = run_labtest(o);
    CHECK_FALSE(full.loaded_past_max_strain);
    CHECK(on.loaded_past_max_strain);
    CHECK_FALSE(on.still_loading);
    CHECK(on.strain_at_peak > 5e-4);
    CHECK(on.peak_stress == full.peak_stress);
    CHECK(on.strain_at_peak == full.strain_at_peak);
    // Its first burst of cracks (30.1 MPa) is not taken for failure: the bonds
    // still carry the load (mechanism 1), as in the run limited at 1%.
    CHECK(on.peak_stress > 30.5e6);
    // Stopped past the peak by the drop rule, within max_strain of it.
    CHECK(on.curve.back().axial_strain <= on.strain_at_peak + 5e-4);
    CHECK(on.steps == full.steps);
}

TEST_CASE("deformable specimens meshed in parallel threads: no heap corruption, the serial meshes") {
    // gmsh's thread count is an OpenMP setting of the calling thread: set once, a
    // second thread meshed with a team of all cores inside gmsh and corrupted the
    // heap (`bbm ucs --deformable-fraction 0.95 --realizations 2 --threads 2`
    // aborted with "free(): unaligned chunk detected in tcache"; meshing/fe_mesh.cpp).
    // The meshes must be the serial ones. (The runs agree here too; a larger
    // specimen side by side rarely did not, so `bbm ucs` now runs deformable
    // realizations one at a time: docs/calibration.md.)
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0;
    o.rock.material.deformable_fraction = 0.95;
    o.stop.max_strain = 2e-4;
    o.stop.strain_cap = 0.0; // the preload and a few steps are what this compares
    o.threads = 1;
    std::vector<LabTestResult> serial, parallel(3);
    for (int k = 0; k < 3; ++k) {
        o.rock.pattern.seed = std::uint64_t(k + 1);
        serial.push_back(run_labtest(o));
    }
    std::vector<std::thread> pool;
    for (int k = 0; k < 3; ++k)
        pool.emplace_back([&parallel, o, k]() mutable {
            o.rock.pattern.seed = std::uint64_t(k + 1);
            parallel[k] = run_labtest(o);
        });
    for (auto& t : pool) t.join();
    for (int k = 0; k < 3; ++k) {
        CHECK(parallel[k].blocks == serial[k].blocks);
        CHECK(parallel[k].contacts == serial[k].contacts);
        CHECK(parallel[k].E == serial[k].E); // the preload: one implicit solve on the mesh
    }
}

TEST_CASE("smooth platens hold the bottom face's middle blocks horizontally") {
    // The anchor once selected no block (a face block is selected by an edge wholly
    // inside its box, and the box was one block size wide): the specimen was free
    // to slide sideways as a whole, and on the paper's specimen CHOLMOD reported
    // the preload's matrix "not positive definite" (an LU solve took over). Checked:
    // with the one-size window this holds 0 blocks for both patterns.
    for (auto o : {LabTestOptions::paper_ucs(), test::paper_trigon_ucs()}) {
        o.width = 2.0, o.height = 4.0;
        o.rough_platens = false;
        const Solver s(meshing::generate_blocks(labtest_geometry(o)), labtest_analysis(o));
        int held_x = 0, held_y = 0;
        for (auto f : s.world().loads.block_fixed) held_x += (f & 1) ? 1 : 0, held_y += (f & 2) ? 1 : 0;
        CHECK(held_x >= 1);
        CHECK(held_x <= 4);      // a few middle blocks, not the face
        CHECK(held_y > held_x);  // both faces are held vertically
    }
}

TEST_CASE("a single plane of weakness slides where Jaeger's closed form says (biaxial, 4 x 8 m, sigma3 5 MPa)" * validation) {
    // σ1 = σ3 + 2 σ3 tan φj / ((1 − tan φj cot β) sin 2β), φj 30°, cj 0: 18.66 MPa at
    // β 45°, 15.00 MPa at 60° (the least). Measured: 18.60, 14.92 MPa.
    for (double beta : {45.0, 60.0}) {
        LabTestOptions o = LabTestOptions::paper_ucs();
        o.kind = LabTestOptions::Kind::biaxial;
        o.width = 4.0, o.height = 8.0;
        o.confinement = 5e6;
        o.rough_platens = false;
        o.joint_set.on = true;
        o.joint_set.angle = beta;
        o.joint_set.joint.kn = o.rock.bonds.kn, o.joint_set.joint.ks = o.rock.bonds.ks;
        o.joint_set.joint.friction = 30.0;
        o.stop.max_strain = 2e-3; // the slip is read before; the pieces then jam
        o.stop.strain_cap = 0.0;
        o.threads = 2;
        const auto r = run_labtest(o);
        const double b = beta * std::numbers::pi / 180.0, mu = std::tan(std::numbers::pi / 6.0);
        const double jaeger = 5e6 + 2.0 * mu * 5e6 / ((1.0 - mu / std::tan(b)) * std::sin(2.0 * b));
        CAPTURE(beta);
        CHECK(r.joint_slip_stress == doctest::Approx(jaeger).epsilon(0.02));
        test::record_check(test::Against::closed_form,
                           "sigma1 at slip (90% of the joint), beta " + test::figure(beta) + "°",
                           "Jaeger (1960), phi_j 30°, c_j 0, sigma3 5 MPa: " + test::figure(jaeger / 1e6) + " MPa",
                           "within 2%",
                           test::figure(r.joint_slip_stress / 1e6) + " MPa (" +
                               test::percent(r.joint_slip_stress, jaeger) + ")",
                           r.joint_slip_stress == doctest::Approx(jaeger).epsilon(0.02));
        CHECK(r.joint_slip_stress_half > 0.8 * jaeger);
    }
}

TEST_CASE("a biaxial test whose confinement leaves a block the implicit preload cannot solve is loaded explicitly" * validation) {
    // Trigon blocks with Lac du Bonnet-like bonds at 71 MPa of confinement (what
    // `bbm calibrate --pattern trigon` on examples/lab/lac_du_bonnet.toml reached at
    // its second iteration): the ramp cracks a few joints, and in seed 2 a triangle
    // is left held at one point, so the elastic preload's matrix is singular. Once
    // that stopped the whole calibration; now the test loads explicitly from the
    // start, and seed 1, which the preload solves, is unchanged in kind.
    auto o = LabTestOptions::paper_ucs();
    o.kind = LabTestOptions::Kind::biaxial;
    o.rock.pattern.kind = meshing::PatternSpec::Kind::trigon;
    o.rock.pattern.size = 0.12, o.width = 2.4, o.height = 4.8;
    o.rock.bonds.kn = 2000.3e9, o.rock.bonds.ks = 683.5e9;
    o.rock.bonds.tensile = 17.9e6, o.rock.bonds.cohesion = 123.9e6, o.rock.bonds.friction = 35.0;
    o.confinement = 71e6;
    o.stop.max_steps = 3000;
    o.threads = 1;
    for (std::uint64_t seed : {1, 2}) {
        o.rock.pattern.seed = seed;
        const auto r = run_labtest(o);
        const double first = r.curve.front().axial_stress, last = r.curve.back().axial_stress;
        MESSAGE("seed " << seed << ": preload " << std::string(r.preload_skipped ? "skipped" : "solved") << ", "
                        << r.curve.size() << " curve points, axial stress " << first / 1e6 << " -> " << last / 1e6
                        << " MPa in " << r.steps << " steps");
        CHECK(r.preload_skipped == (seed == 2));
        // Loading on, from the start: 3,000 steps of 5e-8 strain on a 95 GPa rock.
        CHECK(last > first + 5e6);
    }
}

TEST_CASE("the residual strength: the mean stress over the curve's last 0.2% of strain and the friction it mobilises without cohesion") {
    // A synthetic post-peak curve: peak 100 MPa at 0.3%, a fall to 70 MPa by 1%,
    // then 70 ± 1 MPa to 1.6%. With σ3 = 10 MPa, σ1/σ3 = 7 = (1 + sin φ)/(1 − sin φ):
    // sin φ = 60/80, φ = 48.59°.
    LabTestResult r;
    r.peak_stress = 100e6, r.strain_at_peak = 3e-3;
    for (int k = 0; k <= 160; ++k) {
        const double strain = 1e-4 * k;
        double stress = strain <= 3e-3 ? 100e6 * strain / 3e-3
                        : strain <= 1e-2 ? 100e6 - 30e6 * (strain - 3e-3) / 7e-3
                                          : 70e6 + (k % 2 ? 1e6 : -1e6);
        r.curve.push_back({k * 100L, strain, stress, 0.0, 0, 0, 0.0, 0.0, 0});
    }
    measure_residual_strength(r, 10e6);
    // The window, 1.4–1.6% of strain: 21 points, 11 at 69 MPa and 10 at 71 MPa.
    CHECK(r.residual_stress == doctest::Approx((11 * 69e6 + 10 * 71e6) / 21).epsilon(1e-12));
    const double s1 = r.residual_stress;
    CHECK(r.residual_friction_angle == doctest::Approx(std::asin((s1 - 10e6) / (s1 + 10e6)) * 180 / std::numbers::pi));
    CHECK(r.residual_friction_angle == doctest::Approx(48.59).epsilon(2e-3));
    // Unconfined: the stress, no angle.
    LabTestResult u = r;
    u.residual_stress = u.residual_friction_angle = 0.0;
    measure_residual_strength(u, 0.0);
    CHECK(u.residual_stress == r.residual_stress);
    CHECK(u.residual_friction_angle == 0.0);
    // A curve that ends 0.4% past its peak has no residual yet.
    LabTestResult early = r;
    early.residual_stress = early.residual_friction_angle = 0.0;
    early.curve.resize(71); // to 0.7%
    measure_residual_strength(early, 10e6);
    CHECK(early.residual_stress == 0.0);
    CHECK(early.residual_friction_angle == 0.0);
}

TEST_CASE("the envelope's confined test: its tail past the failure runs at the servo's fastest speed, the peak the same to the last digit" * validation) {
    // studies/lab/labtest.hpp, as_envelope_confined_test: bbm envelope and calibrate
    // stop a biaxial test 2e-4 of strain past its failure, and run that tail at
    // --servo-max instead of the post-failure half speed. Nothing before the
    // failure may change: the same steps up to it, so the same peak, first stall,
    // sigma_ci, E and nu, bit for bit; the tail takes fewer steps.
    auto o = LabTestOptions::paper_ucs();
    o.kind = LabTestOptions::Kind::biaxial;
    o.width = 2.0, o.height = 4.0, o.rock.pattern.seed = 1, o.confinement = 2e6, o.frame_every = 0;
    o.stop.post_peak_strain = envelope_post_peak_strain;
    auto envelope = o;
    as_envelope_confined_test(envelope);
    CHECK(envelope.servo.post_peak_factor == o.servo.max_factor);
    CHECK(envelope.stop.post_peak_strain == envelope_post_peak_strain);
    // A faster post-failure speed given is kept, and a window given is kept.
    auto given = o;
    given.servo.post_peak_factor = 3.0, given.stop.post_peak_strain = 1e-3;
    as_envelope_confined_test(given);
    CHECK(given.servo.post_peak_factor == 3.0);
    CHECK(given.stop.post_peak_strain == 1e-3);

    LabTestResult slow, fast;
    std::thread other([&] { slow = run_labtest(o); });
    fast = run_labtest(envelope);
    other.join();
    MESSAGE("peak " << slow.peak_stress / 1e6 << " MPa at strain " << slow.strain_at_peak << "; steps " << slow.steps
                    << " (half speed after failure) against " << fast.steps);
    REQUIRE(slow.peak_passed);
    CHECK(fast.peak_stress == slow.peak_stress);
    CHECK(fast.strain_at_peak == slow.strain_at_peak);
    CHECK(fast.first_stall_stress == slow.first_stall_stress);
    CHECK(fast.crack_initiation_stress == slow.crack_initiation_stress);
    CHECK(fast.E == slow.E);
    CHECK(fast.nu == slow.nu);
    CHECK(fast.reloads == slow.reloads);
    CHECK(fast.steps < slow.steps);
}
