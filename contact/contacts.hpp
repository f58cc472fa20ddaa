// bbm contact: point contacts between blocks (SPEC §3).
//
// A contact is a vertex of one block (the "vertex block" A) against an edge of
// another (the "edge block" B). Its normal n is the current outward normal of B's
// edge (pointing from B into A), its tangent t the edge direction; both follow
// B's rotation every step. Relative displacement increments come from the relative
// velocity at the vertex, Δun = (v_A − v_B)·n Δt (opening positive) and
// Δus = (v_A − v_B)·t Δt — accumulated, never re-derived from the gap, which keeps
// the bonded contacts of the initial assembly exact. The force on A is
// F = L (σn n − τ t), on B its opposite, both applied at the vertex; L is the
// contact's share of the joint (half of each joint record at each of its ends).
//
// Corners: while the vertex of an unbonded (or broken) contact lies beyond the end
// of its edge (a convex corner of B) the normal is taken from B's rounded corner —
// the direction from a centre set back by r = `corner_radius` behind the corner to
// the vertex — which turns continuously from one edge's normal to the next's; the
// contact passes to the neighbouring edge, with its history, once the vertex is
// past the corner by more than the detection tolerance and projects onto that
// edge. Only corners are rounded: a node along a deformable block's face is none
// (BlockView::corner), the edge's line goes on past it, and on a deformable block
// the contact passes to the next edge as soon as it is beyond the end, its normal
// displacement taken from the new edge (docs/theory.md §3.3–3.4). A bonded contact
// keeps its edge and the edge's normal: an intact joint
// moves by elastic amounts only, and its contacts sit exactly on edge ends, where
// rounding noise must not turn the normal of a loaded bond (that would add a
// spurious geometric stiffness F/r).
//
// Storage is flat (structure of arrays) and indexed by contact id; histories are
// one fixed record per contact (contact/joint_law.hpp). Contacts are grouped in
// batches of one property set so that each law is dispatched once per batch.
//
// Determinism: a block's force is the sum of its contacts' forces in contact-id
// order, whatever the number of threads (contact_pass computes every contact's
// force first, block_contact_force then gathers per block), so a run gives the same bits on 1 or 64
// threads — failure is chaotic, and a result that depends on the partition of the
// work cannot be reproduced on another machine.
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"
#include "contact/joint_law.hpp"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace bbm::contact {

/// A rigid block's hot state: what the contact loop reads of it and integration
/// writes, one 48-byte record per block (the world stores them so: a contact
/// touches one cache line per block, and no step copies them).
struct BodyState {
    Vec2 centroid, velocity;
    double omega = 0.0; ///< rad per unit time, counter-clockwise
    double theta = 0.0; ///< rotation since the model was built, rad
};
static_assert(sizeof(BodyState) == 48);

/// The geometry the contact kernels read: flat per-block and per-vertex arrays
/// of the world (core/world.hpp).
struct BlockView {
    const BodyState* body;    ///< per block
    const Vec2* vertex;       ///< current vertex positions, all blocks, CSR by `first`
    const std::uint32_t* first;
    const double* inv_edge_length; ///< 1 / length of the edge starting at each vertex (rigid: constant)
    // Deformable blocks (fem/): their vertices are FE nodes.
    const std::uint8_t* deformable; ///< per block
    const int* vertex_node;         ///< per vertex: its node, −1 on rigid blocks
    const Vec2* node_velocity;      ///< per node
    /// Per vertex: 1 where the boundary turns at it (a corner, which an unbonded
    /// contact past the end of an edge meets rounded), 0 where a deformable block's
    /// boundary runs on straight or bends inwards (a node along a face: past it the
    /// edge's line goes on, and the contact passes to the next edge at once).
    const std::uint8_t* corner;
};

/// Velocity of the material point of block `blk` at `x`, which is its vertex `v`
/// (deformable: that node's velocity; rigid: v + ω × (x − c)).
inline Vec2 vertex_velocity(const BlockView& b, int blk, int v, Vec2 x) {
    if (b.deformable[blk]) return b.node_velocity[b.vertex_node[v]];
    const BodyState& s = b.body[blk];
    return s.velocity + s.omega * perp(x - s.centroid);
}

/// Velocity of block `blk` at `x`, near its edge (e0, e1) at parameter s: on a
/// deformable edge, linear between the two nodes (s clamped to the edge).
inline Vec2 edge_velocity(const BlockView& b, int blk, int e0, int e1, double s, Vec2 x) {
    if (!b.deformable[blk]) {
        const BodyState& r = b.body[blk];
        return r.velocity + r.omega * perp(x - r.centroid);
    }
    const double w = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    return (1.0 - w) * b.node_velocity[b.vertex_node[e0]] + w * b.node_velocity[b.vertex_node[e1]];
}

