// The geometry pipeline of blocks.hpp: regions, real joints, patterns, topology.
#include "meshing/blocks.hpp"

#include "base/error.hpp"
#include "meshing/cutting.hpp"
#include "meshing/detail.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace bbm::meshing {

const char* to_string(JointTag t) {
    switch (t) {
    case JointTag::inner: return "inner";
    case JointTag::radial: return "radial";
    case JointTag::peripheral: return "peripheral";
    case JointTag::real_joint: return "real_joint";
    case JointTag::interface: return "interface";
    case JointTag::fracture: return "fracture";
    }
    return "?";
}

const char* to_string(PatternSpec::Kind k) {
    using K = PatternSpec::Kind;
    switch (k) {
    case K::voronoi: return "voronoi";
    case K::trigon: return "trigon";
    case K::delaunay: return "delaunay";
    case K::hexagonal: return "hexagonal";
    case K::brick: return "brick";
    case K::single: return "single";
    }
    return "?";
}

void BlockAssembly::add_block(std::span<const Vec2> poly, int region_id, PatternSpec::Kind kind,
                              int parent_id) {
    const bool ccw = signed_area(poly) > 0;
    for (std::size_t i = 0; i < poly.size(); ++i) points.push_back(ccw ? poly[i] : poly[poly.size() - 1 - i]);
    first.push_back(std::uint32_t(points.size()));
    region.push_back(region_id);
    pattern.push_back(kind);
    parent.push_back(parent_id);
    area.push_back(std::abs(signed_area(poly)));
    deformable.push_back(0);
    vertex_node.insert(vertex_node.end(), poly.size(), -1);
}

void BlockAssembly::add_deformable_block(const TriangleMesh& mesh, int region_id,
                                         PatternSpec::Kind kind, int parent_id) {
    const int b = block_count();
    const int base = int(nodes.size());
    const std::span<const Vec2> loop(mesh.nodes.data(), std::size_t(mesh.boundary_nodes));
    BBM_ASSERT(loop.size() >= 3 && signed_area(loop) > 0, "a mesh boundary is counter-clockwise");
    points.insert(points.end(), loop.begin(), loop.end());
    first.push_back(std::uint32_t(points.size()));
    region.push_back(region_id);
    pattern.push_back(kind);
    parent.push_back(parent_id);
    area.push_back(signed_area(loop));
    deformable.push_back(1);
    for (int i = 0; i < mesh.boundary_nodes; ++i)
        vertex_node.push_back(base + i);
    nodes.insert(nodes.end(), mesh.nodes.begin(), mesh.nodes.end());
    node_block.insert(node_block.end(), mesh.nodes.size(), b);
    for (const auto& t : mesh.triangles) {
        zones.push_back({base + t[0], base + t[1], base + t[2]});
        zone_block.push_back(b);
    }
}

double mean_block_size(const BlockAssembly& a, int region) {
    double total = 0.0;
    int n = 0;
    for (int b = 0; b < a.block_count(); ++b)
        if (region < 0 || a.region[b] == region) total += a.area[b], ++n;
    return n ? std::sqrt(4.0 * (total / n) / std::numbers::pi) : 0.0;
}

namespace {

std::vector<Vec2> arc_points(Vec2 from, Vec2 to, Vec2 c, bool clockwise, double max_seg) {
    const double r = norm(from - c);
    const double a0 = std::atan2(from.y - c.y, from.x - c.x);
    double sweep = std::atan2(to.y - c.y, to.x - c.x) - a0;
    const double two_pi = 2.0 * std::numbers::pi;
    if (clockwise) {
        while (sweep >= 0) sweep -= two_pi;
    } else {
        while (sweep <= 0) sweep += two_pi;
    }
    const int n = std::max(2, int(std::ceil(std::abs(sweep) * r / max_seg)));
    std::vector<Vec2> pts;
    for (int k = 1; k < n; ++k) {
        const double t = a0 + sweep * k / n;
        pts.push_back({c.x + r * std::cos(t), c.y + r * std::sin(t)});
    }
    pts.push_back(to);
    return pts;
}

} // namespace

