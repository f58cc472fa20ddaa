#include "studies/model/opening.hpp"

#include "core/joint_flow.hpp"
#include "core/measures.hpp"

#include <algorithm>
#include <functional>
#include <chrono>
#include <cmath>
#include <numbers>

namespace bbm {

namespace {

/// The displacement of the material point (rigid vertex or node, of a block still
/// there) that started nearest p.
Vec2 displacement_nearest(const World& w, Vec2 p) {
    const auto& b = w.blocks;
    const auto& n = w.nodes;
    const auto& x = w.vertices;
    const auto& removed = w.bodies.removed;
    double best = INFINITY;
    Vec2 u{};
    for (int i = 0; i < b.count(); ++i) {
        if (removed[i] || b.deformable[i]) continue;
        const auto& body = w.bodies.state[i];
        const Rotation rot = rotation(body.theta);
        for (std::uint32_t v = b.first[i]; v < b.first[i + 1]; ++v) {
            const Vec2 x0 = b.centroid0[i] + x.local[v];
            if (norm(x0 - p) >= best) continue;
            best = norm(x0 - p);
            u = body.centroid + rot(x.local[v]) - x0;
        }
    }
    for (int k = 0; k < n.count(); ++k)
        if (!removed[n.block[k]] && norm(n.position0[k] - p) < best)
            best = norm(n.position0[k] - p), u = n.position[k] - n.position0[k];
    return u;
}

/// The cracks in the ±30° sectors toward the springline and the crown (into `m`),
/// and the distances beyond the wall of those within ±15° of each.
void count_sector_cracks(const World& w, Vec2 center, Vec2 springline, Vec2 crown, OpeningMeasures& m,
                         std::vector<double>& depth_s, std::vector<double>& depth_c) {
    const auto& x = w.vertices;
    const Vec2 ds = (springline - center) / norm(springline - center), dc = (crown - center) / norm(crown - center);
    const double rs = norm(springline - center), rc = norm(crown - center);
    const double cos30 = std::cos(30.0 * 3.141592653589793 / 180.0), cos15 = std::cos(15.0 * 3.141592653589793 / 180.0);
    const auto& c = contacts(w);
    for (int i = 0; i < c.size(); ++i) {
        const auto mode = c.history[i].broken;
        if (mode != contact::JointState::broken_tension && mode != contact::JointState::broken_shear) continue;
        const Vec2 r = x.position[c.vertex_id[i]] - center;
        const double d = norm(r);
        if (d <= 0) continue;
        const double cs = dot(r, ds) / d, cc = dot(r, dc) / d;
        if (cs >= cos30) {
            ++m.cracks_springline_sector;
            (mode == contact::JointState::broken_tension ? m.tensile_springline_sector : m.shear_springline_sector)++;
        }
        if (cc >= cos30) ++m.cracks_crown_sector;
        if (cs >= cos15) depth_s.push_back(d - rs);
        if (cc >= cos15) depth_c.push_back(d - rc);
    }
}

/// Depth of the failed zone: within it lie 90% of the sector's cracks (a lone
/// crack far from the wall is not a failed zone); fewer than 3 cracks: none.
double sector_crack_depth(std::vector<double>& v) {
    if (v.size() < 3) return 0.0;
    std::sort(v.begin(), v.end());
    return std::max(0.0, v[std::size_t(std::ceil(0.9 * double(v.size()))) - 1]);
}

} // namespace

OpeningMeasures measure_opening(const World& w, Vec2 center, Vec2 springline, Vec2 crown) {
    OpeningMeasures m;
    m.springline_displacement = displacement_nearest(w, springline);
    m.crown_displacement = displacement_nearest(w, crown);
    const Vec2 ds = (springline - center) / norm(springline - center), dc = (crown - center) / norm(crown - center);
    m.springline_convergence = -dot(m.springline_displacement, ds);
    m.crown_convergence = -dot(m.crown_displacement, dc);
    std::vector<double> depth_s, depth_c;
    count_sector_cracks(w, center, springline, crown, m, depth_s, depth_c);
    m.failed_depth_springline = sector_crack_depth(depth_s);
    m.failed_depth_crown = sector_crack_depth(depth_c);
    return m;
}

namespace {

constexpr double pi = 3.141592653589793;
/// The failed zone's depth is read on this many polar grids, their rings shifted
/// by a fraction of a cell (measure_failed_zone).
constexpr int grid_shifts = 8;

/// Cells of `cell` width in rings around the opening from the smaller radius out,
/// `sectors` to a ring, ring-major.
struct PolarCells {
    Vec2 center;
    double radius, cell;
    int sectors, rings = 0;
    /// The ring and sector of a point, or ring −1 inside the radius.
    std::pair<int, int> of(Vec2 p) const {
        const Vec2 r = p - center;
        const double d = norm(r);
        if (d < radius) return {-1, 0};
        double angle = std::atan2(r.y, r.x);
        if (angle < 0) angle += 2 * pi;
        return {int((d - radius) / cell), std::min(sectors - 1, int(angle / (2 * pi) * sectors))};
    }
    int size() const { return rings * sectors; }
};

/// The length of the rock's joints in each cell, all and broken, at their initial
/// positions; and the cells that hold the edge of the opening's region (an
/// interface with a deformable region: the elastic far field).
struct CellJoints {
    std::vector<double> all, broken;
    std::vector<std::uint8_t> edge;
    /// Per contact of the rock's joints: its cell (−1: not the rock's, or inside
    /// the radius), whether broken, and its distance from the centre at its
    /// initial position (the contact point: the vertex the joint's force acts at).
    std::vector<int> cell;
    std::vector<std::uint8_t> is_broken;
    std::vector<double> distance;
};

CellJoints joints_per_cell(const World& w, PolarCells& g) {
    const auto& b = w.blocks;
    const auto& n = w.nodes;
    const auto& removed = w.bodies.removed;
    const auto& c = contacts(w);
    auto initial = [&](int v, int blk) {
        const int node = w.vertices.node[v];
        return node >= 0 ? n.position0[node] : b.centroid0[blk] + w.vertices.local[v];
    };
    CellJoints j;
    j.cell.assign(std::size_t(c.size()), -1), j.is_broken.assign(j.cell.size(), 0), j.distance.assign(j.cell.size(), 0.0);
    for (int i = 0; i < c.size(); ++i) {
        const Vec2 x0 = initial(c.vertex_id[i], c.vertex_block[i]);
        const auto [ring, sector] = g.of(x0);
        if (ring < 0) continue;
        g.rings = std::max(g.rings, ring + 1);
        // Joints of the rock only: a contact formed unbonded during the run (between
        // fragments, or a fragment and the wall) is neither intact rock nor a crack.
        const auto& h = c.history[i];
        const bool is_broken = h.broken == contact::JointState::broken_tension || h.broken == contact::JointState::broken_shear;
        if (!h.bonded && !is_broken) continue;
        j.cell[std::size_t(i)] = ring * g.sectors + sector, j.is_broken[std::size_t(i)] = is_broken;
        j.distance[std::size_t(i)] = norm(x0 - g.center);
    }
    j.all.assign(std::size_t(g.size()), 0.0), j.broken.assign(j.all.size(), 0.0);
    j.edge.assign(j.all.size(), 0);
    for (int i = 0; i < c.size(); ++i) {
        const int ba = c.vertex_block[i], bb = c.edge_block[i];
        if (b.region[ba] == b.region[bb] || removed[ba] || removed[bb] || !(b.deformable[ba] || b.deformable[bb]))
            continue;
        const auto [ring, sector] = g.of(initial(c.vertex_id[i], ba));
        if (ring >= 0 && ring < g.rings) j.edge[std::size_t(ring * g.sectors + sector)] = 1;
    }
    for (int i = 0; i < c.size(); ++i) {
        const int cell_index = j.cell[std::size_t(i)];
        if (cell_index < 0) continue;
        j.all[std::size_t(cell_index)] += c.length[i];
        if (j.is_broken[std::size_t(i)]) j.broken[std::size_t(cell_index)] += c.length[i];
    }
    return j;
}

/// The damaged cells connected to the wall: flooded from the damaged cells of
/// each sector's innermost ring that holds rock (`wall`), across rings and sectors.
std::vector<std::uint8_t> flood_from_wall(const PolarCells& g, const std::vector<int>& wall,
                                          const std::function<bool(int)>& damaged) {
    const int sectors = g.sectors, rings = g.rings;
    std::vector<std::uint8_t> in_zone(std::size_t(g.size()), 0);
    std::vector<int> stack;
    for (int sector = 0; sector < sectors; ++sector) {
        const int k = wall[std::size_t(sector)] * sectors + sector;
        if (wall[std::size_t(sector)] < rings && damaged(k)) in_zone[std::size_t(k)] = 1, stack.push_back(k);
    }
    while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        const int ring = k / sectors, sector = k % sectors;
        const int next[4] = {ring > 0 ? k - sectors : -1, ring + 1 < rings ? k + sectors : -1,
                             ring * sectors + (sector + 1) % sectors, ring * sectors + (sector + sectors - 1) % sectors};
        for (int m : next)
            if (m >= 0 && !in_zone[std::size_t(m)] && damaged(m)) in_zone[std::size_t(m)] = 1, stack.push_back(m);
    }
    return in_zone;
}

/// Toward a point of the wall: the deepest sector whose centre is within 15 deg,
/// and the angular width of the zone within 45 deg.
void zone_toward(const FailedZone& z, int sectors, Vec2 towards, double& depth, double& extent) {
    const Vec2 dir = (towards - z.center) / norm(towards - z.center);
    for (int k = 0; k < sectors; ++k) {
        const double mid = (k + 0.5) * 2 * pi / sectors;
        const double off = std::acos(std::clamp(dir.x * std::cos(mid) + dir.y * std::sin(mid), -1.0, 1.0)) * 180 / pi;
        if (off <= 15.0 + 1e-9) depth = std::max(depth, z.depth[std::size_t(k)]);
        if (off <= 45.0 + 1e-9 && z.depth[std::size_t(k)] > 0) extent += 360.0 / sectors;
    }
}

} // namespace