/// Stage 2's first pass (contact_pass) writes one record per contact; the second
/// pass gathers them per block and per node (block_contact_force, node_contact_force).
struct ContactForce {
    Vec2 force; ///< on the vertex block A (B gets −force)
    /// [0]: moment about A's centroid (rigid A); [1]: about B's centroid, of −force
    /// (rigid B) — on a deformable B instead the weight w of its edge's second node
    /// (the first gets 1 − w). Indexed by the side bit of a block entry.
    double moment[2];
};

/// The contacts: plain data, one entry per contact in every per-contact array;
/// the functions below add, remove, renumber and index them.
struct Contacts {
    // Topology (cold).
    std::vector<int> vertex_block, vertex_id; ///< A and the global id of its vertex
    std::vector<int> edge_block, edge_id;     ///< B and the global id of its edge's first vertex
    std::vector<int> edge_end;                ///< global id of the edge's second vertex
    std::vector<double> length;               ///< L, m
    std::vector<int> property;                ///< property set (index into the law table)
    std::vector<JointHistory> history;
    /// Normal n as of the last step (written by update_normals; the step itself
    /// does not store it); the tangent is t = (−n.y, n.x).
    std::vector<Vec2> normal;
    /// Water in the joints (core/joint_flow.hpp); both empty in a dry model. Per
    /// contact: {domain at its vertex, pipe, second pipe} of the flow network (−1:
    /// none; a contact made by detection has none), moved with its contact; and the
    /// fluid pressure on it (Pa over its length, the flow stage's, before each
    /// contact pass): the law's stress is the effective one, the force adds this.
    std::vector<std::array<int, 3>> flow_link;
    std::vector<double> fluid_pressure;
    bool flow_on = false; ///< the two arrays above are kept, one entry per contact
    bool wet() const { return flow_on; }
    /// Stress corrosion (contact/laws/stress_corrosion.hpp, core/creep.hpp): per
    /// contact the fraction ω of its bond's section left, 1 when intact (and for a
    /// contact made by detection), moved with its contact; its `length` is the
    /// joint's share times ω. Empty in a model no law corrodes.
    std::vector<double> bond_section;
    bool corroding = false; ///< bond_section is kept, one entry per contact

    // Derived index, rebuilt by rebuild_contact_index() whenever contacts are added or removed.
    /// Contacts by property set and kind, flat (CSR): batch k is the contacts
    /// batch_contact[batch_first[k] .. batch_first[k + 1]), in contact order;
    /// batch 2p holds the rigid–rigid contacts of set p (the fast kernel), batch
    /// 2p+1 those with a deformable side.
    std::vector<int> batch_first, batch_contact;
    /// Fixed pieces of the batches (at most `work_item_size` contacts each): the
    /// units of parallel work, and of the partial sums of Σ|F|², so that neither
    /// depends on the thread count.
    struct WorkItem {
        int batch, begin, end;
    };
    static constexpr int work_item_size = 512;
    std::vector<WorkItem> work;
    /// Per work item, the estimated cost of the items before it (one more entry:
    /// the total): a team splits the items into contiguous runs of equal cost
    /// rather than of equal count — items are cut per batch, so their sizes differ
    /// (the trigon tunnel: 21 items, 4 of them partial; an 11/10 split gave one
    /// thread 41% more contacts than the other). Who computes an item does not
    /// change its result.
    std::vector<double> work_cost_before;
    /// A contact with a deformable side costs about this much more than a rigid
    /// pair (node-interpolated velocities; 1.1x measured in the trigon tunnel). A
    /// rough weight: it moves the balance between threads, never a result.
    static constexpr double mixed_contact_cost = 1.25;
    /// Where each thread's run starts, as a fraction of the total cost (team + 1
    /// entries, 0 … 1), moved by the solver toward equal measured times: the
    /// estimate above misses what the laws cost (a softening or sliding contact
    /// costs more than an elastic one; the trigon tunnel's second thread took 18%
    /// longer on its equal share). Empty, or sized for another team: equal shares.
    /// Like the estimate, it decides who computes an item, never a result.
    std::vector<double> team_split;
    /// Per block, the contacts it takes part in, in contact order (CSR): entry
    /// 2·contact + side, side 0 = the block is A, 1 = it is B. Rigid blocks gather
    /// their forces from it; detection finds a block's contacts in it.
    std::vector<int> block_first, block_entry;
    /// Per FE node likewise: entry 4·contact + role, role 0 = A's vertex node
    /// (+F), 1 = first node of B's edge (−(1−w)F), 2 = second node (−wF).
    std::vector<int> node_first, node_entry;
    /// Faces of rigid blocks against deformable blocks, for property sets with
    /// `face_shear` (assign_face_groups): per contact its face or −1; per face its
    /// contacts, in contact order (CSR); and each step the face's mean shear-slip
    /// increment, which every contact of the face takes (face_slip_pass).
    std::vector<int> face_group, face_first{0}, face_entry;
    std::vector<double> face_du_s;
    /// assign_face_groups' (face, contact) pairs, kept between rebuilds so that a
    /// rebuild allocates only when the model has grown.
    std::vector<std::pair<int, int>> face_scratch;
    // Per-step scratch of contact_pass (sized by rebuild_contact_index, never in a step).
    std::vector<ContactForce> force;
    std::vector<double> partial_sum; ///< per work item
    std::vector<double> partial_damped; ///< per work item: Rayleigh's stiffness part's work this step, J/m
    /// Seismic events (core/events.hpp): per contact, 1 where the last contact pass
    /// saw its bond start to soften or break (written only then: the loop's cost is
    /// a compare), cleared by the events row of the same step. Empty, and never
    /// written, in a model that records no events.
    std::vector<std::uint8_t> bond_change;
    /// And its force (on A) before that pass, written with the mark: a bond that
    /// breaks at its peak has let go of it by the time the events row sees it.
    std::vector<Vec2> force_before;
    bool marking = false; ///< bond_change and force_before are kept, one entry per contact
    std::vector<int> fill;           ///< rebuild_contact_index's and the renumbering's cursor

