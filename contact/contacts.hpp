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
// Corners: while a vertex lies beyond the end of its edge (a convex corner of B)
// the normal is taken from B's rounded corner — the direction from a centre set
// back by r = `corner_radius` behind the corner to the vertex — which turns
// continuously from one edge's normal to the next's; the contact passes to the
// neighbouring edge, with its history, once the vertex projects onto that edge.
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
};

struct Contacts {
    // Topology (cold).
    std::vector<int> vertex_block, vertex_id; ///< A and the global id of its vertex
    std::vector<int> edge_block, edge_id;     ///< B and the global id of its edge's first vertex
    std::vector<double> length;               ///< L, m
    std::vector<int> property;                ///< property set (index into the law table)
    std::vector<JointHistory> history;
    // Per step (hot), written by update_kinematics.
    std::vector<Vec2> normal, tangent;
    std::vector<double> dun, dus;
    /// Contacts of each property set, rebuilt when contacts are added or removed.
    std::vector<std::vector<int>> batches;

    int size() const { return static_cast<int>(length.size()); }
    void add(int a, int vertex, int b, int edge, double l, int prop, const JointHistory& h);
    void remove_if_flagged(const std::vector<std::uint8_t>& remove);
    void rebuild_batches(int property_sets);
};

/// Global id of the vertex after `v` around its block.
inline int next_vertex(const std::uint32_t* first, int block, int v) {
    return (v + 1 == int(first[block + 1])) ? int(first[block]) : v + 1;
}

/// Normal/tangent of every contact, and the displacement increments over dt.
void update_kinematics(Contacts& c, const BlockView& b, double dt, double corner_radius);

/// Laws, one dispatch per batch.
void update_stresses(Contacts& c, const std::vector<JointLaw>& laws);

/// Adds contact forces and moments to the blocks' accumulators; returns Σ|F|
/// (the scale of the unbalanced-force ratio).
double accumulate_forces(const Contacts& c, const BlockView& b, Vec2* force, double* moment);

/// Contact force on the vertex block (A); B gets the opposite.
inline Vec2 contact_force(const Contacts& c, int i) {
    const JointHistory& h = c.history[i];
    return c.length[i] * (h.sn * c.normal[i] - h.tau * c.tangent[i]);
}

} // namespace bbm::contact
