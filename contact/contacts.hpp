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
// edge. A bonded contact keeps its edge and the edge's normal: an intact joint
// moves by elastic amounts only, and its contacts sit exactly on edge ends, where
// rounding noise must not turn the normal of a loaded bond (that would add a
// spurious geometric stiffness F/r).
//
// Storage is flat (structure of arrays) and indexed by contact id; histories are
// one fixed record per contact (contact/joint_law.hpp). Contacts are grouped in
// batches of one property set so that each law is dispatched once per batch.
#pragma once

#include "contact/joint_law.hpp"
#include "core/vec2.hpp"

#include <cstdint>
#include <vector>

namespace bbm::contact {

/// The geometry the contact kernels read: flat per-block and per-vertex arrays
/// owned by the solver (core/solver.hpp).
struct BlockView {
    const Vec2* centroid;     ///< per block
    const Vec2* velocity;     ///< per block
    const double* omega;      ///< per block
    const Vec2* vertex;       ///< current vertex positions, all blocks, CSR by `first`
    const std::uint32_t* first;
    const double* inv_edge_length; ///< 1 / length of the edge starting at each vertex (rigid: constant)
    // Deformable blocks (fem/): their vertices are FE nodes.
    const std::uint8_t* deformable; ///< per block
    const int* vertex_node;         ///< per vertex: its node, −1 on rigid blocks
    const Vec2* node_velocity;      ///< per node
};

/// Velocity of the material point of block `blk` at `x`, which is its vertex `v`
/// (deformable: that node's velocity; rigid: v + ω × (x − c)).
inline Vec2 vertex_velocity(const BlockView& b, int blk, int v, Vec2 x) {
    return b.deformable[blk] ? b.node_velocity[b.vertex_node[v]] : b.velocity[blk] + b.omega[blk] * perp(x - b.centroid[blk]);
}

/// Velocity of block `blk` at `x`, near its edge (e0, e1) at parameter s: on a
/// deformable edge, linear between the two nodes (s clamped to the edge).
inline Vec2 edge_velocity(const BlockView& b, int blk, int e0, int e1, double s, Vec2 x) {
    if (!b.deformable[blk]) return b.velocity[blk] + b.omega[blk] * perp(x - b.centroid[blk]);
    const double w = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    return (1.0 - w) * b.node_velocity[b.vertex_node[e0]] + w * b.node_velocity[b.vertex_node[e1]];
}

struct Contacts {
    // Topology (cold).
    std::vector<int> vertex_block, vertex_id; ///< A and the global id of its vertex
    std::vector<int> edge_block, edge_id;     ///< B and the global id of its edge's first vertex
    std::vector<int> edge_end;                ///< global id of the edge's second vertex
    std::vector<double> length;               ///< L, m
    std::vector<int> property;                ///< property set (index into the law table)
    std::vector<JointHistory> history;
    /// Current normal n (written every step); the tangent is t = (−n.y, n.x).
    std::vector<Vec2> normal;
    /// Contacts by property set and kind, rebuilt when contacts are added or
    /// removed: batch 2p holds the rigid–rigid contacts of set p (the fast kernel),
    /// batch 2p+1 those with a deformable side.
    std::vector<std::vector<int>> batches;

    int size() const { return static_cast<int>(length.size()); }
    void add(int a, int vertex, int b, int edge, int end, double l, int prop, const JointHistory& h);
    void remove_if_flagged(const std::vector<std::uint8_t>& remove);
    /// `deformable`: per block, non-zero for deformable blocks (null = all rigid).
    void rebuild_batches(int property_sets, const std::uint8_t* deformable);
};

/// Global id of the vertex after `v` around its block.
inline int next_vertex(const std::uint32_t* first, int block, int v) {
    return (v + 1 == int(first[block + 1])) ? int(first[block]) : v + 1;
}

inline Vec2 tangent_of(Vec2 n) { return {-n.y, n.x}; }

/// Normal of contact i from the current geometry (used outside the step loop,
/// which inlines the same computation).
inline void contact_kinematics(Contacts& c, int i, const BlockView& b, double corner_radius) {
    const Vec2 x = b.vertex[c.vertex_id[i]];
    const Vec2 p = b.vertex[c.edge_id[i]], q = b.vertex[c.edge_end[i]];
    const double inv_len = b.inv_edge_length[c.edge_id[i]];
    Vec2 t = inv_len * (q - p);
    Vec2 nrm{t.y, -t.x}; // outward normal of a counter-clockwise polygon's edge
    // An unbonded contact beyond an end of its edge: normal of the rounded corner.
    const double s = dot(x - p, t) * inv_len;
    if (!c.history[i].bonded && (s < 0.0 || s > 1.0)) [[unlikely]] {
        const Vec2 r = x - ((s < 0.0 ? p : q) - corner_radius * nrm);
        const double rl = norm(r);
        if (rl > 0.0) {
            nrm = r / rl;
            t = Vec2{-nrm.y, nrm.x};
        }
    }
    c.normal[i] = nrm;
}

/// Normals of every contact from the current geometry.
void update_normals(Contacts& c, const BlockView& b, double corner_radius);

/// Contact force on the vertex block (A); B gets the opposite.
inline Vec2 contact_force(const Contacts& c, int i) {
    const JointHistory& h = c.history[i];
    const Vec2 n = c.normal[i];
    return c.length[i] * (h.sn * n - h.tau * tangent_of(n));
}

/// Per-thread force accumulators for step_contacts, kept between steps (sized
/// once, not allocated per step).
struct ThreadForces {
    std::vector<Vec2> force, node_force;
    std::vector<double> moment, sum;
};

/// Force accumulators of stage 2: per block (force, moment) and per FE node.
struct ForceTargets {
    Vec2* force;
    double* moment;
    int blocks;
    Vec2* node_force;
    int nodes;
};

/// Stage 2 of a step, fused per batch so each contact's data is loaded once:
/// kinematics, the batch's law (one dispatch per batch), and the forces and
/// moments added to the blocks' and nodes' accumulators (zeroed by the caller;
/// a force on a deformable edge is split to its two nodes with the weights that
/// interpolate the edge's velocity). Returns Σ|F|² over the contacts (the RMS
/// contact force is the scale of the unbalanced-force ratio; squares spare a
/// square root per contact). With threads > 1 each thread takes a contiguous part
/// of every batch into its own accumulators, summed per block afterwards in thread
/// order: results are deterministic for a given thread count.
double step_contacts(Contacts& c, const std::vector<JointLaw>& laws, const BlockView& b, double dt,
                     double corner_radius, const ForceTargets& out, int threads, ThreadForces& scratch);

} // namespace bbm::contact
