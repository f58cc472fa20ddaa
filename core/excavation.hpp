// bbm core: the stages that change what loads the rock — an in-situ stress, an
// excavation and its relaxing support, an opening's pressure — over the world.
#pragma once

#include "core/world.hpp"

#include <array>
#include <string>
#include <vector>

namespace bbm {

/// An excavation's support along a path (StageSpec::support_path): rows [t,
/// k_mean, k_deviator] over the relaxation's steps, and the in-situ stress whose
/// deviator splits each support force into its mean and deviatoric parts.
struct SupportPath {
    std::vector<std::array<double, 3>> rows;
    StressFieldSpec in_situ;
};

/// Joint stresses from a stress field, with the matching elastic displacements;
/// zone stresses from it at their centroids.
void initialize_stress(World& w, const StressFieldSpec& field);

/// Removes the blocks of these regions; the forces they exerted on the rest are
/// relaxed linearly over relax_steps steps to the fraction `keep` of them, which
/// stays (a support pressure: the convergence–confinement method's 1 − λ).
/// `pressure` (Pa) pushes on the new boundary, normal to it, from now on and for
/// good (a support pressure in Pa); a later excavate replaces both. A support
/// path instead relaxes the support's mean and deviatoric parts each along its
/// own curve (a tunnel face going by; theory.md §6.5).
void excavate(World& w, const std::vector<std::string>& regions, long relax_steps, double keep = 0.0,
              double pressure = 0.0, const SupportPath& path = {});

/// The latest opening's pressure is now `pressure` (Pa): the push on its wall
/// scaled from the excavation's `excavation_pressure`, which must be > 0 (it
/// gave the push its direction and extent), and, with water in the joints,
/// the wall's junctions held at it (`solve_now`: a steady solve at the next
/// step). What a `pressurise` stage does, step by step along its ramp.
void set_opening_pressure(World& w, double pressure, double excavation_pressure, bool solve_now);

/// σ(y) of a stress field, tension positive: {sxx, syy, sxy}.
std::array<double, 3> stress_at(const StressFieldSpec& f, double y);

} // namespace bbm