std::vector<Vec2> outline_polygon(const OutlineSpec& o, double default_max_segment) {
    using K = OutlineSpec::Kind;
    const double max_seg = o.max_segment > 0 ? o.max_segment : default_max_segment;
    std::vector<Vec2> p;
    switch (o.kind) {
    case K::rectangle:
        p = {o.min, {o.max.x, o.min.y}, o.max, {o.min.x, o.max.y}};
        break;
    case K::polygon:
        p = o.points;
        break;
    case K::circle: {
        const int n = std::max(8, int(std::ceil(2.0 * std::numbers::pi * o.radius / max_seg)));
        for (int k = 0; k < n; ++k) {
            const double t = 2.0 * std::numbers::pi * k / n;
            p.push_back({o.center.x + o.radius * std::cos(t), o.center.y + o.radius * std::sin(t)});
        }
        break;
    }
    case K::path: {
        p.push_back(o.start);
        for (const auto& s : o.steps) {
            if (s.arc) {
                const auto arc = arc_points(p.back(), s.to, s.center, s.clockwise, max_seg);
                p.insert(p.end(), arc.begin(), arc.end());
            } else {
                p.push_back(s.to);
            }
        }
        if (p.size() > 1 && p.back() == p.front()) p.pop_back();
        break;
    }
    case K::opening: {
        const double r = 0.5 * o.width;
        const Vec2 c = o.center;
        if (o.half) {
            p = {{c.x, o.floor_y}, {c.x + r, o.floor_y}, {c.x + r, c.y}};
            const auto arc = arc_points({c.x + r, c.y}, {c.x, c.y + r}, c, false, max_seg);
            p.insert(p.end(), arc.begin(), arc.end());
        } else {
            p = {{c.x - r, o.floor_y}, {c.x + r, o.floor_y}, {c.x + r, c.y}};
            const auto arc = arc_points({c.x + r, c.y}, {c.x - r, c.y}, c, false, max_seg);
            p.insert(p.end(), arc.begin(), arc.end());
        }
        break;
    }
    }
    if (p.size() >= 3 && signed_area(p) < 0) std::reverse(p.begin(), p.end());
    return p;
}

namespace {

using cgal::Domain;

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}

/// Traces of a statistical joint set over the box (they are cut to the region later).
std::vector<SegmentSpec> joint_set_traces(const JointSetSpec& js, const Box2& box) {
    detail::Random rng(js.seed);
    const double deg = std::numbers::pi / 180.0;
    const Vec2 t{std::cos(js.angle * deg), std::sin(js.angle * deg)}, n = perp(t);
    double nmin = INFINITY, nmax = -INFINITY, tmin = INFINITY, tmax = -INFINITY;
    for (Vec2 c : {box.lo, Vec2{box.hi.x, box.lo.y}, box.hi, Vec2{box.lo.x, box.hi.y}}) {
        nmin = std::min(nmin, dot(c - js.origin, n)), nmax = std::max(nmax, dot(c - js.origin, n));
        tmin = std::min(tmin, dot(c - js.origin, t)), tmax = std::max(tmax, dot(c - js.origin, t));
    }
    const double margin = 0.05 * (tmax - tmin) + js.spacing;
    tmin -= margin, tmax += margin;
    auto deviate = [&](double x, double frac) { return x * (1.0 + frac * rng.uniform(-1.0, 1.0)); };
    std::vector<SegmentSpec> out;
    auto emit = [&](Vec2 a, Vec2 b) {
        if (js.angle_deviation > 0) {
            const double d = js.angle_deviation * deg * rng.uniform(-1.0, 1.0);
            const Vec2 m = 0.5 * (a + b), h = 0.5 * (b - a);
            const Vec2 hr{h.x * std::cos(d) - h.y * std::sin(d), h.x * std::sin(d) + h.y * std::cos(d)};
            a = m - hr, b = m + hr;
        }
        out.push_back({a, b});
    };
    for (long k = long(std::floor(nmin / js.spacing)) - 1; k <= long(std::ceil(nmax / js.spacing)) + 1; ++k) {
        const double offset = (double(k) + js.spacing_deviation * rng.uniform(-0.5, 0.5)) * js.spacing;
        const Vec2 base = js.origin + offset * n;
        if (js.trace_length <= 0) {
            emit(base + tmin * t, base + tmax * t);
            continue;
        }
        double s = tmin - rng.uniform() * (js.trace_length + js.gap);
        while (s < tmax) {
            const double len = deviate(js.trace_length, js.length_deviation);
            emit(base + s * t, base + (s + len) * t);
            s += len + std::max(0.0, deviate(js.gap, js.length_deviation));
        }
    }
    return out;
}

/// Removes the spikes of a polygon clipped by Boolean operations: a repeated
/// vertex (closer than the rounding), or one where its boundary runs out along a
/// line and straight back (an edge followed by its own reverse, zero area).
/// Returns whether anything was removed.
bool remove_spikes(std::vector<Vec2>& poly, double tol) {
    bool changed = false;
    for (bool again = true; again && poly.size() >= 3;) {
        again = false;
        for (std::size_t i = 0; i < poly.size() && poly.size() >= 3; ++i) {
            const std::size_t n = poly.size();
            const Vec2 p = poly[(i + n - 1) % n], v = poly[i], q = poly[(i + 1) % n];
            const Vec2 a = v - p, b = q - v;
            const bool repeated = norm(a) <= tol;
            const bool spike = !repeated && norm(b) > tol && dot(a, b) < 0.0 &&
                               std::abs(cross(a, b)) <= tol * std::max(norm(a), norm(b));
            if (!repeated && !spike) continue;
            poly.erase(poly.begin() + long(i));
            changed = again = true;
            if (i > 0) --i;
        }
    }
    return changed;
}

struct RegionBlocks {
    std::vector<std::vector<Vec2>> polygons;
    std::vector<int> parent;
};