namespace {

/// The zone on one polar grid: the rock's joints per cell, each sector's wall
/// ring, and the damaged cells connected to the wall.
struct GridZone {
    PolarCells grid;
    CellJoints joints;
    std::vector<int> wall;
    std::vector<std::uint8_t> in_zone;
    bool damaged(int k, double threshold) const {
        return joints.all[std::size_t(k)] > 0 && joints.broken[std::size_t(k)] >= threshold * joints.all[std::size_t(k)];
    }
};

GridZone zone_on_grid(const World& w, PolarCells grid, double threshold) {
    CellJoints joints = joints_per_cell(w, grid); // counts the grid's rings
    GridZone z{grid, std::move(joints), {}, {}};
    const int sectors = z.grid.sectors, rings = z.grid.rings;
    // The wall in each sector: its innermost ring that holds rock (an opening that
    // is not a circle leaves the first rings of its longer directions empty).
    z.wall.assign(std::size_t(sectors), rings);
    for (int sector = 0; sector < sectors; ++sector)
        for (int ring = 0; ring < rings; ++ring)
            if (z.joints.all[std::size_t(ring * sectors + sector)] > 0) {
                z.wall[std::size_t(sector)] = ring;
                break;
            }
    z.in_zone = flood_from_wall(z.grid, z.wall, [&](int k) { return z.damaged(k, threshold); });
    return z;
}

/// Per sector, the distance from the centre of the zone's outermost broken
/// contact point (−inf: none).
std::vector<double> outermost_broken(const GridZone& z) {
    const auto sectors = std::size_t(z.grid.sectors);
    std::vector<double> out(sectors, -INFINITY);
    for (std::size_t i = 0; i < z.joints.cell.size(); ++i) {
        const int k = z.joints.cell[i];
        if (k >= 0 && z.joints.is_broken[i] && z.in_zone[std::size_t(k)])
            out[std::size_t(k) % sectors] = std::max(out[std::size_t(k) % sectors], z.joints.distance[i]);
    }
    return out;
}

/// The band along the region's edge: its cells and their neighbours, inside it.
bool near_region_edge(const GridZone& g, int k) {
    const int sectors = g.grid.sectors, rings = g.grid.rings;
    const int ring = k / sectors, sector = k % sectors;
    for (int dr = -1; dr <= 1; ++dr)
        for (int ds = -1; ds <= 1; ++ds) {
            const int rr = ring + dr, ss = (sector + ds + sectors) % sectors;
            if (rr >= 0 && rr < rings && g.joints.edge[std::size_t(rr * sectors + ss)]) return true;
        }
    return false;
}

/// The cells of rock in the band along the region's edge, and the damaged ones.
void count_edge_cells(FailedZone& z, const GridZone& g, double threshold) {
    for (int k = 0; k < g.grid.size(); ++k)
        if (g.joints.all[std::size_t(k)] > 0 && near_region_edge(g, k))
            ++z.edge_cells, z.edge_cells_damaged += g.damaged(k, threshold);
}

/// The zone's cells on the first grid: its area, its depth per sector in whole
/// cells, and whether (and nearest the centre, where) it reaches the region's edge.
void add_zone_cells(FailedZone& z, const GridZone& g) {
    const int sectors = g.grid.sectors;
    const double cell = z.cell;
    const Vec2 center = z.center;
    for (std::size_t k = 0; k < g.in_zone.size(); ++k) {
        if (!g.in_zone[k]) continue;
        const int ring = int(k) / sectors, sector = int(k) % sectors;
        if (near_region_edge(g, int(k)) &&
            (!z.reaches_region_edge || norm(z.region_edge_point - center) < z.radius + (ring + 0.5) * cell)) {
            const double mid = (sector + 0.5) * 2 * pi / sectors;
            z.reaches_region_edge = true;
            z.region_edge_point = center + (z.radius + (ring + 0.5) * cell) * Vec2{std::cos(mid), std::sin(mid)};
        }
        z.depth_cells[std::size_t(sector)] =
            std::max(z.depth_cells[std::size_t(sector)], (ring + 1 - g.wall[std::size_t(sector)]) * cell);
        const double r0 = z.radius + ring * cell, r1 = r0 + cell;
        z.area += pi * (r1 * r1 - r0 * r0) / sectors;
    }
}

/// The wall in each sector at the contacts' resolution: its innermost contact
/// point of the rock (inf: none).
std::vector<double> wall_distances(const CellJoints& j, int sectors) {
    std::vector<double> wall_distance(std::size_t(sectors), INFINITY);
    for (std::size_t i = 0; i < j.cell.size(); ++i)
        if (j.cell[i] >= 0) {
            const auto sector = std::size_t(j.cell[i] % sectors);
            wall_distance[sector] = std::min(wall_distance[sector], j.distance[i]);
        }
    return wall_distance;
}

/// The depth: the zone's outermost broken contact point, on grids whose rings
/// start `grid_shifts` fractions of a cell apart, the median over them. On one
/// grid the outermost broken contact of a dense zone sits at the outer edge of
/// its deepest cell (the next cell out is under the threshold), so one grid would
/// still step a cell; the shifted grids' edges are a cell / grid_shifts apart.
void set_median_depths(FailedZone& z, const World& w, const GridZone& g0, const std::vector<double>& wall_distance) {
    const int sectors = g0.grid.sectors;
    const double cell = z.cell;
    std::vector<std::vector<double>> depths(z.depth.size());
    for (int shift = 0; shift < grid_shifts; ++shift) {
        const GridZone g = shift == 0 ? g0
                                      : zone_on_grid(w, PolarCells{z.center, z.radius - shift * cell / grid_shifts, cell, sectors},
                                                     z.threshold);
        const auto outermost = outermost_broken(g);
        for (std::size_t sector = 0; sector < std::size_t(sectors); ++sector)
            depths[sector].push_back(std::isfinite(outermost[sector]) ? outermost[sector] - wall_distance[sector] : 0.0);
    }
    for (std::size_t sector = 0; sector < std::size_t(sectors); ++sector) {
        auto& d = depths[sector];
        std::sort(d.begin(), d.end());
        z.depth[sector] = 0.5 * (d[(d.size() - 1) / 2] + d[d.size() / 2]);
    }
}

/// The resolution: the larger of the grids' step and the mean radial step
/// between the distinct contact points a depth can end at, within four cells of
/// the wall, the median over sectors (a sector along a symmetry plane holds only
/// that plane's points).
double depth_resolution(const CellJoints& j, const std::vector<double>& wall_distance, double cell, int sectors) {
    std::vector<std::vector<double>> band(wall_distance.size());
    for (std::size_t i = 0; i < j.cell.size(); ++i)
        if (j.cell[i] >= 0) {
            const auto sector = std::size_t(j.cell[i] % sectors);
            if (j.distance[i] <= wall_distance[sector] + 4 * cell) band[sector].push_back(j.distance[i]);
        }
    std::vector<double> step;
    for (auto& d : band) {
        // A contact point is a block's corner, which several joints' contacts share.
        std::sort(d.begin(), d.end());
        d.erase(std::unique(d.begin(), d.end(), [](double x, double y) { return y - x < 1e-9; }), d.end());
        if (d.size() >= 2) step.push_back((d.back() - d.front()) / double(d.size() - 1));
    }
    double resolution = 0.0;
    if (!step.empty()) {
        std::nth_element(step.begin(), step.begin() + std::ptrdiff_t(step.size() / 2), step.end());
        resolution = step[step.size() / 2];
    }
    return std::max(resolution, cell / grid_shifts);
}

} // namespace

