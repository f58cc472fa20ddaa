// bbm studies: what a tunnel engineer measures around an opening (paper §4.3) —
// wall convergence, cracks by sector, failed-zone depth, hoop-stress profiles —
// read off a solver's state after an excavation.
#pragma once

#include "core/solver.hpp"

#include <array>
#include <vector>

namespace bbm {

/// Measures of an excavation a tunnel engineer looks at (paper §4.3), about the
/// opening's centre: the wall points at the springline and the crown (the
/// material points that started nearest them; convergence = displacement towards
/// the centre, positive inwards), cracks in the ±30° sectors around both
/// directions, and the depth of the failed zone beyond the opening's radius in
/// each direction (±15°): the depth within which 90% of those cracks lie, zero
/// with fewer than 3.
struct OpeningMeasures {
    Vec2 springline_displacement{}, crown_displacement{};
    double springline_convergence = 0, crown_convergence = 0;
    int cracks_springline_sector = 0, cracks_crown_sector = 0;
    double failed_depth_springline = 0, failed_depth_crown = 0;
    int tensile_springline_sector = 0, shear_springline_sector = 0;
};
OpeningMeasures measure_opening(const Solver& s, Vec2 center, Vec2 springline, Vec2 crown);

/// Hoop stress (tension positive) at distance r from `center` along the direction
/// `towards`: the area-weighted mean of the block-averaged stress of rigid blocks
/// and of the zone stresses whose centroids lie within `band` of that point (the
/// scatter of discrete blocks needs an average; SPEC §7). NaN if none is there.
double hoop_stress_at(const Solver& s, const std::vector<std::array<double, 3>>& block_stress, Vec2 center,
                      Vec2 towards, double r, double band);

} // namespace bbm
