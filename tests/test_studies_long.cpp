// Long suite: the study tests of a minute or more each on 2 cores (moved from
// test_calibrate.cpp and test_labtest.cpp to keep the default suite under 8
// minutes): calibration to a steep envelope and to a granite-like sigma_ci/UCS,
// the broken joints' friction calibrated on broken rock's, and the biaxial test
// of the paper's joints at 5 MPa.
#include "base/error.hpp"
#include "studies/calibration/calibrate.hpp"
#include "apps/flags.hpp"
#include "studies/lab/labtest.hpp"
#include "studies/lab/residual_friction.hpp"
#include "tests/validation_record.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

using namespace bbm;
using namespace bbm::studies;

TEST_CASE("calibrate to a steep envelope (Hoek-Brown mi 25): the joints' friction angle rises") {
    // A 3 m x 6 m specimen, one realization, two iterations: the paper's joints give
    // a macro friction angle of about 33 degrees (mi about 8); mi 25 asks for about
    // 49. The first correction must raise phi from 25 degrees, and the second
    // iteration's envelope must be steeper than the first's.
    const std::string json = cli::run_calibrate_args({"--width", "3", "--height", "6", "--realizations", "1",
                                                 "--iterations", "2", "--threads", "2", "--target-ucs", "22e6",
                                                 "--target-tensile", "2e6", "--target-mi", "25"},
                                                true);
    const auto c = nlohmann::json::parse(json);
    const auto& its = c["iterations"];
    REQUIRE(its.size() == 2);
    REQUIRE(c["targets"]["envelope"].size() == 2);
    const double phi1 = its[0]["friction"], phi2 = its[1]["friction"];
    auto slope = [](const nlohmann::json& it, const nlohmann::json& targets) {
        double num = 0, den = 0;
        for (std::size_t k = 0; k < 2; ++k) {
            const double s3 = targets["envelope"][k][0], s1 = it["confined_strength"][k];
            num += s3 * (s1 - it["ucs"].get<double>()), den += s3 * s3;
        }
        return num / den;
    };
    const double k1 = slope(its[0], c["targets"]), k2 = slope(its[1], c["targets"]);
    MESSAGE("phi " << phi1 << " -> " << phi2 << " degrees, envelope slope " << k1 << " -> " << k2);
    CHECK(phi1 == doctest::Approx(25.0));
    CHECK(phi2 > phi1 + 5.0);
    CHECK(k2 > k1);
    // The set written is the best one; its misfit is the largest relative miss.
    const int chosen = c["calibrated_iteration"];
    CHECK(its[chosen - 1]["misfit"].get<double>() <= std::min(its[0]["misfit"].get<double>(), its[1]["misfit"].get<double>()));
    // joint_property.toml holds the set exactly (JSON numbers round-trip): a set
    // rounded to 6 digits is another rock for a brittle specimen
    // (docs/notes/2026-11-28-calibration-history.md, "Lac du Bonnet granite").
    const std::string toml = c["joint_property_toml"];
    for (const char* key : {"kn", "ks", "tensile", "cohesion", "friction"}) {
        const auto at = toml.find(std::string("\n") + key + " = ");
        REQUIRE(at != std::string::npos);
        CAPTURE(key);
        CHECK(std::strtod(toml.c_str() + at + std::strlen(key) + 4, nullptr) == its[chosen - 1][key].get<double>());
    }
}

