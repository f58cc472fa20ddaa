// One declaration per [[joint_property]] key (contact/joint_keys.hpp, issue 47
// items 3 and 4; issue 50 item 3): the model file's reader, the rock's flags of the
// lab tests and of bbm shear, and the key reference in docs/ are all made from it.
// These check that they agree: the reference is not stale, a key and its flag
// refuse the same values in the same words, each law reads exactly its keys, and
// the rules between keys say the same from a file and from the flags.
#include "base/error.hpp"
#include "contact/joint_keys.hpp"
#include "contact/joint_law.hpp"
#include "core/boundary_keys.hpp"
#include "core/event_keys.hpp"
#include "core/flow_keys.hpp"
#include "core/history_keys.hpp"
#include "core/supports/registry.hpp"
#include "core/material_keys.hpp"
#include "core/solver_keys.hpp"
#include "core/stage_keys.hpp"
#include "core/step.hpp"
#include "io/model_input.hpp"
#include "meshing/dfn_keys.hpp"
#include "meshing/model_keys.hpp"
#include "meshing/region_keys.hpp"
#include "apps/flags.hpp"
#include "studies/lab/shear.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace bbm;

namespace {

const std::filesystem::path reference_dir = std::filesystem::path(BBM_SOURCE_DIR) / "docs/reference";

const std::string softening_bond = "name = \"b\"\nlaw = \"softening\"\nkn = 1e10\nks = 1e10\ntensile = 1e6\ncohesion = 2e6\n";

const std::string softening_rock = "[[joint_property]]\n" + softening_bond;

/// The softening bond with `key = value` in place of its own value of the key.
std::string bond_with(std::string_view key, const std::string& value) {
    std::string text;
    std::istringstream lines(softening_bond);
    for (std::string line; std::getline(lines, line);)
        if (!line.starts_with(std::string(key) + " =")) text += line + "\n";
    return text + std::string(key) + " = " + value + "\n";
}

/// The reader's error for a rock file of this [[joint_property]] ("" if accepted).
std::string file_error(const std::string& property) {
    try {
        (void)io::parse_rock("[[joint_property]]\n" + property, "rock.toml");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// The error of `bbm ucs` with these flags ("" if they pass its checks; the test
/// itself is not run: an accepted set would run, so only refused sets are given).
std::string flag_error(const std::vector<std::string>& flags) {
    try {
        (void)cli::run_labtest_args("ucs", flags, true);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// A value just outside the bounds (below them if they have a lower end).
double outside(const Bounds& b) {
    if (!std::isinf(b.lo)) return b.lo_open ? b.lo : b.lo - 1.0;
    return b.hi_open ? b.hi : b.hi + 1.0;
}

} // namespace

/// A generated reference file is the one in docs/reference (BBM_WRITE_REFERENCE=1 rewrites it).
void check_reference(const std::string& name, const std::string& generated) {
    const auto file = reference_dir / name;
    if (std::getenv("BBM_WRITE_REFERENCE")) std::ofstream(file) << generated;
    std::ifstream in(file);
    const std::string missing = file.string() + " is missing: run this test with BBM_WRITE_REFERENCE=1";
    REQUIRE_MESSAGE(in.good(), missing);
    std::stringstream text;
    text << in.rdbuf();
    const std::string stale = file.string() + " is stale: run this test with BBM_WRITE_REFERENCE=1 and commit it";
    CHECK_MESSAGE(text.str() == generated, stale);
}

TEST_CASE("docs/reference/ is the tables the code reads the keys by") {
    const std::string joints = contact::joint_keys_markdown();
    check_reference("joint_property.md", joints);
    for (const contact::JointKey* k : contact::joint_keys())
        CHECK(joints.find("| `" + std::string(k->key) + "` |") != std::string::npos);
    check_reference("material.md", material_keys_markdown());
    const std::string flow = flow_keys_markdown();
    check_reference("flow.md", flow);
    for (const auto& k : flow_keys) CHECK(flow.find("| `" + std::string(k.key) + "` |") != std::string::npos);
    check_reference("solver.md", solver_keys_markdown());
    check_reference("stage.md", stage_keys_markdown());
    // Each support type's page, from the registry.
    for_each_support_type([](auto type) {
        using T = typename decltype(type)::type;
        if constexpr (requires { T::reference(); }) check_reference(std::string(T::table) + ".md", T::reference());
    });
    check_reference("boundary.md", boundary_keys_markdown());
    check_reference("history.md", history_keys_markdown());
    check_reference("events.md", event_keys_markdown());
    check_reference("model.md", meshing::model_keys_markdown());
    check_reference("region.md", meshing::region_keys_markdown());
    check_reference("dfn.md", meshing::dfn_keys_markdown());
}

TEST_CASE("docs/architecture.md lists the stages of the step as core/step.cpp's table has them") {
    // The page's copy sits between two markers; BBM_WRITE_REFERENCE=1 rewrites it.
    const auto file = reference_dir.parent_path() / "architecture.md";
    std::ifstream in(file);
    REQUIRE(in.good());
    std::stringstream text;
    text << in.rdbuf();
    std::string page = text.str();
    const std::string begin = "<!-- stages: generated from core/step.cpp's table (tests/test_reference.cpp) -->\n",
                      end = "<!-- /stages -->";
    const auto a = page.find(begin), b = page.find(end);
    const std::string no_list = file.string() + " has no stage list between its markers",
                      stale = file.string() + "'s stage list is stale: run this test with BBM_WRITE_REFERENCE=1";
    REQUIRE_MESSAGE(a != std::string::npos, no_list);
    REQUIRE(b != std::string::npos);
    const std::string generated = step_stages_markdown();
    if (std::getenv("BBM_WRITE_REFERENCE")) {
        page.replace(a + begin.size(), b - a - begin.size(), generated);
        std::ofstream(file) << page;
        return;
    }
    CHECK_MESSAGE(page.substr(a + begin.size(), b - a - begin.size()) == generated, stale);
}

TEST_CASE("A key and its flag refuse the same values in the same words") {
    // Every joint key a lab test's rock takes as a flag (declared `flag`): its numbers.
    for (const contact::JointKey* declared : contact::joint_keys()) {
        if (!declared->flag || !(declared->kind == KeyKind::number || declared->kind == KeyKind::integer)) continue;
        const contact::JointKey& k = *declared;
        const std::string_view key = k.key;
        const double bad = outside(k.bounds);
        const std::string value = shortest_text(bad);
        INFO(key, " = ", value);
        const bool whole = k.kind == contact::KeyKind::integer;
        const std::string in_file = file_error(bond_with(key, whole ? std::to_string(std::llround(bad)) : value) +
                                               (key.starts_with("strength") ? "weibull_modulus = 3\n" : ""));
        MESSAGE(in_file);
        const std::string as_flag = flag_error({contact::joint_flag(key), value});
        CHECK(in_file.find("joint_property[0]." + std::string(key)) != std::string::npos);
        CHECK(in_file.find(k.bounds.text()) != std::string::npos);
        CHECK(as_flag.find(contact::joint_flag(key)) != std::string::npos);
        CHECK(as_flag.find(k.bounds.text()) != std::string::npos);
    }
    for (const MaterialKey& k : material_keys) {
        if (!k.flag) continue;
        const std::string_view key = k.key;
        const std::string value = shortest_text(outside(k.bounds));
        INFO(key, " = ", value);
        const std::string in_file = [&]() -> std::string {
            try {
                (void)io::parse_rock(softening_rock + "[[material]]\nname = \"m\"\n" +
                                         (key == "young" ? "" : "young = 1e10\n") + std::string(key) + " = " + value + "\n",
                                     "rock.toml");
            } catch (const InputError& e) {
                return e.what();
            }
            return "";
        }();
        const std::string as_flag = flag_error({key_flag(key), value});
        CHECK(in_file.find("material[0]." + std::string(key)) != std::string::npos);
        CHECK(in_file.find(k.bounds.text()) != std::string::npos);
        CHECK(as_flag.find(key_flag(key)) != std::string::npos);
        CHECK(as_flag.find(k.bounds.text()) != std::string::npos);
    }
    // The friction bound that had drifted: [0, 90) in both.
    CHECK(file_error(softening_bond + "friction = 89.95\n") == "");
    CHECK(flag_error({"--friction", "90"}).find("in [0, 90) degrees, got 90") != std::string::npos);
    CHECK(file_error(softening_bond + "friction = 90\n").find("in [0, 90) degrees, got 90") != std::string::npos);
}

TEST_CASE("Each law reads the keys it declares, and a key of another law is refused naming the law") {
    for (const std::string_view law : contact::law_names) {
        const auto keys = contact::law_key_names(law);
        INFO(law);
        CHECK(std::ranges::find(keys, "kn") != keys.end());
        for (const contact::JointKey* k : contact::joint_keys()) {
            if (std::ranges::find(keys, k->key) != keys.end()) continue;
            std::string set = "name = \"s\"\nlaw = \"" + std::string(law) + "\"\nkn = 1e10\nks = 1e10\n";
            const std::string error = file_error(set + std::string(k->key) + " = 1\n");
            CHECK_MESSAGE(error.find("joint_property[0]." + std::string(k->key)) != std::string::npos, k->key);
        }
    }
    // A Barton-Bandis set read through its declared keys.
    const auto rock = io::parse_rock("[[joint_property]]\nname = \"j\"\nlaw = \"barton_bandis\"\nkn = 1e10\nks = 1e9\n"
                                     "friction = 28\njrc = 12\njcs = 80e6\njoint_length = 0.5\n",
                                     "rock.toml");
    CHECK(rock.bonds.jrc == 12.0);
    CHECK(rock.bonds.jcs == 80e6);
    CHECK(rock.bonds.joint_length == 0.5);
    CHECK(rock.bonds.friction == 28.0);
    CHECK(file_error("name = \"j\"\nlaw = \"barton_bandis\"\nkn = 1e10\nks = 1e9\njrc = 12\n").find("jcs") !=
          std::string::npos);
}

TEST_CASE("The rules between keys say the same from a file and from the flags") {
    const std::string pair = "confined_friction (the steeper friction angle, degrees) and confined_friction_from";
    const std::string in_file = file_error(softening_bond + "confined_friction = 45\n");
    CHECK(in_file.find("joint_property[0].confined_friction:") != std::string::npos);
    CHECK(in_file.find(pair) != std::string::npos);
    const std::string as_flags = flag_error({"--confined-friction", "45"});
    CHECK(as_flags.find("--confined-friction") == 0);
    CHECK(as_flags.find(pair) != std::string::npos);
    const std::string peak = "a softening law needs cohesion > 0 Pa";
    CHECK(file_error("name = \"b\"\nlaw = \"softening\"\nkn = 1e10\nks = 1e10\ntensile = 1e6\ncohesion = 0\n").find(peak) !=
          std::string::npos);
    CHECK(flag_error({"--cohesion", "0"}).find(peak) != std::string::npos);
}

TEST_CASE("bbm shear takes the lab tests' rock: --rock, --confined-friction and --strength-classes") {
    auto shear_error = [](const std::vector<std::string>& flags) -> std::string {
        try {
            (void)cli::run_shear_args(flags, true);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    CHECK(shear_error({"--confined-friction", "45"}).find("go together") != std::string::npos);
    CHECK(shear_error({"--strength-classes", "0"}).find("--strength-classes") != std::string::npos);
    CHECK(shear_error({"--joint-friction", "90"}).find("in [0, 90) degrees") != std::string::npos);
    CHECK(shear_error({"--rock", "/nonexistent/rock.toml"}).find("--rock") != std::string::npos);
    // The rock file's bonds reach the test: a file whose softening set lacks its
    // cohesion is refused by the reader, naming the file.
    const auto dir = std::filesystem::temp_directory_path() / "bbm_test_reference";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "rock.toml") << "[[joint_property]]\nname = \"b\"\nlaw = \"softening\"\nkn = 1e10\nks = 1e10\n"
                                        "tensile = 1e6\n";
    CHECK(shear_error({"--rock", (dir / "rock.toml").string()}).find("rock.toml") != std::string::npos);
}
