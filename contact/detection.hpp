// bbm contact: detection of contacts during large displacements (SPEC §3).
//
// The initial contacts come from the joint topology; this pass keeps the contact
// set right as blocks move. It runs when some block has moved more than a quarter
// of the tolerance since its last pass, and then only for such "active" blocks and
// their neighbours, so a few fast fragments do not cost a pass over all pairs
// (two blocks each within a quarter tolerance of their references have moved less
// than the tolerance relative to each other since their pair was last examined):
//   1. a contact whose vertex has left its edge passes, with its history, to the
//      neighbouring edge of the same block if the vertex now projects onto it;
//   2. an unbonded (or broken) contact whose vertex is farther than the tolerance
//      from the edge, or beyond its ends, is removed — bonded ones never are;
//   3. broad phase: every block is in a uniform grid as pieces (runs of at most
//      16 consecutive vertices, each with a box), and only the pieces of active
//      blocks query it; narrow phase: each vertex of one block within the
//      tolerance of an edge of the other (projecting onto it, or near its end:
//      corner contact) becomes a candidate;
//   4. a candidate becomes a new unbonded contact unless the two blocks already
//      have a contact at that point (either way round), found among the contacts
//      of one of the two blocks (Contacts::block_first), or among the candidates
//      of the same pair accepted before it.
// Steps 1, 3 and 4 visit the contacts and neighbours of active blocks only, so a
// pass costs in proportion to what moved, not to the model (the grid itself is
// rebuilt, O(N), only when a piece has left the margin it was stored with).
// A new contact gets the unbonded property set, its current gap as un, and as
// length half of the vertex's adjacent edge that lies most nearly along the
// other block's edge (that edge's share at this end). Candidates are produced and
// accepted in an order fixed by block and vertex numbers, so a pass gives the same
// contacts in the same order every time. The Detector keeps its scratch arrays
// between passes (struct Detector): once their sizes have settled, a pass allocates nothing.
// A team of threads may run a pass together: steps 1–3 share the active blocks
// (contiguous runs in block order, each thread with its own candidate list; the
// lists joined in thread order are the serial order), step 4 and the grid's
// rebuild run on one thread.
#pragma once

#include "contact/contacts.hpp"

#include <cstdint>
#include <vector>