    int size() const { return static_cast<int>(length.size()); }
};

/// Its fields (base/fields.hpp), in the checkpoint's order: topology and
/// histories (saved), then normals and forces (rebuilt). The water links are
/// the flow's (core/joint_flow.hpp), the index the next function's.
template <part_of<Contacts> C, class Visit>
void visit_fields(C& c, Visit&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"contacts.vertex_block", G::contacts, E}, c.vertex_block);
    v(FieldInfo{"contacts.vertex_id", G::contacts, E}, c.vertex_id);
    v(FieldInfo{"contacts.edge_block", G::contacts, E}, c.edge_block);
    v(FieldInfo{"contacts.edge_id", G::contacts, E}, c.edge_id);
    v(FieldInfo{"contacts.edge_end", G::contacts, E}, c.edge_end);
    v(FieldInfo{"contacts.length", G::contacts, E}, c.length);
    v(FieldInfo{"contacts.property", G::contacts, E}, c.property);
    v(FieldInfo{"contacts.history", G::contacts, E}, c.history);
    v(FieldInfo{"contacts.normal", G::contacts, R}, c.normal);
    v(FieldInfo{"contacts.force", G::contacts, R}, c.force);
}
/// The index and scratch rebuilt from the contacts (rebuilt fields).
template <part_of<Contacts> C, class Visit>
void visit_index_fields(C& c, Visit&& v) {
    using G = MemoryGroup;
    constexpr unsigned R = field_use::rebuilt;
    v(FieldInfo{"contacts.block_first", G::blocks, R}, c.block_first);
    v(FieldInfo{"contacts.block_entry", G::contacts, R}, c.block_entry);
    v(FieldInfo{"contacts.node_first", G::nodes, R}, c.node_first);
    v(FieldInfo{"contacts.node_entry", G::contacts, R}, c.node_entry);
    v(FieldInfo{"contacts.fill", G::contacts, R}, c.fill);
    v(FieldInfo{"contacts.partial_sum", G::contacts, R}, c.partial_sum);
    v(FieldInfo{"contacts.partial_damped", G::contacts, R}, c.partial_damped);
    v(FieldInfo{"contacts.bond_change", G::contacts, R}, c.bond_change);
    v(FieldInfo{"contacts.force_before", G::contacts, R}, c.force_before);
    v(FieldInfo{"contacts.work", G::contacts, R}, c.work);
    v(FieldInfo{"contacts.work_cost_before", G::contacts, R}, c.work_cost_before);
    v(FieldInfo{"contacts.team_split", G::other, R}, c.team_split);
    v(FieldInfo{"contacts.face_group", G::contacts, R}, c.face_group);
    v(FieldInfo{"contacts.face_first", G::contacts, R}, c.face_first);
    v(FieldInfo{"contacts.face_entry", G::contacts, R}, c.face_entry);
    v(FieldInfo{"contacts.face_du_s", G::contacts, R}, c.face_du_s);
    v(FieldInfo{"contacts.face_scratch", G::contacts, R}, c.face_scratch);
    v(FieldInfo{"contacts.batch_first", G::contacts, R}, c.batch_first);
    v(FieldInfo{"contacts.batch_contact", G::contacts, R}, c.batch_contact);
}

