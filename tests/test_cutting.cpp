// Cutting a region by its traces (meshing/cutting.hpp) is exact, so it cannot
// fail: 200 random networks in 6 m x 6 m (orientation and length laws, intensities
// up to 10,000 fractures in 40 m x 40 m, clustering, termination, every pattern,
// tunnels; the long suite has them at 40 m x 40 m)
// and networks of traces on a coarse grid (shared ends, T-junctions, overlaps,
// traces along the region's edge) are cut with no error into blocks that tile the
// region, with every stretch of trace a fracture joint once and no trace ending
// inside a block (tests/cutting_checks.hpp). And the rules, one by one: a trace
// ending inside a block goes on to its edge; a fracture ending at an earlier one
// ends exactly on it (no rock bridge beyond); a closed cycle of fractures inside a
// block is opened by a vertical cut; slivers are merged.
#include "cutting_checks.hpp"

#include "meshing/blocks.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"

#include <cmath>
#include <random>
#include <string>

using namespace bbm;
using namespace bbm::meshing;
using namespace bbm::cutting_checks;

namespace {

/// 10,000 fractures in 40 m x 40 m: centres per m².
constexpr double dense = 10000.0 / 1600.0;

void random_networks(std::uint64_t first, int n) {
    int blocks = 0, bridges = 0, merged = 0, holes = 0, exact_length = 0;
    double worst = 0.0;
    for (std::uint64_t seed = first; seed < first + std::uint64_t(n); ++seed) {
        double area = 0.0;
        const auto spec = random_network(seed, 6.0, dense, area);
        Tiling t;
        try {
            t = measure(spec, area);
        } catch (const std::exception& e) {
            FAIL("network " << seed << " failed: " << e.what());
        }
        check(t, "network " + std::to_string(seed));
        blocks += t.blocks, bridges += t.stats.rock_bridges, merged += t.stats.merged_slivers, holes += t.stats.hole_cuts;
        const double miss = std::abs(t.fracture_joints - t.trace_length) / std::max(t.trace_length, 1.0);
        exact_length += miss <= 1e-6;
        worst = std::max(worst, miss);
    }
    MESSAGE(n << " networks: " << blocks << " blocks, " << bridges << " rock bridges, " << holes << " hole cuts, "
              << merged << " slivers merged; fracture joints within 1e-6 of the traces in " << exact_length
              << ", at worst " << worst << " off");
}

ModelGeometrySpec square_with(std::vector<SegmentSpec> joints, PatternSpec::Kind kind, double size = 0.5) {
    ModelGeometrySpec spec;
    RegionSpec reg;
    reg.name = "rock";
    reg.outline.kind = OutlineSpec::Kind::rectangle;
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {4.0, 4.0};
    reg.pattern.kind = kind;
    reg.pattern.size = kind == PatternSpec::Kind::single ? 0.0 : size;
    reg.pattern.seed = 7;
    reg.joints = std::move(joints);
    spec.regions.push_back(std::move(reg));
    return spec;
}

/// Joints cut as explicit segments: their length that became joints of the tag
/// real_joint, and the stats.
double real_joint_length(const ModelGeometrySpec& spec, GenerationStats& st, int* blocks = nullptr) {
    const auto a = generate_blocks(spec, &st);
    double l = 0.0;
    for (const auto& j : a.joints)
        if (j.tag == JointTag::real_joint) l += j.length();
    double area = 0.0;
    for (int b = 0; b < a.block_count(); ++b) area += a.area[std::size_t(b)];
    CHECK(area == doctest::Approx(16.0).epsilon(1e-12));
    if (blocks) *blocks = a.block_count();
    return l;
}

} // namespace

TEST_CASE("random networks 1-50 are cut exactly: the blocks tile the region, every trace is joints, no tip inside a block" * validation) {
    random_networks(1, 50);
}
TEST_CASE("random networks 51-100 are cut exactly" * validation) { random_networks(51, 50); }
TEST_CASE("random networks 101-150 are cut exactly" * validation) { random_networks(101, 50); }
TEST_CASE("random networks 151-200 are cut exactly" * validation) { random_networks(151, 50); }

TEST_CASE("traces on a coarse grid: shared ends, T-junctions, overlaps and traces along the edge are cut exactly") {
    // Coordinates on a 0.25 m grid make every degeneracy happen: traces that share
    // an end, end on another, overlap one, run along the region's edge or across a
    // pattern's vertex, or have no length.
    std::mt19937_64 rng(5);
    const PatternSpec::Kind kinds[] = {PatternSpec::Kind::voronoi, PatternSpec::Kind::brick, PatternSpec::Kind::single,
                                       PatternSpec::Kind::hexagonal, PatternSpec::Kind::trigon};
    for (int c = 0; c < 40; ++c) {
        std::vector<SegmentSpec> joints;
        const int n = 2 + int(rng() % 30);
        auto grid = [&] { return 0.25 * double(int(rng() % 21) - 2); }; // -0.5 .. 4.5
        for (int i = 0; i < n; ++i) joints.push_back({{grid(), grid()}, {grid(), grid()}});
        auto spec = square_with(joints, kinds[c % 5], 0.4);
        spec.regions[0].pattern.angle = 0.0; // lattices aligned with the grid: more coincidences
        GenerationStats st;
        INFO("case " << c << ", " << n << " traces");
        CHECK_NOTHROW((void)real_joint_length(spec, st));
    }
}

