// bbm meshing: the block assembly — blocks, and the joints between them.
//
// generate_blocks() is the whole geometry pipeline of paper §3.1:
//   1. each region's domain = outline − holes − subtracted regions (CGAL Boolean
//      operations, exact kernel), checked for self-intersection, holes outside the
//      outline and overlap with other regions;
//   2. the region is cut by its real discontinuities (explicit segments, joint
//      sets, fracture networks) in one exact computation (cutting.hpp): a CGAL
//      arrangement on the exact kernel whose faces are the "rock blocks";
//   3. the inner pattern is generated inside each rock block, so no inner block
//      crosses a real joint, and its cells are cut to the rock block exactly; a
//      real joint that ends inside an inner block (a finite trace) goes on along
//      its line to that block's edge, the part beyond its tip an ordinary inner
//      joint (a rock bridge that can break);
//   4. short edges are collapsed (shared vertices move together, so the blocks
//      still tile the region exactly);
//   5. deformable blocks (regions with a mesh, SPEC §6): each block's edges are
//      subdivided at the region's target size (fe_mesh.hpp: points on a shared edge
//      depend only on its endpoints, so neighbours in one region conform) and the
//      block is meshed into constant-strain triangles; its polygon becomes the
//      boundary loop of the mesh, so every vertex of it is an FE node;
//   6. topology: every stretch of boundary shared by two blocks — a full shared
//      edge or the part of an edge against a T-junction (a rigid block's vertex in
//      the middle of a deformable block's boundary segment, or the reverse) —
//      becomes one JointRecord.
//
// The assembly is flat (structure of arrays, compressed vertex lists) because the
// contact code walks it for ~10^5 blocks.
#pragma once

#include "base/vec2.hpp"
#include "meshing/dfn.hpp"
#include "meshing/fe_mesh.hpp"
#include "meshing/spec.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace bbm::meshing {

enum class JointTag : std::uint8_t {
    inner,      ///< between inner blocks of a Voronoi / Delaunay / lattice pattern
    radial,     ///< trigon: between triangles of the same Voronoi cell
    peripheral, ///< trigon: between triangles of different Voronoi cells
    real_joint, ///< on a real discontinuity (explicit segment or joint set)
    interface,  ///< between blocks of different regions
    fracture,   ///< on a fracture of a discrete fracture network ([[region.dfn]])
};
const char* to_string(JointTag t);
const char* to_string(PatternSpec::Kind k);

struct JointRecord {
    int block_a = -1, block_b = -1;
    /// Edge of each block the joint lies on: edge i of a block runs from its vertex
    /// i to vertex i+1. The joint is the part of both edges between p0 and p1.
    int edge_a = -1, edge_b = -1;
    Vec2 p0{}, p1{};
    JointTag tag = JointTag::inner;
    int fracture_set = -1; ///< fracture joints: index into BlockAssembly::fracture_sets
    double length() const { return norm(p1 - p0); }
};

struct BlockAssembly {
    // Block b has vertices points[first[b] .. first[b+1]), counter-clockwise.
    std::vector<Vec2> points;
    std::vector<std::uint32_t> first{0};
    std::vector<int> region;              ///< index into region_names
    std::vector<PatternSpec::Kind> pattern;
    /// The Voronoi cell a trigon triangle came from, or the block itself.
    std::vector<int> parent;
    std::vector<double> area;
    std::vector<JointRecord> joints;
    std::vector<std::string> region_names;
    /// Target size of each region's pattern (for the summary and checks).
    std::vector<double> region_size;
    /// Segments of real discontinuities after cutting (for output and checks).
    std::vector<SegmentSpec> real_segments;
    /// Discrete fracture networks: every region's sets in order, their traces
    /// (clipped to the region, before cutting) and what was built against what
    /// was asked (meshing/dfn.hpp).
    struct FractureSet {
        std::string name, property; ///< property "" = by the assignment rules
        int region = -1;
    };
    std::vector<FractureSet> fracture_sets;
    std::vector<SegmentSpec> fracture_traces;
    std::vector<int> fracture_trace_set; ///< per trace: index into fracture_sets
    std::vector<FractureSetStats> fracture_stats; ///< per set

