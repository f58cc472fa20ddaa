// bbm core: seismic events from breaking bonds (Hazzard and Young 2002) — the
// acoustic emission of a lab test, the microseismicity of a tunnel.
//
// A bond's failure is a seismic source. It opens when the bond starts to soften
// (its peak reached: the joint law's damage leaves 0) or, for a brittle bond,
// when it breaks; its source region is the two rigid blocks it joins. Other bonds
// that start to fail within `join_distance` of a bond of an open event join it,
// and their blocks join its region. While the event is open its moment tensor is
// the change, since each block joined, of the first moments of the contact
// forces on the region's blocks, each about its own centroid — the stress glut
// of the source region, its area times the drop of its block-averaged stress
// (SPEC §7):
//     M_ij(t) = −Σ_{b ∈ S} [ Σ_{c ∋ b} F_i^c(t) (x_j^c − x_j^b) ]_{since b joined}   (symmetrised),
// F^c the force of contact c on block b at its point x^c. Hazzard and Young sum
// the force changes on the contacts around the crack times their distance from
// its centre; about each block's centroid the sum leaves out the net force that
// accelerates the blocks (which would make the tensor depend on the point it is
// taken about), and the broken bond's own force counts as the dipole F ⊗ (x_B − x_A)
// it was. The sign makes a tensile crack an explosive source (positive trace):
// its region's tension drops. The event's tensor is the one of largest scalar
// moment over its duration (a rebound's overshoot of the static drop included;
// the tensor at its close, the settled drop, is reported beside it),
//     M0 = √((m1² + m2²) / 2)   (m1, m2 its eigenvalues; N·m per m of thickness),
// and it closes `window` steps after the last of its bonds broke or started to
// fail; bonds still softening then leave it (one that breaks later is a source of
// its own). An event none of whose bonds broke is no event: it is dropped once
// 100 windows pass without a break.
//
// Moment magnitude (Hanks and Kanamori 1979, with the IASPEI constant for M0 in N·m):
//     Mw = (log10 M0 − 9.1) / 1.5,   M0 = M0_2D × thickness,
// the thickness the event's own length (its broken bonds' total joint length: an
// equidimensional crack in three dimensions) unless [events] thickness is given.
// Failure type by the isotropic part (Feignier and Young 1992, in 2D):
//     R = 100 tr M / (|tr M| + Σ|m_j − tr M / 2|),  tensile R > 30, implosive R < −30, shear between.
// Energy: the largest rise of the region's kinetic energy (real masses) over the
// event's duration (Hazzard and Young 2004), meaningful in the dynamic mode (in the
// quasi-static mode velocities are not physical); and the fracture energy its
// bonds dissipated, meaningful in both.
//
// The part is plain data: the settings, the open events as flat arrays (an open
// event's blocks and bonds in lists tagged by its index), and the catalogue as one
// column per quantity. It is saved, not hashed: a record of what happened, like
// the verdict's samples (recorded states do not change with events on). The step
// row (core/step.cpp, after the zones) reads the contact pass's marks
// (Contacts::bond_change) and the forces it wrote.
#pragma once

#include "base/fields.hpp"
#include "base/vec2.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace bbm {

/// Hanks and Kanamori's constant for M0 in N·m.
inline constexpr double moment_magnitude_constant = 9.1;
inline double moment_magnitude(double m0) { return m0 > 0.0 ? (std::log10(m0) - moment_magnitude_constant) / 1.5 : -99.0; }

struct Events {
    // Settings, resolved when the world is built.
    double join_distance = 0.0; ///< m
    long window = 0;            ///< steps
    double thickness = 0.0;     ///< m; 0: each event's own length

