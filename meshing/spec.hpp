// bbm meshing: the description of a block model's geometry, as the model file gives it.
//
// A model is a list of regions. Each region has an outline (rectangle, polygon,
// circle, a path of straight and circular-arc pieces, or a tunnel opening with
// vertical side walls and an arched roof), optional holes, optional other regions
// subtracted from it ("outer minus bonded"), the real discontinuities that cut it
// (explicit segments and statistical joint sets), and the pattern of inner blocks
// that fills each piece left after cutting (paper §3.1: real joints first, inner
// blocks second), and optionally a triangle mesh that makes its blocks deformable.
// Curved outlines become polylines whose segments are no longer than
// `max_segment`. These structs are plain data: the input layer (apps/) fills
// them, generate_blocks() in blocks.hpp turns them into blocks and joints.
#pragma once

#include "base/vec2.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm::meshing {

/// One outline. Only the fields of its kind are read.
struct OutlineSpec {
    enum class Kind { rectangle, polygon, circle, path, opening };
    Kind kind = Kind::rectangle;

    // rectangle
    Vec2 min{}, max{};
    // polygon: the vertices, either orientation, not repeated at the end
    std::vector<Vec2> points;
    // circle and opening
    Vec2 center{};
    double radius = 0.0;
    // path: starts at `start`; each step goes to `to`, straight or along a circular
    // arc about `center` (counter-clockwise unless `clockwise`); closes back to start.
    struct Step {
        Vec2 to{};
        bool arc = false;
        Vec2 center{};
        bool clockwise = false;
    };
    Vec2 start{};
    std::vector<Step> steps;
    // opening: side walls at center.x ± width/2 from floor_y up to the springline
    // center.y, then a circular roof of radius width/2 about `center` (a horseshoe
    // with a flat floor). With `half`, only the part x >= center.x (for a model cut
    // on its vertical symmetry plane).
    double width = 0.0;
    double floor_y = 0.0;
    bool half = false;

    /// Longest polyline segment for arcs and circles (m); 0 = the model's default.
    double max_segment = 0.0;
};

struct PatternSpec {
    enum class Kind { voronoi, trigon, delaunay, hexagonal, brick, single };
    /// What `size` measures for the random patterns (voronoi, trigon, delaunay).
    ///   feret: the mean Feret (caliper) diameter of the blocks — a block's width
    ///          averaged over all directions, perimeter / π for a convex block —
    ///          the "average dimension" of paper §4.1 (docs/input.md, Patterns:
    ///          with it the paper's Voronoi and trigon calibrations give the same
    ///          modulus in bbm as in the paper). For trigon, of the triangles.
    ///   area:  the diameter of the circle of the mean area of the generator's
    ///          cells (voronoi, trigon: the Voronoi cells before splitting;
    ///          delaunay: the triangles).
    enum class SizeMeasure { feret, area };
    Kind kind = Kind::voronoi;
    /// Mean block size d (m), measured as `size_measure` says (random patterns);
    /// hexagonal: lattice spacing; brick: brick height.
    double size = 0.0;
    SizeMeasure size_measure = SizeMeasure::feret;
    int lloyd_iterations = 0;
    /// Edges shorter than this are collapsed (m); < 0 = default 0.1 × size.
    double min_edge = -1.0;
    std::uint64_t seed = 1;
    /// brick: brick length over height; 1 gives squares.
    double aspect = 2.0;
    /// brick: running bond (rows offset by half a brick) or stack bond.
    bool running_bond = true;
    /// hexagonal, brick: lattice origin and rotation (degrees, counter-clockwise).
    Vec2 origin{};
    double angle = 0.0;
};

/// A statistical set of parallel joints (a simple discrete fracture network).
struct JointSetSpec {
    double angle = 0.0;         ///< trace direction, degrees counter-clockwise from +x
    double spacing = 0.0;       ///< mean normal distance between traces (m)
    double trace_length = 0.0;  ///< mean trace length (m); 0 = persistent (cuts through)
    double gap = 0.0;           ///< mean rock bridge between collinear traces (m)
    double angle_deviation = 0.0;   ///< uniform random deviation of each trace, ± degrees
    double spacing_deviation = 0.0; ///< uniform random deviation of each offset, ± fraction of spacing
    double length_deviation = 0.0;  ///< uniform random deviation of trace and gap, ± fraction
    Vec2 origin{};              ///< a point one trace line passes through (before deviation)
    std::uint64_t seed = 1;
};