    // Deformable blocks (regions with a mesh): the polygon of such a block is the
    // boundary loop of its triangle mesh (its vertices are FE nodes). The nodes of a
    // block are contiguous and never shared with another block; its boundary nodes
    // come first, in the order of its vertices.
    std::vector<std::uint8_t> deformable;       ///< per block: 1 if meshed
    std::vector<Vec2> nodes;                    ///< FE nodes of all deformable blocks
    std::vector<int> node_block;                ///< per node
    std::vector<std::array<int, 3>> zones;      ///< constant-strain triangles: node ids, counter-clockwise
    std::vector<int> zone_block;                ///< per zone
    std::vector<int> vertex_node;               ///< per polygon vertex (index into points): its node, -1 for rigid blocks

    int block_count() const { return static_cast<int>(region.size()); }
    std::span<const Vec2> block(int b) const {
        return {points.data() + first[b], points.data() + first[b + 1]};
    }
    /// A rigid block; `poly` of either orientation.
    void add_block(std::span<const Vec2> poly, int region_id, PatternSpec::Kind kind, int parent_id);
    /// A deformable block: its polygon is the mesh's boundary loop (counter-clockwise),
    /// its nodes and triangles are appended with the ids shifted.
    void add_deformable_block(const TriangleMesh& mesh, int region_id, PatternSpec::Kind kind,
                              int parent_id);
};

struct GenerationStats {
    double seconds_regions = 0, seconds_patterns = 0, seconds_topology = 0;
    int collapsed_edges = 0;
    /// Edges still shorter than their region's minimum (e.g. a short edge of the
    /// outline itself); reported, never hidden.
    int short_edges_left = 0;
    /// Cutting by real joints and fractures (meshing/cutting.hpp): blocks under 1e-8
    /// of a block's area (`size`²: where traces cross nearly at one point) merged into
    /// the neighbour they share most boundary with, and those that had none.
    int merged_slivers = 0, slivers_left = 0;
    /// Length of trace between merged slivers and their neighbours, which is no
    /// joint any more (micrometres: where two traces run within micrometres).
    double merged_trace_length = 0.0;
    /// Traces ending inside a block carried on to its edge (rock bridges), and
    /// vertical cuts that opened a block with a hole.
    int rock_bridges = 0, hole_cuts = 0;
    /// Deformable blocks: triangles made, and the time spent subdividing and meshing.
    int zones = 0;
    double seconds_meshing = 0;
};

/// What a region will generate, estimated from its area and sizes before anything
/// is generated (within a factor of about 2 for the random patterns; an upper
/// bound for graded meshes), and the memory that takes.
struct SizeEstimate {
    double blocks = 0, zones = 0;
    double bytes() const;
};
/// Blocks and triangles one region of `area` m² asks for; `toward_perimeter` is the
/// length of the boundaries its mesh is refined toward (graded meshes).
SizeEstimate estimate_region(const RegionSpec& region, double area, double toward_perimeter);
/// The limit on blocks + triangles when the model sets none: what fits in half of
/// the machine's physical memory.
double default_max_elements();

/// The whole pipeline above. Throws GeometryError for an invalid description, for
/// a model that asks for more than spec.max_elements blocks and triangles, and for
/// a patterned region that generates no blocks or far fewer than its size implies.
BlockAssembly generate_blocks(const ModelGeometrySpec& spec, GenerationStats* stats = nullptr);

/// Polygon (counter-clockwise) of an outline, with arcs as polylines.
std::vector<Vec2> outline_polygon(const OutlineSpec& o, double default_max_segment);

/// Mean block size of the given blocks: diameter of the circle of their mean area.
double mean_block_size(const BlockAssembly& a, int region = -1);

/// Mean Feret (caliper) diameter of a polygon: its width averaged over all
/// directions, the perimeter of its convex hull / π (Cauchy's formula).
double mean_feret_diameter(std::span<const Vec2> poly);
/// Mean of it over the blocks of a region (all regions: −1), cut blocks included.
double mean_feret_diameter(const BlockAssembly& a, int region = -1);

} // namespace bbm::meshing