namespace bbm::contact {

/// A vertex of one block on the boundary of another block it has no joint with:
/// at one of that block's vertices or inside one of its edges. The touching point
/// moves with the other block: the point at parameter s of its edge (e0, e1).
struct Junction {
    int vertex; ///< global id of the touching vertex
    int block;  ///< the block it touches
    int e0, e1; ///< that block's edge, as global vertex ids (e1 follows e0)
    double s;   ///< position of the point along the edge, 0 at e0, 1 at e1
    bool operator<(const Junction& o) const { return vertex < o.vertex || (vertex == o.vertex && block < o.block); }
};

struct DetectionInput {
    BlockView blocks;
    int block_count = 0;
    const std::uint8_t* removed = nullptr; ///< excavated blocks take no part
    /// Blocks that moved enough since their last pass: only pairs with at least
    /// one active block are examined (null = all).
    const std::uint8_t* active = nullptr;
    double tolerance = 0.0;
    int new_contact_property = 0;
    /// The step about to run: its contact update adds v·Δt, motion already in the
    /// measured gap, so a new contact's un starts at gap − v_rel·n Δt.
    double dt = 0.0;
    /// Vertices that touched another block, with no joint between the two, in the
    /// initial tessellation (sorted by vertex, then block). Such a vertex still
    /// within the tolerance of the point it touched gets no new contact with that
    /// block: the point is interior to the rock, and a contact there would carry
    /// load no joint carries — corner to corner where six trigon triangles meet at
    /// each centre (locking the fragments once the bonds break), or a cell's corner
    /// pressed into a meshed region it touched only at that point. Once they have
    /// moved apart by more than the tolerance, contacts form as between any blocks.
    const std::vector<Junction>* junctions = nullptr;
    /// Radius of the rounded corners unbonded contacts see past the end of an edge
    /// (contact_kinematics): a vertex beside a corner starts with its gap to the
    /// rounded corner, the surface its later increments are measured against.
    double corner_radius = 0.0;
    /// A new contact's length: false, half of the vertex's adjacent edge that lies
    /// most along B's edge; true, half of that edge's overlap with B's edge (at
    /// least corner_radius) — a face shared by its two end contacts, as UDEC does.
    bool overlap_length = false;
    /// A new contact born overlapped (its vertex already up to the tolerance inside
    /// the other block, having passed a corner unseen between passes) takes that
    /// overlap as its rest position (upn = un < 0): only further approach loads it.
    /// Without this, in a dynamic run, the overlap is a spring compressed at birth
    /// whose energy no work paid for (docs/theory.md §19.4). Quasi-static runs keep
    /// the stiff push-out, which relaxation dissipates.
    bool overlap_at_rest = false;
};

/// Key of an unordered block pair.
inline std::uint64_t block_pair_key(int a, int b) {
    return (std::uint64_t(std::uint32_t(a < b ? a : b)) << 32) | std::uint32_t(a < b ? b : a);
}

/// The junctions of an assembly: every vertex lying (within `eps`) on the
/// boundary of another block that it shares no joint with. `joined`: the sorted
/// pair keys of the blocks that have a joint. O(vertices) with a uniform grid.
std::vector<Junction> find_junctions(const std::vector<Vec2>& vertex, const std::vector<std::uint32_t>& first,
                                     const std::vector<std::uint64_t>& joined, double eps);

struct DetectionResult {
    int created = 0, removed = 0, transferred = 0;
    /// Of the removed: cracks (broken bonds), so that crack counts stay cumulative.
    int removed_tensile = 0, removed_shear = 0;
};
static_assert(sizeof(DetectionResult) == 5 * sizeof(int)); // saved and hashed as raw bytes

/// The detection's state between passes: the broad-phase grid and the scratch
/// arrays (plain data; detect() below runs a pass over it). Nothing here is part
/// of the physics: a grid rebuilt from scratch offers a superset of the same
/// pairs, so a checkpoint does not save it.
struct Detector {
    /// A run of at most 16 consecutive vertices of a block and the edges they start.
    struct Piece {
        int block;
        std::uint32_t v0, v1;
    };
    struct Candidate {
        std::uint64_t pair;
        int vertex_block, vertex, edge_block, edge, edge_end;
        double length, un;
    };
    // Broad phase. Pieces enter the grid with their box at the build inflated by
    // the tolerance and a margin; while every piece stays inside its stored box
    // (checked for the active ones, which are the ones that moved), the grid
    // still finds every pair within the tolerance, and only needs rebuilding
    // when one leaves it — not at every pass.
    std::vector<Piece> pieces;
    std::vector<int> block_piece; ///< per block, its first piece (CSR)
    std::vector<Box2> stored;     ///< per piece, its box at the last build (inflated)
    Box2 grid_box;
    double cell = 0.0, margin = 0.0;
    int nx = 0, ny = 0;
    std::vector<int> cell_first, cell_piece;
    /// false: the grid is rebuilt at the next pass (blocks were removed, or the
    /// state replaced by a checkpoint's).
    bool grid_valid = false;

    // Scratch kept between passes.
    std::vector<std::uint8_t> drop; ///< per contact; all zero between passes
    std::vector<int> active_blocks; ///< this pass's active blocks, in order
    /// Per thread of the team: its candidates, the contacts it dropped and moved,
    /// and its broad-phase scratch (one cache line apart).
    struct alignas(64) ThreadScratch {
        std::vector<Candidate> candidates;
        std::vector<int> near;
        int dropped = 0, dropped_tensile = 0, dropped_shear = 0, transferred = 0, transferred_on_nodes = 0;
    };
    std::vector<ThreadScratch> team;
    std::vector<Candidate> candidates;
    std::vector<int> order, accepted;
    bool stale = false, left_box = false; ///< this pass: grid invalid, a piece left its box
    DetectionResult result;
    /// Of the last pass's removed contacts, the energy their joints had dissipated
    /// (friction, fracture; J/m): it leaves the contacts' sum with them, and the
    /// energy account keeps it (core/measures.hpp dissipated_energy).
    double removed_dissipated = 0.0;
    /// Of the last pass's transfers, those onto another edge of a deformable block:
    /// they change which nodes a contact loads, so the index is stale after them too.
    int transferred_on_nodes = 0;
};

/// One pass (steps 1–4 above). Needs `c`'s index (rebuild_contact_index) to be
/// current; leaves it stale if contacts were created or removed (the result says
/// so) or passed to another edge of a deformable block (d.transferred_on_nodes),
/// for the caller to rebuild once. Called by every thread of an OpenMP team (all
/// get the result), or outside one: the same contacts in the same order on any
/// number of threads.
DetectionResult detect(Contacts& c, Detector& d, const DetectionInput& in);

} // namespace bbm::contact

template <>
struct bbm::ElementTraits<bbm::contact::DetectionResult> : bbm::PackedRecordTraits<bbm::contact::DetectionResult> {};
