// Geometry generation (meshing/): tiling, polygon validity, edge lengths, block
// sizes, pattern invariants, real joints, topology and invalid geometry.
#include "base/error.hpp"
#include "meshing/blocks.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>

using namespace bbm;
using namespace bbm::meshing;

namespace {

RegionSpec rect_region(std::string name, Vec2 lo, Vec2 hi, PatternSpec::Kind kind, double size,
                       std::uint64_t seed = 1) {
    RegionSpec r;
    r.name = std::move(name);
    r.outline.kind = OutlineSpec::Kind::rectangle;
    r.outline.min = lo;
    r.outline.max = hi;
    r.pattern.kind = kind;
    r.pattern.size = size;
    r.pattern.seed = seed;
    return r;
}

OutlineSpec circle(Vec2 c, double r) {
    OutlineSpec o;
    o.kind = OutlineSpec::Kind::circle;
    o.center = c;
    o.radius = r;
    return o;
}

ModelGeometrySpec one(RegionSpec r) {
    ModelGeometrySpec m;
    m.regions.push_back(std::move(r));
    return m;
}

/// Mean Feret diameter of the blocks of `region` whose whole boundary is jointed
/// to blocks of the same region (the others are cut by its outline).
double interior_feret(const BlockAssembly& a, int region) {
    std::vector<double> jointed(a.block_count(), 0.0);
    for (const auto& j : a.joints)
        if (a.region[j.block_a] == region && a.region[j.block_b] == region)
            jointed[j.block_a] += j.length(), jointed[j.block_b] += j.length();
    double sum = 0.0;
    int n = 0;
    for (int b = 0; b < a.block_count(); ++b) {
        if (a.region[b] != region) continue;
        const auto p = a.block(b);
        double perimeter = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) perimeter += norm(p[(i + 1) % p.size()] - p[i]);
        if (jointed[b] > perimeter * (1 - 1e-9)) sum += mean_feret_diameter(p), ++n;
    }
    return n ? sum / n : 0.0;
}

/// The paper's tunnel model (examples/tunnel_*.toml) built in code.
ModelGeometrySpec tunnel(PatternSpec::Kind kind) {
    ModelGeometrySpec m;
    auto outer = rect_region("outer", {0, -20}, {20, 20}, PatternSpec::Kind::single, 0);
    outer.minus = {"bonded"};
    auto bonded = rect_region("bonded", {0, -8}, {8, 8}, kind, 0.3, 7);
    bonded.minus = {"opening"};
    RegionSpec opening;
    opening.name = "opening";
    opening.outline.kind = OutlineSpec::Kind::path;
    opening.outline.start = {0, -4};
    opening.outline.steps.push_back({{0, 4}, true, {0, 0}, false});
    opening.pattern.kind = kind;
    opening.pattern.size = 0.3;
    opening.pattern.seed = 8;
    m.regions = {outer, bonded, opening};
    return m;
}

double total_edge_length(const BlockAssembly& a) {
    double l = 0;
    for (int b = 0; b < a.block_count(); ++b) {
        const auto p = a.block(b);
        for (std::size_t i = 0; i < p.size(); ++i) l += norm(p[(i + 1) % p.size()] - p[i]);
    }
    return l;
}

double total_joint_length(const BlockAssembly& a) {
    double l = 0;
    for (const auto& j : a.joints) l += j.length();
    return l;
}

/// Proper crossing, with points within `tol` of the other segment's line counted
/// as on it (vertices created on a joint line are rounded to within 1e-16 of it).
bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d, double tol = 0.0) {
    const double lab = norm(b - a), lcd = norm(d - c);
    const double s1 = cross(b - a, c - a) / lab, s2 = cross(b - a, d - a) / lab;
    const double s3 = cross(d - c, a - c) / lcd, s4 = cross(d - c, b - c) / lcd;
    return ((s1 > tol && s2 < -tol) || (s1 < -tol && s2 > tol)) &&
           ((s3 > tol && s4 < -tol) || (s3 < -tol && s4 > tol));
}

bool is_simple_ccw(std::span<const Vec2> p) {
    if (p.size() < 3 || signed_area(p) <= 0) return false;
    const std::size_t n = p.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue;
            if (segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
        }
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            if (p[i] == p[j]) return false;
    return true;
}

double min_edge(const BlockAssembly& a, PatternSpec::Kind skip = PatternSpec::Kind::single) {
    double m = INFINITY;
    for (int b = 0; b < a.block_count(); ++b) {
        if (a.pattern[b] == skip) continue;
        const auto p = a.block(b);
        for (std::size_t i = 0; i < p.size(); ++i) m = std::min(m, norm(p[(i + 1) % p.size()] - p[i]));
    }
    return m;
}

