// bbm core: viscous boundaries, the dynamic mode's absorbing edges (Lysmer &
// Kuhlemeyer 1969), and the plane waves sent in through them.
//
// A wave reaching a model's edge should leave it, as it would leave the rock
// around. On an edge of outward normal n and tangent t, dashpots of ρ c_p (normal)
// and ρ c_s (shear) per unit length put the traction
//     t_d = −ρ c_p (v·n) n − ρ c_s (v·t) t
// on it: a plane wave arriving normally is absorbed whole (P and S alike), one
// arriving obliquely mostly (Lysmer & Kuhlemeyer's ratio). An incident wave of
// particle velocity v_in(t) is sent in through the same edge as the traction
// 2 ρ c v_in(t) along its motion, the dashpot taking half of it (Itasca's
// "stress input through a quiet boundary"), so the edge keeps absorbing what
// comes back. Plane strain: c_p = √((λ + 2G)/ρ), c_s = √(G/ρ), of the material of
// the deformable block the edge belongs to.
//
// Each edge's dashpot is lumped to its two nodes (half its exposed length each,
// by position along a partly covered edge). A node's dashpots are integrated
// with its central difference, implicitly in the dashpot force (its velocity the
// mean of the half-steps before and after), so that a stiff dashpot on a light
// node stays stable at any time step:
//     (m/Δt + C/2) v⁺ = (m/Δt − C/2) v⁻ + F + F_in,
// C the node's 2 × 2 sum of ρ c L (n nᵀ, t tᵀ). The energy each boundary absorbs
// and the work its incident wave does are accumulated per boundary (J/m): the
// dynamic run's energy account.
//
// A rigid block's face at the edge takes the same dashpots, of its region's
// material (E, ν, ρ: the rock mass's), lumped at the ends of each exposed stretch
// (half its length each) as points of the body: a point's velocity v + ω × r,
// its force and moment on the body. The body's three velocities are solved for
// together, (M/Δt + C₃/2) u⁺ = (M/Δt − C₃/2) u + f, C₃ = Σ Jᵀ C J over its points,
// J = [1 0 −r_y; 0 1 r_x], M = diag(m, m, I).
//
// The world's part (ViscousBoundaries) is plain data, the stage a free function
// (core/step.cpp's table, after the gathers).
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"
#include "core/model_spec.hpp"

#include <array>
#include <string>
#include <vector>

namespace bbm {

/// The particle velocity of an incident wave at its boundary at time t (m/s).
double incident_velocity(const IncidentWaveSpec& wave, double t);
/// When the incident wave has passed its boundary (s): its start plus its length
/// (a Ricker wavelet's 2.4/f, its peak in the middle; a half-sine's 1/(2f); a
/// train's cycles/f; a record's last time). 0 without a pulse.
double incident_end(const IncidentWaveSpec& wave);

/// The model's viscous boundaries: one dashpot entry per (node, edge stretch), in
/// node order; per boundary its incident wave and its energy account.
struct ViscousBoundaries {
    std::vector<int> node;                      ///< per entry: its FE node
    std::vector<int> boundary;                  ///< per entry: which viscous boundary (0, 1, ...)
    std::vector<std::array<double, 3>> damping; ///< per entry: C = ρ c L (n nᵀ, t tᵀ) as cxx, cxy, cyy (N·s/m per m)
    std::vector<Vec2> input;                    ///< per entry: its force per m/s of incident velocity, 2 ρ c L d (N·s/m per m)
    /// Rigid faces: per entry, in body order, its body, boundary, point (from the
    /// centroid, in the body's frame as built), C and input as the nodes' above.
    std::vector<int> face_body, face_boundary;
    std::vector<Vec2> face_offset;
    std::vector<std::array<double, 3>> face_damping;
    std::vector<Vec2> face_input;
    std::vector<IncidentWaveSpec> waves;        ///< per boundary
    std::vector<std::string> names;             ///< per boundary: its [[boundary]] name
    std::vector<double> absorbed;               ///< per boundary: the energy its dashpots took, J/m
    std::vector<double> supplied;               ///< per boundary: the work of its incident wave, J/m
    int count() const { return static_cast<int>(node.size()); }
    int face_count() const { return static_cast<int>(face_body.size()); }
};

/// Its fields (base/fields.hpp): the dashpots are the model's, the energies evolve;
/// all empty in a model without one (which keeps its state hash).
template <part_of<ViscousBoundaries> P, class V>
void visit_fields(P& b, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model;
    v(FieldInfo{"viscous.node", G::nodes, M}, b.node);
    v(FieldInfo{"viscous.boundary", G::nodes, M}, b.boundary);
    v(FieldInfo{"viscous.damping", G::nodes, M}, b.damping);
    v(FieldInfo{"viscous.input", G::nodes, M}, b.input);
    v(FieldInfo{"viscous.face_body", G::blocks, M}, b.face_body);
    v(FieldInfo{"viscous.face_boundary", G::blocks, M}, b.face_boundary);
    v(FieldInfo{"viscous.face_offset", G::blocks, M}, b.face_offset);
    v(FieldInfo{"viscous.face_damping", G::blocks, M}, b.face_damping);
    v(FieldInfo{"viscous.face_input", G::blocks, M}, b.face_input);
    v(FieldInfo{"viscous.absorbed", G::other, E}, b.absorbed);
    v(FieldInfo{"viscous.supplied", G::other, E}, b.supplied);
}

/// One dashpot entry of an exposed edge stretch of length `length` (m), outward
/// normal n, on node `node`, of a material ρ, λ + 2G, G.
void add_dashpot(ViscousBoundaries& b, int boundary, int node, double length, Vec2 n, double density,
                 double p_modulus, double shear_modulus);
/// The same at a point `offset` from rigid body `body`'s centroid (as built).
void add_face_dashpot(ViscousBoundaries& b, int boundary, int body, Vec2 offset, double length, Vec2 n,
                      double density, double p_modulus, double shear_modulus);

/// Entries in node order (stable: a node's entries keep the order they were added).
void sort_dashpots(ViscousBoundaries& b);

} // namespace bbm
