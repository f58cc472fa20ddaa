// bbm contact: one joint property set as a model file gives it (SPEC §4) — the
// law, stiffnesses, strengths and the post-peak softening points. Plain data,
// checked by the input layer; joint_law.hpp turns it into a law.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace bbm {

/// One joint property set (SPEC §4). Which law is used follows `law`.
struct JointPropertySpec {
    enum class Law { elastic, coulomb, softening };
    std::string name;
    Law law = Law::softening;
    double kn = 0.0;              ///< normal stiffness, Pa/m (> 0)
    double ks = 0.0;              ///< shear stiffness, Pa/m (> 0)
    double friction = 30.0;       ///< friction angle φ, degrees
    double residual_friction = -1; ///< φr after failure, degrees; < 0 = friction
    double cohesion = 0.0;        ///< c, Pa (coulomb: brittle bond; softening: peak cohesion)
    double tensile = 0.0;         ///< σt, Pa
    /// Post-peak points (α, β) of the softening curves, normalised as in SPEC §4
    /// (α: displacement over the elastic displacement at peak, β: stress over peak),
    /// in increasing α, the last with β = 0. Empty = brittle (drops to 0 at once).
    std::vector<std::pair<double, double>> tension_softening;
    std::vector<std::pair<double, double>> shear_softening;
};

} // namespace bbm