/// The blocks marked gone removed, the others kept in order.
void drop_blocks(RegionBlocks& rb, const std::vector<char>& gone) {
    std::size_t kept = 0;
    for (std::size_t k = 0; k < rb.polygons.size(); ++k) {
        if (gone[k]) continue;
        if (kept != k) rb.polygons[kept] = std::move(rb.polygons[k]), rb.parent[kept] = rb.parent[k];
        ++kept;
    }
    rb.polygons.resize(kept);
    rb.parent.resize(kept);
}

/// The spikes of every block removed; a block that was nothing but a spike (no
/// area left) is dropped.
void remove_spikes(RegionBlocks& rb, double tol) {
    std::vector<char> gone(rb.polygons.size(), 0);
    for (std::size_t k = 0; k < rb.polygons.size(); ++k) {
        remove_spikes(rb.polygons[k], tol);
        gone[k] = rb.polygons[k].size() < 3 || std::abs(signed_area(rb.polygons[k])) <= tol * tol;
    }
    drop_blocks(rb, gone);
}

/// Index of a point along a Hilbert curve over a box, 16 bits per axis. Unlike a
/// Z-order curve, consecutive indices are always adjacent cells, so blocks that
/// are neighbours in space are nearer in number (no long jumps at the seams).
std::uint32_t hilbert_index(Vec2 p, const Box2& box) {
    constexpr std::uint32_t side = 1u << 16;
    auto cell = [&](double v, double lo, double extent) {
        const double t = (v - lo) / std::max(extent, 1e-300) * double(side - 1);
        return std::uint32_t(std::clamp(t, 0.0, double(side - 1)));
    };
    std::uint32_t x = cell(p.x, box.lo.x, box.width()), y = cell(p.y, box.lo.y, box.height()), d = 0;
    for (std::uint32_t s = side / 2; s > 0; s /= 2) {
        const std::uint32_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
        d += s * s * ((3 * rx) ^ ry);
        if (ry == 0) { // rotate the quadrant so the curve stays continuous
            if (rx == 1) x = side - 1 - x, y = side - 1 - y;
            std::swap(x, y);
        }
    }
    return d;
}

/// Blocks in space-filling-curve order, so that neighbours have nearby ids: the
/// contact loop then reads block data from cache, not from random memory.
void order_along_curve(RegionBlocks& rb) {
    Box2 box;
    std::vector<Vec2> c;
    for (const auto& p : rb.polygons) c.push_back(centroid(p)), box.add(c.back());
    std::vector<std::pair<std::uint32_t, int>> keys;
    for (int k = 0; k < int(c.size()); ++k) keys.push_back({hilbert_index(c[k], box), k});
    std::stable_sort(keys.begin(), keys.end());
    RegionBlocks sorted;
    for (const auto& [key, k] : keys) {
        sorted.polygons.push_back(std::move(rb.polygons[k]));
        sorted.parent.push_back(rb.parent[k]);
    }
    rb = std::move(sorted);
}

/// The target triangle size of region r's mesh (spec.hpp, MeshSpec). Regions do not
/// overlap, so a point of region r lies outside the union U of the `toward` regions,
/// and its distance to the boundary of U equals its distance to the nearest edge of
/// any of their domains (a segment from it to an edge inside U crosses U's boundary
/// first): the edges of the domains, outer rings and holes, are used as they are.
SizeFunction mesh_size_function(const ModelGeometrySpec& spec, int r,
                                const std::vector<Domain>& domain) {
    const MeshSpec& m = spec.regions[r].mesh;
    const double size = m.size, far = m.size_far > 0 ? m.size_far : m.size;
    if (m.toward.empty() || m.grading <= 0 || far <= size) return [size](Vec2) { return size; };
    std::vector<std::pair<Vec2, Vec2>> edges;
    auto add_ring = [&](const std::vector<Vec2>& ring) {
        for (std::size_t i = 0; i < ring.size(); ++i)
            edges.push_back({ring[i], ring[(i + 1) % ring.size()]});
    };
    for (const auto& name : m.toward) {
        const auto it = std::find_if(spec.regions.begin(), spec.regions.end(),
                                     [&](const RegionSpec& o) { return o.name == name; });
        for (const auto& p : domain[std::size_t(it - spec.regions.begin())]) {
            add_ring(p.outer);
            for (const auto& h : p.holes)
                add_ring(h);
        }
    }
    // Beyond this distance the size is size_far whatever the exact distance.
    const double reach = (far - size) / m.grading;
    auto grid =
        std::make_shared<const detail::SegmentGrid>(std::move(edges), std::max(size, 0.25 * reach));
    return [grid, size, far, reach, grading = m.grading](Vec2 x) {
        const double d = grid->distance_within(x, reach);
        return std::isfinite(d) ? std::min(far, size + grading * d) : far;
    };
}