TEST_CASE("a trace ending inside a block goes on along its line to the block's edge: the rock bridge") {
    // One trace wholly inside a single block: both tips go on to the block's edge,
    // cutting it in two; the trace is a real joint, the two bridges inner joints.
    GenerationStats st;
    int blocks = 0;
    const double l = real_joint_length(square_with({{{1.5, 2.0}, {2.5, 2.0}}}, PatternSpec::Kind::single), st, &blocks);
    CHECK(st.rock_bridges == 2);
    CHECK(blocks == 2);
    CHECK(l == doctest::Approx(1.0).epsilon(1e-12));
    // A trace ending exactly on a pattern's edge (a brick's) needs no bridge there.
    auto spec = square_with({{{0.5, 1.0}, {2.0, 1.0}}}, PatternSpec::Kind::brick, 0.5);
    spec.regions[0].pattern.size_measure = PatternSpec::SizeMeasure::area;
    (void)real_joint_length(spec, st);
    CHECK(st.rock_bridges == 0);
}

TEST_CASE("a fracture that ends at an earlier one ends exactly on it: no rock bridge beyond") {
    // J2 crosses J1 everywhere it can and ends at the first crossing with
    // probability 1: its ends on J1 are where the lines cross, not points rounded
    // to one side, so no bridge is carried on across J1 (once half of such ends
    // overshot J1 by an ulp and split the block beyond it).
    ModelGeometrySpec spec;
    RegionSpec reg;
    reg.name = "rock";
    reg.outline.kind = OutlineSpec::Kind::rectangle;
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {10.0, 10.0};
    reg.pattern.kind = PatternSpec::Kind::single;
    DfnSetSpec j1;
    j1.name = "J1";
    j1.orientation.mean = 0.0;
    j1.orientation.concentration = 50.0;
    j1.length.kind = FractureLengthSpec::Kind::fixed;
    j1.length.value = 30.0; // cuts through the region
    j1.count = 6;
    j1.seed = 3;
    DfnSetSpec j2 = j1;
    j2.name = "J2";
    j2.orientation.mean = 90.0;
    j2.length.value = 4.0;
    j2.count = 40;
    j2.seed = 4;
    j2.terminate_at = {0};
    j2.terminate_probability = 1.0;
    reg.dfn = {j1, j2};
    spec.regions.push_back(reg);
    double area = 100.0;
    const Tiling t = measure(spec, area);
    check(t, "J2 ending at J1");
    // Every end is on another trace, on the region's edge or free inside the rock:
    // the free ones (a J2 that did not reach a J1 before its length ran out, a J1
    // centred outside) are the only bridges.
    const auto a = generate_blocks(spec);
    int free_ends = 0;
    for (std::size_t i = 0; i < a.fracture_traces.size(); ++i) {
        for (Vec2 p : {a.fracture_traces[i].a, a.fracture_traces[i].b}) {
            bool on_other = false;
            for (std::size_t k = 0; k < a.fracture_traces.size(); ++k)
                if (k != i && distance_to_segment(p, a.fracture_traces[k].a, a.fracture_traces[k].b) < 1e-9)
                    on_other = true;
            const bool on_edge = p.x <= 1e-9 || p.y <= 1e-9 || p.x >= 10 - 1e-9 || p.y >= 10 - 1e-9;
            if (!on_other && !on_edge) ++free_ends;
        }
    }
    MESSAGE(t.stats.rock_bridges << " rock bridges, " << free_ends << " ends free in the rock");
    CHECK(free_ends > 0);
    CHECK(t.stats.rock_bridges == free_ends);
}

TEST_CASE("a closed cycle of fractures inside a block is opened by a vertical cut — a sliver is merged") {
    // A triangle of traces inside one block: a block of its own, and the block
    // around it, which would have a hole, is cut open along the vertical line
    // through the middle of the triangle's x-range.
    GenerationStats st;
    int blocks = 0;
    const std::vector<SegmentSpec> triangle{{{1.0, 1.0}, {3.0, 1.5}}, {{3.0, 1.5}, {1.5, 3.0}}, {{1.5, 3.0}, {1.0, 1.0}}};
    (void)real_joint_length(square_with(triangle, PatternSpec::Kind::single), st, &blocks);
    CHECK(st.hole_cuts == 1);
    CHECK(blocks == 3); // the triangle, and the rest in two
    // Three traces crossing nearly at one point leave a triangle of 1e-13 m²
    // between them: under 1e-8 of a block's area, merged into a neighbour.
    const std::vector<SegmentSpec> near_point{
        {{0.0, 2.0}, {4.0, 2.0}}, {{2.0, 0.0}, {2.0, 4.0}}, {{0.0, 4.0 + 1e-6}, {4.0, 0.0 + 1e-6}}};
    (void)real_joint_length(square_with(near_point, PatternSpec::Kind::voronoi, 0.5), st, &blocks);
    CHECK(st.merged_slivers >= 1);
}
