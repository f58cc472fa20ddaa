// What every cut of a region by its traces must satisfy, and random networks to
// hold it to (tests/test_cutting.cpp; the large networks in the long suite):
//   * the blocks tile the region: their areas add up to its area within 1e-9;
//   * every stretch of trace inside it became fracture joints, once: their lengths
//     add up to the clipped traces' less the stretches between merged slivers and
//     their neighbours (reported) within 1e-9, and those stretches are under 1e-5
//     of the traces (micrometres where two traces run within micrometres);
//   * no trace ends inside a block: every tip is on a block's edge (a trace that
//     stops inside a block goes on to its edge as a rock bridge).
#pragma once

#include "meshing/blocks.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace bbm::cutting_checks {

using namespace bbm::meshing;

struct Tiling {
    int blocks = 0;
    double area = 0.0, region_area = 0.0;
    double trace_length = 0.0, fracture_joints = 0.0;
    int tips = 0, tips_inside = 0; ///< trace ends in the region; those strictly inside a block
    GenerationStats stats;
};

/// Blocks, areas, trace lengths and tips of region `r` (the only region with
/// fractures) as generated from `spec`.
inline Tiling measure(const ModelGeometrySpec& spec, double region_area) {
    Tiling t;
    const BlockAssembly a = generate_blocks(spec, &t.stats);
    t.blocks = a.block_count();
    t.region_area = region_area;
    for (int b = 0; b < a.block_count(); ++b) t.area += a.area[std::size_t(b)];
    for (const auto& s : a.fracture_traces) t.trace_length += norm(s.b - s.a);
    for (const auto& j : a.joints)
        if (j.tag == JointTag::fracture) t.fracture_joints += j.length();
    // A tip strictly inside a block: farther than the rounding from all its edges.
    Box2 all;
    for (const Vec2& p : a.points) all.add(p);
    const double tol = 1e-9 * std::max(all.width(), all.height());
    const double cell = std::max(0.5, all.width() / 256.0);
    const int nx = int(all.width() / cell) + 1, ny = int(all.height() / cell) + 1;
    std::vector<std::vector<int>> grid(std::size_t(nx) * std::size_t(ny));
    auto cx = [&](double x) { return std::clamp(int((x - all.lo.x) / cell), 0, nx - 1); };
    auto cy = [&](double y) { return std::clamp(int((y - all.lo.y) / cell), 0, ny - 1); };
    for (int b = 0; b < a.block_count(); ++b) {
        const Box2 bb = bounding_box(a.block(b));
        for (int j = cy(bb.lo.y); j <= cy(bb.hi.y); ++j)
            for (int i = cx(bb.lo.x); i <= cx(bb.hi.x); ++i) grid[std::size_t(j * nx + i)].push_back(b);
    }
    for (const auto& s : a.fracture_traces)
        for (const Vec2 p : {s.a, s.b}) {
            ++t.tips;
            for (int b : grid[std::size_t(cy(p.y) * nx + cx(p.x))]) {
                const auto poly = a.block(b);
                double d = INFINITY;
                for (std::size_t i = 0; i < poly.size(); ++i)
                    d = std::min(d, distance_to_segment(p, poly[i], poly[(i + 1) % poly.size()]));
                if (d > tol && point_in_polygon(p, poly)) ++t.tips_inside;
            }
        }
    return t;
}

/// The three properties, as doctest checks with the case named.
inline void check(const Tiling& t, const std::string& name) {
    INFO(name << ": " << t.blocks << " blocks, " << t.area << " of " << t.region_area << " m², traces "
              << t.trace_length << " m, fracture joints " << t.fracture_joints << " m, " << t.tips_inside << " of "
              << t.tips << " tips inside a block");
    CHECK(std::abs(t.area - t.region_area) <= 1e-9 * t.region_area);
    const double scale = std::max(t.trace_length, 1.0);
    CHECK(std::abs(t.fracture_joints - (t.trace_length - t.stats.merged_trace_length)) <= 1e-9 * scale);
    CHECK(t.stats.merged_trace_length <= 1e-5 * scale);
    CHECK(t.tips_inside == 0);
}

