// Heterogeneous joint strengths (JointPropertySpec::weibull_modulus): the class
// factors are a Weibull law of mean 1, joints fall evenly and reproducibly into the
// classes, the model-file keys are checked, and a heterogeneous rock cracks
// earlier and is weaker than the uniform one with the same blocks.
#include "base/error.hpp"
#include "contact/joint_law.hpp"
#include "core/solver.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"
#include "studies/lab/labtest.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"

#include <cmath>
#include <map>
#include <string>

using namespace bbm;

TEST_CASE("heterogeneous strengths: class factors of mean 1 and the Weibull law's spread") {
    for (double m : {2.0, 4.0, 10.0}) {
        const auto f = strength_class_factors(m, 64);
        double mean = 0.0, var = 0.0;
        for (double x : f) mean += x;
        mean /= double(f.size());
        for (double x : f) var += (x - mean) * (x - mean);
        const double cv = std::sqrt(var / double(f.size()));
        // Weibull: CV² = Γ(1 + 2/m) / Γ(1 + 1/m)² − 1 (64 classes: the tails are cut).
        const double exact = std::sqrt(std::tgamma(1 + 2 / m) / std::pow(std::tgamma(1 + 1 / m), 2) - 1);
        CAPTURE(m);
        CHECK(mean == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(cv == doctest::Approx(exact).epsilon(0.05));
        CHECK(std::is_sorted(f.begin(), f.end()));
    }
    CHECK(strength_class_factors(0.0, 16) == std::vector<double>(16, 1.0));
}

TEST_CASE("heterogeneous strengths: joints fall evenly into the classes, the same way every time") {
    LabTestOptions o = LabTestOptions::paper_ucs();
    o.width = 6.0, o.height = 12.0;
    o.rock.bonds.weibull_modulus = 3.0;
    o.rock.bonds.strength_classes = 8;
    const auto blocks = meshing::generate_blocks(labtest_geometry(o));
    auto classes_of = [&](std::uint64_t seed) {
        LabTestOptions p = o;
        p.rock.pattern.seed = seed;
        Solver s(blocks, labtest_analysis(p));
        std::vector<int> props;
        for (int i = 0; i < contacts(s.world()).size(); ++i) props.push_back(contacts(s.world()).property[i]);
        return std::pair{props, s.world().properties.names};
    };
    const auto [a, names] = classes_of(1);
    const auto [b, names_b] = classes_of(1);
    const auto [c, names_c] = classes_of(2);
    CHECK(a == b);
    CHECK(a != c); // the specimen's seed draws them
    std::map<int, int> count;
    for (int p : a) ++count[p];
    int bonded_classes = 0;
    double chi2 = 0.0;
    const double expected = double(a.size()) / 8.0;
    for (const auto& [p, n] : count) {
        REQUIRE(names[p].find("strength class") != std::string::npos);
        ++bonded_classes;
        chi2 += (n - expected) * (n - expected) / expected;
    }
    CHECK(bonded_classes == 8);
    CHECK(chi2 < 24.3); // chi-square, 7 degrees of freedom, 0.1%
}

TEST_CASE("heterogeneous strengths: a weaker rock that cracks earlier (4 x 8 m, seed 1)" * validation) {
    LabTestOptions o = LabTestOptions::paper_ucs();
    o.width = 4.0, o.height = 8.0;
    o.threads = 2;
    const auto uniform = run_labtest(o);
    o.rock.bonds.weibull_modulus = 2.0;
    const auto heterogeneous = run_labtest(o);
    // Stiffness untouched (the preload ends at another load: 5e-6 from geometric nonlinearity).
    CHECK(heterogeneous.E == doctest::Approx(uniform.E).epsilon(1e-4));
    CHECK(heterogeneous.peak_stress < 0.9 * uniform.peak_stress);
    CHECK(heterogeneous.crack_initiation_stress / heterogeneous.peak_stress <
          uniform.crack_initiation_stress / uniform.peak_stress - 0.05);
}

TEST_CASE("heterogeneous strengths: model-file keys") {
    const std::string head = "[[region]]\nname = \"a\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [2.0, 2.0] }\n"
                             "pattern = { type = \"voronoi\", size = 0.5 }\n";
    auto error_of = [&](const std::string& property) -> std::string {
        try {
            io::parse_model(head + "[[joint_property]]\n" + property, "h.toml");
        } catch (const InputError& e) {
            return e.key() + ": " + e.message();
        }
        return "";
    };
    const std::string bond = "name = \"b\"\nlaw = \"coulomb\"\nkn = 1e10\nks = 1e10\n";
    // face_shear (the interface with a far field) is a key of every law.
    CHECK(error_of("name = \"e\"\nlaw = \"elastic\"\nkn = 1e10\nks = 1e10\nface_shear = true\n") == "");
    CHECK(error_of(bond + "face_shear = 1\n").find("joint_property[0].face_shear") == 0);
    CHECK(error_of(bond + "cohesion = 1e6\nweibull_modulus = 3\nstrength_classes = 8\nstrength_seed = 4\n") == "");
    CHECK(error_of(bond + "weibull_modulus = 3\n").find("joint_property[0].weibull_modulus: heterogeneous strengths need a bond") == 0);
    CHECK(error_of(bond + "cohesion = 1e6\nstrength_classes = 8\n").find("joint_property[0].strength_classes: goes with weibull_modulus") == 0);
    CHECK(error_of(bond + "cohesion = 1e6\nweibull_modulus = -1\n").find("joint_property[0].weibull_modulus") == 0);
    CHECK(error_of("name = \"e\"\nlaw = \"elastic\"\nkn = 1e10\nks = 1e10\nweibull_modulus = 3\n").find("joint_property[0].weibull_modulus") == 0);
}
