// The strength envelope (issue 23): the Hoek–Brown and Mohr–Coulomb fits checked
// exactly on synthetic points and as least squares on scattered ones, the record
// reader's errors, and a small envelope end to end; the rock of a model file as a
// specimen (bbm compare --envelope).
#include "apps/flags.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "io/model_input.hpp"
#include "base/error.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <vector>

using namespace bbm;
using namespace bbm::studies;

namespace {

std::vector<double> hoek_brown_points(double sigma_ci, double mi, const std::vector<double>& s3) {
    std::vector<double> s1;
    for (double x : s3) s1.push_back(x + sigma_ci * std::sqrt(mi * x / sigma_ci + 1.0));
    return s1;
}

double hb_cost(const std::vector<double>& s3, const std::vector<double>& s1, double sigma_ci, double mi) {
    double ss = 0.0;
    for (std::size_t i = 0; i < s3.size(); ++i)
        ss += std::pow(s3[i] + sigma_ci * std::sqrt(mi * s3[i] / sigma_ci + 1.0) - s1[i], 2);
    return ss;
}

} // namespace

TEST_CASE("envelope fits: Hoek-Brown recovers sigma_ci and mi exactly from points on the criterion") {
    // Lac du Bonnet-like numbers: sigma_ci 213 MPa, mi 30, sigma3 up to a third of it.
    const std::vector<double> s3{0.0, 5e6, 10e6, 20e6, 40e6, 70e6};
    const auto s1 = hoek_brown_points(213e6, 30.0, s3);
    const auto f = fit_hoek_brown(s3, s1);
    REQUIRE(f.valid);
    CHECK(f.sigma_ci == doctest::Approx(213e6).epsilon(1e-10));
    CHECK(f.mi == doctest::Approx(30.0).epsilon(1e-10));
    CHECK(f.rms < 1e-6 * 213e6);
    // The criterion's tensile strength: sigma_ci (sqrt(mi^2 + 4) - mi) / 2 = 7.09 MPa.
    CHECK(f.tensile_strength() == doctest::Approx(0.5 * 213e6 * (std::sqrt(904.0) - 30.0)).epsilon(1e-12));
    CHECK(f.sigma1(10e6) == doctest::Approx(s1[2]).epsilon(1e-12));
}

TEST_CASE("envelope fits: on scattered points Hoek-Brown is the least squares of sigma1 (no better neighbour)") {
    const std::vector<double> s3{0.0, 0.0, 0.0, 2e6, 2e6, 5e6, 5e6, 10e6, 10e6};
    auto s1 = hoek_brown_points(20e6, 12.0, s3);
    const double noise[] = {1.2e6, -0.8e6, 0.3e6, -1.1e6, 0.9e6, 0.5e6, -0.6e6, 1.4e6, -1.0e6};
    for (std::size_t i = 0; i < s1.size(); ++i) s1[i] += noise[i];
    const auto f = fit_hoek_brown(s3, s1);
    REQUIRE(f.valid);
    const double best = hb_cost(s3, s1, f.sigma_ci, f.mi);
    CHECK(f.rms == doctest::Approx(std::sqrt(best / double(s3.size()))).epsilon(1e-9));
    for (double da : {-1e-3, 1e-3})
        for (double db : {-1e-3, 1e-3}) {
            CHECK(hb_cost(s3, s1, f.sigma_ci * (1 + da), f.mi) >= best);
            CHECK(hb_cost(s3, s1, f.sigma_ci, f.mi * (1 + db)) >= best);
        }
    // Close to the generating criterion, as the noise is small.
    CHECK(f.sigma_ci == doctest::Approx(20e6).epsilon(0.1));
    CHECK(f.mi == doctest::Approx(12.0).epsilon(0.3));
}

TEST_CASE("envelope fits: Hoek-Brown fits an envelope whose linearisation has a negative intercept") {
    // The hexagonal lattice's envelope (bbm envelope --pattern hexagonal, MPa): it
    // interlocks, rising faster than the criterion at low confinement.
    const std::vector<double> s3{0.0, 4.3e6, 8.6e6, 12.9e6, 17.2e6, 21.5e6};
    const std::vector<double> s1{43.05e6, 81.76e6, 121.56e6, 164.13e6, 230.04e6, 236.88e6};
    const auto f = fit_hoek_brown(s3, s1);
    REQUIRE(f.valid);
    const double best = hb_cost(s3, s1, f.sigma_ci, f.mi);
    for (double d : {-1e-3, 1e-3}) {
        CHECK(hb_cost(s3, s1, f.sigma_ci * (1 + d), f.mi) >= best);
        CHECK(hb_cost(s3, s1, f.sigma_ci, f.mi * (1 + d)) >= best);
    }
    MESSAGE("sigma_ci " << f.sigma_ci / 1e6 << " MPa, mi " << f.mi << ", rms " << f.rms / 1e6 << " MPa");
}