/// Σ edge lengths = 2 Σ joint lengths + outer perimeter holds only if the blocks
/// neither overlap nor leave gaps along shared boundaries, and the joint records
/// cover every shared stretch exactly once.
void check_tiling(const BlockAssembly& a, double area, double perimeter) {
    double sum = 0;
    for (double x : a.area) sum += x;
    CHECK(std::abs(sum - area) <= 1e-9 * area);
    CHECK(std::abs(total_edge_length(a) - 2 * total_joint_length(a) - perimeter) <= 1e-9 * perimeter);
    for (int b = 0; b < a.block_count(); ++b) {
        INFO("block " << b);
        REQUIRE(is_simple_ccw(a.block(b)));
    }
}

std::uint64_t hash(const BlockAssembly& a) {
    std::uint64_t h = 1469598103934665603ull;
    for (Vec2 p : a.points)
        for (double v : {p.x, p.y}) {
            std::uint64_t bits;
            std::memcpy(&bits, &v, 8);
            h = (h ^ bits) * 1099511628211ull;
        }
    return h;
}

} // namespace

TEST_CASE("polygon integrals are exact for a rectangle and a triangle") {
    const std::vector<Vec2> r{{0, 0}, {2, 0}, {2, 1}, {0, 1}};
    CHECK(signed_area(r) == doctest::Approx(2.0).epsilon(1e-15));
    CHECK(centroid(r).x == doctest::Approx(1.0));
    CHECK(centroid(r).y == doctest::Approx(0.5));
    // ∫(x²+y²)dA about the centroid of a b×h rectangle = b h (b² + h²) / 12.
    CHECK(polar_moment_about_centroid(r) == doctest::Approx(2.0 * 5.0 / 12.0).epsilon(1e-14));
    const std::vector<Vec2> t{{1e6, 1e6}, {1e6 + 3, 1e6}, {1e6, 1e6 + 3}};
    CHECK(centroid(t).x == doctest::Approx(1e6 + 1.0).epsilon(1e-14));
}

TEST_CASE("mean Feret diameter: perimeter of the convex hull over pi") {
    const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    CHECK(mean_feret_diameter(square) == doctest::Approx(4.0 / std::numbers::pi).epsilon(1e-14));
    // An L-shape has the mean width of its hull (the unit square with a corner cut).
    const std::vector<Vec2> ell{{0, 0}, {1, 0}, {1, 0.5}, {0.5, 0.5}, {0.5, 1}, {0, 1}};
    CHECK(mean_feret_diameter(ell) == doctest::Approx((3.0 + std::sqrt(0.5)) / std::numbers::pi).epsilon(1e-14));
    // A regular hexagon of side s: 6 s / π, against 1.82 s for the diameter of its area.
    std::vector<Vec2> hex;
    for (int k = 0; k < 6; ++k) hex.push_back({std::cos(k * std::numbers::pi / 3), std::sin(k * std::numbers::pi / 3)});
    CHECK(mean_feret_diameter(hex) == doctest::Approx(6.0 / std::numbers::pi).epsilon(1e-14));
}

TEST_CASE("random patterns: size is the blocks' mean Feret diameter, or the diameter of their mean area") {
    for (auto kind : {PatternSpec::Kind::voronoi, PatternSpec::Kind::trigon, PatternSpec::Kind::delaunay}) {
        for (int lloyd : {0, 2}) {
            INFO(std::string(to_string(kind)) << ", lloyd " << lloyd);
            auto r = rect_region("rock", {0, 0}, {12, 12}, kind, 0.4, 5);
            r.pattern.lloyd_iterations = lloyd;
            const auto feret = generate_blocks(one(r));
            CHECK(interior_feret(feret, 0) == doctest::Approx(0.4).epsilon(0.03));
            check_tiling(feret, 144.0, 48.0);
            r.pattern.size_measure = PatternSpec::SizeMeasure::area;
            const auto area = generate_blocks(one(r));
            // By area: Voronoi cells of that equal-area diameter; trigon splits such
            // cells (about six triangles each). (Delaunay drops seeds closer than its
            // hard core, so its triangles by area come out larger: tested below.)
            if (kind == PatternSpec::Kind::voronoi)
                CHECK(mean_block_size(area) == doctest::Approx(0.4).epsilon(0.05));
            if (kind == PatternSpec::Kind::trigon)
                CHECK(double(area.block_count()) / 6.0 ==
                      doctest::Approx(144.0 / (std::numbers::pi * 0.04)).epsilon(0.1));
        }
    }
}

