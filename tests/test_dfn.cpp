// Discrete fracture networks (issue 26): the generated network has the asked
// intensity (P21 within 3% over a large region), its angles and lengths pass a
// Kolmogorov–Smirnov test at 5% against the asked laws, later sets end at earlier
// ones, and the traces cut a bonded region into blocks along fracture joints with
// rock bridges between them.
#include "base/error.hpp"
#include "cutting_checks.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"
#include "meshing/dfn.hpp"
#include "studies/model/sweep.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

using namespace bbm;
using namespace bbm::meshing;

namespace {

cgal::Domain square(double side) {
    const std::vector<Vec2> outer{{0, 0}, {side, 0}, {side, side}, {0, side}};
    return cgal::make_domain(outer, {});
}

/// Kolmogorov–Smirnov statistic of the sample against the CDF F.
double ks_statistic(std::vector<double> x, const std::function<double(double)>& F) {
    std::sort(x.begin(), x.end());
    const double n = double(x.size());
    double d = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double f = F(x[i]);
        d = std::max({d, f - double(i) / n, double(i + 1) / n - f});
    }
    return d;
}

/// The 5% critical value of the KS statistic for n points (asymptotic, n > 35).
double ks_critical(std::size_t n) { return 1.358 / std::sqrt(double(n)); }

DfnSetSpec power_law_set() {
    DfnSetSpec s;
    s.name = "J1";
    s.orientation.mean = 30.0;
    s.orientation.concentration = 10.0;
    s.length.kind = FractureLengthSpec::Kind::power_law;
    s.length.exponent = 2.5;
    s.length.min = 1.0;
    s.length.max = 20.0;
    s.p21 = 1.0;
    s.seed = 1;
    return s;
}

/// Angles (degrees, folded about the set's mean as generated) and lengths of set k.
void angles_and_lengths(const FractureNetwork& net, int k, double mean, std::vector<double>& angles,
                        std::vector<double>& lengths) {
    for (const auto& f : net.fractures) {
        if (f.set != k) continue;
        double a = std::atan2(f.b.y - f.a.y, f.b.x - f.a.x) * 180.0 / std::numbers::pi;
        a = mean + std::remainder(a - mean, 180.0);
        if (a >= mean + 90.0) a -= 180.0;
        angles.push_back(a);
        lengths.push_back(norm(f.b - f.a));
    }
}

} // namespace