TEST_CASE("calibrate --fit-ci: the paper's rock to a granite-like sigma_ci/UCS of 0.30 by heterogeneous bonds") {
    // Uniform bonds give the paper's rock sigma_ci/UCS of about 0.40 on this 3 m x
    // 6 m specimen (0.42 at 8 x 16 m). The calibration must add heterogeneity (a
    // finite Weibull modulus), converge with sigma_ci/UCS within 0.05 of 0.30, and
    // hold that on seeds it has not seen. Measured 2026-11-26: converged at
    // iteration 6, m 1.73, sigma_ci/UCS 0.33; fresh seeds 0.34 (their UCS +13%:
    // strongly heterogeneous small specimens scatter, std 2 MPa).
    const std::string json = cli::run_calibrate_args({"--width", "3", "--height", "6", "--realizations", "2", "--iterations",
                                                 "8", "--threads", "2", "--target-ucs", "22e6", "--target-tensile",
                                                 "1.9e6", "--target-ci-ratio", "0.30", "--fit-ci"},
                                                true);
    const auto c = nlohmann::json::parse(json);
    const auto& its = c["iterations"];
    const auto& best = its[c["calibrated_iteration"].get<int>() - 1];
    MESSAGE("iterations " << its.size() << ", m " << best["weibull_modulus"].get<double>() << ", sigma_ci/UCS "
                          << best["ci_ratio"].get<double>() << ", fresh seeds " << c["fresh_seeds"]["ci_ratio"].get<double>());
    CHECK(its[0]["ci_ratio"].get<double>() > 0.0);
    CHECK(c["converged"].get<bool>());
    CHECK(best["weibull_modulus"].get<double>() > 0.0);
    CHECK(best["weibull_modulus"].get<double>() < 5.0);
    CHECK(std::abs(best["ci_ratio"].get<double>() - 0.30) <= 0.05);
    CHECK(std::abs(c["fresh_seeds"]["ci_ratio"].get<double>() - 0.30) <= 0.05);
    CHECK(c["joint_property_toml"].get<std::string>().find("weibull_modulus = ") != std::string::npos);
}

TEST_CASE("biaxial at 5 MPa with the paper's joints: confinement applied without cracking and broken blocks that interlock unless they slide at a lower friction (4 x 8 m)") {
    auto o = LabTestOptions::paper_ucs();
    o.width = 4.0, o.height = 8.0;
    const auto ucs = run_labtest(o);
    o.kind = LabTestOptions::Kind::biaxial;
    o.confinement = 5e6;
    // Macro friction from sigma1 = UCS + k sigma3, k = tan^2(45 + phi/2), for a Coulomb material.
    auto macro_friction = [&](double sigma1) {
        const double k = (sigma1 - ucs.peak_stress) / o.confinement;
        return 2.0 * std::atan(std::sqrt(k)) * 180.0 / std::numbers::pi - 90.0;
    };
    // The paper's joints: broken joints keep their 25 degrees.
    const auto locked = run_labtest(o);
    // Broken joints slide at 10 degrees.
    o.rock.bonds.residual_friction = 10.0;
    const auto sliding = run_labtest(o);
    INFO("UCS " << ucs.peak_stress / 1e6 << " MPa at strain " << ucs.strain_at_peak << "; residual 25 deg: first stall "
                << locked.first_stall_stress / 1e6 << " MPa (macro friction " << macro_friction(locked.first_stall_stress)
                << "), peak " << locked.peak_stress / 1e6 << " MPa at strain " << locked.strain_at_peak
                << " (macro friction " << macro_friction(locked.peak_stress) << "); residual 10 deg: peak "
                << sliding.peak_stress / 1e6 << " MPa at strain " << sliding.strain_at_peak << " (macro friction "
                << macro_friction(sliding.peak_stress) << "); cracks before axial loading "
                << locked.curve.front().cracks_tensile + locked.curve.front().cracks_shear << " of " << locked.contacts);
    // Ramped, the confinement breaks almost nothing (at once it broke joints), and
    // the axial stress starts near the Poisson response, not at a shock.
    CHECK(locked.curve.front().cracks_tensile + locked.curve.front().cracks_shear < locked.contacts / 200);
    CHECK(locked.curve.front().axial_stress < o.confinement);
    // The paper's joints: the specimen yields like a frictional rock (the first
    // stall, at a macro friction between the joints' 25 degrees and 50) and then
    // hardens far past it: rigid fragments interlock, and the laboratory's peak
    // comes late, at several times the unconfined peak's strain and above 3 x UCS
    // (measured 2026-11-27: yield 44 MPa, peak 111 MPa at 1.75% strain).
    CHECK(macro_friction(locked.first_stall_stress) > 25.0);
    CHECK(macro_friction(locked.first_stall_stress) < 50.0);
    CHECK(locked.peak_stress > 3.0 * ucs.peak_stress);
    CHECK(locked.strain_at_peak > 5.0 * ucs.strain_at_peak);
    // Sliding at 10 degrees once broken, the specimen fails at its yield: a
    // frictional envelope (macro friction between 25 and 50 degrees), a peak soon
    // after the unconfined one's strain, and a drop past it.
    CHECK(sliding.peak_passed);
    CHECK(!sliding.still_loading);
    CHECK(macro_friction(sliding.peak_stress) > 25.0);
    CHECK(macro_friction(sliding.peak_stress) < 50.0);
    CHECK(sliding.strain_at_peak < 3.0 * ucs.strain_at_peak);
}