TEST_CASE("the paper's tunnel model tiles its 20 m x 40 m domain") {
    for (auto kind : {PatternSpec::Kind::voronoi, PatternSpec::Kind::trigon, PatternSpec::Kind::delaunay}) {
        INFO("pattern " << to_string(kind));
        const auto spec = tunnel(kind);
        GenerationStats st;
        const auto a = generate_blocks(spec, &st);
        check_tiling(a, 800.0, 120.0);
        // Region areas: the half disc is a polyline of pieces <= 0.1 m.
        const double half_disc = signed_area(outline_polygon(spec.regions[2].outline, spec.max_segment));
        CHECK(half_disc == doctest::Approx(8 * std::numbers::pi).epsilon(2e-4));
        std::map<int, double> area;
        for (int b = 0; b < a.block_count(); ++b) area[a.region[b]] += a.area[b];
        CHECK(std::abs(area[1] - (128.0 - half_disc)) <= 1e-9 * 128.0);
        CHECK(std::abs(area[2] - half_disc) <= 1e-9 * 128.0);
        int interface = 0;
        for (const auto& j : a.joints) {
            REQUIRE((a.region[j.block_a] != a.region[j.block_b]) == (j.tag == JointTag::interface));
            interface += j.tag == JointTag::interface;
        }
        CHECK(interface > 0);
        // Blocks of 0.3 m average dimension (mean Feret diameter) away from the
        // region's outline, which cuts the others.
        CHECK(interior_feret(a, 1) == doctest::Approx(0.3).epsilon(0.03));
        if (kind == PatternSpec::Kind::voronoi) {
            // A short edge is collapsed unless that would shrink a block by more than
            // 3/4 or move the region's outline: with the cells of random points a
            // couple of such edges remain at the opening, reported and just short.
            CHECK(min_edge(a) >= 0.9 * 0.03);
            CHECK(st.short_edges_left <= 4);
        }
    }
}

TEST_CASE("voronoi: size, minimum edge and Lloyd relaxation") {
    for (int lloyd : {0, 3}) {
        auto r = rect_region("rock", {0, 0}, {10, 6}, PatternSpec::Kind::voronoi, 0.4, 11);
        r.holes.push_back(circle({5, 3}, 1.5));
        r.pattern.size_measure = PatternSpec::SizeMeasure::area;
        r.pattern.lloyd_iterations = lloyd;
        r.pattern.min_edge = 0.06;
        GenerationStats st;
        const auto a = generate_blocks(one(r), &st);
        const double hole = signed_area(outline_polygon(r.holes[0], 0.1));
        const double hole_perimeter = [&] {
            const auto p = outline_polygon(r.holes[0], 0.1);
            double l = 0;
            for (std::size_t i = 0; i < p.size(); ++i) l += norm(p[(i + 1) % p.size()] - p[i]);
            return l;
        }();
        INFO("lloyd " << lloyd << ", collapsed " << st.collapsed_edges);
        check_tiling(a, 60.0 - hole, 32.0 + hole_perimeter);
        CHECK(mean_block_size(a) == doctest::Approx(0.4).epsilon(0.05));
        CHECK(min_edge(a) >= 0.06 * (1 - 1e-12));
        CHECK(st.short_edges_left == 0);
        if (lloyd == 0) CHECK(st.collapsed_edges > 0);
    }
}

TEST_CASE("voronoi: every shared edge is exactly one joint record") {
    const auto a = generate_blocks(one(rect_region("rock", {0, 0}, {5, 5}, PatternSpec::Kind::voronoi, 0.5, 3)));
    std::map<std::pair<int, int>, int> records;
    for (const auto& j : a.joints) {
        ++records[{j.block_a, j.edge_a}];
        ++records[{j.block_b, j.edge_b}];
        CHECK(j.tag == JointTag::inner);
    }
    int interior = 0;
    for (int b = 0; b < a.block_count(); ++b) {
        const auto p = a.block(b);
        for (int i = 0; i < int(p.size()); ++i) {
            const Vec2 m = 0.5 * (p[i] + p[(i + 1) % p.size()]);
            const bool on_boundary = std::min({m.x, m.y, 5 - m.x, 5 - m.y}) < 1e-12;
            const auto it = records.find({b, i});
            const int n = it == records.end() ? 0 : it->second;
            if (!on_boundary) ++interior;
            CHECK(n == (on_boundary ? 0 : 1));
        }
    }
    CHECK(interior == 2 * int(a.joints.size()));
    for (const auto& j : a.joints) {
        const auto pa = a.block(j.block_a);
        CHECK(j.length() == doctest::Approx(norm(pa[(j.edge_a + 1) % pa.size()] - pa[j.edge_a])));
    }
}