FailedZone measure_failed_zone(const World& w, Vec2 center, Vec2 springline, Vec2 crown, double cell,
                               double threshold, int sectors) {
    FailedZone z;
    z.cell = cell, z.threshold = threshold, z.center = center;
    z.radius = std::min(norm(springline - center), norm(crown - center));
    z.depth.assign(std::size_t(sectors), 0.0), z.depth_cells.assign(std::size_t(sectors), 0.0);
    const GridZone g0 = zone_on_grid(w, PolarCells{center, z.radius, cell, sectors}, threshold);
    count_edge_cells(z, g0, threshold);
    add_zone_cells(z, g0);
    const std::vector<double> wall_distance = wall_distances(g0.joints, sectors);
    z.wall_offset.assign(std::size_t(sectors), 0.0);
    for (std::size_t sector = 0; sector < std::size_t(sectors); ++sector)
        if (std::isfinite(wall_distance[sector])) z.wall_offset[sector] = std::max(0.0, wall_distance[sector] - z.radius);
    set_median_depths(z, w, g0, wall_distance);
    z.resolution = depth_resolution(g0.joints, wall_distance, cell, sectors);
    zone_toward(z, sectors, springline, z.depth_springline, z.extent_springline_deg);
    zone_toward(z, sectors, crown, z.depth_crown, z.extent_crown_deg);
    return z;
}