void add_contact(Contacts& c, int a, int vertex, int b, int edge, int end, double l, int prop, const JointHistory& h);
void remove_flagged_contacts(Contacts& c, const std::vector<std::uint8_t>& remove);
/// Renumbers the contacts in order of their block pair (lower block id first,
/// then the other; ties by vertex): with blocks numbered along a space-filling
/// curve, a contact's blocks then sit near those of the contacts before it, and
/// the loop reads them from cache. Returns whether anything moved.
bool sort_contacts_by_blocks(Contacts& c);
/// Rebuilds batches, work items and the per-block and per-node index.
/// `deformable`: per block, non-zero for deformable blocks; `vertex_node`: per
/// vertex, its FE node (−1 on rigid blocks); both may be null for rigid models.
void rebuild_contact_index(Contacts& c, int property_sets, int blocks, const std::uint8_t* deformable, int nodes,
                           const int* vertex_node);

/// Global id of the vertex after `v` around its block.
inline int next_vertex(const std::uint32_t* first, int block, int v) {
    return (v + 1 == int(first[block + 1])) ? int(first[block]) : v + 1;
}

/// Global id of the vertex before `v` around its block.
inline int prev_vertex(const std::uint32_t* first, int block, int v) {
    return v == int(first[block]) ? int(first[block + 1]) - 1 : v - 1;
}

inline Vec2 tangent_of(Vec2 n) { return {-n.y, n.x}; }

/// The frame of a contact whose vertex x lies against the edge p → q (1/|q − p| =
/// inv_len): normal n (the edge's outward normal), tangent t, and the vertex's
/// parameter s along the edge. An unbonded contact beyond an end of its edge takes
/// the normal of the rounded corner if that end is a corner (`corner`, per vertex,
/// of the ends p_id and q_id; null: every vertex is one, as on rigid blocks). The
/// step loop, the face pass and contact_kinematics all read the frame from here.
struct ContactFrame {
    Vec2 n, t;
    double s;
};
inline ContactFrame contact_frame(Vec2 x, Vec2 p, Vec2 q, double inv_len, bool bonded, double corner_radius,
                                  const std::uint8_t* corner = nullptr, int p_id = 0, int q_id = 0) {
    ContactFrame f;
    f.t = inv_len * (q - p);
    f.n = Vec2{f.t.y, -f.t.x}; // outward normal of a counter-clockwise polygon's edge
    f.s = dot(x - p, f.t) * inv_len;
    if (!bonded && (f.s < 0.0 || f.s > 1.0)) [[unlikely]] {
        // A node along a deformable block's face is no corner: rounded, the gap
        // past it would grow as the square of the distance while the vertex slides
        // on along the face (and into the next edge, unseen).
        if (corner && !corner[f.s < 0.0 ? p_id : q_id]) return f;
        const Vec2 r = x - ((f.s < 0.0 ? p : q) - corner_radius * f.n);
        const double rl = norm(r);
        if (rl > 0.0) f.n = r / rl, f.t = Vec2{-f.n.y, f.n.x};
    }
    return f;
}

/// Normal of contact i from the current geometry (used outside the step loop).
inline void contact_kinematics(Contacts& c, int i, const BlockView& b, double corner_radius) {
    c.normal[i] = contact_frame(b.vertex[c.vertex_id[i]], b.vertex[c.edge_id[i]], b.vertex[c.edge_end[i]],
                                b.inv_edge_length[c.edge_id[i]], c.history[i].bonded, corner_radius, b.corner,
                                c.edge_id[i], c.edge_end[i])
                      .n;
}

/// Normals of every contact from the current geometry.
void update_normals(Contacts& c, const BlockView& b, double corner_radius);

/// Groups the contacts between a rigid block and a deformable one whose property
/// set has `face_shear[property]` by the rigid block's face: the rigid block's
/// edge when it is the edge block, else the edge at its vertex that runs most
/// nearly against the deformable edge (current geometry). Clears the groups when
/// no set asks for them.
void assign_face_groups(Contacts& c, const BlockView& b, const std::vector<std::uint8_t>& face_shear);