/// Step 5: every block of a region with a mesh becomes a deformable block. Block ids
/// stay the same; the assembly is rebuilt because the polygons gain vertices.
void mesh_deformable_blocks(BlockAssembly& a, const ModelGeometrySpec& spec,
                            const std::vector<Domain>& domain, GenerationStats& st) {
    const int nr = int(spec.regions.size());
    std::vector<SizeFunction> size(nr);
    for (int r = 0; r < nr; ++r)
        if (spec.regions[r].mesh.enabled) size[r] = mesh_size_function(spec, r, domain);
    BlockAssembly out;
    out.region_names = std::move(a.region_names);
    out.region_size = std::move(a.region_size);
    out.real_segments = std::move(a.real_segments);
    out.fracture_sets = std::move(a.fracture_sets);
    out.fracture_traces = std::move(a.fracture_traces);
    out.fracture_trace_set = std::move(a.fracture_trace_set);
    out.fracture_stats = std::move(a.fracture_stats);
    for (int b = 0; b < a.block_count(); ++b) {
        const int r = a.region[b];
        if (!size[r]) {
            out.add_block(a.block(b), r, a.pattern[b], a.parent[b]);
            continue;
        }
        TriangleMesh mesh;
        try {
            // The inserted points lie on the edges (up to rounding): the area is unchanged.
            const auto boundary = subdivide_boundary(a.block(b), size[r]);
            BBM_ASSERT(std::abs(signed_area(boundary) - a.area[b]) <= 1e-9 * a.area[b],
                       "subdividing the edges keeps the area");
            mesh = mesh_polygon(boundary, size[r]);
        } catch (const GeometryError& e) {
            throw GeometryError(r, "mesh",
                                "meshing a block of region '" + spec.regions[r].name +
                                    "' (centroid " + fmt(centroid(a.block(b)).x) + ", " +
                                    fmt(centroid(a.block(b)).y) + ") failed: " + e.what());
        }
        st.zones += int(mesh.triangles.size());
        out.add_deformable_block(mesh, r, a.pattern[b], a.parent[b]);
    }
    a = std::move(out);
}

} // namespace

namespace {
// Peak memory of generating and running a model, per block and per triangle
// (measured with /usr/bin/time: a UCS of 82,678 Voronoi blocks peaked at 442 MB,
// 5.3 kB a block; one of 5,167 deformable blocks meshed into about 330,000
// triangles at 1.25 GB, 3.8 kB a triangle); rounded up.
constexpr double bytes_per_block = 6000, bytes_per_zone = 4000;
constexpr double triangle_area_factor = 0.433; ///< equilateral triangle of size h: 0.433 h²
} // namespace

double SizeEstimate::bytes() const { return blocks * bytes_per_block + zones * bytes_per_zone; }

SizeEstimate estimate_region(const RegionSpec& region, double area, double toward_perimeter) {
    using Kind = PatternSpec::Kind;
    const PatternSpec& p = region.pattern;
    SizeEstimate e;
    if (p.kind == Kind::single) {
        e.blocks = 1;
    } else {
        const double d = p.size;
        // Area per block: regular shapes for the lattices; for the random patterns
        // the mean area measured for a mean Feret diameter d (Voronoi cells about
        // 0.65 d², triangles 0.45 d²) or the circle of diameter d.
        double per_block = 0.65 * d * d;
        if (p.kind == Kind::hexagonal) per_block = std::sqrt(3.0) / 2.0 * d * d;
        else if (p.kind == Kind::brick) per_block = p.aspect * d * d;
        else if (p.size_measure == PatternSpec::SizeMeasure::area)
            per_block = std::numbers::pi / 4.0 * d * d / (p.kind == Kind::trigon ? 6.0 : 1.0);
        else if (p.kind == Kind::trigon || p.kind == Kind::delaunay) per_block = 0.45 * d * d;
        e.blocks = area / per_block;
    }
    if (region.mesh.enabled) {
        const double h = region.mesh.size, far = std::max(h, region.mesh.size_far);
        e.zones = area / (triangle_area_factor * h * h);
        // Graded: h grows by `grading` per metre from the boundaries it is refined
        // toward; the rings of fine triangles along them, plus the rest at the far size.
        if (region.mesh.grading > 0 && !region.mesh.toward.empty() && far > h)
            e.zones = std::min(e.zones, toward_perimeter / (triangle_area_factor * region.mesh.grading * h) +
                                            area / (triangle_area_factor * far * far));
        e.zones = std::max(e.zones, e.blocks);
    }
    return e;
}

double default_max_elements() {
    const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    return memory > 0 ? 0.5 * memory / bytes_per_block : 1e6;
}