FailedZone measure_failed_zone(const World& w, Vec2 center, Vec2 springline, Vec2 crown) {
    const auto& c = contacts(w);
    double length = 0.0;
    for (int i = 0; i < c.size(); ++i) length += c.length[i];
    const double cell = c.size() > 0 ? 4.0 * length / c.size() : 0.3;
    return measure_failed_zone(w, center, springline, crown, cell);
}

std::vector<Vec2> FailedZone::outline() const {
    std::vector<Vec2> points;
    const int sectors = int(depth.size());
    for (int k = 0; k < sectors; ++k) {
        const double mid = (k + 0.5) * 2 * 3.141592653589793 / sectors;
        points.push_back(center + (radius + wall_offset[std::size_t(k)] + depth[std::size_t(k)]) *
                                      Vec2{std::cos(mid), std::sin(mid)});
    }
    return points;
}

std::vector<FailedZone::Lobe> FailedZone::lobes() const {
    const int sectors = int(depth.size());
    const double pi = std::numbers::pi, width = 2 * pi / std::max(1, sectors);
    std::vector<Lobe> out;
    // Start the walk after an empty sector, so a lobe across 0 degrees is one lobe.
    int start = -1;
    for (int k = 0; k < sectors; ++k)
        if (depth[std::size_t(k)] <= 0) start = k;
    if (start < 0) start = 0; // the zone goes all round: one lobe
    double sx = 0, sy = 0;
    Lobe lobe;
    auto close = [&] {
        if (lobe.width_deg <= 0) return;
        double c = std::atan2(sy, sx) * 180 / pi;
        lobe.centre_deg = c < 0 ? c + 360 : c;
        out.push_back(lobe);
        lobe = {}, sx = sy = 0;
    };
    for (int n = 1; n <= sectors; ++n) {
        const int k = (start + n) % sectors;
        const double d = depth[std::size_t(k)];
        if (d <= 0) {
            close();
            continue;
        }
        const double mid = (k + 0.5) * width, r = radius + (wall_offset.empty() ? 0.0 : wall_offset[std::size_t(k)]);
        sx += d * std::cos(mid), sy += d * std::sin(mid);
        lobe.depth = std::max(lobe.depth, d);
        lobe.width_deg += 360.0 / sectors;
        lobe.area += 0.5 * width * ((r + d) * (r + d) - r * r);
    }
    close();
    std::stable_sort(out.begin(), out.end(), [](const Lobe& a, const Lobe& b) { return a.area > b.area; });
    return out;
}