TEST_CASE("a fracture set has the asked P21, and its angles and lengths follow the asked laws" * validation) {
    // 200 m × 200 m, P21 = 1 /m: about 17,000 fractures centred inside. The
    // sampling error of P21 is about CV(L)/√N ≈ 1%; the test asks 3%.
    const auto domain = square(200.0);
    for (const auto kind : {FractureLengthSpec::Kind::power_law, FractureLengthSpec::Kind::lognormal,
                            FractureLengthSpec::Kind::exponential}) {
        DfnSetSpec s = power_law_set();
        s.length.kind = kind;
        if (kind == FractureLengthSpec::Kind::lognormal) s.length = {kind, 0, 0, 3.0, 2.0, 0.5, 30.0};
        if (kind == FractureLengthSpec::Kind::exponential) s.length = {kind, 0, 0, 2.5, 0, 0.2, 0.0};
        CAPTURE(int(kind));
        const auto net = generate_fracture_network(std::span(&s, 1), domain);
        REQUIRE(net.stats.size() == 1);
        const auto& st = net.stats[0];
        MESSAGE("P21 " << st.p21 << " (target " << st.p21_target << "), fractures " << st.fractures
                       << ", mean length " << st.mean_length << " m (E[L] " << st.mean_length_target
                       << "), mean angle " << st.mean_angle << " (30), kappa " << st.concentration
                       << " (10), P10 along x " << st.p10_x << ", along y " << st.p10_y);
        CHECK(st.p21 == doctest::Approx(1.0).epsilon(0.03));
        CHECK(st.mean_length == doctest::Approx(st.mean_length_target).epsilon(0.03));
        // The mean's standard error is about 1/√(κ N) rad: within 4 of them.
        CHECK(std::abs(st.mean_angle - 30.0) < 4.0 * 180.0 / std::numbers::pi / std::sqrt(10.0 * st.fractures));
        CHECK(st.concentration == doctest::Approx(10.0).epsilon(0.05));
        // P10 along a scanline of direction u: P21 × E|sin(θ − u)|.
        std::vector<double> angles, lengths;
        angles_and_lengths(net, 0, 30.0, angles, lengths);
        double sin_x = 0.0, sin_y = 0.0, total = 0.0;
        for (std::size_t i = 0; i < angles.size(); ++i) {
            const double t = angles[i] * std::numbers::pi / 180.0;
            sin_x += lengths[i] * std::abs(std::sin(t)), sin_y += lengths[i] * std::abs(std::cos(t));
            total += lengths[i];
        }
        CHECK(st.p10_x == doctest::Approx(st.p21 * sin_x / total).epsilon(0.05));
        CHECK(st.p10_y == doctest::Approx(st.p21 * sin_y / total).epsilon(0.05));

        const double box = norm(Vec2{200.0, 200.0});
        const double d_angle = ks_statistic(angles, [&](double x) { return dfn::angle_cdf(s.orientation, x); });
        const double d_length = ks_statistic(lengths, [&](double x) { return dfn::length_cdf(s.length, box, x); });
        MESSAGE("KS: angles D = " << d_angle << ", lengths D = " << d_length << " (5% critical value "
                                  << ks_critical(angles.size()) << ", n = " << angles.size() << ")");
        CHECK(d_angle < ks_critical(angles.size()));
        CHECK(d_length < ks_critical(lengths.size()));
        // The test has power: the lengths 3% longer, or the angles turned by 1°, fail it.
        std::vector<double> longer = lengths, turned = angles;
        for (double& l : longer) l *= 1.03;
        for (double& t : turned) t += 1.0;
        CHECK(ks_statistic(longer, [&](double x) { return dfn::length_cdf(s.length, box, x); }) >
              ks_critical(lengths.size()));
        CHECK(ks_statistic(turned, [&](double x) { return dfn::angle_cdf(s.orientation, x); }) >
              ks_critical(angles.size()));
    }
}

TEST_CASE("a fracture set given by count, uniform or listed angles, clustered centres") {
    const auto domain = square(100.0);
    DfnSetSpec s = power_law_set();
    s.p21 = 0.0;
    s.count = 2000;
    s.orientation.kind = FractureOrientationSpec::Kind::list;
    s.orientation.angles = {10.0, 100.0};
    s.orientation.weights = {3.0, 1.0};
    const auto net = generate_fracture_network(std::span(&s, 1), domain);
    // Uniform centres: the count inside is binomial about 2,000 (σ ≈ 45).
    CHECK(std::abs(net.stats[0].fractures - 2000) < 180);
    std::vector<double> angles, lengths;
    angles_and_lengths(net, 0, 55.0, angles, lengths);
    const auto at_10 = std::count_if(angles.begin(), angles.end(), [](double a) { return std::abs(a - 10.0) < 1e-9; });
    CHECK(double(at_10) / double(angles.size()) == doctest::Approx(0.75).epsilon(0.03));
    CHECK(std::count_if(angles.begin(), angles.end(), [](double a) { return std::abs(a - 100.0) < 1e-9; }) ==
          long(angles.size()) - at_10);

    // Clustered: the same count, in clusters. Morisita's index of the centres in
    // 10 m quadrats is 1 for Poisson centres; for this Thomas process about
    // 1 + p/(ρ_c A_q) = 1.6 (ρ_c = 0.01 clusters per m², A_q = 100 m², p ≈ 0.6 the
    // chance that two fractures of a cluster share a quadrat).
    s.centres = DfnSetSpec::Centres::clustered;
    s.cluster_size = 20.0;
    s.cluster_radius = 2.0;
    auto morisita = [&](const FractureNetwork& n) {
        std::vector<double> q(100, 0.0);
        double total = 0.0;
        for (const auto& f : n.fractures) {
            const Vec2 c = 0.5 * (f.a + f.b);
            if (c.x < 0 || c.x >= 100 || c.y < 0 || c.y >= 100) continue;
            q[int(c.y / 10) * 10 + int(c.x / 10)] += 1.0, total += 1.0;
        }
        double sum = 0.0;
        for (double v : q) sum += v * (v - 1.0);
        return 100.0 * sum / (total * (total - 1.0));
    };
    const auto clustered = generate_fracture_network(std::span(&s, 1), domain);
    MESSAGE("centres inside: Poisson " << net.stats[0].fractures << ", clustered " << clustered.stats[0].fractures
                                       << "; Morisita index " << morisita(net) << " / " << morisita(clustered));
    CHECK(std::abs(clustered.stats[0].fractures - 2000) < 600);
    CHECK(morisita(net) == doctest::Approx(1.0).epsilon(0.1));
    CHECK(morisita(clustered) > 1.3);
    CHECK(morisita(clustered) < 2.0);
}

