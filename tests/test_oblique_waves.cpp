// A viscous boundary struck obliquely against Lysmer & Kuhlemeyer's theory
// (tests/oblique_beam.hpp): the closed form's own identities, and the one beam
// a 0.3 m mesh resolves to within its discretisation (an S wave past the critical
// angle); the four of the issue, P and S at 30° and 60° on two meshes, are the
// long suite's (tests/test_dynamics_long.cpp).
#include "oblique_beam.hpp"
#include "tests/validation.hpp"
#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>

using namespace bbm::test::oblique;

TEST_CASE("Lysmer and Kuhlemeyer's reflection off a viscous boundary: the closed form's own identities") {
    // Normal incidence: none; P at 60° and S at 30° are the same two rays (7/2 − 2√3);
    // S at 60°: 3 − 5/√3, its P evanescent.
    CHECK(reflected(Wave::p, 0.0) < 1e-20);
    CHECK(reflected(Wave::s, 0.0) < 1e-20);
    const double deg = std::numbers::pi / 180.0;
    CHECK(reflected(Wave::p, 60 * deg) == doctest::Approx(3.5 - 2.0 * std::sqrt(3.0)).epsilon(1e-9));
    CHECK(reflected(Wave::s, 30 * deg) == doctest::Approx(3.5 - 2.0 * std::sqrt(3.0)).epsilon(1e-9));
    CHECK(lysmer_kuhlemeyer(Wave::s, 60 * deg)[0] == 0.0);
    CHECK(reflected(Wave::s, 60 * deg) == doctest::Approx(3.0 - 5.0 / std::sqrt(3.0)).epsilon(1e-9));
    CHECK(reflected(Wave::p, 30 * deg) == doctest::Approx(3.083e-4).epsilon(1e-3));
    // Grazing: all of it.
    CHECK(reflected(Wave::p, 0.5 * std::numbers::pi - 1e-6) == doctest::Approx(1.0).epsilon(1e-3));
}

TEST_CASE("an S beam striking a viscous boundary at 60 degrees reflects the energy Lysmer and Kuhlemeyer's theory "
          "gives" * validation) {
    const Result r = strike(Wave::s, 60.0, 0.3);
    MESSAGE("reflected ", 100 * r.measured, "% (theory ", 100 * r.expected_plane, "% for a plane wave, ",
            100 * r.expected_beam, "% for the beam), account ", 100 * r.account, "%, ", r.zones, " zones");
    CHECK(std::abs(r.measured / r.expected_beam - 1.0) < 0.05);
    CHECK(r.account < 0.01);
    using bbm::test::figure;
    std::string reference = "Lysmer & Kuhlemeyer over the beam's spectrum: ", measured = figure(100 * r.measured, 3);
    reference += figure(100 * r.expected_beam, 3) + "% (" + figure(100 * r.expected_plane, 3) + "% for a plane wave)";
    measured += "% (";
    measured += bbm::test::percent(r.measured, r.expected_beam);
    measured += ")";
    bbm::test::record_check(bbm::test::Against::closed_form,
                            "energy an S beam reflects off a viscous boundary at 60° (0.3 m mesh)", reference,
                            "within 5%", measured, std::abs(r.measured / r.expected_beam - 1.0) < 0.05);
}