TEST_CASE("envelope fits: Mohr-Coulomb gives c and phi from sigma1 = sigma_c + k sigma3") {
    // phi 30 deg: k = 3; c 5 MPa: sigma_c = 2 c cos(phi) / (1 - sin(phi)) = 17.32 MPa.
    const double phi = std::numbers::pi / 6.0, c = 5e6;
    const double k = (1 + std::sin(phi)) / (1 - std::sin(phi)), sc = 2 * c * std::cos(phi) / (1 - std::sin(phi));
    const std::vector<double> s3{0.0, 2e6, 5e6, 10e6};
    std::vector<double> s1;
    for (double x : s3) s1.push_back(sc + k * x);
    const auto f = fit_mohr_coulomb(s3, s1);
    REQUIRE(f.valid);
    CHECK(f.friction_deg == doctest::Approx(30.0).epsilon(1e-10));
    CHECK(f.cohesion == doctest::Approx(5e6).epsilon(1e-10));
    CHECK(f.sigma_c == doctest::Approx(sc).epsilon(1e-12));
    CHECK(f.rms < 1e-6);
    // One confinement only: no envelope.
    CHECK_FALSE(fit_mohr_coulomb({5e6, 5e6}, {30e6, 31e6}).valid);
    CHECK_FALSE(fit_hoek_brown({5e6, 5e6}, {30e6, 31e6}).valid);
}

TEST_CASE("envelope: a strength record is read in MPa with its header, and a bad line is named") {
    const auto dir = std::filesystem::temp_directory_path() / "bbm_envelope_record";
    std::filesystem::create_directories(dir);
    {
        std::ofstream(dir / "good.csv") << "sigma3_MPa,sigma1_MPa\n0,213\n# a comment\n10, 380.5\n";
        std::ofstream(dir / "bad.csv") << "sigma3,sigma1\n0,213\n10;abc\n";
    }
    const auto r = read_strength_record((dir / "good.csv").string());
    REQUIRE(r.size() == 2);
    CHECK(r[1].first == doctest::Approx(10e6));
    CHECK(r[1].second == doctest::Approx(380.5e6));
    CHECK_THROWS_WITH(read_strength_record((dir / "bad.csv").string()), doctest::Contains("bad.csv:3"));
}

TEST_CASE("envelope of a small Voronoi specimen: strength rises with confinement, the fits and ratios are reported" * validation) {
    EnvelopeStudy study = cli::run_envelope_args(
        {"--width", "2", "--height", "4", "--confinements", "2e6,5e6", "--threads", "1", "--realizations", "1"}, true);
    const auto& runs = study.runs;
    REQUIRE(runs.size() == 4); // ucs, tension, two biaxial
    double ucs = 0, t = 0, b2 = 0, b5 = 0;
    for (const auto& r : runs) {
        if (r.test == "ucs") ucs = r.result.peak_stress;
        if (r.test == "tension") t = r.result.peak_stress;
        if (r.test == "biaxial" && r.confinement == 2e6) b2 = r.result.peak_stress;
        if (r.test == "biaxial" && r.confinement == 5e6) b5 = r.result.peak_stress;
    }
    MESSAGE("UCS " << ucs / 1e6 << ", T " << t / 1e6 << ", sigma1 at 2 MPa " << b2 / 1e6 << ", at 5 MPa " << b5 / 1e6
                   << " MPa");
    CHECK(ucs > 10e6);
    CHECK(t > 0.02 * ucs);
    CHECK(t < 0.3 * ucs);
    CHECK(b2 > ucs);
    CHECK(b5 > b2);
    CHECK(study.summary_json.find("\"hoek_brown\"") != std::string::npos);
    CHECK(study.summary_json.find("\"mohr_coulomb\"") != std::string::npos);
    // Run longest first (the biaxials), reported in the list's order, each test's
    // strength in its own statistics: the tension's mean is the tension run's.
    CHECK(runs[0].test == "ucs");
    CHECK(runs[1].test == "tension");
    CHECK(runs[2].confinement == 2e6);
    CHECK(runs[3].confinement == 5e6);
    const auto summary = nlohmann::json::parse(study.summary_json);
    CHECK(summary["ucs"]["n"] == 1);
    CHECK(summary["ucs"]["mean"].get<double>() == ucs);
    CHECK(summary["tension"]["strength"]["n"] == 1);
    CHECK(summary["tension"]["strength"]["mean"].get<double>() == t);
}

// ---- The rock of a model file as a specimen (bbm compare --envelope) ----

