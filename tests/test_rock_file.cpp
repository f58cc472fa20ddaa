// One schema for the rock (issue 47, item 4): `--rock FILE` gives the lab tests
// the bonds and material of a rock file — a [[joint_property]] and a [[material]]
// read by the model file's own readers, as bbm calibrate writes them — the same
// bits as the same values given as flags; flags given beside it override it; a
// bad file is refused naming file, line and key. The first runs four lab tests to
// their answer: a validation (tests/validation.hpp), not run in the checking build.
#include "base/error.hpp"
#include "io/model_input.hpp"
#include "apps/checks.hpp"
#include "apps/flags.hpp"
#include "tests/validation.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace bbm;
using namespace bbm::studies;

namespace {

const char* const rock_text = R"(# what bbm calibrate writes, and a material
[[joint_property]]
name = "calibrated"
law = "softening"
kn = 40e9
ks = 16e9
tensile = 2e6
cohesion = 6e6
friction = 30.0
tension_softening = [[1.7, 0.5], [4.0, 0.0]]
shear_softening = [[1.3, 0.5], [2.1, 0.0]]

[[material]]
name = "granite"
density = 2650.0
)";

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

/// A small quick specimen.
const std::vector<std::string> specimen{"--width", "1", "--height", "2", "--size", "0.25", "--seed", "3"};
/// The rock file's values as flags.
std::vector<std::string> as_flags(const std::string& tensile = "2e6") {
    return {"--kn",     "40e9", "--ks",       "16e9", "--tensile", tensile,
            "--cohesion", "6e6", "--friction", "30",   "--density", "2650"};
}

void check_same(const LabTestStudy& a, const LabTestStudy& b) {
    REQUIRE(a.results.size() == 1);
    REQUIRE(b.results.size() == 1);
    CHECK(a.results[0].steps == b.results[0].steps);
    CHECK(a.results[0].peak_stress == b.results[0].peak_stress);
    CHECK(a.results[0].E == b.results[0].E);
    CHECK(a.results[0].cracks_tensile == b.results[0].cracks_tensile);
}

} // namespace

TEST_CASE("--rock: a rock file is the same rock as its values given as flags, and flags beside it override it" *
          validation) {
    const auto dir = std::filesystem::temp_directory_path() / "bbm_test_rock_file";
    std::filesystem::create_directories(dir);
    const std::string file = (dir / "rock.toml").string();
    std::ofstream(file) << rock_text;
    const auto by_file = cli::run_labtest_args("ucs", with(specimen, {"--rock", file}), true);
    const auto by_flags = cli::run_labtest_args("ucs", with(specimen, as_flags()), true);
    MESSAGE("UCS " << by_file.results[0].peak_stress << " Pa from the file, " << by_flags.results[0].peak_stress
                   << " from the flags");
    CHECK(by_file.results[0].peak_stress > 0.0);
    check_same(by_file, by_flags);
    // A flag given beside --rock wins over the file, whatever their order.
    const auto over = cli::run_labtest_args("ucs", with(specimen, {"--tensile", "3e6", "--rock", file}), true);
    const auto over_flags = cli::run_labtest_args("ucs", with(specimen, as_flags("3e6")), true);
    check_same(over, over_flags);
    CHECK(over.results[0].peak_stress != by_file.results[0].peak_stress);
    std::filesystem::remove_all(dir);
}

TEST_CASE("--rock: a bad rock file is refused naming the file, the line and the key") {
    auto refused = [](const std::string& text, const std::string& what) {
        INFO(what);
        CHECK_THROWS_WITH_AS((void)io::parse_rock(text, "rock.toml"), doctest::Contains(what.c_str()), InputError);
    };
    std::string misspelt = rock_text;
    misspelt.replace(misspelt.find("tensile = 2e6"), 13, "tensil = 2e6");
    refused(misspelt, "rock.toml:7: joint_property[0].tensil"); // with a "did you mean"
    refused(misspelt, "tensil");
    std::string negative = rock_text;
    negative.replace(negative.find("kn = 40e9"), 9, "kn = -1.0");
    refused(negative, "joint_property[0].kn");
    refused(std::string(rock_text) + "\n[[joint_property]]\nname = \"b\"\nlaw = \"elastic\"\nkn = 1e9\nks = 1e9\n",
            "one [[joint_property]]");
    refused(std::string(rock_text) + "\n[solver]\nmode = \"quasi_static\"\n", "solver");
    const auto rock = io::parse_rock(rock_text, "rock.toml");
    CHECK(rock.bonds.kn == 40e9);
    CHECK(rock.bonds.tension_softening.size() == 2);
    CHECK(rock.material.density == 2650.0);
    // What the file does not give is the base rock's: the paper's pattern.
    CHECK(rock.pattern.size == paper_rock().pattern.size);
    // The table bbm calibrate writes reads back to the same set.
    const auto again = io::parse_rock(io::joint_property_toml(rock.bonds), "again.toml");
    CHECK(again.bonds.kn == rock.bonds.kn);
    CHECK(again.bonds.ks == rock.bonds.ks);
    CHECK(again.bonds.tensile == rock.bonds.tensile);
    CHECK(again.bonds.cohesion == rock.bonds.cohesion);
    CHECK(again.bonds.friction == rock.bonds.friction);
    CHECK(again.bonds.tension_softening == rock.bonds.tension_softening);
    CHECK(again.bonds.shear_softening == rock.bonds.shear_softening);
}

TEST_CASE("the rock's flags: one rock, its curves written as a model file writes them (b1,a1,a2 still read)") {
    auto parsed = [](const std::vector<std::string>& args) {
        studies::LabTestValues v;
        CLI::App app{"ucs", "ucs"};
        bool quiet = true;
        cli::add_labtest_options(&app, v, quiet);
        cli::parse_args(app, "ucs", args);
        return v.o.rock;
    };
    using Curve = std::vector<std::pair<double, double>>;
    const RockSpec rock = parsed({"--pattern", "trigon", "--size", "0.2", "--size-measure", "area", "--lloyd", "2",
                                  "--seed", "9", "--tension-softening", "[[2.0, 0.4], [3.0, 0.1], [5, 0]]",
                                  "--density", "2650"});
    CHECK(rock.pattern.kind == meshing::PatternSpec::Kind::trigon);
    CHECK(rock.pattern.size == 0.2);
    CHECK(rock.pattern.size_measure == meshing::PatternSpec::SizeMeasure::area);
    CHECK(rock.pattern.lloyd_iterations == 2);
    CHECK(rock.pattern.seed == 9);
    CHECK(rock.bonds.tension_softening == Curve{{2.0, 0.4}, {3.0, 0.1}, {5.0, 0.0}});
    CHECK(rock.bonds.shear_softening == paper_rock().bonds.shear_softening);
    CHECK(rock.material.density == 2650.0);
    // The former three numbers b1,a1,a2: the points (a1, b1), (a2, 0).
    CHECK(parsed({"--shear-softening", "0.4,1.5,3"}).bonds.shear_softening == Curve{{1.5, 0.4}, {3.0, 0.0}});
    // A curve is checked by the model file's rules, the message naming the flag and the point.
    try {
        (void)parsed({"--tension-softening", "[[1.7, 0.5], [1.5, 0]]"});
        FAIL("a curve snapping back was accepted");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("--tension-softening: [1][0]: the curve snaps back") != std::string::npos);
    }
}
