// The creep step of stress corrosion (core/creep.hpp).
#include "core/creep.hpp"

#include "core/world.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

namespace bbm {

namespace {

/// Per property set, its corroding law, or null.
const contact::StressCorrosionLaw* corroding_law(const World& w, int set) {
    return std::get_if<contact::StressCorrosionLaw>(&w.properties.laws[set]);
}

/// f(contact, law, s, rate) for every intact bond of a corroding law loaded above
/// its threshold.
template <class F>
void for_each_corroding_bond(const World& w, F&& f) {
    const auto& c = w.contacts;
    for (int i = 0; i < c.size(); ++i) {
        const auto* law = corroding_law(w, c.property[i]);
        if (!law || !c.history[i].bonded) continue;
        const double s = law->stress_ratio(c.history[i]), rate = law->section_rate(s);
        if (rate > 0.0) f(i, *law, s, rate);
    }
}

} // namespace

double highest_stress_ratio(const World& w) {
    double highest = 0.0;
    const auto& c = w.contacts;
    for (int i = 0; i < c.size(); ++i)
        if (const auto* law = corroding_law(w, c.property[i]))
            highest = std::max(highest, law->stress_ratio(c.history[i]));
    return highest;
}

double take_creep_step(World& w) {
    Creep& cr = *w.creep;
    auto& c = w.contacts;
    double dt = std::max(cr.until - cr.time, 0.0);
    for_each_corroding_bond(w, [&](int, const contact::StressCorrosionLaw& law, double s, double rate) {
        dt = std::min(dt, cr.loss / (rate * std::max(1.0, law.exponent * s)));
    });
    if (dt > 0.0)
        for_each_corroding_bond(w, [&](int i, const contact::StressCorrosionLaw& law, double s, double rate) {
            double& section = c.bond_section[i];
            // The midpoint rule under the bond's load held: s ω is its stress ratio
            // on the intact section.
            const double mid = section - 0.5 * dt * rate;
            const double lost = dt * law.section_rate(mid > 0.0 ? s * section / mid : 1.0);
            const double left = std::max(section - lost, 0.5 * law.section_left_at_break);
            c.length[i] *= left / section;
            section = left;
            if (section < law.section_left_at_break) {
                law.corrode_through(c.history[i]);
                if (c.marking) // a source for the seismic events (core/events.hpp), its force the last pass's
                    c.bond_change[i] = 1, c.force_before[i] = c.force[i].force;
            }
        });
    cr.time = dt < cr.until - cr.time ? cr.time + dt : std::max(cr.time, cr.until);
    cr.last_step = dt;
    ++cr.steps;
    cr.since = 0;
    return dt;
}

} // namespace bbm