TEST_CASE("generation is reproducible from the seed") {
    auto r = rect_region("rock", {0, 0}, {6, 4}, PatternSpec::Kind::voronoi, 0.3, 5);
    r.pattern.lloyd_iterations = 1;
    const auto h1 = hash(generate_blocks(one(r)));
    CHECK(h1 == hash(generate_blocks(one(r))));
    r.pattern.seed = 6;
    CHECK(h1 != hash(generate_blocks(one(r))));
}

TEST_CASE("trigon: each Voronoi cell becomes as many triangles as it has vertices") {
    // Sized by area, a trigon pattern splits the very cells of the Voronoi one.
    auto v = rect_region("rock", {0, 0}, {6, 4}, PatternSpec::Kind::voronoi, 0.5, 9);
    v.pattern.size_measure = PatternSpec::SizeMeasure::area;
    auto t = v;
    t.pattern.kind = PatternSpec::Kind::trigon;
    const auto cells = generate_blocks(one(v));
    const auto tri = generate_blocks(one(t));
    std::size_t vertices = 0;
    for (int b = 0; b < cells.block_count(); ++b) vertices += cells.block(b).size();
    CHECK(tri.block_count() == int(vertices));
    check_tiling(tri, 24.0, 20.0);
    std::map<JointTag, int> tags;
    for (const auto& j : tri.joints) {
        ++tags[j.tag];
        CHECK((j.tag == JointTag::radial) == (tri.parent[j.block_a] == tri.parent[j.block_b]));
    }
    CHECK(tags[JointTag::radial] == int(vertices));                 // one per cell vertex
    CHECK(tags[JointTag::peripheral] == int(cells.joints.size()) * 1); // the cells' shared edges
    CHECK(tags[JointTag::inner] == 0);
}

TEST_CASE("hexagonal: interior cells are regular hexagons of the lattice spacing") {
    const double s = 0.5;
    auto r = rect_region("rock", {0.01, 0.02}, {5.01, 4.02}, PatternSpec::Kind::hexagonal, s);
    r.pattern.min_edge = 0.02;
    const auto a = generate_blocks(one(r));
    check_tiling(a, 20.0, 18.0);
    int hexagons = 0;
    for (int b = 0; b < a.block_count(); ++b) {
        if (a.block(b).size() != 6) continue;
        const auto p = a.block(b);
        bool regular = true;
        for (int i = 0; i < 6; ++i) regular = regular && std::abs(norm(p[(i + 1) % 6] - p[i]) - s / std::sqrt(3.0)) < 1e-12;
        if (!regular) continue;
        ++hexagons;
        CHECK(a.area[b] == doctest::Approx(std::sqrt(3.0) / 2 * s * s).epsilon(1e-12));
    }
    // 20 m² over 0.2165 m² a cell: ~92 cells, most of them interior.
    CHECK(hexagons > 50);
}

TEST_CASE("brick: running bond gives T-junction joints, stack bond full edges") {
    auto r = rect_region("wall", {0, 0}, {4, 2}, PatternSpec::Kind::brick, 0.25);
    r.pattern.aspect = 2.0;
    auto a = generate_blocks(one(r));
    check_tiling(a, 8.0, 12.0);
    // 8 rows of 0.25 m; every interior horizontal joint runs half a brick (0.25 m).
    int half_brick = 0;
    for (const auto& j : a.joints) half_brick += std::abs(j.length() - 0.25) < 1e-12;
    CHECK(half_brick == int(a.joints.size()));
    r.pattern.running_bond = false;
    r.pattern.aspect = 1.0;
    a = generate_blocks(one(r));
    check_tiling(a, 8.0, 12.0);
    CHECK(a.block_count() == 16 * 8);
    CHECK(a.joints.size() == std::size_t(15 * 8 + 16 * 7));
}

TEST_CASE("delaunay: triangles of the target mean size with no short edges") {
    auto r = rect_region("rock", {0, 0}, {8, 6}, PatternSpec::Kind::delaunay, 0.4, 4);
    r.pattern.size_measure = PatternSpec::SizeMeasure::area;
    GenerationStats st;
    const auto a = generate_blocks(one(r), &st);
    check_tiling(a, 48.0, 28.0);
    for (int b = 0; b < a.block_count(); ++b) CHECK(a.block(b).size() == 3);
    CHECK(mean_block_size(a) == doctest::Approx(0.4).epsilon(0.1));
    CHECK(min_edge(a) >= 0.04);
}