namespace {
/// Refuses, before anything is generated, a model that asks for more blocks and
/// triangles than the limit; returns the estimate of each region.
std::vector<SizeEstimate> check_model_size(const ModelGeometrySpec& spec, const std::vector<cgal::Domain>& domain) {
    const int nr = int(spec.regions.size());
    std::vector<SizeEstimate> estimate(nr);
    double total = 0.0, bytes = 0.0;
    int largest = 0;
    for (int r = 0; r < nr; ++r) {
        double toward_perimeter = 0.0;
        for (const auto& name : spec.regions[r].mesh.toward)
            for (const auto& other : spec.regions)
                if (other.name == name) {
                    const auto poly = outline_polygon(other.outline, spec.max_segment);
                    for (std::size_t i = 0; i < poly.size(); ++i) toward_perimeter += norm(poly[(i + 1) % poly.size()] - poly[i]);
                }
        const RegionSpec& reg = spec.regions[r];
        estimate[r] = estimate_region(reg, cgal::area(domain[r]), toward_perimeter);
        // A fracture network: the fractures drawn, and the blocks its traces add by
        // splitting those they cross (about one per 0.8 block size of trace).
        for (std::size_t k = 0; k < reg.dfn.size(); ++k) {
            const auto size = dfn::expected_size(reg.dfn[k], domain[r]);
            const double limit = spec.max_elements > 0 ? spec.max_elements : default_max_elements();
            if (!(size.fractures <= limit))
                throw GeometryError(r, "dfn[" + std::to_string(k) + "]",
                                    "fracture set '" + reg.dfn[k].name + "' would draw about " + fmt(size.fractures) +
                                        " fractures, over the limit of " + fmt(limit) +
                                        " elements; give a lower intensity or raise the limit ([model] "
                                        "max_elements, --max-elements)");
            if (reg.pattern.kind != PatternSpec::Kind::single && reg.pattern.size > 0.0)
                estimate[r].blocks += size.p21 * cgal::area(domain[r]) / (0.8 * reg.pattern.size);
        }
        if (reg.pattern.kind != PatternSpec::Kind::single && estimate[r].blocks < 2)
            throw GeometryError(r, "pattern.size",
                                "block size " + fmt(reg.pattern.size) + " m is too large for region '" + reg.name +
                                    "' (" + fmt(cgal::area(domain[r])) +
                                    " m², room for about " + fmt(estimate[r].blocks) +
                                    " blocks): give a size smaller than the region, or pattern \"single\" for one block");
        total += estimate[r].blocks + estimate[r].zones;
        bytes += estimate[r].bytes();
        if (estimate[r].blocks + estimate[r].zones > estimate[largest].blocks + estimate[largest].zones) largest = r;
    }
    const double limit = spec.max_elements > 0 ? spec.max_elements : default_max_elements();
    if (!(total <= limit)) {
        const RegionSpec& reg = spec.regions[largest];
        const SizeEstimate& e = estimate[largest];
        const bool zones = e.zones > e.blocks;
        throw GeometryError(
            largest, zones ? "mesh.size" : "pattern.size",
            "the model asks for about " + fmt(total) + " blocks and triangles (about " + fmt(bytes / 1e9) +
                " GB), over the limit of " + fmt(limit) +
                (spec.max_elements > 0 ? " set by max_elements" : " (half of this machine's memory)") + ": region '" +
                reg.name + "' alone, " + fmt(cgal::area(domain[largest])) + " m² at " +
                (zones ? "triangle size " + fmt(reg.mesh.size) : "block size " + fmt(reg.pattern.size)) +
                " m, makes about " + fmt(zones ? e.zones : e.blocks) + (zones ? " triangles" : " blocks") +
                "; give a larger size, or raise the limit ([model] max_elements, --max-elements) if the machine has the memory");
    }
    return estimate;
}

/// A patterned region must give blocks: none, or far fewer than its area and size
/// imply, means the pattern did not fit (a size larger than the region).
void check_region_filled(const RegionSpec& reg, int r, int blocks, const SizeEstimate& e, double area) {
    if (reg.pattern.kind == PatternSpec::Kind::single) return;
    if (blocks == 0)
        throw GeometryError(r, "pattern.size",
                            "region '" + reg.name + "' (" + fmt(area) + " m²) generated no blocks at block size " +
                                fmt(reg.pattern.size) + " m; give a size smaller than the region");
    if (e.blocks >= 20 && blocks < 0.2 * e.blocks)
        throw GeometryError(r, "pattern.size",
                            "region '" + reg.name + "' generated " + std::to_string(blocks) + " blocks where its area " +
                                fmt(area) + " m² and block size " + fmt(reg.pattern.size) + " m imply about " +
                                fmt(e.blocks));
}

/// The region's real discontinuities for the exact cutter: explicit joints,
/// joint-set traces and the fractures' pieces inside the region, as they are, but
/// for the end of a fracture that stops at an earlier one: that end lies exactly on
/// the earlier fracture's line.
std::vector<detail::CutTrace> cut_traces(const std::vector<SegmentSpec>& segments, const FractureNetwork& net) {
    std::vector<detail::CutTrace> traces;
    traces.reserve(segments.size() + net.traces.size());
    for (const auto& s : segments) traces.push_back({s.a, s.b, s.a, s.b, -1, -1});
    // The first piece of each fracture, whose line an end stopping at it is put on.
    const int base = int(traces.size());
    std::vector<int> first_piece(net.fractures.size(), -1);
    for (std::size_t i = 0; i < net.traces.size(); ++i) {
        int& f = first_piece[std::size_t(net.trace_fracture[i])];
        if (f < 0) f = base + int(i);
    }
    for (std::size_t i = 0; i < net.traces.size(); ++i) {
        const Fracture& f = net.fractures[std::size_t(net.trace_fracture[i])];
        const SegmentSpec& s = net.traces[i];
        // Where the fracture ends: at the earlier fracture it stops at, if any, or
        // its own end (the piece's is that rounded); where the region cuts it off,
        // on the region's boundary.
        const double near = 1e-12 * norm(f.b - f.a);
        auto end = [&](Vec2 p, Vec2& given) {
            if (norm(p - f.a) > near && norm(p - f.b) > near) return detail::CutTrace::on_boundary;
            const bool at_a = norm(p - f.a) <= near;
            given = at_a ? f.a : f.b;
            const int j = at_a ? f.a_at : f.b_at;
            return j >= 0 ? first_piece[std::size_t(j)] : -1;
        };
        detail::CutTrace t{s.a, s.b, f.line_a, f.line_b, -1, -1};
        t.a_at = end(s.a, t.a);
        t.b_at = end(s.b, t.b);
        traces.push_back(t);
    }
    return traces;
}

/// The blocks of rock block k: the pattern's cells laid over it and cut to it
/// exactly (cutting.hpp), their short edges collapsed as in a rock block no trace
/// cuts.
detail::FaceFill cut_face(const detail::RegionCut& cut, int k, const PatternSpec& pattern, detail::Random& rng,
                          detail::CutStats& cs) {
    using K = PatternSpec::Kind;
    const cgal::PolygonWithHoles& face = cut.face(k);
    if (pattern.kind == K::single && cut.plain(k)) return {{face.outer}, {0}, 0};
    detail::PatternCells pc;
    if (pattern.kind != K::single)
        pc = detail::pattern_cells(face, pattern, rng, [&](const detail::Cells& c) { return cut.clip(k, c); }, true);
    detail::Collapse collapse;
    if (pattern.kind == K::voronoi || pattern.kind == K::trigon || pattern.kind == K::hexagonal || pattern.kind == K::brick)
        collapse = [&](detail::Cells& pieces) {
            return detail::collapse_short_edges(pieces, face, detail::min_edge_of(pattern));
        };
    detail::FaceFill fill =
        cut.blocks(k, pc.cells, pc.fitted, collapse, pc.fans ? detail::CentreOf(detail::star_center) : nullptr, cs);
    if (pattern.kind == K::brick)
        for (std::size_t i = 0; i < fill.parent.size(); ++i) fill.parent[i] = int(i);
    return fill;
}
} // namespace