TEST_CASE("calibrate --target-residual-friction: Lac du Bonnet's broken joints from 5 degrees to the friction of broken rock (Byerlee 40.4 degrees)") {
    // Issue 48, item 2: the broken joints' friction fixed by the laboratory before
    // the field. The in-situ set's bonds (docs/calibration.md, "The residual
    // strength": at 5 degrees its rubble slid at 32.7, at 10 at 41.1, at 15 at
    // 45.6 degrees), biaxial at sigma3 = 10 MPa to 2% strain, 3 seeds an
    // iteration as `bbm calibrate` runs it. Targets: within 1 degree of 40.4 in at
    // most 5 iterations, and the set's rubble on 3 fresh seeds within 2 degrees.
    // With 2 seeds (2026-11-29) the fit converged at 10.60 degrees (39.9) and the
    // fresh seeds 2001-2002 slid at 43.5 (std 2.7): one seed's rubble scatters by
    // 2-2.7 degrees, too much for 2 degrees on a mean of two. The command's own
    // run on 3 seeds: 9.45 degrees, fresh seeds 39.9 (std 2.0; docs/calibration.md).
    // This test on 3 seeds (2026-11-29): 9.62 degrees after 2 iterations, fresh
    // seeds 2001-2003 41.3 (std 2.0).
    CalibrationOptions o;
    o.base.rock.pattern.size = 0.12, o.base.width = 2.4, o.base.height = 4.8;
    o.base.rock.material.density = 2650;
    o.base.rock.pattern.seed = 1001;
    auto& j = o.base.rock.bonds;
    j.kn = 954.511e9, j.ks = 257.441e9, j.tensile = 15.1313e6, j.cohesion = 41.843e6;
    j.friction = 5, j.residual_friction = 5;
    o.realizations = 3, o.threads = 2;
    const ResidualFrictionTarget target{40.4, 10e6};
    const auto steps = calibrate_residual_friction(j, target, o, [](const ResidualFrictionStep& s) {
        MESSAGE("broken joints " << s.residual_friction << " deg: rubble " << s.rubble_friction << " deg (std "
                                 << s.rubble_std << "), residual " << s.residual_stress / 1e6 << " MPa, " << s.seconds
                                 << " s");
    });
    const auto& best = best_residual_step(steps, target.friction);
    CHECK(best.converged);
    CHECK(steps.size() <= 5);
    CHECK(best.residual_friction > 5.0);
    CHECK(best.residual_friction < 15.0);
    auto calibrated = j;
    calibrated.residual_friction = best.residual_friction;
    const auto fresh = measure_rubble_friction(calibrated, target, o, 2001);
    MESSAGE("fresh seeds 2001-2003: rubble " << fresh.rubble_friction << " deg (std " << fresh.rubble_std << ")");
    CHECK(fresh.unmeasured == 0);
    CHECK(std::abs(fresh.rubble_friction - 40.4) <= 2.0);
    test::record_check(test::Against::laboratory, "broken joints' friction calibrated on the rubble's, sigma3 10 MPa",
                       "40.4°, broken crystalline rock's tau = 0.85 sigma_n (Byerlee 1978); issue 48",
                       "within 1° in <= 5 iterations; fresh seeds within 2°",
                       test::figure(best.residual_friction) + "° after " + std::to_string(steps.size()) +
                           " iterations; the rubble " + test::figure(best.rubble_friction) + "°, on fresh seeds " +
                           test::figure(fresh.rubble_friction) + "° (std " + test::figure(fresh.rubble_std) + ")",
                       best.converged && steps.size() <= 5 && std::abs(fresh.rubble_friction - 40.4) <= 2.0);
}