TEST_CASE("real joints cut first, and no inner block crosses them") {
    auto r = rect_region("rock", {0, 0}, {10, 10}, PatternSpec::Kind::voronoi, 0.5, 2);
    r.joints.push_back({{-1, 2}, {11, 7.5}});   // persistent: crosses the region
    r.joints.push_back({{2, 8}, {6, 9}});       // ends inside: a finite trace
    JointSetSpec js;
    js.angle = 70;
    js.spacing = 3;
    js.trace_length = 3;
    js.gap = 1.5;
    js.seed = 3;
    r.joint_sets.push_back(js);
    const auto a = generate_blocks(one(r));
    check_tiling(a, 100.0, 40.0);
    REQUIRE(!a.real_segments.empty());
    // No segment of a real joint passes through the inside of a block.
    for (const auto& s : a.real_segments)
        for (int b = 0; b < a.block_count(); ++b) {
            const auto p = a.block(b);
            for (std::size_t i = 0; i < p.size(); ++i)
                REQUIRE_FALSE(segments_cross(s.a, s.b, p[i], p[(i + 1) % p.size()], 1e-9));
            for (double t : {0.25, 0.5, 0.75}) {
                const Vec2 q = s.a + t * (s.b - s.a);
                double d = INFINITY;
                for (std::size_t i = 0; i < p.size(); ++i) d = std::min(d, distance_to_segment(q, p[i], p[(i + 1) % p.size()]));
                REQUIRE_FALSE((d > 1e-9 && point_in_polygon(q, p)));
            }
        }
    // The joints tagged real add up to the real traces inside the region.
    double real = 0, traces = 0;
    for (const auto& j : a.joints) real += j.tag == JointTag::real_joint ? j.length() : 0.0;
    for (const auto& s : a.real_segments) traces += norm(s.b - s.a);
    CHECK(real == doctest::Approx(traces).epsilon(1e-9));
    CHECK(traces > norm(Vec2{10, 4.583333}) + std::sqrt(17.0)); // both explicit joints and the set
}

TEST_CASE("invalid geometry is reported with the region and key") {
    auto r = rect_region("a", {0, 0}, {1, 1}, PatternSpec::Kind::single, 0);
    SUBCASE("self-intersecting outline") {
        r.outline.kind = OutlineSpec::Kind::polygon;
        r.outline.points = {{0, 0}, {1, 1}, {1, 0}, {0, 1}};
        try {
            generate_blocks(one(r));
            FAIL("no error");
        } catch (const GeometryError& e) {
            CHECK(e.region() == 0);
            CHECK(e.key() == "outline");
        }
    }
    SUBCASE("hole outside its region") {
        r.holes.push_back(circle({0.9, 0.5}, 0.3));
        try {
            generate_blocks(one(r));
            FAIL("no error");
        } catch (const GeometryError& e) {
            CHECK(e.key() == "holes[0]");
        }
    }
    SUBCASE("overlapping regions") {
        ModelGeometrySpec m = one(r);
        m.regions.push_back(rect_region("b", {0.5, 0.5}, {2, 2}, PatternSpec::Kind::single, 0));
        try {
            generate_blocks(m);
            FAIL("no error");
        } catch (const GeometryError& e) {
            CHECK(e.region() == 1);
            CHECK(std::string(e.what()).find("overlaps region 'a'") != std::string::npos);
        }
        m.regions[1].minus = {"a"}; // b = b minus a: now they only touch
        const auto a = generate_blocks(m);
        check_tiling(a, 1.0 + 2.25 - 0.25, 8.0);
        CHECK(a.joints.size() == 2); // a's top-right corner edges against b
    }
}

// --- deformable blocks: boundary subdivision, gmsh meshes, meshed regions ------------