/// A random network in a `side` × `side` region of 0.5 m blocks: 1 to 3 sets with
/// random orientation laws, length laws, intensities up to `max_per_m2` fracture
/// centres per m², clustering and termination; the pattern mostly Voronoi, at times
/// another; at times a tunnel hole. `area` receives the region's area.
inline ModelGeometrySpec random_network(std::uint64_t seed, double side, double max_per_m2, double& area) {
    std::mt19937_64 rng(seed);
    auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * double(rng() >> 11) * 0x1.0p-53; };
    auto pick = [&](int n) { return int(rng() % std::uint64_t(n)); };
    ModelGeometrySpec spec;
    spec.max_segment = 0.1;
    RegionSpec reg;
    reg.name = "rock mass";
    reg.outline.kind = OutlineSpec::Kind::rectangle;
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {side, side};
    area = side * side;
    if (pick(4) == 0) { // a tunnel through it
        OutlineSpec hole;
        hole.kind = OutlineSpec::Kind::circle;
        hole.center = {uniform(0.3, 0.7) * side, uniform(0.3, 0.7) * side};
        hole.radius = uniform(0.05, 0.2) * side;
        reg.holes.push_back(hole);
        const int n = std::max(8, int(std::ceil(2.0 * M_PI * hole.radius / spec.max_segment)));
        area -= 0.5 * n * hole.radius * hole.radius * std::sin(2.0 * M_PI / n);
    }
    const PatternSpec::Kind kinds[] = {PatternSpec::Kind::voronoi, PatternSpec::Kind::voronoi, PatternSpec::Kind::voronoi,
                                       PatternSpec::Kind::trigon,  PatternSpec::Kind::brick,   PatternSpec::Kind::hexagonal,
                                       PatternSpec::Kind::delaunay, PatternSpec::Kind::single};
    reg.pattern.kind = kinds[pick(8)];
    reg.pattern.size = reg.pattern.kind == PatternSpec::Kind::single ? 0.0 : 0.5;
    reg.pattern.seed = rng();
    reg.pattern.lloyd_iterations = pick(4) == 0 ? 1 : 0;
    reg.pattern.angle = uniform(0.0, 90.0) * double(pick(2));
    const int sets = 1 + pick(3);
    for (int k = 0; k < sets; ++k) {
        DfnSetSpec s;
        s.name = "J" + std::to_string(k + 1);
        s.seed = rng();
        if (pick(3) == 0) {
            s.orientation.kind = FractureOrientationSpec::Kind::uniform;
        } else {
            s.orientation.mean = uniform(0.0, 180.0);
            s.orientation.concentration = uniform(0.5, 60.0);
        }
        switch (pick(4)) {
        case 0:
            s.length.kind = FractureLengthSpec::Kind::power_law;
            s.length.exponent = uniform(1.5, 3.5);
            s.length.min = uniform(0.2, 1.0);
            s.length.max = s.length.min * uniform(2.0, 20.0);
            break;
        case 1:
            s.length.kind = FractureLengthSpec::Kind::lognormal;
            s.length.mean = uniform(0.5, 3.0);
            s.length.std_dev = s.length.mean * uniform(0.2, 1.0);
            s.length.min = 0.1;
            s.length.max = 3.0 * side;
            break;
        case 2:
            s.length.kind = FractureLengthSpec::Kind::exponential;
            s.length.mean = uniform(0.3, 2.0);
            s.length.min = 0.05;
            break;
        default:
            s.length.kind = FractureLengthSpec::Kind::fixed;
            s.length.value = uniform(0.2, 0.6 * side);
        }
        s.count = long(std::ceil(uniform(0.01, 1.0) * max_per_m2 * side * side / sets));
        if (pick(4) == 0) {
            s.centres = DfnSetSpec::Centres::clustered;
            s.cluster_size = uniform(3.0, 30.0);
            s.cluster_radius = uniform(0.2, 2.0);
        }
        if (k > 0 && pick(2) == 0) {
            s.terminate_at = {pick(k)};
            s.terminate_probability = pick(3) == 0 ? 1.0 : uniform(0.1, 0.9);
        }
        reg.dfn.push_back(std::move(s));
    }
    spec.regions.push_back(std::move(reg));
    spec.max_elements = 1e7;
    return spec;
}

} // namespace bbm::cutting_checks