/// Per face of [first, last), the length-weighted mean of its contacts'
/// shear-slip increments this step, into `c.face_du_s` (the same kinematics as
/// contact_pass). Between a rigid face and a deformable body the pointwise slip
/// grows along the face with the body's strain, and pointwise shear springs
/// would load the rigid block with a couple of forces a joint between two rigid
/// blocks never carries; on the mean slip the face's shear traction is uniform,
/// as on such a joint (docs/theory.md §11.1). Faces are independent: a team
/// shares them and meets at a barrier before contact_pass reads the result.
void face_slip_pass(Contacts& c, const BlockView& b, double dt, double corner_radius, int first, int last);
inline int face_count(const Contacts& c) { return static_cast<int>(c.face_du_s.size()); }

/// Contact force on the vertex block (A); B gets the opposite.
inline Vec2 contact_force(const Contacts& c, int i) {
    const JointHistory& h = c.history[i];
    const Vec2 n = c.normal[i];
    const double sn = c.wet() ? h.sn + c.fluid_pressure[i] : h.sn;
    return c.length[i] * (sn * n - h.tau * tangent_of(n));
}

/// Stage 2 of a step, first pass: per contact of the work items [first, last)
/// (each law dispatched once per batch) its kinematics, the law, and its force
/// and moments into `c.force` — no contact writes anything another contact
/// reads, so a team shares the items (contact_share) and meets at a barrier
/// before the gathers below. `stiffness_damping` β > 0 adds Rayleigh's
/// stiffness-proportional viscous stresses −β kn u̇n and β ks u̇s to the forces of
/// bonded and closed contacts (not to their histories).
void contact_pass(Contacts& c, const std::vector<JointLaw>& laws, const BlockView& b, double dt,
                  double corner_radius, int first, int last, double stiffness_damping = 0.0);
inline int contact_items(const Contacts& c) { return static_cast<int>(c.work.size()); }

/// The work items [first, last) of `thread` in a team of `team`: contiguous runs
/// of about equal cost (`cost_before`: Contacts::work_cost_before), or of the
/// fractions of the cost in `split` (team + 1 entries from 0 to 1; ignored unless
/// so); every item goes to exactly one thread, in order.
std::pair<int, int> team_share(const std::vector<double>& cost_before, int thread, int team,
                               const std::vector<double>* split = nullptr);

/// The work items of `thread` in the contact pass: contiguous runs of equal
/// estimated cost moved toward equal measured times (Contacts::team_split). The
/// same run every step while the contacts do not change, so its contacts'
/// histories and forces stay in that core's cache (dynamic handing-out moved them
/// between cores every step; paired runs of the trigon tunnel on 2 threads: 8%
/// less wall time, median of 8).
inline std::pair<int, int> contact_share(const Contacts& c, int thread, int team) {
    return team_share(c.work_cost_before, thread, team, &c.team_split);
}

/// Second pass, per block: the force and moment of its contacts, summed in
/// contact order — so the sum does not depend on which thread computed what.
inline void block_contact_force(const Contacts& c, int block, Vec2& force, double& moment) {
    const ContactForce* cf = c.force.data();
    const int last = c.block_first[block + 1], entries = int(c.block_entry.size());
    Vec2 f{};
    double m = 0.0;
    for (int e = c.block_first[block]; e < last; ++e) {
        if (e + 32 < entries) __builtin_prefetch(&cf[c.block_entry[e + 32] >> 1]);
        // Branch-free: the side bit picks the sign and the moment (a side is as
        // good as random to the branch predictor).
        const int entry = c.block_entry[e], side = entry & 1;
        const ContactForce& r = cf[entry >> 1];
        f += double(1 - 2 * side) * r.force;
        m += r.moment[side];
    }
    force = f, moment = m;
}

/// Per FE node likewise; a force on a deformable edge is split to its two nodes
/// with the weights that interpolate the edge's velocity.
inline Vec2 node_contact_force(const Contacts& c, int node) {
    const ContactForce* cf = c.force.data();
    Vec2 f{};
    for (int e = c.node_first[node]; e < c.node_first[node + 1]; ++e) {
        const int entry = c.node_entry[e], role = entry & 3;
        const ContactForce& r = cf[entry >> 2];
        const double w = r.moment[1];
        const double weight = role == 0 ? 1.0 : (role == 1 ? -(1.0 - w) : -w);
        f += weight * r.force;
    }
    return f;
}

/// Σ|F|² over the contacts of the last pass (the RMS contact force is the scale
/// of the unbalanced-force ratio; squares spare a square root per contact): per
/// work item, then over the items in order.
double contact_force_squares(const Contacts& c);

} // namespace bbm::contact
