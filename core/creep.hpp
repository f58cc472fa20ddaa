// bbm core: real time in a quasi-static run — the creep step of stress corrosion
// (contact/laws/stress_corrosion.hpp; docs/theory.md §17).
//
// A `creep` stage alternates mechanical equilibrium with creep steps, as PFC's
// stress-corrosion scheme does (Potyondy 2007): at equilibrium every bond of a
// corroding law loses section at its rate ω̇(s) over a creep time Δt, and the
// step table runs again until the model is at rest under the lost section (or a
// bond that broke has let the rock fail). Δt is sized so that no bond loses more
// than the fraction `loss` of its intact section, divided by β s where the rate is
// that steep (the rate then changes by about e^loss over the step):
//     Δt = min over bonds  loss / (ω̇(s) · max(1, β s)),
// and at most the time left to the stage's end. Each bond's loss is integrated
// with the midpoint rule, its force held (the load on it does not change within
// the creep step: its stress on the section rises as 1/ω),
//     Δω = Δt · ω̇(s ω / (ω − Δt ω̇(s) / 2)),
// second order in Δt for a bond under constant load. A bond whose section falls
// below 1% is corroded through and breaks (among stiff neighbours a shrinking
// bond sheds its load, and its stress ratio may never reach 1). Nothing is computed while
// no bond is above its threshold: the creep step is then the time left.
//
// The world's part (Creep) is plain data: the creep time, the current stage's
// end and loss, and whether a creep step is due; the step is a row of the step
// table (core/step.cpp) that the creep stage arms at equilibrium.
#pragma once

#include "base/fields.hpp"

namespace bbm {

/// A Julian year, s (the unit summary.json gives creep time in besides seconds).
inline constexpr double seconds_per_year = 365.25 * 86400.0;

struct Creep {
    double time = 0.0;  ///< creep time since the model was built, s
    double until = 0.0; ///< the current creep stage's end, s
    double loss = 0.02; ///< its largest fraction of a bond's section lost in one creep step
    double last_step = 0.0; ///< the last creep step's Δt, s
    long steps = 0;     ///< creep steps taken
    long since = 0;     ///< mechanical steps since the last creep step
    int due = 0;        ///< 1: the next step takes a creep step first (set and cleared by the stage)
};
template <part_of<Creep> P, class V>
void visit_fields(P& c, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving;
    v(FieldInfo{"creep.time", G::other, E}, c.time);
    v(FieldInfo{"creep.until", G::other, E}, c.until);
    v(FieldInfo{"creep.loss", G::other, E}, c.loss);
    v(FieldInfo{"creep.last_step", G::other, E}, c.last_step);
    v(FieldInfo{"creep.steps", G::other, E}, c.steps);
    v(FieldInfo{"creep.since", G::other, E}, c.since);
    v(FieldInfo{"creep.due", G::other, E}, c.due);
}

struct World;

/// One creep step: Δt by the rule above (at most until − time), every corroding
/// bond's section and its contact's length reduced, the creep time advanced.
/// Returns Δt.
double take_creep_step(World& w);

/// The largest stress ratio of a corroding bond (0 if none: all broken).
double highest_stress_ratio(const World& w);

} // namespace bbm