TEST_CASE("a later fracture set ends at an earlier one") {
    const auto domain = square(60.0);
    DfnSetSpec first = power_law_set(), second = power_law_set();
    first.p21 = 0.3;
    second.name = "J2";
    second.orientation.mean = 120.0;
    second.p21 = 0.3;
    second.seed = 2;
    second.terminate_at = {0};
    second.terminate_probability = 1.0;
    const std::vector<DfnSetSpec> sets{first, second};
    const auto net = generate_fracture_network(sets, domain);
    const auto free = generate_fracture_network(std::span(&sets[0], 2).subspan(0, 1), domain);
    std::vector<Fracture> older, later;
    for (const auto& f : net.fractures) (f.set == 0 ? older : later).push_back(f);
    auto crosses = [](const Fracture& f, const Fracture& g) {
        const Vec2 d = f.b - f.a, e = g.b - g.a;
        const double den = cross(d, e);
        if (std::abs(den) < 1e-300) return false;
        const double t = cross(g.a - f.a, e) / den, u = cross(g.a - f.a, d) / den;
        return t > 1e-9 && t < 1 - 1e-9 && u > 1e-9 && u < 1 - 1e-9;
    };
    // With probability 1, a J2 fracture stops at its first crossing on each side:
    // it crosses none, and an end that moved lies on a J1 fracture.
    int crossings = 0, ends_on_j1 = 0;
    for (const auto& f : later)
        for (const auto& g : older) {
            crossings += crosses(f, g);
            ends_on_j1 += (distance_to_segment(f.a, g.a, g.b) < 1e-9) + (distance_to_segment(f.b, g.a, g.b) < 1e-9);
        }
    MESSAGE(later.size() << " J2 fractures, " << ends_on_j1 << " ends on J1, P21 of J2 " << net.stats[1].p21
                         << " (0.3 before termination)");
    CHECK(crossings == 0);
    CHECK(ends_on_j1 > int(later.size()) / 4);
    CHECK(net.stats[1].p21 < 0.9 * 0.3);
    // The earlier set is not changed by the later one.
    REQUIRE(free.fractures.size() == older.size());
    CHECK(free.fractures.back().b == older.back().b);
}

TEST_CASE("a DFN cuts a bonded region: fracture joints along the traces, rock bridges between them") {
    const std::string text = R"(
[[material]]
name = "rock"
young = 20e9
poisson = 0.25

[[region]]
name = "rock mass"
outline = { type = "rectangle", min = [0.0, 0.0], max = [10.0, 10.0] }
pattern = { type = "voronoi", size = 0.5, seed = 3 }
material = "rock"

[[region.dfn]]
name = "J1"
orientation = { distribution = "von_mises", mean = 20.0, concentration = 30.0 }
length = { distribution = "power_law", exponent = 2.5, min = 1.0, max = 6.0 }
p21 = 0.6
property = "joint"
seed = 4

[[region.dfn]]
name = "J2"
orientation = { distribution = "von_mises", mean = 110.0, concentration = 30.0 }
length = { distribution = "fixed", value = 2.0 }
count = 15
terminate = { at = ["J1"], probability = 0.5 }
seed = 5

[[joint_property]]
name = "bond"
law = "elastic"
kn = 1e12
ks = 1e12

[[joint_property]]
name = "joint"
law = "coulomb"
kn = 1e11
ks = 1e11
friction = 30.0

[[joint_assignment]]
property = "bond"
)";
    const auto mf = io::parse_model(text, "dfn.toml");
    REQUIRE(mf.geometry.regions[0].dfn.size() == 2);
    CHECK(mf.geometry.regions[0].dfn[1].terminate_at == std::vector<int>{0});
    const auto a = generate_blocks(mf.geometry);
    REQUIRE(a.fracture_sets.size() == 2);
    REQUIRE(a.fracture_stats.size() == 2);
    // Every stretch of trace inside the region became fracture joints of its set,
    // to the rounding: also where a trace ends inside a block that an earlier piece
    // of the same trace had split along its line (the tip is inserted as a vertex).
    double trace_length[2] = {0, 0}, joint_length[2] = {0, 0};
    for (std::size_t i = 0; i < a.fracture_traces.size(); ++i)
        trace_length[a.fracture_trace_set[i]] += norm(a.fracture_traces[i].b - a.fracture_traces[i].a);
    int bridges = 0;
    for (const auto& j : a.joints) {
        if (j.tag == JointTag::fracture) joint_length[j.fracture_set] += j.length();
        if (j.tag == JointTag::inner) ++bridges;
    }
    MESSAGE("traces " << trace_length[0] << " + " << trace_length[1] << " m, fracture joints " << joint_length[0]
                      << " + " << joint_length[1] << " m; " << a.block_count() << " blocks, " << bridges
                      << " inner joints");
    for (int k = 0; k < 2; ++k) CHECK(joint_length[k] == doctest::Approx(trace_length[k]).epsilon(1e-6));
    CHECK(trace_length[0] / 100.0 == doctest::Approx(a.fracture_stats[0].p21).epsilon(1e-9));
    CHECK(bridges > 100);
}