    // Open events, per event e.
    std::vector<long> open_step;            ///< step its first bond started to fail
    std::vector<long> open_last;            ///< step of its last break or onset
    std::vector<double> open_time;          ///< time of its first break, s (−1: none yet)
    std::vector<long> open_break_step;      ///< step of its first break
    std::vector<Vec2> open_origin;          ///< x0: its first bond
    std::vector<std::array<double, 3>> open_base;   ///< Σ first moments of its blocks when they joined {xx, yy, xy}
    std::vector<std::array<double, 3>> open_best;   ///< the moment tensor of largest M0 so far
    std::vector<double> open_best_m0;
    std::vector<std::array<double, 3>> open_now;    ///< the moment tensor at the last step
    std::vector<double> open_kinetic_base, open_kinetic_rise; ///< J/m
    std::vector<int> open_broken, open_tensile;
    std::vector<double> open_length;        ///< its broken bonds' joint length, m
    std::vector<double> open_fracture;      ///< their fracture energy, J/m
    std::vector<Vec2> open_sum_point;       ///< Σ of its broken bonds' points
    // Their blocks and bonds, each tagged by its event.
    std::vector<int> member_event, member_block;
    std::vector<long> member_step;          ///< the step it joined (its base's forces)
    std::vector<int> bond_event, bond_vertex, bond_edge;
    std::vector<Vec2> bond_point;
    std::vector<std::uint8_t> bond_broken;

    // The catalogue: closed events, in the order they closed.
    std::vector<double> time;               ///< s
    std::vector<long> step, first_step;
    std::vector<Vec2> position;             ///< mean of its broken bonds' points
    std::vector<std::array<double, 3>> tensor; ///< {Mxx, Myy, Mxy}, N·m/m
    std::vector<std::array<double, 3>> static_tensor; ///< at its close: the static drop, without the rebound
    std::vector<double> moment;             ///< M0, N·m/m
    std::vector<double> length;             ///< m
    std::vector<int> bonds, tensile_bonds;
    std::vector<double> energy, fracture_energy; ///< J/m

    // The row's scratch (rebuilt): sized as the open events grow, so a step allocates
    // only when there are more of them than ever before.
    std::vector<std::array<double, 3>> scratch_moment;
    std::vector<double> scratch_kinetic;
    std::vector<int> scratch_renumber;

    int count() const { return int(time.size()); }
    int open_count() const { return int(open_step.size()); }
};
template <part_of<Events> P, class V>
void visit_fields(P& e, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned S = field_use::saved;
    constexpr unsigned M = field_use::model;
    v(FieldInfo{"events.join_distance", G::other, M}, e.join_distance);
    v(FieldInfo{"events.window", G::other, M}, e.window);
    v(FieldInfo{"events.thickness", G::other, M}, e.thickness);
    v(FieldInfo{"events.open_step", G::other, S}, e.open_step);
    v(FieldInfo{"events.open_last", G::other, S}, e.open_last);
    v(FieldInfo{"events.open_time", G::other, S}, e.open_time);
    v(FieldInfo{"events.open_break_step", G::other, S}, e.open_break_step);
    v(FieldInfo{"events.open_origin", G::other, S}, e.open_origin);
    v(FieldInfo{"events.open_base", G::other, S}, e.open_base);
    v(FieldInfo{"events.open_best", G::other, S}, e.open_best);
    v(FieldInfo{"events.open_best_m0", G::other, S}, e.open_best_m0);
    v(FieldInfo{"events.open_now", G::other, S}, e.open_now);
    v(FieldInfo{"events.open_kinetic_base", G::other, S}, e.open_kinetic_base);
    v(FieldInfo{"events.open_kinetic_rise", G::other, S}, e.open_kinetic_rise);
    v(FieldInfo{"events.open_broken", G::other, S}, e.open_broken);
    v(FieldInfo{"events.open_tensile", G::other, S}, e.open_tensile);
    v(FieldInfo{"events.open_length", G::other, S}, e.open_length);
    v(FieldInfo{"events.open_fracture", G::other, S}, e.open_fracture);
    v(FieldInfo{"events.open_sum_point", G::other, S}, e.open_sum_point);
    v(FieldInfo{"events.member_event", G::other, S}, e.member_event);
    v(FieldInfo{"events.member_block", G::other, S}, e.member_block);
    v(FieldInfo{"events.member_step", G::other, S}, e.member_step);
    v(FieldInfo{"events.bond_event", G::other, S}, e.bond_event);
    v(FieldInfo{"events.bond_vertex", G::other, S}, e.bond_vertex);
    v(FieldInfo{"events.bond_edge", G::other, S}, e.bond_edge);
    v(FieldInfo{"events.bond_point", G::other, S}, e.bond_point);
    v(FieldInfo{"events.bond_broken", G::other, S}, e.bond_broken);
    v(FieldInfo{"events.time", G::other, S}, e.time);
    v(FieldInfo{"events.step", G::other, S}, e.step);
    v(FieldInfo{"events.first_step", G::other, S}, e.first_step);
    v(FieldInfo{"events.position", G::other, S}, e.position);
    v(FieldInfo{"events.tensor", G::other, S}, e.tensor);
    v(FieldInfo{"events.static_tensor", G::other, S}, e.static_tensor);
    v(FieldInfo{"events.moment", G::other, S}, e.moment);
    v(FieldInfo{"events.length", G::other, S}, e.length);
    v(FieldInfo{"events.bonds", G::other, S}, e.bonds);
    v(FieldInfo{"events.tensile_bonds", G::other, S}, e.tensile_bonds);
    v(FieldInfo{"events.energy", G::other, S}, e.energy);
    v(FieldInfo{"events.fracture_energy", G::other, S}, e.fracture_energy);
    constexpr unsigned R = field_use::rebuilt;
    v(FieldInfo{"events.scratch_moment", G::other, R}, e.scratch_moment);
    v(FieldInfo{"events.scratch_kinetic", G::other, R}, e.scratch_kinetic);
    v(FieldInfo{"events.scratch_renumber", G::other, R}, e.scratch_renumber);
}

