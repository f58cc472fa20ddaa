// bbm core: the implicit elastic stage (SPEC §5) and kinematic moves over the world.
#pragma once

#include "core/world.hpp"

#include <string>
#include <vector>

namespace bbm {

struct ElasticSolveReport {
    int equations = 0, iterations = 0;
    long nonzeros = 0;
    std::string method;
    double relative_residual = 0, seconds = 0, ratio_before = 0, ratio_after = 0;
};

/// Assembles the linear stiffness of blocks (3 DOF), nodes (2 DOF), contacts (kn,
/// ks) and zones at the current state, solves K Δu = unbalanced force with
/// CHOLMOD (prescribed components held), and applies Δu through the contact laws
/// and zones. Velocities are zero after it. Throws SingularSystemError naming the
/// cause if the system is singular (a floating block or a model without
/// supports), NumericalError for loads no stiffness can carry.
ElasticSolveReport solve_elastic(World& w);

/// Moves the prescribed velocity components by fixed velocity × `time` through
/// the contact laws and zones, every free component held (one kinematic step, no
/// dynamics); velocities are zero after it. Followed by solve_elastic(): the
/// static state at that support displacement (a lab test's elastic preload).
void move_supports(World& w, double time);

/// Moves every block and node by the given displacement and rotation increments
/// (per block, per node) through the contact laws and zones, as one kinematic
/// step; velocities are zero after it. Scaling a linear-elastic solution: add
/// (λ − 1) times its displacements to reach λ times its state.
void move_bodies(World& w, const std::vector<Vec2>& block_displacement, const std::vector<double>& block_rotation,
                 const std::vector<Vec2>& node_displacement);

} // namespace bbm
