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
//   3. broad phase: block boxes inflated by the tolerance in a uniform grid
//      (O(N)); narrow phase: each vertex of one block within the tolerance of an
//      edge of the other (projecting onto it, or near its end: corner contact)
//      becomes a new unbonded contact, unless the two blocks already have a
//      contact at that point (either way round).
// A new contact gets the unbonded property set, its current gap as un, and as
// length half of the vertex's adjacent edge that lies most nearly along the
// other block's edge (that edge's share at this end).
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

DetectionResult update_contacts(Contacts& c, const DetectionInput& in);

} // namespace bbm::contact