namespace {

double triangle_area(const std::vector<Vec2>& nodes, const std::array<int, 3>& t) {
    return 0.5 * cross(nodes[t[1]] - nodes[t[0]], nodes[t[2]] - nodes[t[0]]);
}

/// The facts every mesh of `boundary` must satisfy: boundary nodes are the given points,
/// bit for bit; triangles are positive and tile the polygon; every boundary segment is
/// the edge of one triangle (gmsh added no node on it).
void check_mesh(const TriangleMesh& m, std::span<const Vec2> boundary) {
    REQUIRE(m.boundary_nodes == int(boundary.size()));
    REQUIRE(m.nodes.size() >= boundary.size());
    for (std::size_t i = 0; i < boundary.size(); ++i)
        REQUIRE(m.nodes[i] == boundary[i]);
    double sum = 0;
    std::map<std::pair<int, int>, int> edges;
    for (const auto& t : m.triangles) {
        const double a = triangle_area(m.nodes, t);
        REQUIRE(a > 0);
        sum += a;
        for (int k = 0; k < 3; ++k)
            ++edges[{t[k], t[(k + 1) % 3]}];
    }
    const double area = signed_area(boundary);
    CHECK(std::abs(sum - area) <= 1e-12 * area);
    const int n = m.boundary_nodes;
    for (int i = 0; i < n; ++i)
        CHECK(edges[{i, (i + 1) % n}] == 1); // counter-clockwise, once
}

SizeFunction uniform(double h) {
    return [h](Vec2) { return h; };
}

RegionSpec meshed(RegionSpec r, double size) {
    r.mesh.enabled = true;
    r.mesh.size = size;
    return r;
}

/// Each deformable block's vertices map to distinct nodes of its own node range (its
/// nodes are contiguous), at the same place; rigid blocks map to none; zones belong
/// to the block of their nodes.
void check_nodes(const BlockAssembly& a) {
    REQUIRE(a.deformable.size() == std::size_t(a.block_count()));
    REQUIRE(a.vertex_node.size() == a.points.size());
    REQUIRE(a.node_block.size() == a.nodes.size());
    REQUIRE(a.zone_block.size() == a.zones.size());
    for (std::size_t n = 1; n < a.nodes.size(); ++n)
        REQUIRE(a.node_block[n - 1] <= a.node_block[n]);
    for (int b = 0; b < a.block_count(); ++b) {
        std::vector<int> seen;
        for (std::uint32_t v = a.first[b]; v < a.first[b + 1]; ++v) {
            const int n = a.vertex_node[v];
            if (!a.deformable[b]) {
                REQUIRE(n == -1);
                continue;
            }
            REQUIRE(n >= 0);
            REQUIRE(n < int(a.nodes.size()));
            REQUIRE(a.node_block[n] == b);
            REQUIRE(a.nodes[n] == a.points[v]);
            seen.push_back(n);
        }
        std::sort(seen.begin(), seen.end());
        REQUIRE(std::adjacent_find(seen.begin(), seen.end()) == seen.end());
    }
    std::vector<double> zone_area(a.block_count(), 0.0);
    for (std::size_t z = 0; z < a.zones.size(); ++z) {
        for (int n : a.zones[z])
            REQUIRE(a.node_block[n] == a.zone_block[z]);
        const double za = triangle_area(a.nodes, a.zones[z]);
        REQUIRE(za > 0);
        zone_area[a.zone_block[z]] += za;
    }
    for (int b = 0; b < a.block_count(); ++b)
        if (a.deformable[b]) CHECK(std::abs(zone_area[b] - a.area[b]) <= 1e-12 * a.area[b]);
}

} // namespace

