// bbm core: what a run is measured by — energies, cracks, boundary reactions,
// block-averaged stresses (SPEC §7) — as free functions over the world.
#pragma once

#include "core/world.hpp"

#include <array>
#include <string>
#include <vector>

namespace bbm {

/// The contacts with their normals brought up to date: the step does not store
/// them (a write of every contact every step, for readers outside the loop), so
/// they are computed from the vertex positions the last step used, which gives
/// the same values.
const contact::Contacts& contacts(const World& w);
contact::Contacts& contacts(World& w);

/// The scale of the unbalanced-force ratio: the RMS contact (and zone nodal) force.
double force_scale(const World& w);
/// J/m, real masses.
double kinetic_energy(const World& w);
/// Elastic energy in the contacts and the zones, J/m.
double strain_energy(const World& w);
/// Total strain energy of the zones (½ σ·D⁻¹σ A), J/m.
double zone_strain_energy(const World& w);
/// Plastic work of the joints so far, J/m.
double dissipated_energy(const World& w);
/// The energy the viscous boundaries' dashpots have taken so far, J/m (core/viscous.hpp).
double absorbed_energy(const World& w);
/// The work their incident waves have done so far, J/m.
double wave_energy(const World& w);
/// The energy account (J/m): what the loads, the prescribed velocities and the
/// incident waves supplied, against what is stored (kinetic at the masses as
/// integrated — scaled in the quasi-static mode —, strain in contacts and zones)
/// and spent (the joints' plastic work, damping's, the viscous boundaries'
/// radiation), all since the model was built; `error` is supplied − stored − spent
/// since the current stage started (an initialize, elastic or excavate stage sets
/// stresses or removes rock without work: the account starts again after it).
struct EnergyAccount {
    double work = 0.0, wave_input = 0.0, kinetic = 0.0, strain = 0.0, joints = 0.0, damping = 0.0, radiated = 0.0;
    double supports = 0.0; ///< the work the rock did on its supports (each type's energy: core/supports/support.hpp)
    double error = 0.0;
};
EnergyAccount energy_account(const World& w);
/// The account's origin at the start of a stage (core/stages.cpp).
void start_energy_account(World& w);

/// Cracks (broken bonds) so far, by mode; cumulative.
int cracks(const World& w, contact::JointState mode);
/// Total contact force on a boundary's blocks in the last step, N/m (for a
/// prescribed-velocity boundary: minus the reaction its supports provide).
Vec2 boundary_force(const World& w, const std::string& boundary);
/// Block-averaged stress of every block (SPEC §7): σ = (1/A) Σ x ⊗ f over its
/// contacts and boundary tractions, symmetrised; tension positive. {sxx, syy, sxy}.
std::vector<std::array<double, 3>> block_stresses(const World& w);
/// The block whose centroid is nearest p.
int block_at(const World& w, Vec2 p);

} // namespace bbm