namespace {

/// The index of the region named `name` other than r, or -1.
int other_region(const ModelGeometrySpec& spec, int r, const std::string& name) {
    const auto it = std::find_if(spec.regions.begin(), spec.regions.end(),
                                 [&](const RegionSpec& o) { return o.name == name; });
    return it == spec.regions.end() || it - spec.regions.begin() == r ? -1 : int(it - spec.regions.begin());
}

/// A region's outline with its holes, checked: simple, with area, holes inside.
Domain outline_domain(const ModelGeometrySpec& spec, int r) {
    const RegionSpec& reg = spec.regions[r];
    const auto outer = outline_polygon(reg.outline, spec.max_segment);
    if (outer.size() >= 3 && !cgal::is_simple(outer))
        throw GeometryError(r, "outline", "outline of region '" + reg.name + "' intersects itself");
    if (outer.size() < 3 || std::abs(signed_area(outer)) <= 0)
        throw GeometryError(r, "outline", "outline of region '" + reg.name + "' has no area");
    std::vector<std::vector<Vec2>> holes;
    const Domain outer_domain = cgal::make_domain(outer, {});
    for (int h = 0; h < int(reg.holes.size()); ++h) {
        const std::string key = "holes[" + std::to_string(h) + "]";
        auto hole = outline_polygon(reg.holes[h], spec.max_segment);
        if (hole.size() < 3 || !cgal::is_simple(hole))
            throw GeometryError(r, key, "hole " + std::to_string(h) + " of region '" + reg.name +
                                            "' is not a simple polygon");
        const double outside = cgal::area(cgal::difference(cgal::make_domain(hole, {}), outer_domain));
        if (outside > 1e-9 * std::abs(signed_area(hole)))
            throw GeometryError(r, key, "hole " + std::to_string(h) + " of region '" + reg.name +
                                            "' lies outside its outline by " + fmt(outside) + " m²");
        holes.push_back(std::move(hole));
    }
    return cgal::make_domain(outer, holes);
}

/// The mesh of a deformable region: sizes and the regions it is refined toward.
void check_region_mesh(const ModelGeometrySpec& spec, int r) {
    const RegionSpec& reg = spec.regions[r];
    const MeshSpec& mesh = reg.mesh;
    if (!mesh.enabled) return;
    if (!(mesh.size > 0))
        throw GeometryError(r, "mesh.size",
                            "the mesh size of region '" + reg.name + "' must be > 0 m, got " + fmt(mesh.size));
    if (mesh.size_far != 0 && !(mesh.size_far >= mesh.size))
        throw GeometryError(r, "mesh.size_far",
                            "the far mesh size of region '" + reg.name + "' must be >= its size " + fmt(mesh.size) +
                                " m, got " + fmt(mesh.size_far));
    if (!(mesh.grading >= 0))
        throw GeometryError(r, "mesh.grading",
                            "the mesh grading of region '" + reg.name + "' must be >= 0, got " + fmt(mesh.grading));
    for (const auto& name : mesh.toward)
        if (other_region(spec, r, name) < 0)
            throw GeometryError(r, "mesh.toward",
                                "the mesh of region '" + reg.name + "' is refined toward '" + name +
                                    "', which is not another region");
}

/// Step 1: each region's domain (its outline and holes less the regions it
/// subtracts), with the checks a user needs to hear about; no two overlap.
std::vector<Domain> region_domains(const ModelGeometrySpec& spec) {
    const int nr = int(spec.regions.size());
    std::vector<Domain> base(nr), domain(nr);
    for (int r = 0; r < nr; ++r) base[r] = outline_domain(spec, r);
    for (int r = 0; r < nr; ++r) {
        const RegionSpec& reg = spec.regions[r];
        domain[r] = base[r];
        for (const auto& name : reg.minus) {
            const int other = other_region(spec, r, name);
            if (other < 0)
                throw GeometryError(r, "minus", "region '" + reg.name + "' subtracts '" + name +
                                                    "', which is not another region");
            domain[r] = cgal::difference(domain[r], base[other]);
        }
        if (cgal::area(domain[r]) <= 1e-12 * cgal::area(base[r]))
            throw GeometryError(r, "minus", "nothing is left of region '" + reg.name + "' after subtraction");
        check_region_mesh(spec, r);
    }
    for (int r = 0; r < nr; ++r)
        for (int q = 0; q < r; ++q) {
            const double overlap = cgal::area(cgal::intersection(domain[r], domain[q]));
            if (overlap > 1e-9 * std::min(cgal::area(domain[r]), cgal::area(domain[q])))
                throw GeometryError(r, "outline",
                                    "region '" + spec.regions[r].name + "' overlaps region '" +
                                        spec.regions[q].name + "' by " + fmt(overlap) +
                                        " m² (subtract one from the other with `minus`)");
        }
    return domain;
}

/// A region's real joints: its segments, its joint sets' traces and its DFN's
/// fractures (recorded in the assembly's fracture sets, traces and statistics).
struct RegionJoints {
    std::vector<SegmentSpec> segments;
    FractureNetwork network;
    bool any() const { return !segments.empty() || !network.fractures.empty(); }
};

RegionJoints region_joints(const RegionSpec& reg, int r, const Domain& domain, BlockAssembly& a) {
    Box2 box;
    for (const auto& p : domain)
        for (Vec2 q : p.outer) box.add(q);
    RegionJoints j;
    j.segments = reg.joints;
    for (const auto& js : reg.joint_sets) {
        const auto traces = joint_set_traces(js, box);
        j.segments.insert(j.segments.end(), traces.begin(), traces.end());
    }
    if (reg.dfn.empty()) return j;
    try {
        j.network = generate_fracture_network(reg.dfn, domain);
    } catch (const std::invalid_argument& e) {
        throw GeometryError(r, "dfn", e.what());
    }
    const int set_base = int(a.fracture_sets.size());
    for (const auto& s : reg.dfn) a.fracture_sets.push_back({s.name, s.property, r});
    for (std::size_t i = 0; i < j.network.traces.size(); ++i) {
        a.fracture_traces.push_back(j.network.traces[i]);
        a.fracture_trace_set.push_back(set_base + j.network.trace_set[i]);
    }
    a.fracture_stats.insert(a.fracture_stats.end(), j.network.stats.begin(), j.network.stats.end());
    return j;
}

/// Steps 2-4 for one region: its rock blocks cut by the real joints, each filled
/// with the inner pattern.
RegionBlocks fill_region(const RegionSpec& reg, const Domain& domain, const RegionJoints& joints, double tol,
                         BlockAssembly& a, GenerationStats& st) {
    detail::Random rng(reg.pattern.seed);
    const PatternSpec pattern = detail::generator_pattern(reg.pattern);
    RegionBlocks rb;
    auto add = [&](detail::FaceFill& fill) {
        st.collapsed_edges += fill.collapsed_edges;
        const int offset = rb.parent.empty() ? 0 : *std::max_element(rb.parent.begin(), rb.parent.end()) + 1;
        for (std::size_t k = 0; k < fill.polygons.size(); ++k) {
            rb.polygons.push_back(std::move(fill.polygons[k]));
            rb.parent.push_back(offset + fill.parent[k]);
        }
    };
    if (!joints.any()) {
        for (const auto& face : domain) {
            auto fill = detail::fill_face(face, pattern, rng);
            add(fill);
        }
        remove_spikes(rb, tol);
        return rb;
    }
    // Blocks under 1e-6 of a block's area (size²; a millimetre across in 0.5 m
    // blocks, cut off where a pattern's edge passes near a trace's crossing or
    // tip) run away in the first steps: merged across a pattern's edge, which
    // loses no trace. A rock block bounded by traces alone is merged at 1e-8
    // (where three traces cross nearly at one point), losing micrometres of trace.
    const double size2 = reg.pattern.size * reg.pattern.size;
    const detail::RegionCut cut(domain, cut_traces(joints.segments, joints.network), 1e-6 * size2, 1e-8 * size2, tol);
    const auto real = cut.real_segments();
    a.real_segments.insert(a.real_segments.end(), real.begin(), real.end());
    detail::CutStats cs;
    for (int k = 0; k < cut.face_count(); ++k) {
        auto fill = cut_face(cut, k, pattern, rng, cs);
        add(fill);
    }
    // A sliver the exact cut kept (thinner than the rounding, with no cell
    // edge to merge across) can round to a polygon of no area: no block.
    std::vector<char> flat(rb.polygons.size(), 0);
    for (std::size_t k = 0; k < rb.polygons.size(); ++k)
        flat[k] = rb.polygons[k].size() < 3 || std::abs(signed_area(rb.polygons[k])) <= tol * tol;
    cs.slivers_left += int(std::count(flat.begin(), flat.end(), char(1)));
    drop_blocks(rb, flat);
    st.merged_slivers += cut.merged_faces() + cs.merged_slivers;
    st.merged_trace_length += cut.merged_trace_length();
    st.slivers_left += cs.slivers_left;
    st.rock_bridges += cs.rock_bridges;
    st.hole_cuts += cs.hole_cuts;
    return rb;
}

/// The checks of a region's blocks once added: an exact cut tiles the region (else
/// a bug of bbm, never of the input); edges shorter than the pattern's minimum
/// are counted.
void check_region_blocks(const BlockAssembly& a, const RegionSpec& reg, int first_block, const Domain& domain,
                         bool cut_by_joints, GenerationStats& st) {
    if (cut_by_joints) {
        double covered = 0.0;
        for (int b = first_block; b < a.block_count(); ++b) covered += a.area[b];
        const double want = cgal::area(domain);
        if (!(std::abs(covered - want) <= 1e-9 * want))
            throw std::logic_error("bbm's cutting of region '" + reg.name + "' left " + fmt(covered) + " m² of " +
                                   fmt(want) + " m² covered (a bug)");
    }
    if (reg.pattern.kind == PatternSpec::Kind::single) return;
    const PatternSpec pattern = detail::generator_pattern(reg.pattern);
    const double min_edge = pattern.min_edge >= 0 ? pattern.min_edge : 0.1 * pattern.size;
    for (int b = first_block; b < a.block_count(); ++b) {
        const auto poly = a.block(b);
        for (std::size_t i = 0; i < poly.size(); ++i)
            if (norm(poly[(i + 1) % poly.size()] - poly[i]) < min_edge * (1.0 - 1e-12)) ++st.short_edges_left;
    }
}

} // namespace

