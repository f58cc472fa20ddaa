// bbm studies: what a tunnel engineer measures around an opening (paper §4.3) —
// wall convergence, cracks by sector, failed-zone depth, hoop-stress profiles —
// read off a solver's state after an excavation.
#pragma once

#include "core/world.hpp"

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
OpeningMeasures measure_opening(const World& w, Vec2 center, Vec2 springline, Vec2 crown);

/// The failed zone as engineers map it around an opening: the damaged rock that is
/// connected to the wall. A polar grid about the centre — `sectors` equal sectors
/// (36: 10 degrees), rings of `cell` metres from the opening's radius outwards —
/// holds the joints at their initial position (where the rock was: a fragment that
/// fell to the floor is mapped where it came from). A cell is damaged when at least
/// `threshold` of its joint length is broken (the broken-contact density per unit
/// area over that of the intact pattern: independent of the block size); the zone
/// is the damaged cells connected through damaged neighbours (across rings and
/// sectors) to a damaged cell at the wall (a sector's innermost ring with rock).
/// Its depth in a sector is measured finer than the cells, from the broken
/// contacts themselves: the distance of the zone's outermost broken contact point
/// (at its initial position) less the wall's (the sector's innermost contact point
/// of the rock), the median over 8 grids whose rings start an eighth of a cell
/// apart (on one grid a dense zone's outermost crack sits at its deepest cell's
/// outer edge). Its step (`resolution`) is the larger of an eighth of a cell and
/// the radial spacing of contact points, not a cell. A scattered
/// crack deep in the rock, not connected to the wall, is not in it (the deepest
/// single crack is OpeningMeasures' failed depth).
struct FailedZone {
    double cell = 0, threshold = 0, radius = 0;
    Vec2 center{};
    std::vector<double> depth; ///< per sector, counter-clockwise from +x, from the wall, m (0: none)
    /// Per sector, the outer edge of the zone's deepest cell from the wall's cell
    /// (whole cells: the coarse measure, at least `depth`).
    std::vector<double> depth_cells;
    /// The step of `depth`, m: the larger of cell / 8 and the mean radial spacing
    /// of the rock's distinct contact points within four cells of the wall (the
    /// median over sectors).
    double resolution = 0;
    /// Per sector, the wall's distance beyond `radius` (non-zero where the opening
    /// is wider than its smaller radius).
    std::vector<double> wall_offset;
    double depth_springline = 0, depth_crown = 0; ///< deepest within +/-15 deg of each direction
    /// Angular width of the zone (sectors with a depth) within +/-45 deg of each direction.
    double extent_springline_deg = 0, extent_crown_deg = 0;
    double area = 0; ///< m^2, the cells of the zone
    /// The zone reaches the edge of the opening's region: a cell of it holds, or
    /// borders, a contact between blocks of two regions one of which is deformable
    /// (the interface with an elastic far field). The failure is then the model's
    /// boundary's as much as the rock's: the model is too small.
    bool reaches_region_edge = false;
    Vec2 region_edge_point{}; ///< where (the outermost such cell's centre)
    /// Cells holding that edge, and those of them damaged (connected to the wall
    /// or not: cracks along the interface mean the far field loads the rock there
    /// unlike rock would).
    int edge_cells = 0, edge_cells_damaged = 0;
    /// The zone's outer edge: per sector, its centre direction at radius + depth.
    std::vector<Vec2> outline() const;
    /// The zone's lobes — notches or breakouts — as an engineer maps them: each
    /// run of neighbouring sectors with a depth, largest area first.
    struct Lobe {
        double centre_deg = 0; ///< depth-weighted mean direction, counter-clockwise from +x, [0, 360)
        double depth = 0;      ///< deepest sector, m from the wall
        double width_deg = 0;  ///< angular width (sectors times their width)
        double area = 0;       ///< m^2 between the wall and the lobe's outer edge
    };
    std::vector<Lobe> lobes() const;
};
FailedZone measure_failed_zone(const World& w, Vec2 center, Vec2 springline, Vec2 crown, double cell,
                               double threshold = 0.2, int sectors = 36);
/// The failed zone with cells of four mean contact lengths (about one block: two
/// contacts share each joint edge), as summary.json and failure.png give it.
FailedZone measure_failed_zone(const World& w, Vec2 center, Vec2 springline, Vec2 crown);

/// The damaged zone as a path for water along the tunnel ([flow] models; AECL's
/// connected-permeability tests at the Mine-by tunnel: docs/field.md, "Water in the
/// damaged zone"). Each pipe of the flow network is a joint plane running along
/// the tunnel's axis: along the axis it carries a^3 / 12 per metre of its trace
/// (the cubic law, per unit pressure gradient over the viscosity), so a part of the
/// section of area A has the axial permeability k = sum(L a^3 / 12) / A. Joints at
/// their initial positions, distances from the wall (`radius` about `center`).
struct AxialPermeability {
    double intact = 0;     ///< m^2: the flow regions with every bond intact (bond aperture)
    double ring = 0;       ///< m: width of the profiles' rings, from the wall outwards
    /// Per ring: k, m^2, within 30 deg of the crown's direction, of the springline's, and all round.
    std::vector<double> crown, springline, all_round;
    /// The damaged zone for water: the joints that carry at least 10 times an
    /// intact bond (one order of magnitude in transmissivity: the EDZ of Tsang et
    /// al. 2005), connected through such joints to the opening's drained wall.
    int edz_joints = 0;
    double edz_area = 0;           ///< m^2: the blocks bordering those joints
    double edz_depth = 0;          ///< m from the wall: the deepest of their midpoints
    double edz_transmissivity = 0; ///< m^4: sum L a^3 / 12 over them
    double edz_permeability = 0;   ///< m^2: edz_transmissivity / edz_area
    /// m^2: the blocks bordering the fewest of those joints (largest first) that
    /// carry 90% of edz_transmissivity: where most of the flow goes.
    double core_area = 0;
    int core_joints = 0;
    int parted_joints = 0; ///< of the zone's: blocks moved apart (the network's largest aperture)
};
/// Rings of `ring` metres out to the nearest held junction that is not the wall's
/// (the interface with the dry far field). Zero figures in a dry model.
AxialPermeability measure_axial_permeability(const World& w, Vec2 center, Vec2 springline, Vec2 crown,
                                             double ring);

/// Hoop stress (tension positive) at distance r from `center` along the direction
/// `towards`: the area-weighted mean of the block-averaged stress of rigid blocks
/// and of the zone stresses whose centroids lie within `band` of that point (the
/// scatter of discrete blocks needs an average; SPEC §7). NaN if none is there.
double hoop_stress_at(const World& w, const std::vector<std::array<double, 3>>& block_stress, Vec2 center,
                      Vec2 towards, double r, double band);

} // namespace bbm