TEST_CASE("mapped joints from a DXF drawing cut the tunnel's bonded region, the curved fault as its chords") {
    const auto mf = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/dfn/tunnel_voronoi_mapped.toml");
    const auto& sets = mf.geometry.regions[1].dfn;
    REQUIRE(sets.size() == 3);
    CHECK(sets[0].traces.size() == 25); // layer J1: 25 LINEs
    CHECK(sets[1].traces.size() == 25);
    CHECK(sets[2].traces.size() == 17); // two arcs of 45.2° and 34.1°: 10 + 7 chords of <= 5°
    CHECK(sets[2].import_note.find("left out: 1 TEXT") != std::string::npos);
    const auto a = generate_blocks(mf.geometry);
    // The drawing is in mm: once in metres its traces cross the 8 m x 16 m region.
    std::vector<double> trace_length(3, 0.0), joint_length(3, 0.0);
    for (std::size_t i = 0; i < a.fracture_traces.size(); ++i)
        trace_length[a.fracture_trace_set[i]] += norm(a.fracture_traces[i].b - a.fracture_traces[i].a);
    for (const auto& j : a.joints)
        if (j.tag == JointTag::fracture) joint_length[j.fracture_set] += j.length();
    MESSAGE("mapped traces " << trace_length[0] << " / " << trace_length[1] << " / " << trace_length[2]
                             << " m, fracture joints " << joint_length[0] << " / " << joint_length[1] << " / "
                             << joint_length[2] << " m");
    for (int k = 0; k < 3; ++k) {
        CHECK(trace_length[k] > 1.0);
        CHECK(joint_length[k] == doctest::Approx(trace_length[k]).epsilon(1e-6));
    }
}

TEST_CASE("bbm sweep moves generated fracture sets with the seeds and sets joined keys together") {
    const std::string text = R"(
[[material]]
name = "rock"
young = 20e9
poisson = 0.25

[[region]]
name = "rock mass"
outline = { type = "rectangle", min = [0.0, 0.0], max = [10.0, 10.0] }
pattern = { type = "voronoi", size = 0.5, seed = 3 }
material = "rock"

[[region.dfn]]
name = "J1"
orientation = { distribution = "uniform" }
length = { distribution = "fixed", value = 2.0 }
p21 = 0.2
seed = 4

[[region.dfn]]
name = "J2"
orientation = { distribution = "uniform" }
length = { distribution = "fixed", value = 2.0 }
p21 = 0.1

[[joint_property]]
name = "bond"
law = "elastic"
kn = 1e12
ks = 1e12

[[joint_assignment]]
property = "bond"
)";
    const auto edits = studies::split_joined_keys({{"region[0].dfn[0].p21+region[0].dfn[1].p21", "0.35"}});
    REQUIRE(edits.size() == 2);
    CHECK(edits[1].first == "region[0].dfn[1].p21");
    const auto mf = io::parse_model(io::edit_model_text(text, "dfn.toml", edits, 2), "dfn.toml");
    const auto& region = mf.geometry.regions[0];
    REQUIRE(region.dfn.size() == 2);
    CHECK(region.dfn[0].p21 == 0.35);
    CHECK(region.dfn[1].p21 == 0.35);
    // Seed offset 2: the pattern's 3 -> 5, the sets' 4 -> 6 and (default) 1 -> 3, so
    // every realization of a sweep draws its own network.
    CHECK(region.pattern.seed == 5);
    CHECK(region.dfn[0].seed == 6);
    CHECK(region.dfn[1].seed == 3);
    CHECK_THROWS_AS(studies::parse_set("region[0].dfn[0].p21+=0.1"), InputError);
}