double hoop_stress_at(const World& w, const std::vector<std::array<double, 3>>& block_stress, Vec2 center,
                      Vec2 towards, double r, double band) {
    const Vec2 dir = (towards - center) / norm(towards - center), p = center + r * dir;
    const auto& b = w.blocks;
    const auto& removed = w.bodies.removed;
    double sum = 0.0, weight = 0.0;
    // σθθ = t·σ·t with t the tangent of the circle through x.
    auto add = [&](Vec2 x, const std::array<double, 3>& st, double area) {
        if (norm(x - p) > band) return;
        const Vec2 rad = (x - center) / norm(x - center), t{-rad.y, rad.x};
        sum += area * (st[0] * t.x * t.x + st[1] * t.y * t.y + 2.0 * st[2] * t.x * t.y);
        weight += area;
    };
    for (int i = 0; i < b.count(); ++i)
        if (!removed[i] && !b.deformable[i]) add(w.bodies.state[i].centroid, block_stress[i], b.area[i]);
    const auto& z = w.zones;
    const auto& n = w.nodes;
    for (int k = 0; k < z.size(); ++k) {
        if (removed[z.block[k]]) continue;
        const auto& t = z.node[k];
        const auto g = fem::gradients(n.position[t[0]], n.position[t[1]], n.position[t[2]]);
        add((n.position[t[0]] + n.position[t[1]] + n.position[t[2]]) / 3.0, z.stress[k], g.area);
    }
    return weight > 0 ? sum / weight : NAN;
}

} // namespace bbm

