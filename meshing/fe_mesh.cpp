// Boundary subdivision and gmsh triangle meshes of deformable blocks (fe_mesh.hpp).
#include "meshing/fe_mesh.hpp"

#include "base/error.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <string>

namespace bbm::meshing {
namespace {

GeometryError mesh_error(const std::string& message) {
    return GeometryError(-1, "mesh", message);
}

std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string fmt(Vec2 p) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "(%.9g, %.9g)", p.x, p.y);
    return buf;
}

double checked_size(const SizeFunction& size, Vec2 at) {
    const double h = size(at);
    if (!(h > 0) || !std::isfinite(h))
        throw mesh_error("the mesh size at " + fmt(at) + " is " + fmt(h) + " m; it must be > 0");
    return h;
}

bool lexicographically_less(Vec2 a, Vec2 b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

/// Appends the interior points of the edge a→b, a lexicographically before b.
void edge_points(Vec2 a, Vec2 b, const SizeFunction& size, std::vector<Vec2>& out) {
    constexpr int samples = 16; // intervals of the trapezoidal rule
    const Vec2 d = b - a;
    const double step = norm(d) / samples;
    double cum[samples + 1]; // ∫ 1/h ds from a to sample k
    cum[0] = 0.0;
    double prev = 1.0 / checked_size(size, a);
    for (int k = 1; k <= samples; ++k) {
        const Vec2 x = k == samples ? b : a + (double(k) / samples) * d;
        const double inv = 1.0 / checked_size(size, x);
        cum[k] = cum[k - 1] + 0.5 * (prev + inv) * step;
        prev = inv;
    }
    const double total = cum[samples];
    if (!(total < 1e7))
        throw mesh_error("the edge " + fmt(a) + " - " + fmt(b) + " would get over 1e7 points");
    // The relative slack keeps an edge of exactly 10 sizes at 10 pieces despite rounding.
    const int n = std::max(1, int(std::ceil(total * (1.0 - 1e-12))));
    int k = 0;
    for (int j = 1; j < n; ++j) {
        const double target = total * double(j) / n;
        while (k < samples - 1 && cum[k + 1] < target)
            ++k;
        const double f = (target - cum[k]) / (cum[k + 1] - cum[k]);
        out.push_back(a + ((k + f) / samples) * d);
    }
}

// gmsh has one global state: it is initialised once per process, and every call
// into it holds this lock.
std::mutex gmsh_mutex;
bool gmsh_ready = false;

void initialise_gmsh() {
    if (gmsh_ready) return;
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    // gmsh meshes faces inside an OpenMP region, from which an exception cannot
    // escape (std::terminate): errors are logged instead, and the mesh is checked.
    gmsh::option::setNumber("General.AbortOnError", 0);
    gmsh::option::setNumber("General.NumThreads", 1);     // serial: reproducible meshes
    gmsh::option::setNumber("Geometry.AutoCoherence", 0); // never merge close boundary points
    gmsh::option::setNumber("Mesh.Algorithm", 6);         // Frontal-Delaunay: well-shaped triangles
    gmsh::option::setNumber("Mesh.ElementOrder", 1);
    gmsh::option::setNumber("Mesh.RecombineAll", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 1);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 1);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    std::atexit([] { gmsh::finalize(); });
    gmsh_ready = true;
}

/// The gmsh model of one call, with its messages logged: removed (and the log
/// stopped) however the call ends.
class GmshModel {
  public:
    GmshModel() {
        gmsh::logger::start();
        gmsh::model::add("bbm_block");
    }
    ~GmshModel() {
        try {
            gmsh::model::remove();
            gmsh::logger::stop();
        } catch (...) {
        }
    }
    GmshModel(const GmshModel&) = delete;
    GmshModel& operator=(const GmshModel&) = delete;
    /// The first error gmsh logged in this model, or "".
    std::string first_error() const {
        std::vector<std::string> log;
        gmsh::logger::get(log);
        for (const auto& line : log)
            if (line.rfind("Error", 0) == 0)
                return line.substr(std::min<std::size_t>(line.size(), 7));
        return {};
    }
};

