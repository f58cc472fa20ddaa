// libFuzzer target: cutting a region by its traces (meshing/cutting.hpp).
//
// The input is a network: its first byte picks the pattern (and whether the region
// has a tunnel through it), the rest are traces of 4 bytes each, their ends on a
// grid of 0.02 m over a 4 m x 4 m region and half a metre beyond it, so that the
// degenerate cases an exact computation must get right come up all the time:
// traces sharing ends, ending on one another, overlapping, running along the
// region's edge or through a pattern's vertices. Seeds: dense networks
// (tests/fuzz/seeds/cut, written by make_cut_seeds.py). Every network must be cut
// without an error — the region is valid whatever the traces — into blocks that
// tile it, each of positive area. Anything else is a bug: an exception, an area off by more than the
// rounding, a crash, a sanitizer report or (built without NDEBUG, as .ci/fuzz
// builds it) a failed CGAL precondition or assertion.
#include "meshing/blocks.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace bbm;
    using namespace bbm::meshing;
    if (size < 1) return 0;
    ModelGeometrySpec spec;
    spec.max_elements = 20000;
    RegionSpec reg;
    reg.name = "rock";
    reg.outline.kind = OutlineSpec::Kind::rectangle;
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {4.0, 4.0};
    const PatternSpec::Kind kinds[] = {PatternSpec::Kind::voronoi, PatternSpec::Kind::trigon,
                                       PatternSpec::Kind::delaunay, PatternSpec::Kind::hexagonal,
                                       PatternSpec::Kind::brick, PatternSpec::Kind::single};
    reg.pattern.kind = kinds[(data[0] & 0x7f) % 6];
    reg.pattern.size = reg.pattern.kind == PatternSpec::Kind::single ? 0.0 : 0.4;
    reg.pattern.seed = data[0];
    double area = 16.0;
    if (data[0] & 0x80) {
        OutlineSpec hole;
        hole.kind = OutlineSpec::Kind::circle;
        hole.center = {2.0, 2.0};
        hole.radius = 0.7;
        reg.holes.push_back(hole);
        const int n = std::max(8, int(std::ceil(2.0 * std::numbers::pi * hole.radius / spec.max_segment)));
        area -= 0.5 * n * hole.radius * hole.radius * std::sin(2.0 * std::numbers::pi / n);
    }
    auto coordinate = [](std::uint8_t b) { return -0.5 + 0.02 * double(b % 251); }; // -0.5 .. 4.5
    for (std::size_t i = 1; i + 4 <= size && reg.joints.size() < 400; i += 4)
        reg.joints.push_back({{coordinate(data[i]), coordinate(data[i + 1])},
                              {coordinate(data[i + 2]), coordinate(data[i + 3])}});
    spec.regions.push_back(reg);
    const BlockAssembly a = generate_blocks(spec); // any exception escapes: a finding
    double covered = 0.0;
    for (int b = 0; b < a.block_count(); ++b) {
        if (!(a.area[std::size_t(b)] > 0.0)) {
            std::fprintf(stderr, "block %d has area %.17g\n", b, a.area[std::size_t(b)]);
            std::abort();
        }
        covered += a.area[std::size_t(b)];
    }
    if (!(std::abs(covered - area) <= 1e-9 * area)) {
        std::fprintf(stderr, "blocks cover %.17g m² of %.17g m²\n", covered, area);
        std::abort();
    }
    return 0;
}
