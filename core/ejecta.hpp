// bbm core: how violently the rock moved, and what it threw — the peak
// velocities of every body and the rock a burst ejects into an opening.
//
// Peak velocities (the dynamic mode's PPV map): per rigid block (its centroid's
// speed) and per FE node, the largest speed since the run began, with the time it
// was reached, and since the current stage began (a wave's stage: its own PPV,
// not the excavation's before it). A stage row after integration keeps them
// (core/step.cpp); they are a record, saved in a checkpoint but not in the state
// hash, as the seismic events are.
//
// Ejected rock (measure_ejecta) at any state: rigid blocks detached from the rock
// mass (find_fragments, core/verdict.hpp: no contact carrying force joins them to
// a supported body or the heaviest group) moving into the opening faster than a
// threshold ([report] ejection_speed, 1 m/s by default). Detachment alone is not
// ejection: in a burst the whole failed zone bulks, its broken blocks free of
// force for a moment while they separate (in the trigon tunnel excavated at once,
// 0.05 s on, detached rock reaches 4 m behind the wall at under 1 m/s while its
// skin flies at 3 m/s), so the mass of detached rock inward faster than 0.5, 1,
// 2, 3 and 5 m/s is reported beside it. A fragment in flight keeps the speed it
// left the wall with (gravity apart): its speed now is its ejection velocity, and
// its peak speed is reported beside it. Around a circular opening (a centre and a
// radius: the [report] table's) the depth behind the wall the ejected rock came
// from and the length of wall it came off (1° sectors of the wall holding an
// ejected block's origin), so its weight and kinetic energy per m² of wall: the
// measures rockburst damage and the support's energy demand are given in
// (Kaiser, McCreath and Tannant 1996; docs/theory.md §19.5).
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"
#include "core/model_spec.hpp"

#include <array>
#include <cstdint>
#include <iterator>
#include <optional>
#include <vector>

namespace bbm {

struct World;

struct PeakVelocities {
    std::vector<double> block_run, block_time, block_stage; ///< per block: m/s, s, m/s
    std::vector<double> node_run, node_stage;               ///< per node: m/s
    // What ejected rock is measured by (the [report] table's).
    double ejection_speed = 1.0;  ///< m/s
    std::vector<double> opening;  ///< {centre x, centre y, radius}, empty without one
};
template <part_of<PeakVelocities> P, class V>
void visit_fields(P& p, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned S = field_use::saved;
    v(FieldInfo{"peak.block_speed", G::blocks, S}, p.block_run);
    v(FieldInfo{"peak.block_time", G::blocks, S}, p.block_time);
    v(FieldInfo{"peak.block_stage_speed", G::blocks, S}, p.block_stage);
    v(FieldInfo{"peak.node_speed", G::nodes, S}, p.node_run);
    v(FieldInfo{"peak.node_stage_speed", G::nodes, S}, p.node_stage);
    v(FieldInfo{"peak.ejection_speed", G::other, field_use::model}, p.ejection_speed);
    v(FieldInfo{"peak.opening", G::other, field_use::model}, p.opening);
}

/// Sized for the world's bodies, every peak 0; ejected rock measured around the
/// report's opening, if it has one.
PeakVelocities start_peak_velocities(const World& w, const ReportSpec& report);
/// A stage starts: its own peaks from 0 again.
void start_stage_peaks(PeakVelocities& p);
/// The stage row's work over chunks [r.first, r.last) of Team::sum_chunk bodies,
/// blocks' chunks then nodes' (the integrate row's chunks).
void record_peak_velocities(World& w, int first_chunk, int last_chunk);

/// A circular opening: where the ejected rock is measured from.
struct OpeningCircle {
    Vec2 center;
    double radius = 0.0;
};

/// The speeds the mass of detached rock moving inward is tabulated above, m/s.
inline constexpr double ejecta_speed_steps[] = {0.5, 1.0, 2.0, 3.0, 5.0};

struct Ejecta {
    double threshold = 0.0;             ///< m/s: the ejection speed it was measured with
    std::vector<std::uint8_t> ejected;  ///< per block
    int blocks = 0;
    double mass = 0.0;                  ///< kg/m
    double speed_mean = 0.0, speed_max = 0.0; ///< now: mass-weighted mean, fastest (m/s)
    double peak_speed_mean = 0.0, peak_speed_max = 0.0; ///< of their peaks over the run (m/s; 0 without them)
    double kinetic = 0.0;               ///< now, translation and rotation, J/m
    double kinetic_at_peak = 0.0;       ///< Σ ½ m v_peak², J/m
    int detached_blocks = 0;            ///< all rigid blocks detached from the rock mass
    double detached_mass = 0.0;         ///< kg/m
    /// The detached rock moving inward faster than each of ejecta_speed_steps, kg/m.
    std::array<double, std::size(ejecta_speed_steps)> mass_faster{};
    // Around the opening (only when one is given).
    bool around_opening = false;
    double depth = 0.0;                 ///< deepest origin behind the wall, m
    double mean_depth = 0.0;            ///< mass-weighted, m
    double wall_length = 0.0;           ///< of the wall it came off, m
};
Ejecta measure_ejecta(const World& w, const std::optional<OpeningCircle>& opening, double threshold);
/// With the world's settings (PeakVelocities' opening and speed; outside the
/// dynamic mode: no opening, 1 m/s).
Ejecta measure_ejecta(const World& w);

} // namespace bbm
