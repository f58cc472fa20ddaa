// Seismic events from breaking bonds (core/events.hpp).
#include "core/events.hpp"

#include "core/model_spec.hpp"
#include "core/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>

namespace bbm {

namespace {

using Tensor = std::array<double, 3>; // {xx, yy, xy}

/// A rigid block's first moment of its contact forces about its centroid,
/// Σ_c F^c ⊗ (x^c − x_b) symmetrised: its area times its block-averaged stress
/// (SPEC §7). About each block's own centroid, so the sum over a region does not
/// take in the net force that accelerates its blocks.
Tensor first_moment(const World& w, int block) {
    const auto& c = w.contacts;
    const Vec2 centroid = w.bodies.state[block].centroid;
    Tensor m{};
    for (int e = c.block_first[block]; e < c.block_first[block + 1]; ++e) {
        const int entry = c.block_entry[e], i = entry >> 1;
        const Vec2 f = double(1 - 2 * (entry & 1)) * c.force[i].force;
        const Vec2 r = w.vertices.position[c.vertex_id[i]] - centroid;
        m[0] += f.x * r.x;
        m[1] += f.y * r.y;
        m[2] += 0.5 * (f.x * r.y + f.y * r.x);
    }
    return m;
}

double kinetic(const World& w, int block) {
    const auto& b = w.bodies.state[block];
    return 0.5 * w.blocks.real_mass[block] * norm2(b.velocity) + 0.5 * w.blocks.real_inertia[block] * b.omega * b.omega;
}

int open_event(Events& ev, Vec2 origin, long step) {
    ev.open_step.push_back(step);
    ev.open_last.push_back(step);
    ev.open_time.push_back(-1.0);
    ev.open_break_step.push_back(step);
    ev.open_origin.push_back(origin);
    ev.open_base.push_back({});
    ev.open_best.push_back({});
    ev.open_best_m0.push_back(0.0);
    ev.open_now.push_back({});
    ev.open_kinetic_base.push_back(0.0);
    ev.open_kinetic_rise.push_back(0.0);
    ev.open_broken.push_back(0);
    ev.open_tensile.push_back(0);
    ev.open_length.push_back(0.0);
    ev.open_fracture.push_back(0.0);
    ev.open_sum_point.push_back({});
    return ev.open_count() - 1;
}

/// Block `block` into event e's region, its first moment and kinetic energy now
/// the base; whether its base is of this step's forces (it joined now, or earlier
/// in this step). False for a deformable or excavated block.
bool join_block(World& w, int e, int block) {
    Events& ev = *w.events;
    if (w.blocks.deformable[block] || w.bodies.removed[block]) return false;
    for (std::size_t k = 0; k < ev.member_block.size(); ++k)
        if (ev.member_event[k] == e && ev.member_block[k] == block) return ev.member_step[k] == w.clock.steps;
    ev.member_event.push_back(e);
    ev.member_block.push_back(block);
    ev.member_step.push_back(w.clock.steps);
    const Tensor m = first_moment(w, block);
    for (int j = 0; j < 3; ++j) ev.open_base[e][j] += m[j];
    ev.open_kinetic_base[e] += kinetic(w, block);
    return true;
}

/// The open event a new failure at x joins: the lowest-numbered one with a bond
/// within the join distance; −1 if none.
int event_near(const Events& ev, Vec2 x) {
    int best = -1;
    const double d2 = ev.join_distance * ev.join_distance;
    for (std::size_t k = 0; k < ev.bond_point.size(); ++k)
        if (norm2(ev.bond_point[k] - x) <= d2 && (best < 0 || ev.bond_event[k] < best)) best = ev.bond_event[k];
    return best;
}

/// A bond of contact i started to fail (softening) or broke.
void take_failure(World& w, int i) {
    Events& ev = *w.events;
    const auto& c = w.contacts;
    const auto& h = c.history[i];
    const Vec2 x = w.vertices.position[c.vertex_id[i]];
    const long step = w.clock.steps;
    int bond = -1;
    for (std::size_t k = 0; k < ev.bond_vertex.size(); ++k)
        if (ev.bond_vertex[k] == c.vertex_id[i] && ev.bond_edge[k] == c.edge_id[i] && !ev.bond_broken[k]) bond = int(k);
    int e = bond >= 0 ? ev.bond_event[bond] : event_near(ev, x);
    if (e < 0) e = open_event(ev, x, step);
    if (bond < 0) {
        ev.bond_event.push_back(e);
        ev.bond_vertex.push_back(c.vertex_id[i]);
        ev.bond_edge.push_back(c.edge_id[i]);
        ev.bond_point.push_back(x);
        ev.bond_broken.push_back(0);
        bond = int(ev.bond_event.size()) - 1;
        // A block whose base is of the pass that broke the bond (a bond broken at
        // its peak) had the bond's force before it: the base takes the bond's
        // dipole as it was (the block's other forces have not yet felt the break).
        const Vec2 change = c.force_before[i] - c.force[i].force;
        for (const int side : {0, 1}) {
            const int block = side == 0 ? c.vertex_block[i] : c.edge_block[i];
            if (!join_block(w, e, block) || h.bonded) continue;
            const Vec2 f = double(1 - 2 * side) * change, r = x - w.bodies.state[block].centroid;
            ev.open_base[e][0] += f.x * r.x;
            ev.open_base[e][1] += f.y * r.y;
            ev.open_base[e][2] += 0.5 * (f.x * r.y + f.y * r.x);
        }
    }
    ev.open_last[e] = step;
    if (h.bonded) return;
    ev.bond_broken[bond] = 1;
    if (ev.open_broken[e]++ == 0) ev.open_time[e] = w.clock.time, ev.open_break_step[e] = step;
    ev.open_tensile[e] += h.broken == contact::JointState::broken_tension;
    ev.open_length[e] += c.length[i];
    ev.open_fracture[e] += h.dissipated * c.length[i];
    ev.open_sum_point[e] += x;
}

/// Every open event's moment tensor and kinetic energy at this step.
void follow_open_events(World& w) {
    Events& ev = *w.events;
    const int n = ev.open_count();
    // Scratch kept in the part: it grows with the open events, not every step.
    auto& sum = ev.scratch_moment;
    auto& energy = ev.scratch_kinetic;
    sum.assign(std::size_t(n), Tensor{});
    energy.assign(std::size_t(n), 0.0);
    for (std::size_t k = 0; k < ev.member_block.size(); ++k) {
        const int e = ev.member_event[k], b = ev.member_block[k];
        const Tensor m = first_moment(w, b);
        for (int j = 0; j < 3; ++j) sum[e][j] += m[j];
        energy[e] += kinetic(w, b);
    }
    for (int e = 0; e < n; ++e) {
        const Tensor m{ev.open_base[e][0] - sum[e][0], ev.open_base[e][1] - sum[e][1], ev.open_base[e][2] - sum[e][2]};
        ev.open_now[e] = m;
        if (const double m0 = scalar_moment(m); m0 > ev.open_best_m0[e]) ev.open_best_m0[e] = m0, ev.open_best[e] = m;
        ev.open_kinetic_rise[e] = std::max(ev.open_kinetic_rise[e], energy[e] - ev.open_kinetic_base[e]);
    }
}

void catalogue(Events& ev, int e) {
    ev.time.push_back(ev.open_time[e]);
    ev.step.push_back(ev.open_break_step[e]);
    ev.first_step.push_back(ev.open_step[e]);
    ev.position.push_back((1.0 / double(ev.open_broken[e])) * ev.open_sum_point[e]);
    ev.tensor.push_back(ev.open_best[e]);
    ev.static_tensor.push_back(ev.open_now[e]);
    ev.moment.push_back(ev.open_best_m0[e]);
    ev.length.push_back(ev.open_length[e]);
    ev.bonds.push_back(ev.open_broken[e]);
    ev.tensile_bonds.push_back(ev.open_tensile[e]);
    ev.energy.push_back(ev.open_kinetic_rise[e]);
    ev.fracture_energy.push_back(ev.open_fracture[e]);
}

/// Keeps the entries whose event is kept, renumbered.
template <class T>
void keep_tagged(std::vector<T>& values, const std::vector<int>& tag, const std::vector<int>& renumber) {
    std::size_t out = 0;
    for (std::size_t k = 0; k < values.size(); ++k)
        if (renumber[tag[k]] >= 0) values[out++] = values[k];
    values.resize(out);
}

template <class T>
void keep_events(std::vector<T>& values, const std::vector<int>& renumber) {
    std::size_t out = 0;
    for (std::size_t e = 0; e < values.size(); ++e)
        if (renumber[e] >= 0) values[out++] = values[e];
    values.resize(out);
}

/// Events whose window has passed into the catalogue; events none of whose
/// bonds broke in 100 windows dropped.
void close_events(World& w) {
    Events& ev = *w.events;
    const long step = w.clock.steps;
    const int n = ev.open_count();
    auto& renumber = ev.scratch_renumber;
    renumber.assign(std::size_t(n), 0);
    int kept = 0, closed = 0;
    for (int e = 0; e < n; ++e) {
        const long quiet = step - ev.open_last[e];
        const bool done = ev.open_broken[e] > 0 ? quiet >= ev.window : quiet >= 100 * ev.window;
        if (done && ev.open_broken[e] > 0) catalogue(ev, e);
        renumber[e] = done ? -1 : kept++;
        closed += done;
    }
    if (closed == 0) return;
    keep_tagged(ev.member_block, ev.member_event, renumber);
    keep_tagged(ev.member_step, ev.member_event, renumber);
    keep_tagged(ev.bond_vertex, ev.bond_event, renumber);
    keep_tagged(ev.bond_edge, ev.bond_event, renumber);
    keep_tagged(ev.bond_point, ev.bond_event, renumber);
    keep_tagged(ev.bond_broken, ev.bond_event, renumber);
    for (auto* tags : {&ev.member_event, &ev.bond_event}) {
        std::size_t out = 0;
        for (int t : *tags)
            if (renumber[t] >= 0) (*tags)[out++] = renumber[t];
        tags->resize(out);
    }
    keep_events(ev.open_step, renumber);
    keep_events(ev.open_last, renumber);
    keep_events(ev.open_time, renumber);
    keep_events(ev.open_break_step, renumber);
    keep_events(ev.open_origin, renumber);
    keep_events(ev.open_base, renumber);
    keep_events(ev.open_best, renumber);
    keep_events(ev.open_best_m0, renumber);
    keep_events(ev.open_now, renumber);
    keep_events(ev.open_kinetic_base, renumber);
    keep_events(ev.open_kinetic_rise, renumber);
    keep_events(ev.open_broken, renumber);
    keep_events(ev.open_tensile, renumber);
    keep_events(ev.open_length, renumber);
    keep_events(ev.open_fracture, renumber);
    keep_events(ev.open_sum_point, renumber);
}

} // namespace

void start_events(World& w, const EventSpec& spec) {
    if (!spec.on) return;
    double area = 0.0;
    int rigid = 0;
    for (int i = 0; i < w.blocks.count(); ++i)
        if (!w.blocks.deformable[i]) area += w.blocks.area[i], ++rigid;
    const double size = rigid > 0 ? std::sqrt(area / rigid) : 0.0;
    Events& ev = w.events.emplace();
    ev.join_distance = spec.join_distance > 0.0 ? spec.join_distance : 2.0 * size;
    ev.window = spec.window > 0 ? spec.window : 50;
    ev.thickness = spec.thickness;
    w.contacts.marking = true;
    w.contacts.bond_change.assign(w.contacts.length.size(), 0);
    w.contacts.force_before.resize(w.contacts.length.size());
}

void record_events(World& w) {
    auto& c = w.contacts;
    // New onsets and breaks, in contact order (the marks do not depend on which
    // thread ran which contact).
    if (!c.bond_change.empty()) {
        const std::uint8_t* first = c.bond_change.data();
        const std::size_t size = c.bond_change.size();
        for (const void* at = std::memchr(first, 1, size); at;) {
            const std::size_t i = std::size_t(static_cast<const std::uint8_t*>(at) - first);
            c.bond_change[i] = 0;
            take_failure(w, int(i));
            at = i + 1 < size ? std::memchr(first + i + 1, 1, size - i - 1) : nullptr;
        }
    }
    if (w.events->open_count() == 0) return;
    follow_open_events(w);
    close_events(w);
}

double scalar_moment(const Tensor& m) {
    // m1² + m2² = (trace)² − 2 det = mxx² + myy² + 2 mxy².
    return std::sqrt(0.5 * (m[0] * m[0] + m[1] * m[1] + 2.0 * m[2] * m[2]));
}

double isotropic_ratio(const Tensor& m) {
    const double trace = m[0] + m[1];
    const double half_difference = std::sqrt(0.25 * (m[0] - m[1]) * (m[0] - m[1]) + m[2] * m[2]);
    // Deviatoric eigenvalues ±half_difference.
    const double denominator = std::abs(trace) + 2.0 * half_difference;
    return denominator > 0.0 ? 100.0 * trace / denominator : 0.0;
}

const char* failure_type(double r) { return r > 30.0 ? "tensile" : r < -30.0 ? "implosive" : "shear"; }

namespace {

SeismicEvent reported(const Events& ev, double time, long step, long first_step, Vec2 position, const Tensor& tensor,
                      const Tensor& settled, double m0, double length, int bonds, int tensile, double energy,
                      double fracture) {
    SeismicEvent s;
    s.time = time, s.step = step, s.first_step = first_step, s.position = position, s.tensor = tensor;
    s.static_tensor = settled;
    s.moment = m0, s.length = length, s.bonds = bonds, s.tensile_bonds = tensile;
    s.energy = energy, s.fracture_energy = fracture;
    s.moment_nm = m0 * (ev.thickness > 0.0 ? ev.thickness : length);
    s.magnitude = moment_magnitude(s.moment_nm);
    s.r_value = isotropic_ratio(tensor);
    s.type = failure_type(s.r_value);
    return s;
}

} // namespace

std::vector<SeismicEvent> event_catalogue(const Events& ev) {
    std::vector<SeismicEvent> out;
    for (int k = 0; k < ev.count(); ++k)
        out.push_back(reported(ev, ev.time[k], ev.step[k], ev.first_step[k], ev.position[k], ev.tensor[k],
                               ev.static_tensor[k], ev.moment[k],
                               ev.length[k], ev.bonds[k], ev.tensile_bonds[k], ev.energy[k], ev.fracture_energy[k]));
    for (int e = 0; e < ev.open_count(); ++e)
        if (ev.open_broken[e] > 0)
            out.push_back(reported(ev, ev.open_time[e], ev.open_break_step[e], ev.open_step[e],
                                   (1.0 / double(ev.open_broken[e])) * ev.open_sum_point[e], ev.open_best[e],
                                   ev.open_now[e], ev.open_best_m0[e], ev.open_length[e], ev.open_broken[e], ev.open_tensile[e],
                                   ev.open_kinetic_rise[e], ev.open_fracture[e]));
    return out;
}

GutenbergRichter gutenberg_richter(const std::vector<double>& magnitudes) {
    GutenbergRichter g;
    if (magnitudes.empty()) return g;
    // The magnitude of completeness: the most populated 0.1 bin (maximum curvature).
    std::vector<long> bins;
    const double lowest = *std::min_element(magnitudes.begin(), magnitudes.end());
    const double origin = std::floor(lowest * 10.0) / 10.0;
    for (double m : magnitudes) {
        const std::size_t k = std::size_t(std::floor((m - origin) * 10.0 + 1e-9));
        if (k >= bins.size()) bins.resize(k + 1, 0);
        ++bins[k];
    }
    const std::size_t mode = std::size_t(std::max_element(bins.begin(), bins.end()) - bins.begin());
    g.completeness = origin + 0.1 * double(mode);
    double sum = 0.0;
    for (double m : magnitudes)
        if (m >= g.completeness - 1e-12) sum += m, ++g.count;
    if (g.count < 10) return g;
    const double mean = sum / g.count;
    double spread = 0.0;
    for (double m : magnitudes)
        if (m >= g.completeness - 1e-12) spread += (m - mean) * (m - mean);
    if (!(mean > g.completeness)) return g;
    g.b = std::numbers::log10e / (mean - g.completeness);
    g.b_error = 2.30 * g.b * g.b * std::sqrt(spread / (double(g.count) * double(g.count - 1)));
    g.a = std::log10(double(g.count)) + g.b * g.completeness;
    g.fitted = true;
    return g;
}

std::string events_csv(const std::vector<SeismicEvent>& events) {
    std::string out = "time_s,step,first_step,x_m,y_m,mxx_Nm_per_m,myy_Nm_per_m,mxy_Nm_per_m,m0_Nm_per_m,m0_Nm,mw,"
                      "r_value_percent,type,bonds,tensile_bonds,shear_bonds,length_m,kinetic_energy_J_per_m,"
                      "fracture_energy_J_per_m,static_mxx,static_myy,static_mxy\n";
    char line[512];
    for (const SeismicEvent& e : events) {
        std::snprintf(line, sizeof line, "%.9g,%ld,%ld,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4f,%.2f,%s,%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                      e.time, e.step, e.first_step, e.position.x, e.position.y, e.tensor[0], e.tensor[1], e.tensor[2],
                      e.moment, e.moment_nm, e.magnitude, e.r_value, e.type.c_str(), e.bonds, e.tensile_bonds,
                      e.bonds - e.tensile_bonds, e.length, e.energy, e.fracture_energy, e.static_tensor[0],
                      e.static_tensor[1], e.static_tensor[2]);
        out += line;
    }
    return out;
}

} // namespace bbm
