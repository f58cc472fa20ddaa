// The long variants of tests/test_cutting.cpp: dense networks at full size.
//   * the four networks of 10,000 fractures in 40 m x 40 m of 0.5 m Voronoi blocks
//     that bbm once refused (three: "blocks cover 1599.99 m² of 1600") or crashed
//     on (one: SIGSEGV inside CGAL's Boolean operations), and the documented one
//     (docs/notes/2026-11-25-dfn-cutting-guards.md) that left 163 trace tips unsplit;
//   * 20 random networks in 40 m x 40 m with up to 10,000 fractures.
// Each must be cut with no error into blocks that tile the region, every trace a
// fracture joint once, no tip inside a block (tests/cutting_checks.hpp).
#include "cutting_checks.hpp"

#include <doctest/doctest.h>

#include <chrono>
#include <string>

using namespace bbm;
using namespace bbm::meshing;
using namespace bbm::cutting_checks;

namespace {

/// Two power-law sets (0.5-5 m, exponent 2.5, κ 10) of 5,000 fractures each in
/// 40 m x 40 m of 0.5 m Voronoi blocks, the second ending at the first with
/// probability 0.5.
ModelGeometrySpec two_sets(double angle1, double angle2, std::uint64_t seed1, std::uint64_t seed2) {
    ModelGeometrySpec spec;
    spec.max_elements = 1e7;
    RegionSpec reg;
    reg.name = "rock";
    reg.outline.kind = OutlineSpec::Kind::rectangle;
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {40.0, 40.0};
    reg.pattern.kind = PatternSpec::Kind::voronoi;
    reg.pattern.size = 0.5;
    reg.pattern.seed = 3;
    for (int k = 0; k < 2; ++k) {
        DfnSetSpec s;
        s.name = k == 0 ? "J1" : "J2";
        s.orientation.mean = k == 0 ? angle1 : angle2;
        s.orientation.concentration = 10.0;
        s.length.kind = FractureLengthSpec::Kind::power_law;
        s.length.exponent = 2.5;
        s.length.min = 0.5;
        s.length.max = 5.0;
        s.count = 5000;
        s.seed = k == 0 ? seed1 : seed2;
        if (k == 1) {
            s.terminate_at = {0};
            s.terminate_probability = 0.5;
        }
        reg.dfn.push_back(s);
    }
    spec.regions.push_back(reg);
    return spec;
}

void dense(const std::string& name, const ModelGeometrySpec& spec) {
    const auto t0 = std::chrono::steady_clock::now();
    const Tiling t = measure(spec, 1600.0);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    MESSAGE(name << ": " << t.blocks << " blocks, " << t.stats.rock_bridges << " rock bridges, "
                 << t.stats.merged_slivers << " slivers merged (" << t.stats.slivers_left << " left), "
                 << t.stats.hole_cuts << " hole cuts, " << s << " s");
    check(t, name);
}

} // namespace

TEST_CASE("10,000 fractures in 40 m x 40 m, the networks once refused or crashed on, are cut exactly") {
    dense("35/125 degrees, seeds 21, 22 (refused: 1600.01 m²)", two_sets(35.0, 125.0, 21, 22));
    dense("10/80 degrees, seeds 31, 32 (SIGSEGV in CGAL)", two_sets(10.0, 80.0, 31, 32));
    dense("60/150 degrees, seeds 41, 42 (refused: 1599.99 m²)", two_sets(60.0, 150.0, 41, 42));
    dense("0/95 degrees, seeds 51, 52 (refused: 1600.00 m²)", two_sets(0.0, 95.0, 51, 52));
    dense("20/110 degrees, seeds 4, 5 (docs/notes/2026-11-25-dfn-cutting-guards.md: 163 tips unsplit)", two_sets(20.0, 110.0, 4, 5));
}

TEST_CASE("20 random networks in 40 m x 40 m with up to 10,000 fractures are cut exactly") {
    int blocks = 0;
    for (std::uint64_t seed = 1001; seed <= 1020; ++seed) {
        double area = 0.0;
        const auto spec = random_network(seed, 40.0, 10000.0 / 1600.0, area);
        const Tiling t = measure(spec, area);
        check(t, "network " + std::to_string(seed));
        blocks += t.blocks;
    }
    MESSAGE("20 networks: " << blocks << " blocks");
}