namespace {

std::string read_text(const std::string& file) {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace

TEST_CASE("the rock of a model: the bonded region's pattern, joints and blocks become the specimen's") {
    const std::string dir = std::string(BBM_SOURCE_DIR) + "/examples/";
    const auto rigid = io::rock_of_model(io::read_model(dir + "compare_rigid_deformable/rigid.toml"), "rigid.toml");
    CHECK(rigid.pattern.kind == meshing::PatternSpec::Kind::voronoi);
    CHECK(rigid.pattern.size == 0.3);
    CHECK(rigid.pattern.seed == 7);
    CHECK(rigid.material.deformable_fraction == 0.0);
    CHECK(rigid.bonds.kn == 96.6e9);
    CHECK(rigid.bonds.ks == 40.3e9);
    CHECK(rigid.bonds.tensile == 3.0e6);
    CHECK(rigid.bonds.cohesion == 9.5e6);
    CHECK(rigid.bonds.friction == 25.0);
    CHECK(rigid.bonds.tension_softening == std::vector<std::pair<double, double>>{{1.7, 0.5}, {4.0, 0.0}});
    CHECK(rigid.bonds.shear_softening == std::vector<std::pair<double, double>>{{1.3, 0.5}, {2.1, 0.0}});

    const auto f095 =
        io::rock_of_model(io::read_model(dir + "compare_rigid_deformable/deformable_f095.toml"), "deformable_f095.toml");
    CHECK(f095.material.deformable_fraction == 0.95);
    CHECK(f095.material.young == 22.4e9);
    CHECK(f095.material.poisson == 0.2);
    CHECK(f095.mesh_size == 0.15);
    CHECK(f095.bonds.kn == 96.6e9); // the split (kn / (1 - f)) is the lab test's, as the model's

    const auto trigon = io::rock_of_model(io::read_model(dir + "tunnel_trigon.toml"), "tunnel_trigon.toml");
    CHECK(trigon.pattern.kind == meshing::PatternSpec::Kind::trigon);
    CHECK(trigon.bonds.name == "bond");

    // What a specimen's pattern cannot carry is refused, naming the key: a given shortest edge.
    std::string edited = read_text(dir + "compare_rigid_deformable/rigid.toml");
    const std::string voronoi = "pattern = { type = \"voronoi\", size = 0.3, seed = 7 }";
    REQUIRE(edited.find(voronoi) != std::string::npos);
    edited.replace(edited.find(voronoi), voronoi.size(), "pattern = { type = \"voronoi\", size = 0.3, seed = 7, min_edge = 0.01 }");
    try {
        (void)io::rock_of_model(io::parse_model(edited, "min_edge.toml"), "min_edge.toml");
        FAIL("expected an InputError");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("region[1].pattern.min_edge") != std::string::npos);
    }

    // A specimen has one bond: trigon radial and peripheral joints of different properties are refused.
    const std::string text = read_text(dir + "tunnel_trigon.toml") +
                             "\n[[joint_assignment]]\nproperty = \"unbonded\"\ntags = [\"radial\"]\n";
    const auto two_bonds = io::parse_model(text, "two_bonds.toml");
    try {
        (void)io::rock_of_model(two_bonds, "two_bonds.toml");
        FAIL("expected an InputError");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("two_bonds.toml") != std::string::npos);
        CHECK(std::string(e.what()).find("radial and peripheral") != std::string::npos);
    }
}

TEST_CASE("compare --envelope and envelope --model measure a model's rock exactly as bbm envelope does on the same specimen" * validation) {
    const std::string model = std::string(BBM_SOURCE_DIR) + "/examples/compare_rigid_deformable/rigid.toml";
    const auto out = std::filesystem::temp_directory_path() / "bbm_test_compare_envelope";
    std::filesystem::remove_all(out);
    CompareEnvelopeOptions options;
    options.enabled = true;
    options.width = 1.5, options.height = 3.0;
    options.confinements = {2e6};
    const std::string table = compare_envelopes({model}, out, 1, true, options);
    // The same rock by hand: the paper's joints on Voronoi blocks of 0.3 m, the model's seed 7.
    const EnvelopeStudy direct = cli::run_envelope_args(
        {"--width", "1.5", "--height", "3", "--seed", "7", "--confinements", "2e6", "--threads", "1", "--realizations", "1"},
        true);
    const auto by_hand = nlohmann::json::parse(direct.summary_json);
    const auto measured = nlohmann::json::parse(read_text((out / "rigid" / "envelope" / "envelope.json").string()));
    CHECK(measured["ucs"]["mean"].get<double>() == by_hand["ucs"]["mean"].get<double>());
    CHECK(measured["levels"].back()["peak"]["mean"].get<double>() == by_hand["levels"].back()["peak"]["mean"].get<double>());
    CHECK(measured["ucs"]["mean"].get<double>() > 10e6);
    // bbm envelope --model: the same rock from the model file.
    const auto from_model = nlohmann::json::parse(
        cli::run_envelope_args({"--model", model, "--width", "1.5", "--height", "3", "--confinements", "2e6", "--threads", "1"}, true)
            .summary_json);
    CHECK(from_model["ucs"]["mean"].get<double>() == by_hand["ucs"]["mean"].get<double>());
    CHECK(from_model["specimen"]["model"].get<std::string>() == model);
    CHECK(table.find("| rigid | voronoi 0.3 m, rigid |") != std::string::npos);
    const std::string csv = read_text((out / "envelopes.csv").string());
    CHECK(csv.find("\nrigid,voronoi,0.3,0,1.5,3,1,") != std::string::npos);
    std::filesystem::remove_all(out);
}