BlockAssembly generate_blocks(const ModelGeometrySpec& spec, GenerationStats* stats) {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    // 1. Region domains.
    const std::vector<Domain> domain = region_domains(spec);
    const std::vector<SizeEstimate> estimate = check_model_size(spec, domain);
    const auto t1 = clock::now();

    // 2–4. Real joints, then the inner pattern in each rock block.
    BlockAssembly a;
    GenerationStats st;
    Box2 all;
    for (const auto& d : domain)
        for (const auto& p : d)
            for (Vec2 q : p.outer) all.add(q);
    const double tol = 1e-9 * std::max(all.width(), all.height());
    for (int r = 0; r < int(spec.regions.size()); ++r) {
        const RegionSpec& reg = spec.regions[r];
        a.region_names.push_back(reg.name);
        a.region_size.push_back(reg.pattern.size);
        const RegionJoints joints = region_joints(reg, r, domain[r], a);
        RegionBlocks rb = fill_region(reg, domain[r], joints, tol, a, st);
        order_along_curve(rb);
        const int parent_base = a.block_count();
        for (std::size_t k = 0; k < rb.polygons.size(); ++k)
            a.add_block(rb.polygons[k], r, reg.pattern.kind, parent_base + rb.parent[k]);
        check_region_filled(reg, r, a.block_count() - parent_base, estimate[r], cgal::area(domain[r]));
        check_region_blocks(a, reg, parent_base, domain[r], joints.any(), st);
    }
    const auto t2 = clock::now();

    // 5. Deformable blocks.
    if (std::any_of(spec.regions.begin(), spec.regions.end(),
                    [](const RegionSpec& reg) { return reg.mesh.enabled; }))
        mesh_deformable_blocks(a, spec, domain, st);
    const auto t3 = clock::now();

    // 6. Topology.
    detail::build_joints(a);
    const auto t4 = clock::now();
    st.seconds_regions = std::chrono::duration<double>(t1 - t0).count();
    st.seconds_patterns = std::chrono::duration<double>(t2 - t1).count();
    st.seconds_meshing = std::chrono::duration<double>(t3 - t2).count();
    st.seconds_topology = std::chrono::duration<double>(t4 - t3).count();
    if (stats) *stats = st;
    return a;
}

} // namespace bbm::meshing