namespace bbm {

namespace {

/// What the axial-permeability measures share: the network, its state, the
/// blocks, the opening (centre and smaller radius).
struct AxialNetwork {
    const JointFlow& flow;
    const flow::Network& net;
    const flow::State& st;
    const Blocks& b;
    const std::vector<std::uint8_t>& removed;
    Vec2 center;
    double radius;
    /// L a³ / 12: what pipe p carries along the tunnel per unit gradient over μ.
    double transmissivity(int p) const {
        const double a = flow::hydraulic_aperture(flow.fluid, st.aperture[p]);
        return net.pipe_length[p] * a * a * a / 12.0;
    }
    Vec2 midpoint(int p) const {
        return 0.5 * (net.domain_position[net.pipe_from[p]] + net.domain_position[net.pipe_to[p]]);
    }
};

/// The permeability by ring of `ring` metres out to the nearest held junction
/// that is not the wall's (the interface with the dry far field: whole rings of
/// wet rock), toward the crown, the springline (both sides, 60° each) and all round.
void axial_profiles(const AxialNetwork& an, Vec2 springline, Vec2 crown, AxialPermeability& k) {
    const auto& net = an.net;
    double reach = INFINITY, farthest = 0.0;
    for (int d = 0; d < net.domains(); ++d) {
        const double r = norm(net.domain_position[d] - an.center);
        farthest = std::max(farthest, r);
        if (an.st.held[std::size_t(d)] && !an.flow.drained[std::size_t(d)]) reach = std::min(reach, r);
    }
    if (!std::isfinite(reach)) reach = farthest;
    const int rings = std::max(0, int((reach - an.radius) / k.ring));
    const Vec2 dc = (crown - an.center) / norm(crown - an.center);
    const Vec2 ds = (springline - an.center) / norm(springline - an.center);
    const double cos30 = std::cos(30.0 * std::numbers::pi / 180.0);
    std::vector<double> t_crown(std::size_t(rings), 0.0), t_spring(t_crown), t_all(t_crown);
    for (int p = 0; p < net.pipes(); ++p) {
        const Vec2 r = an.midpoint(p) - an.center;
        const double d = norm(r);
        const int i = d >= an.radius ? int((d - an.radius) / k.ring) : -1;
        if (i < 0 || i >= rings) continue;
        const double t = an.transmissivity(p);
        t_all[std::size_t(i)] += t;
        if (std::abs(dot(r, dc)) >= cos30 * d) t_crown[std::size_t(i)] += t;
        if (std::abs(dot(r, ds)) >= cos30 * d) t_spring[std::size_t(i)] += t;
    }
    for (int i = 0; i < rings; ++i) {
        const double r0 = an.radius + i * k.ring, r1 = r0 + k.ring, area = std::numbers::pi * (r1 * r1 - r0 * r0);
        k.all_round.push_back(t_all[std::size_t(i)] / area);
        k.crown.push_back(t_crown[std::size_t(i)] / (area / 3.0));
        k.springline.push_back(t_spring[std::size_t(i)] / (area / 3.0));
    }
}

/// The damaged zone: the fractured pipes (a³ ≥ 10 a_bond³) reached from the
/// drained wall through fractured pipes; its area, depth, transmissivity, and
/// the core: the fewest of its pipes (largest first) carrying 90% of it.
void damaged_zone(const AxialNetwork& an, double bond, AxialPermeability& k) {
    const auto& net = an.net;
    const double fractured_t = 10.0 * bond * bond * bond;
    auto fractured = [&](int p) {
        const double a = flow::hydraulic_aperture(an.flow.fluid, an.st.aperture[p]);
        return a > 0.0 && a * a * a >= fractured_t;
    };
    std::vector<std::vector<int>> pipes_at(std::size_t(net.domains()));
    for (int p = 0; p < net.pipes(); ++p)
        if (fractured(p)) pipes_at[std::size_t(net.pipe_from[p])].push_back(p), pipes_at[std::size_t(net.pipe_to[p])].push_back(p);
    std::vector<std::uint8_t> reached(std::size_t(net.domains()), 0), in_zone(std::size_t(net.pipes()), 0);
    std::vector<int> stack;
    for (int d = 0; d < net.domains(); ++d)
        if (an.flow.drained[std::size_t(d)]) reached[std::size_t(d)] = 1, stack.push_back(d);
    while (!stack.empty()) {
        const int d = stack.back();
        stack.pop_back();
        for (int p : pipes_at[std::size_t(d)]) {
            in_zone[std::size_t(p)] = 1;
            for (int e : {net.pipe_from[p], net.pipe_to[p]})
                if (!reached[std::size_t(e)]) reached[std::size_t(e)] = 1, stack.push_back(e);
        }
    }
    std::vector<std::pair<double, int>> zone;
    std::vector<std::uint8_t> bordering(std::size_t(an.b.count()), 0);
    auto border_area = [&](int p) {
        double area = 0.0;
        for (int blk : {an.flow.pipe_block_a[p], an.flow.pipe_block_b[p]})
            if (!an.removed[blk] && !bordering[std::size_t(blk)]) bordering[std::size_t(blk)] = 1, area += an.b.area[blk];
        return area;
    };
    for (int p = 0; p < net.pipes(); ++p) {
        if (!in_zone[std::size_t(p)]) continue;
        const double t = an.transmissivity(p);
        zone.push_back({t, p});
        ++k.edz_joints;
        k.edz_transmissivity += t;
        k.edz_area += border_area(p);
        k.edz_depth = std::max(k.edz_depth, norm(an.midpoint(p) - an.center) - an.radius);
        k.parted_joints += an.st.aperture[p] >= an.flow.fluid.max_aperture;
    }
    k.edz_permeability = k.edz_area > 0 ? k.edz_transmissivity / k.edz_area : 0.0;
    // Largest first, ties by pipe number: the same on any thread count.
    std::sort(zone.begin(), zone.end(), [](const auto& x, const auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
    std::fill(bordering.begin(), bordering.end(), 0);
    double carried = 0.0;
    for (const auto& [t, p] : zone) {
        if (carried >= 0.9 * k.edz_transmissivity) break;
        carried += t;
        ++k.core_joints;
        k.core_area += border_area(p);
    }
}

} // namespace

AxialPermeability measure_axial_permeability(const World& w, Vec2 center, Vec2 springline, Vec2 crown,
                                             double ring) {
    AxialPermeability k;
    k.ring = ring;
    if (!w.flow || !(ring > 0)) return k;
    const JointFlow& flow = *w.flow;
    const AxialNetwork an{flow, flow.net, flow.state, w.blocks, w.bodies.removed, center,
                          std::min(norm(springline - center), norm(crown - center))};
    // Intact: every bond at its aperture, over the flow regions' rock.
    const double bond = flow::hydraulic_aperture(flow.fluid, flow.spec.bond_aperture);
    double joint_length = 0.0, rock_area = 0.0;
    std::vector<std::uint8_t> wet(std::size_t(an.b.count()), 0);
    for (int p = 0; p < an.net.pipes(); ++p) {
        joint_length += an.net.pipe_length[p];
        wet[std::size_t(flow.pipe_block_a[p])] = wet[std::size_t(flow.pipe_block_b[p])] = 1;
    }
    for (int i = 0; i < an.b.count(); ++i)
        if (wet[std::size_t(i)]) rock_area += an.b.area[i];
    k.intact = rock_area > 0 ? joint_length * bond * bond * bond / 12.0 / rock_area : 0.0;
    axial_profiles(an, springline, crown, k);
    damaged_zone(an, bond, k);
    return k;
}

} // namespace bbm