TEST_CASE("mesh_polygon: a square and an L tiled exactly, boundary points kept") {
    const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const std::vector<Vec2> ell{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
    for (const auto& [poly, h] : {std::pair{square, 0.1}, std::pair{ell, 0.2}}) {
        const auto boundary = subdivide_boundary(poly, uniform(h));
        // Perimeter over size (4 / 0.1, 8 / 0.2): no extra piece from rounding.
        CHECK(boundary.size() == 40);
        const auto m = mesh_polygon(boundary, uniform(h));
        check_mesh(m, boundary);
        // Equilateral triangles of side h: area √3/4 h², about twice as many as nodes.
        const double area = signed_area(poly);
        const double triangles = area / (std::sqrt(3.0) / 4.0 * h * h);
        INFO("nodes " << m.nodes.size() << ", triangles " << m.triangles.size());
        CHECK(double(m.triangles.size()) > 0.7 * triangles);
        CHECK(double(m.triangles.size()) < 1.6 * triangles);
        CHECK(double(m.nodes.size()) > 0.35 * triangles);
        CHECK(double(m.nodes.size()) < 1.0 * triangles);
        // Deterministic.
        const auto again = mesh_polygon(boundary, uniform(h));
        CHECK(again.nodes == m.nodes);
        CHECK(again.triangles == m.triangles);
    }
}

TEST_CASE("subdivide_boundary: an edge gets the same points in either direction") {
    // A size that varies along the edge, so the points are not equally spaced.
    const SizeFunction size = [](Vec2 x) { return 0.05 + 0.1 * x.x * x.x; };
    const Vec2 a{0.3, 0.1}, b{2.7, 1.9};
    const std::vector<Vec2> left{a, b, {0.2, 2.5}};  // a -> b
    const std::vector<Vec2> right{b, a, {2.9, 0.0}}; // b -> a
    const auto p = subdivide_boundary(left, size);
    const auto q = subdivide_boundary(right, size);
    CHECK(p[0] == a);
    CHECK(q[0] == b);
    const auto pb = std::find(p.begin(), p.end(), b), qa = std::find(q.begin(), q.end(), a);
    REQUIRE(pb != p.end());
    REQUIRE(qa != q.end());
    const std::vector<Vec2> forward(p.begin() + 1, pb), backward(q.begin() + 1, qa);
    REQUIRE(forward.size() > 10);
    REQUIRE(forward.size() == backward.size());
    for (std::size_t i = 0; i < forward.size(); ++i) {
        const Vec2 u = forward[i], v = backward[backward.size() - 1 - i];
        CHECK(std::memcmp(&u, &v, sizeof(Vec2)) == 0);
        CHECK(distance_to_segment(u, a, b) < 1e-15);
    }
    // Pieces shrink where the size does: the first (small x) is shorter than the last.
    CHECK(norm(forward.front() - a) < 0.5 * norm(b - forward.back()));
}

TEST_CASE("two meshed regions side by side share their nodes on the common edge") {
    ModelGeometrySpec m;
    m.regions.push_back(
        meshed(rect_region("left", {0, 0}, {1, 1}, PatternSpec::Kind::single, 0), 0.25));
    m.regions.push_back(
        meshed(rect_region("right", {1, 0}, {2, 1}, PatternSpec::Kind::single, 0), 0.25));
    GenerationStats st;
    const auto a = generate_blocks(m, &st);
    REQUIRE(a.block_count() == 2);
    CHECK(a.deformable[0] == 1);
    CHECK(a.deformable[1] == 1);
    check_nodes(a);
    check_tiling(a, 2.0, 6.0);
    auto on_edge = [&](int b) {
        std::vector<Vec2> pts;
        for (Vec2 p : a.block(b))
            if (p.x == 1.0) pts.push_back(p);
        std::sort(pts.begin(), pts.end(), [](Vec2 u, Vec2 v) { return u.y < v.y; });
        return pts;
    };
    const auto l = on_edge(0), r = on_edge(1);
    CHECK(l.size() == 5); // 4 pieces of 0.25 m
    CHECK(l == r);
    double joints = 0;
    for (const auto& j : a.joints) {
        CHECK(j.tag == JointTag::interface);
        CHECK(j.p0.x == 1.0);
        CHECK(j.p1.x == 1.0);
        joints += j.length();
    }
    CHECK(a.joints.size() == 4);
    CHECK(std::abs(joints - 1.0) <= 1e-12);
    double zones = 0;
    for (const auto& z : a.zones)
        zones += triangle_area(a.nodes, z);
    CHECK(std::abs(zones - 2.0) <= 1e-12);
    CHECK(st.zones == int(a.zones.size()));
}

TEST_CASE("a meshed region against rigid Voronoi blocks: non-conforming interface") {
    ModelGeometrySpec m;
    m.regions.push_back(
        meshed(rect_region("elastic", {0, 0}, {1, 1}, PatternSpec::Kind::single, 0), 0.13));
    m.regions.push_back(rect_region("bonded", {1, 0}, {2, 1}, PatternSpec::Kind::voronoi, 0.2, 3));
    const auto a = generate_blocks(m);
    check_nodes(a);
    check_tiling(a, 2.0, 6.0);
    double interface = 0;
    int t_junctions = 0;
    for (const auto& j : a.joints) {
        if (j.tag != JointTag::interface) continue;
        CHECK(std::abs(j.p0.x - 1.0) < 1e-15);
        CHECK(std::abs(j.p1.x - 1.0) < 1e-15);
        interface += j.length();
        // The record ends at a vertex of one block that lies inside an edge of the other.
        const auto pa = a.block(j.block_a), pb = a.block(j.block_b);
        const bool ends_match = (j.p0 == pa[j.edge_a] || j.p0 == pa[(j.edge_a + 1) % pa.size()]) &&
                                (j.p0 == pb[j.edge_b] || j.p0 == pb[(j.edge_b + 1) % pb.size()]);
        t_junctions += !ends_match;
    }
    CHECK(std::abs(interface - 1.0) <= 1e-9);
    CHECK(t_junctions > 0);
}

TEST_CASE("meshed Voronoi blocks: each block its own mesh, conforming to its neighbours") {
    auto r = meshed(rect_region("rock", {0, 0}, {2, 1}, PatternSpec::Kind::voronoi, 0.5, 5), 0.1);
    const auto a = generate_blocks(one(r));
    check_nodes(a);
    check_tiling(a, 2.0, 6.0);
    // Shared edges of one region are subdivided identically: every joint record runs
    // between vertices of both blocks.
    for (const auto& j : a.joints) {
        const auto pa = a.block(j.block_a), pb = a.block(j.block_b);
        CHECK(j.p0 == pb[(j.edge_b + 1) % pb.size()]);
        CHECK(j.p1 == pb[j.edge_b]);
        CHECK(j.p0 == pa[j.edge_a]);
        CHECK(j.p1 == pa[(j.edge_a + 1) % pa.size()]);
    }
}

TEST_CASE("the tunnel's outer region meshed with triangles graded toward the bonded region") {
    auto spec = tunnel(PatternSpec::Kind::voronoi);
    spec.regions[0].mesh = {true, 0.3, 3.0, 0.25, {"bonded"}};
    GenerationStats st;
    const auto a = generate_blocks(spec, &st);
    MESSAGE("outer region: " << st.zones << " zones, " << a.nodes.size() << " nodes, meshed in "
                             << st.seconds_meshing << " s");
    check_tiling(a, 800.0, 120.0);
    check_nodes(a);
    int outer_blocks = 0;
    for (int b = 0; b < a.block_count(); ++b) {
        CHECK(bool(a.deformable[b]) == (a.region[b] == 0));
        outer_blocks += a.region[b] == 0;
    }
    CHECK(outer_blocks == 1);
    CHECK(st.zones == int(a.zones.size()));
    // Zones touching the bonded region (x = 8, |y| <= 8) against those at the far side.
    double near = 0, far = 0;
    int n_near = 0, n_far = 0;
    for (const auto& z : a.zones) {
        const Vec2 c = (a.nodes[z[0]] + a.nodes[z[1]] + a.nodes[z[2]]) / 3.0;
        const double area = triangle_area(a.nodes, z);
        if (c.x > 8 && c.x < 8.3 && std::abs(c.y) < 7) near += area, ++n_near;
        if (c.x > 17) far += area, ++n_far;
    }
    REQUIRE(n_near > 0);
    REQUIRE(n_far > 0);
    const double h_near = std::sqrt(near / n_near / (std::sqrt(3.0) / 4.0));
    const double h_far = std::sqrt(far / n_far / (std::sqrt(3.0) / 4.0));
    INFO("equilateral side of the mean zone: near " << h_near << " m, far " << h_far << " m");
    CHECK(h_near < 0.45);
    CHECK(h_far > 2.0);
    CHECK(h_far > 5 * h_near);
    // The whole interface (x = 8 and y = ±8 up to x = 8) is covered by joint records.
    double interface = 0;
    for (const auto& j : a.joints)
        if (j.tag == JointTag::interface && (a.region[j.block_a] == 0 || a.region[j.block_b] == 0))
            interface += j.length();
    CHECK(std::abs(interface - 32.0) <= 1e-9 * 32.0);
}

TEST_CASE("invalid meshes are reported with the region and key") {
    ModelGeometrySpec m;
    m.regions.push_back(
        meshed(rect_region("a", {0, 0}, {1, 1}, PatternSpec::Kind::single, 0), 0.2));
    m.regions.push_back(rect_region("b", {1, 0}, {2, 1}, PatternSpec::Kind::single, 0));
    m.regions[0].mesh.grading = 0.5;
    m.regions[0].mesh.size_far = 1.0;
    m.regions[0].mesh.toward = {"c"};
    try {
        generate_blocks(m);
        FAIL("no error");
    } catch (const GeometryError& e) {
        CHECK(e.region() == 0);
        CHECK(e.key() == "mesh.toward");
        CHECK(std::string(e.what()).find("'c', which is not another region") != std::string::npos);
    }
    m.regions[0].mesh.toward = {"b"};
    const auto a = generate_blocks(m);
    check_nodes(a);
    check_tiling(a, 2.0, 6.0);
    m.regions[0].mesh.size = 0;
    try {
        generate_blocks(m);
        FAIL("no error");
    } catch (const GeometryError& e) {
        CHECK(e.key() == "mesh.size");
    }
}
