// One schema for the rock (issue 47, item 4): `--rock FILE` gives the lab tests
// the bonds and material of a rock file — a [[joint_property]] and a [[material]]
// read by the model file's own readers, as bbm calibrate writes them — the same
// bits as the same values given as flags; flags given beside it override it; a
// bad file is refused naming file, line and key. The first runs four lab tests to
// their answer: a validation (tests/validation.hpp), not run in the checking build.
#include "base/error.hpp"
#include "io/model_input.hpp"
#include "studies/commands.hpp"
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
    const auto by_file = run_labtest_args("ucs", with(specimen, {"--rock", file}), true);
    const auto by_flags = run_labtest_args("ucs", with(specimen, as_flags()), true);
    MESSAGE("UCS " << by_file.results[0].peak_stress << " Pa from the file, " << by_flags.results[0].peak_stress
                   << " from the flags");
    CHECK(by_file.results[0].peak_stress > 0.0);
    check_same(by_file, by_flags);
    // A flag given beside --rock wins over the file, whatever their order.
    const auto over = run_labtest_args("ucs", with(specimen, {"--tensile", "3e6", "--rock", file}), true);
    const auto over_flags = run_labtest_args("ucs", with(specimen, as_flags("3e6")), true);
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
    CHECK(rock.joint.kn == 40e9);
    CHECK(rock.joint.tension_softening.size() == 2);
    REQUIRE(rock.material.has_value());
    CHECK(rock.material->density == 2650.0);
    CHECK_FALSE(rock.model.has_value());
}