/// Nodes and triangles of the current gmsh model, boundary points first.
TriangleMesh read_mesh(std::span<const Vec2> boundary) {
    const int nb = int(boundary.size());
    std::vector<std::size_t> tags, tri_tags, tri_nodes;
    std::vector<double> xyz, param;

    gmsh::model::mesh::getNodes(tags, xyz, param, 1, -1, false, false);
    if (!tags.empty())
        throw mesh_error("gmsh added " + std::to_string(tags.size()) +
                         " nodes on the boundary segments");

    gmsh::model::mesh::getNodes(tags, xyz, param, -1, -1, false, false);
    std::size_t max_tag = 0;
    for (std::size_t t : tags)
        max_tag = std::max(max_tag, t);
    std::vector<int> index(max_tag + 1, -1);
    std::vector<int> gmsh_node(max_tag + 1, -1); // tag -> position in `tags`
    for (std::size_t i = 0; i < tags.size(); ++i)
        gmsh_node[tags[i]] = int(i);

    TriangleMesh m;
    m.nodes.assign(boundary.begin(), boundary.end());
    m.boundary_nodes = nb;
    const Box2 box = bounding_box(boundary);
    const double tol = 1e-9 * std::max(box.width(), box.height());
    std::vector<std::size_t> point_tags;
    std::vector<double> point_xyz;
    for (int i = 0; i < nb; ++i) {
        gmsh::model::mesh::getNodes(point_tags, point_xyz, param, 0, i + 1, false, false);
        if (point_tags.size() != 1 || point_tags[0] > max_tag || index[point_tags[0]] != -1)
            throw mesh_error("gmsh gave no single node for the boundary point " + fmt(boundary[i]));
        const Vec2 g{point_xyz[0], point_xyz[1]};
        if (norm(g - boundary[i]) > tol)
            throw mesh_error("gmsh moved the boundary point " + fmt(boundary[i]) + " to " + fmt(g));
        index[point_tags[0]] = i;
    }

    gmsh::model::mesh::getElementsByType(2, tri_tags, tri_nodes, -1);
    if (tri_tags.empty()) throw mesh_error("gmsh returned no triangles");
    m.triangles.reserve(tri_tags.size());
    for (std::size_t e = 0; e < tri_tags.size(); ++e) {
        std::array<int, 3> t;
        for (int k = 0; k < 3; ++k) {
            const std::size_t tag = tri_nodes[3 * e + k];
            if (tag > max_tag || gmsh_node[tag] < 0)
                throw mesh_error("gmsh returned a triangle with an unknown node");
            if (index[tag] < 0) { // an interior node, numbered in order of first use
                const int g = gmsh_node[tag];
                index[tag] = int(m.nodes.size());
                m.nodes.push_back({xyz[3 * g], xyz[3 * g + 1]});
            }
            t[k] = index[tag];
        }
        m.triangles.push_back(t);
    }
    return m;
}

/// Orients every triangle counter-clockwise and checks that they cover the polygon.
void orient_and_check(TriangleMesh& m, std::span<const Vec2> boundary) {
    const double polygon = signed_area(boundary);
    double covered = 0.0;
    for (auto& t : m.triangles) {
        const Vec2 a = m.nodes[t[0]], b = m.nodes[t[1]], c = m.nodes[t[2]];
        double area = 0.5 * cross(b - a, c - a);
        if (area < 0) std::swap(t[1], t[2]), area = -area;
        if (!(area > 1e-14 * polygon))
            throw mesh_error("gmsh returned a degenerate triangle at " + fmt((a + b + c) / 3.0));
        covered += area;
    }
    if (std::abs(covered - polygon) > 1e-9 * polygon)
        throw mesh_error("the triangles cover " + fmt(covered) + " m² of the polygon's " +
                         fmt(polygon) + " m²");
}

} // namespace

std::vector<Vec2> subdivide_boundary(std::span<const Vec2> polygon, const SizeFunction& size) {
    std::vector<Vec2> out, piece;
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = polygon[i], b = polygon[(i + 1) % n];
        out.push_back(a);
        if (a == b) continue;
        piece.clear();
        if (lexicographically_less(a, b)) {
            edge_points(a, b, size, piece);
        } else {
            edge_points(b, a, size, piece);
            std::reverse(piece.begin(), piece.end());
        }
        out.insert(out.end(), piece.begin(), piece.end());
    }
    return out;
}

TriangleMesh mesh_polygon(std::span<const Vec2> boundary, const SizeFunction& size, bool verbose) {
    const int n = int(boundary.size());
    if (n < 3 || !(signed_area(boundary) > 0))
        throw mesh_error("the polygon to mesh is not counter-clockwise with 3 or more points");
    for (int i = 0; i < n; ++i)
        if (boundary[i] == boundary[(i + 1) % n])
            throw mesh_error("the polygon to mesh repeats the point " + fmt(boundary[i]));
    std::vector<double> h(n);
    for (int i = 0; i < n; ++i)
        h[i] = checked_size(size, boundary[i]);

    const std::lock_guard<std::mutex> lock(gmsh_mutex);
    TriangleMesh m;
    try {
        initialise_gmsh();
        // gmsh applies its thread count as the calling thread's OpenMP setting, and
        // each thread has its own: set once, it held for the first thread that meshed
        // only, and a second thread (parallel realizations) meshed with a team of
        // all cores inside gmsh, whose shared state is not thread-safe — the heap
        // was corrupted (free(): unaligned chunk). Set here, under the lock, every call.
        gmsh::option::setNumber("General.NumThreads", 1);
        gmsh::option::setNumber("General.Terminal", verbose ? 1 : 0);
        const GmshModel model;
        std::vector<int> lines(n);
        for (int i = 0; i < n; ++i)
            gmsh::model::geo::addPoint(boundary[i].x, boundary[i].y, 0.0, h[i], i + 1);
        for (int i = 0; i < n; ++i) {
            lines[i] = gmsh::model::geo::addLine(i + 1, (i + 1) % n + 1, i + 1);
            // Two nodes per segment: the boundary points are the boundary nodes, no more.
            gmsh::model::geo::mesh::setTransfiniteCurve(lines[i], 2);
        }
        gmsh::model::geo::addCurveLoop(lines, 1);
        gmsh::model::geo::addPlaneSurface({1}, 1);
        gmsh::model::geo::synchronize();
        gmsh::model::mesh::generate(2);
        if (const std::string e = model.first_error(); !e.empty()) throw mesh_error("gmsh: " + e);
        m = read_mesh(boundary);
    } catch (const GeometryError&) {
        throw;
    } catch (const std::exception& e) {
        throw mesh_error(std::string("gmsh failed: ") + e.what());
    } catch (const std::string& e) {
        throw mesh_error("gmsh failed: " + e);
    } catch (...) {
        throw mesh_error("gmsh failed");
    }
    orient_and_check(m, boundary);
    return m;
}

} // namespace bbm::meshing