struct SegmentSpec {
    Vec2 a{}, b{};
};

/// The trace-length distribution of a fracture set (meshing/dfn.hpp).
struct FractureLengthSpec {
    enum class Kind { fixed, power_law, lognormal, exponential };
    Kind kind = Kind::fixed;
    double value = 0.0;      ///< fixed: every trace this long (m)
    double exponent = 0.0;   ///< power_law: density ∝ l^−exponent on [min, max]
    double mean = 0.0;       ///< lognormal, exponential: mean of the untruncated law (m)
    double std_dev = 0.0;    ///< lognormal: its standard deviation (m)
    double min = 0.0, max = 0.0; ///< truncation (m); max 0 = the region's diagonal (not power_law)
};

/// The trace-angle distribution of a fracture set, degrees counter-clockwise from +x.
struct FractureOrientationSpec {
    enum class Kind { von_mises, uniform, list };
    Kind kind = Kind::von_mises;
    double mean = 0.0;          ///< von_mises: mean angle
    double concentration = 0.0; ///< von_mises: κ, density ∝ exp(κ cos(θ − mean)); 0 = uniform
    std::vector<double> angles, weights; ///< list: angles picked with these weights (default equal)
};

/// One set of a discrete fracture network ([[region.dfn]]): stochastic traces with
/// random centres, orientations and lengths at a target intensity, or traces read
/// from a file (CSV: x1, y1, x2, y2[, set]; or DXF lines and polylines).
struct DfnSetSpec {
    std::string name;
    enum class Centres { poisson, clustered };
    Centres centres = Centres::poisson;
    double cluster_size = 0.0;   ///< clustered: mean fractures per cluster
    double cluster_radius = 0.0; ///< clustered: standard deviation of a fracture's offset from its cluster's centre (m)
    FractureOrientationSpec orientation;
    FractureLengthSpec length;
    double p21 = 0.0;            ///< target trace length per unit area (1/m) ...
    long count = 0;              ///< ... or number of fracture centres in the region
    /// Fractures that cross a fracture of one of these earlier sets end there, at
    /// each crossing with this probability (on each side of the centre).
    std::vector<int> terminate_at;
    double terminate_probability = 0.0;
    std::string property;        ///< joint property of its traces ("" = by the assignment rules)
    std::uint64_t seed = 1;
    std::vector<SegmentSpec> traces; ///< given traces (from a file); non-empty = not generated
    std::string file;            ///< where `traces` came from (for the report)
    std::string import_note;     ///< what the file held and what was left out (DXF), for the report
};

/// The triangle mesh of a region's deformable blocks (SPEC §6). A region with a mesh
/// has deformable blocks: every block of its pattern is meshed into constant-strain
/// triangles (with pattern `single`, the pieces of the region are the blocks: an
/// elastic outer region). The target triangle size at a point x is
///   h(x) = min(size_far, size + grading · d(x)),
/// d(x) the distance from x to the boundary of the regions named in `toward`; with
/// no `toward` or grading 0, h = size everywhere.
struct MeshSpec {
    bool enabled = false;
    double size = 0.0;      ///< target triangle size next to the `toward` regions (or everywhere), m
    double size_far = 0.0;  ///< largest triangle size, m; 0 = size
    double grading = 0.0;   ///< growth of the size per metre of distance from `toward` (m/m); 0 = uniform
    std::vector<std::string> toward; ///< names of other regions the mesh is refined toward
};

struct RegionSpec {
    std::string name;
    OutlineSpec outline;
    std::vector<OutlineSpec> holes;
    /// Names of regions (earlier or later in the list) subtracted from this one.
    std::vector<std::string> minus;
    PatternSpec pattern;
    std::vector<SegmentSpec> joints;
    std::vector<JointSetSpec> joint_sets;
    std::vector<DfnSetSpec> dfn; ///< fracture sets, in order (a set may end at the earlier ones)
    MeshSpec mesh;
};

struct ModelGeometrySpec {
    std::vector<RegionSpec> regions;
    /// Default longest polyline segment for circles and arcs (m).
    double max_segment = 0.1;
    /// Largest number of blocks plus triangles a model may ask for (estimated from
    /// the regions' areas and sizes before anything is generated); 0 = what fits
    /// in half of this machine's memory (default_max_elements()).
    double max_elements = 0;
};

} // namespace bbm::meshing