struct World;
struct EventSpec;

/// The catalogue on, as [events] asks (core/model_spec.hpp): its defaults
/// resolved against the world's blocks, the contact pass's marks kept.
void start_events(World& w, const EventSpec& spec);

/// The step row: the contact pass's new onsets and breaks joined into events,
/// every open event's moment tensor and kinetic energy brought up to date, the
/// events whose window has passed closed into the catalogue.
void record_events(World& w);

/// One event as reported: the catalogue's columns and what follows from them.
struct SeismicEvent {
    double time = 0.0;
    long step = 0, first_step = 0;
    Vec2 position{};
    std::array<double, 3> tensor{}; ///< {Mxx, Myy, Mxy}, N·m/m: the largest over its duration
    std::array<double, 3> static_tensor{}; ///< at its close (or now): the settled drop
    double moment = 0.0;            ///< M0, N·m/m
    double moment_nm = 0.0;         ///< M0 × thickness, N·m
    double magnitude = 0.0;         ///< Mw
    double r_value = 0.0;           ///< Feignier and Young's isotropic ratio, %
    std::string type;               ///< tensile, shear or implosive
    double length = 0.0;
    int bonds = 0, tensile_bonds = 0;
    double energy = 0.0, fracture_energy = 0.0;
};

/// The catalogue and, as if closed now, the open events that have a broken bond
/// (the state is not changed: a run goes on, or resumes, the same).
std::vector<SeismicEvent> event_catalogue(const Events& e);

/// Feignier and Young's R of a 2D moment tensor, % (0 for a zero tensor).
double isotropic_ratio(const std::array<double, 3>& m);
/// Its failure type: tensile (R > 30), implosive (R < −30) or shear.
const char* failure_type(double r_value);
/// Scalar moment of a 2D tensor: √((m1² + m2²) / 2).
double scalar_moment(const std::array<double, 3>& m);

/// The Gutenberg–Richter fit of a list of magnitudes (Aki 1965's maximum
/// likelihood above the magnitude of completeness, taken at the mode of a 0.1
/// histogram — the maximum curvature method, Wiemer and Wyss 2000; uncertainty
/// after Shi and Bolt 1982): log10 N(≥ M) = a − b M.
struct GutenbergRichter {
    int count = 0;            ///< events at or above the completeness
    double completeness = 0.0, b = 0.0, b_error = 0.0, a = 0.0;
    bool fitted = false;      ///< at least 10 events above the completeness
};
GutenbergRichter gutenberg_richter(const std::vector<double>& magnitudes);

/// events.csv: one row per event, its header naming each column with its unit.
std::string events_csv(const std::vector<SeismicEvent>& events);

} // namespace bbm