TEST_CASE("a network too large is refused before it is drawn — a dense one is cut into blocks that tile the region") {
    const auto model = [](const std::string& sets) {
        return std::string(R"(
[model]
max_elements = 1000000

[[region]]
name = "rock mass"
outline = { type = "rectangle", min = [0.0, 0.0], max = [40.0, 40.0] }
pattern = { type = "voronoi", size = 0.5, seed = 3 }
)") + sets + R"(
[[joint_property]]
name = "bond"
law = "elastic"
kn = 1e12
ks = 1e12

[[joint_assignment]]
property = "bond"
)";
    };
    const auto set = [](const std::string& name, double angle, long count, int seed, const std::string& extra) {
        return "[[region.dfn]]\nname = \"" + name + "\"\norientation = { distribution = \"von_mises\", mean = " +
               std::to_string(angle) + ", concentration = 10.0 }\nlength = { distribution = \"power_law\", exponent = "
               "2.5, min = 0.5, max = 5.0 }\ncount = " + std::to_string(count) + "\nseed = " + std::to_string(seed) +
               "\n" + extra;
    };
    auto error_of = [](const std::string& text) -> std::string {
        auto mf = io::parse_model(text, "dense.toml");
        try {
            (void)generate_blocks(mf.geometry);
        } catch (const GeometryError& e) {
            return e.key() + ": " + e.what();
        }
        return "";
    };
    // Ten million fractures: refused from the estimate, before any is drawn.
    const std::string huge = error_of(model(set("J1", 20.0, 10'000'000, 4, "")));
    MESSAGE(huge);
    CHECK(huge.find("dfn[0]: fracture set 'J1' would draw about") == 0);
    // 1,000 + 1,000 fractures (P21 0.66 /m each, 0.5 m blocks): once refused (a face
    // whose walk made an excursion along a fracture to a closed cycle of fractures
    // lost the cycle's corner), then cut with guards around a block-by-block split
    // (29 tips left inside blocks, spikes counting trace twice). Cut exactly now:
    // the blocks tile the region, every trace is fracture joints once, no tip is
    // left inside a block (tests/cutting_checks.hpp).
    auto mf = io::parse_model(model(set("J1", 20.0, 1000, 4, "") +
                                    set("J2", 110.0, 1000, 5, "terminate = { at = [\"J1\"], probability = 0.5 }\n")),
                              "dense.toml");
    const auto t = cutting_checks::measure(mf.geometry, 1600.0);
    MESSAGE(t.blocks << " blocks over " << t.area << " m²; traces " << t.trace_length << " m, fracture joints "
                     << t.fracture_joints << " m; " << t.stats.rock_bridges << " rock bridges, "
                     << t.stats.merged_slivers << " slivers merged");
    cutting_checks::check(t, "1,000 + 1,000 fractures");
    CHECK(t.blocks > 15000);
    // Slivers where fractures cross nearly at one point (2.7e-10 m² here) are
    // merged into a neighbour: none is left under 1e-8 of a block's area.
    const auto a = generate_blocks(mf.geometry);
    double smallest = 1e300;
    for (int b = 0; b < a.block_count(); ++b) smallest = std::min(smallest, a.area[b]);
    MESSAGE("smallest block " << smallest << " m²");
    CHECK(t.stats.merged_slivers > 0);
    CHECK(t.stats.slivers_left == 0);
    CHECK(smallest >= 1e-8 * 0.5 * 0.5);
}
