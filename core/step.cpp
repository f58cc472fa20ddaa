// The stages of a step (core/step.hpp) and the driver that walks them.
#include "core/step.hpp"

#include "core/measures.hpp"
#include "core/supports/ties.hpp"

#include <algorithm>
#include <cmath>
#include <omp.h>
#include <utility>

namespace bbm {

contact::BlockView block_view(const World& w) {
    return {w.bodies.state.data(),   w.vertices.position.data(), w.blocks.first.data(),
            w.vertices.inv_edge_length.data(), w.blocks.deformable.data(), w.vertices.node.data(),
            w.nodes.velocity.data(), w.vertices.corner.data()};
}

namespace {

// --- shares -------------------------------------------------------------------

/// [first, last) of `n` items split into equal contiguous parts (items that cost
/// about the same: faces, zone items, nodes).
Range equal_share(int n, const StepContext& ctx) {
    return {int(std::int64_t(n) * ctx.thread / ctx.team), int(std::int64_t(n) * (ctx.thread + 1) / ctx.team)};
}

Range by_cost(const std::vector<double>& cost_before, const StepContext& ctx) {
    const auto [first, last] = contact::team_share(cost_before, ctx.thread, ctx.team);
    return {first, last};
}

// --- 0. placing the bodies ------------------------------------------------------

void place_rigid_block(World& w, int i) {
    const contact::BodyState& b = w.bodies.state[i];
    const Rotation rot = rotation(b.theta);
    const Vec2 c = b.centroid;
    for (std::uint32_t v = w.blocks.first[i]; v < w.blocks.first[i + 1]; ++v)
        w.vertices.position[v] = c + rot(w.vertices.local[v]);
}

void place_deformable_block(World& w, int i) {
    // The polygon follows the boundary nodes; edge lengths change.
    auto& x = w.vertices;
    const std::uint32_t v0 = w.blocks.first[i], v1 = w.blocks.first[i + 1];
    for (std::uint32_t v = v0; v < v1; ++v) x.position[v] = w.nodes.position[x.node[v]];
    for (std::uint32_t v = v0; v < v1; ++v)
        x.inv_edge_length[v] = 1.0 / norm(x.position[v + 1 == v1 ? v0 : v + 1] - x.position[v]);
}

void place_stage(World& w, const StepContext&, Range r) {
    for (int i = r.first; i < r.last; ++i) {
        if (w.blocks.deformable[i]) place_deformable_block(w, i);
        else if (!w.bodies.removed[i]) place_rigid_block(w, i);
    }
}

Range place_share(const World& w, const StepContext& ctx) { return by_cost(w.team.place_cost_before, ctx); }

// --- 1. contact detection ---------------------------------------------------------

/// One pass of the detector over the active blocks, by the whole team; then, on
/// one thread, the bookkeeping and the index if contacts changed.
void detection_pass(World& w) {
    auto& d = w.detection;
    contact::DetectionInput in{block_view(w), w.bodies.count(), w.bodies.removed.data(), d.active.data(),
                               d.tolerance, w.properties.new_contact, w.clock.dt, &d.junctions, d.corner_radius,
                               w.settings.new_contact_length == SolverSpec::NewContactLength::overlap,
                               w.settings.overlap_at_rest()};
    const auto r = contact::detect(w.contacts, d.detector, in);
#pragma omp single
    {
        for (int i = 0; i < w.bodies.count(); ++i) {
            if (!d.active[i]) continue;
            d.detected_at[i] = w.bodies.state[i].centroid, d.detected_theta[i] = w.bodies.state[i].theta;
            if (w.blocks.deformable[i])
                for (std::uint32_t v = w.blocks.first[i]; v < w.blocks.first[i + 1]; ++v)
                    d.detected_vertex[v] = w.vertices.position[v];
        }
        d.totals.created += r.created;
        d.totals.removed += r.removed;
        d.totals.transferred += r.transferred;
        d.totals.removed_tensile += r.removed_tensile;
        d.dissipated_removed += d.detector.removed_dissipated;
        d.totals.removed_shear += r.removed_shear;
        // A contact passed to another edge of a deformable block loads that edge's
        // nodes: the per-node index (and the faces of face_shear) must follow it,
        // or its force would go on to the nodes it left, and a resumed run, which
        // builds the index afresh, would part from the uninterrupted one.
        const bool moved_on_nodes = d.detector.transferred_on_nodes > 0;
        if (r.created > 0 || r.removed > 0 || moved_on_nodes) {
            // New contacts are appended; once they are more than a sixteenth of all,
            // renumber the contacts by block again (the loop's locality) — rarely
            // enough that the renumbering costs little.
            d.unsorted_contacts += r.created;
            if (16 * d.unsorted_contacts > w.contacts.size()) {
                contact::sort_contacts_by_blocks(w.contacts);
                d.unsorted_contacts = 0;
            }
            reindex_contacts(w);
            update_timestep(w);
        }
    }
}

void detection_stage(World& w, const StepContext&, Range) {
    // Every few steps: which blocks have moved a quarter of the tolerance since
    // their last pass? Only they (and their neighbours) are examined. A deformable
    // block counts as moved when any of its boundary vertices has. The scan and
    // the pass's search are shared by the team.
    if (w.clock.steps % 4 != 0) return;
    auto& d = w.detection;
    const double limit = 0.25 * d.tolerance;
    const int nb = w.bodies.count();
#pragma omp single
    d.any_active = 0;
    bool any = false;
#pragma omp for schedule(static) nowait
    for (int i = 0; i < nb; ++i) {
        bool moved = false;
        if (w.bodies.removed[i]) {
        } else if (w.blocks.deformable[i]) {
            for (std::uint32_t v = w.blocks.first[i]; v < w.blocks.first[i + 1] && !moved; ++v)
                moved = norm2(w.vertices.position[v] - d.detected_vertex[v]) >= limit * limit;
        } else {
            const auto& b = w.bodies.state[i];
            moved = norm(b.centroid - d.detected_at[i]) + std::abs(b.theta - d.detected_theta[i]) * d.radius[i] >= limit;
        }
        d.active[i] = moved;
        any = any || moved;
    }
    if (any) {
#pragma omp atomic write
        d.any_active = 1;
    }
#pragma omp barrier
    if (d.any_active) detection_pass(w);
}

// --- water in the joints ------------------------------------------------------------

void flow_stage(World& w, const StepContext&, Range) { advance_flow(*w.flow, w.contacts, w.clock.dt, w.clock.steps); }
bool has_flow(const World& w) { return w.flow.has_value(); }

// --- 2. rigid faces on deformable blocks: their mean slip ----------------------------

void face_slip_stage(World& w, const StepContext&, Range r) {
    contact::face_slip_pass(w.contacts, block_view(w), w.clock.dt, w.detection.corner_radius, r.first, r.last);
}
Range face_share(const World& w, const StepContext& ctx) { return equal_share(contact::face_count(w.contacts), ctx); }
bool has_faces(const World& w) { return contact::face_count(w.contacts) > 0; }

// --- 4. the supports: their forces and what their ties put on the rock -------------

void support_stage(World& w, const StepContext&, Range) {
    const SupportRock rock = support_rock(w);
    std::size_t k = 0;
    for_each_support(w.supports, [&](auto type, auto& state) {
        using T = typename decltype(type)::type;
        const int first = w.ties.first[k++];
        if (T::tie_count(state) > 0) T::force_pass(state, rock, w.ties.reaction.data() + first, w.ties.moment.data() + first);
    });
}
bool has_ties(const World& w) { return !w.ties.reaction.empty(); }

// --- 2, 3. contacts and zones ---------------------------------------------------------

/// A team times its shares of the contact and zone passes: balance_contact_pass()
/// moves the contacts' split toward equal times.
bool timed(const World& w, const StepContext& ctx) {
    return ctx.team > 1 && int(w.team.pass_time.size()) == ctx.team;
}

void contact_stage(World& w, const StepContext& ctx, Range r) {
    const double t0 = timed(w, ctx) ? omp_get_wtime() : 0.0;
    contact::contact_pass(w.contacts, w.properties.laws, block_view(w), w.clock.dt, w.detection.corner_radius, r.first,
                          r.last, w.settings.rayleigh_beta());
    w.normals_stale = true;
    if (timed(w, ctx)) w.team.pass_time[ctx.thread].contacts += omp_get_wtime() - t0;
}
Range contact_share(const World& w, const StepContext& ctx) {
    const auto [first, last] = contact::contact_share(w.contacts, ctx.thread, ctx.team);
    return {first, last};
}

void zone_stage(World& w, const StepContext& ctx, Range r) {
    const double t0 = timed(w, ctx) ? omp_get_wtime() : 0.0;
    fem::zone_pass(w.zones, w.nodes.position.data(), w.nodes.velocity.data(), w.clock.dt, w.bodies.removed.data(),
                   r.first, r.last, w.settings.rayleigh_beta());
    if (timed(w, ctx)) w.team.pass_time[ctx.thread].zones += omp_get_wtime() - t0;
}
Range zone_share(const World& w, const StepContext& ctx) { return equal_share(fem::zone_items(w.zones), ctx); }

// --- 4. the gather: each body's forces with its loads ----------------------------------

/// The support of the excavated rock now: relaxed linearly to the fraction kept
/// (a fictitious support pressure, the convergence–confinement method's 1 − λ),
/// or its mean and deviator each along a path (a face going by, theory.md §6.5):
/// the factors on the whole in-situ support and on its deviatoric part besides.
std::pair<double, double> relaxation_factors(const Loads& l) {
    if (l.relax_block_force.empty() && l.relax_node_force.empty()) return {0.0, 0.0};
    if (l.relax_path.empty())
        return {l.relax_left > 0 ? l.relax_keep + (1.0 - l.relax_keep) * double(l.relax_left) / double(l.relax_total + 1)
                                 : l.relax_keep,
                0.0};
    // Along the path: at t = k / (N + 1) on the k-th step of N (the linear
    // relaxation's factor is 1 − t), then at its last row.
    const auto& path = l.relax_path;
    const double t = l.relax_left > 0 ? 1.0 - double(l.relax_left) / double(l.relax_total + 1) : 1.0;
    std::size_t r = 3;
    while (r + 3 < path.size() && path[r] < t) r += 3;
    const double t0 = path[r - 3], t1 = path[r], s = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    const double k_mean = (1.0 - s) * path[r - 2] + s * path[r + 1];
    const double k_deviator = (1.0 - s) * path[r - 1] + s * path[r + 2];
    return {k_mean, k_deviator - k_mean};
}

/// The load factors of a gather, the same for every body of a step.
struct GatherFactors {
    double relax = 0.0, deviator = 0.0, pressure_scale = 1.0;
    bool pressure = false, ties = false;
    explicit GatherFactors(const World& w) {
        // (Plain members, not a structured binding: clang 14 cannot use one in the loops.)
        const std::pair<double, double> f = relaxation_factors(w.loads);
        relax = f.first, deviator = f.second;
        pressure = !w.loads.pressure_block_force.empty();
        // 1 as excavated (x 1.0 is exact: the same bits as without a scale).
        pressure_scale = w.loads.pressure_scale.empty() ? 1.0 : w.loads.pressure_scale[0];
        ties = !w.ties.reaction.empty();
    }
};

void gather_block_stage(World& w, const StepContext&, Range r) {
    // One gather per block: its contacts' forces in a fixed order, plus gravity,
    // boundary loads, relaxing and constant support pressures and the reactions
    // of its support ties. Deformable blocks gather through their nodes.
    const GatherFactors k(w);
    const Vec2 g = w.settings.gravity;
    const auto& l = w.loads;
    const auto& t = w.ties;
    for (int i = r.first; i < r.last; ++i) {
        Vec2 f{};
        double m = 0.0;
        if (!w.blocks.deformable[i]) contact::block_contact_force(w.contacts, i, f, m);
        f += l.block_force[i] + w.blocks.real_mass[i] * g;
        m += l.block_moment[i];
        if (k.relax != 0.0) f += k.relax * l.relax_block_force[i], m += k.relax * l.relax_block_moment[i];
        if (k.deviator != 0.0)
            f += k.deviator * l.deviator_block_force[i], m += k.deviator * l.deviator_block_moment[i];
        if (k.pressure) f += k.pressure_scale * l.pressure_block_force[i], m += k.pressure_scale * l.pressure_block_moment[i];
        if (k.ties)
            for (int e = t.block_first[i]; e < t.block_first[i + 1]; ++e) {
                const int tie = t.block_tie[e];
                f += t.reaction[tie], m += t.moment[tie];
            }
        w.bodies.force[i] = f;
        w.bodies.moment[i] = m;
    }
}
Range gather_block_share(const World& w, const StepContext& ctx) { return by_cost(w.team.gather_cost_before, ctx); }

void gather_node_stage(World& w, const StepContext&, Range r) {
    const GatherFactors k(w);
    const Vec2 g = w.settings.gravity;
    const auto& l = w.loads;
    const auto& t = w.ties;
    for (int n = r.first; n < r.last; ++n) {
        Vec2 f = contact::node_contact_force(w.contacts, n) + fem::node_zone_force(w.zones, n) + l.node_force[n] +
                 w.nodes.real_mass[n] * g;
        if (k.relax != 0.0) f += k.relax * l.relax_node_force[n];
        if (k.deviator != 0.0) f += k.deviator * l.deviator_node_force[n];
        if (k.pressure) f += k.pressure_scale * l.pressure_node_force[n];
        if (k.ties)
            for (int e = t.node_first[n]; e < t.node_first[n + 1]; ++e) {
                const auto [tie, weight] = t.node_tie[e];
                f += weight * t.reaction[tie];
            }
        w.nodes.force[n] = f;
    }
}
Range node_share(const World& w, const StepContext& ctx) { return equal_share(w.nodes.count(), ctx); }

/// The viscous boundaries' dashpots and incident waves (core/viscous.hpp): each
/// node's force gains F_in − C v̄, v̄ the mean of its velocity before and after
/// this step's central difference, solved for with the gathered force; the
/// energy each boundary absorbs and supplies is added in entry order.
void viscous_faces(World& w);
void viscous_stage(World& w, const StepContext&, Range) {
    auto& b = w.viscous;
    const double dt = w.clock.dt, time = w.clock.time;
    for (int e = 0; e < b.count();) {
        const int n = b.node[e];
        int end = e;
        std::array<double, 3> c{};
        Vec2 input{};
        for (; end < b.count() && b.node[end] == n; ++end) {
            for (int k = 0; k < 3; ++k) c[k] += b.damping[end][k];
            input += incident_velocity(b.waves[b.boundary[end]], time) * b.input[end];
        }
        if (w.bodies.removed[w.nodes.block[n]]) {
            e = end;
            continue;
        }
        // A held component takes no dashpot (its velocity is prescribed).
        const std::uint8_t held = w.loads.node_fixed[n];
        if (held & 1) c[0] = c[1] = input.x = 0.0;
        if (held & 2) c[2] = c[1] = input.y = 0.0;
        const Vec2 v = w.nodes.velocity[n], f = w.nodes.force[n] + input;
        const double a = w.nodes.mass[n] / dt;
        // (a + C/2) v⁺ = (a − C/2) v + f.
        const double m00 = a + 0.5 * c[0], m01 = 0.5 * c[1], m11 = a + 0.5 * c[2];
        const Vec2 rhs{(a - 0.5 * c[0]) * v.x - 0.5 * c[1] * v.y + f.x, -0.5 * c[1] * v.x + (a - 0.5 * c[2]) * v.y + f.y};
        const double det = m00 * m11 - m01 * m01;
        const Vec2 after{(m11 * rhs.x - m01 * rhs.y) / det, (m00 * rhs.y - m01 * rhs.x) / det};
        const Vec2 mean = 0.5 * (v + after);
        w.nodes.force[n] = f - Vec2{c[0] * mean.x + c[1] * mean.y, c[1] * mean.x + c[2] * mean.y};
        // The energy of the free components only (a held one does no work here).
        const Vec2 moving{held & 1 ? 0.0 : mean.x, held & 2 ? 0.0 : mean.y};
        for (; e < end; ++e) {
            const auto& d = b.damping[e];
            const Vec2 fd{d[0] * moving.x + d[1] * moving.y, d[1] * moving.x + d[2] * moving.y};
            const std::size_t k = std::size_t(b.boundary[e]);
            b.absorbed[k] += dot(fd, moving) * dt;
            b.supplied[k] += incident_velocity(b.waves[k], time) * dot(b.input[e], moving) * dt;
        }
    }
    viscous_faces(w);
}

namespace {

/// x solving the symmetric 3 × 3 system a x = b (a positive definite: M/Δt + C₃/2).
std::array<double, 3> solve3(const std::array<double, 9>& a, const std::array<double, 3>& b) {
    const double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8], c02 = a[3] * a[7] - a[4] * a[6];
    const double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
    const double c11 = a[0] * a[8] - a[2] * a[6], c12 = a[2] * a[3] - a[0] * a[5], c22 = a[0] * a[4] - a[1] * a[3];
    // Symmetric: the adjugate's (i, j) is its (j, i).
    return {(c00 * b[0] + c01 * b[1] + c02 * b[2]) / det, (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det,
            (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det};
}

/// The point's velocity on body u = (v, ω) at offset r: v + ω r⊥.
Vec2 point_velocity(const std::array<double, 3>& u, Vec2 r) { return {u[0] - u[2] * r.y, u[1] + u[2] * r.x}; }

} // namespace

/// One rigid body's face dashpots, entries [first, end): C₃ = Σ Jᵀ C J and the
/// incident waves' force and moment, at the points turned by the body's angle.
struct BodyDashpots {
    std::array<double, 9> c3{};
    std::array<double, 3> input{};
    int end = 0;
};
Vec2 turned(Vec2 r, double theta) {
    const double c = std::cos(theta), s = std::sin(theta);
    return {c * r.x - s * r.y, s * r.x + c * r.y};
}
BodyDashpots body_dashpots(const ViscousBoundaries& b, int first, double theta, double time) {
    BodyDashpots out;
    const int body = b.face_body[first];
    for (out.end = first; out.end < b.face_count() && b.face_body[out.end] == body; ++out.end) {
        const Vec2 r = turned(b.face_offset[out.end], theta);
        const auto& c = b.face_damping[out.end];
        // J = [1 0 −r_y; 0 1 r_x].
        const double j0[3] = {1.0, 0.0, -r.y}, j1[3] = {0.0, 1.0, r.x};
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q)
                out.c3[3 * p + q] += j0[p] * (c[0] * j0[q] + c[1] * j1[q]) + j1[p] * (c[1] * j0[q] + c[2] * j1[q]);
        const Vec2 f = incident_velocity(b.waves[b.face_boundary[out.end]], time) * b.face_input[out.end];
        out.input[0] += f.x, out.input[1] += f.y, out.input[2] += cross(r, f);
    }
    return out;
}

/// The rigid faces' dashpots (core/viscous.hpp): per body, its three velocities
/// after the step solved for with its points' C₃, the force and moment of the
/// dashpots at their mean added to the gathered ones, and each boundary's energy.
void viscous_faces(World& w) {
    auto& b = w.viscous;
    const double dt = w.clock.dt, time = w.clock.time;
    for (int e = 0; e < b.face_count();) {
        const int i = b.face_body[e];
        const contact::BodyState& body = w.bodies.state[i];
        BodyDashpots d = body_dashpots(b, e, body.theta, time);
        if (w.bodies.removed[i]) {
            e = d.end;
            continue;
        }
        // A held velocity takes no dashpot (it is prescribed).
        const std::uint8_t held = w.loads.block_fixed[i];
        for (int p = 0; p < 3; ++p)
            if (held & (1 << p)) {
                d.input[p] = 0.0;
                for (int q = 0; q < 3; ++q) d.c3[3 * p + q] = d.c3[3 * q + p] = 0.0;
            }
        const std::array<double, 3> u{body.velocity.x, body.velocity.y, body.omega};
        const std::array<double, 3> f{w.bodies.force[i].x + d.input[0], w.bodies.force[i].y + d.input[1],
                                      w.bodies.moment[i] + d.input[2]};
        const double m[3] = {w.bodies.mass[i] / dt, w.bodies.mass[i] / dt, w.bodies.inertia[i] / dt};
        // (M/Δt + C₃/2) u⁺ = (M/Δt − C₃/2) u + f.
        std::array<double, 9> a{};
        std::array<double, 3> rhs{};
        for (int p = 0; p < 3; ++p) {
            rhs[p] = m[p] * u[p] + f[p];
            for (int q = 0; q < 3; ++q) {
                a[3 * p + q] = (p == q ? m[p] : 0.0) + 0.5 * d.c3[3 * p + q];
                rhs[p] -= 0.5 * d.c3[3 * p + q] * u[q];
            }
        }
        const auto after = solve3(a, rhs);
        std::array<double, 3> mean{}, g = f;
        for (int p = 0; p < 3; ++p) mean[p] = held & (1 << p) ? 0.0 : 0.5 * (u[p] + after[p]);
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) g[p] -= d.c3[3 * p + q] * mean[q];
        w.bodies.force[i] = {g[0], g[1]}, w.bodies.moment[i] = g[2];
        for (; e < d.end; ++e) {
            const Vec2 v = point_velocity(mean, turned(b.face_offset[e], body.theta));
            const auto& c = b.face_damping[e];
            const Vec2 fd{c[0] * v.x + c[1] * v.y, c[1] * v.x + c[2] * v.y};
            const std::size_t k = std::size_t(b.face_boundary[e]);
            b.absorbed[k] += dot(fd, v) * dt;
            b.supplied[k] += incident_velocity(b.waves[k], time) * dot(b.face_input[e], v) * dt;
        }
    }
}

bool has_viscous(const World& w) { return w.viscous.count() > 0 || w.viscous.face_count() > 0; }

/// A creep step of stress corrosion, armed by a creep stage at equilibrium
/// (core/creep.hpp): the bonds' sections and lengths before the contact pass.
void creep_stage(World& w, const StepContext&, Range) { take_creep_step(w); }
bool creep_step_due(const World& w) { return w.creep && w.creep->due; }

/// Seismic events (core/events.hpp): the bonds the contact pass saw start to fail
/// or break, joined into events; the open events' moment tensors.
void events_stage(World& w, const StepContext&, Range) { record_events(w); }
bool has_events(const World& w) { return w.events.has_value(); }

// --- 5. damping and integration ----------------------------------------------------------

/// Local damping against the velocity, branch-free (the sign of v is as good as
/// random to the branch predictor): sign(v) is 0 at rest.
inline double damped(double f, double v, double alpha) { return f - alpha * std::abs(f) * double((v > 0.0) - (v < 0.0)); }

/// Translation of one body (rigid block or node): damped central difference with
/// its prescribed components held; returns the work of its loads and of the
/// supports on the prescribed components (reaction −F) over the step, and raises
/// `unbalanced` to its largest free force component.
/// Mass-proportional (Rayleigh) damping −a m v, taken implicitly over the step:
/// v⁺ = ((1 − a Δt/2) v + F Δt/m) / (1 + a Δt/2), `keep` = 1 − a Δt/2 and
/// `scale` = 1 / (1 + a Δt/2) (both 1 without it: the same bits).
struct MassDamping {
    double keep = 1.0, scale = 1.0, mass_part = 0.0; ///< mass_part: a
    MassDamping(double a, double dt) : keep(1.0 - 0.5 * a * dt), scale(1.0 / (1.0 + 0.5 * a * dt)), mass_part(a) {}
    double operator()(double v, double dv) const { return keep == 1.0 ? v + dv : (keep * v + dv) * scale; }
};

template <bool Account>
[[gnu::always_inline]] inline double translate(std::uint8_t fx, Vec2& v, Vec2 f, Vec2 fixed_v, double mass, Vec2 load, double alpha, double dt,
                        const MassDamping& md, double& unbalanced, double& taken, double& kinetic) {
    if (!(fx & 1)) unbalanced = std::max(unbalanced, std::abs(f.x));
    if (!(fx & 2)) unbalanced = std::max(unbalanced, std::abs(f.y));
    const Vec2 before = v;
    if constexpr (Account) {
        v.x = (fx & 1) ? fixed_v.x : md(v.x, damped(f.x, v.x, alpha) / mass * dt);
        v.y = (fx & 2) ? fixed_v.y : md(v.y, damped(f.y, v.y, alpha) / mass * dt);
    } else { // no Rayleigh damping without the account (a dynamic run keeps it)
        v.x = (fx & 1) ? fixed_v.x : v.x + damped(f.x, v.x, alpha) / mass * dt;
        v.y = (fx & 2) ? fixed_v.y : v.y + damped(f.y, v.y, alpha) / mass * dt;
    }
    // The damping's work over the step at the mean velocity v̄ on the free
    // components: local damping's α|F| sign(v⁻) and Rayleigh's a m v̄.
    if constexpr (Account) {
        const Vec2 mean = 0.5 * (v + before);
        auto damping_force = [&](double force, double v0, double vm) {
            return alpha * std::abs(force) * double((v0 > 0.0) - (v0 < 0.0)) + md.mass_part * mass * vm;
        };
        if (!(fx & 1)) taken += damping_force(f.x, before.x, mean.x) * mean.x * dt;
        if (!(fx & 2)) taken += damping_force(f.y, before.y, mean.y) * mean.y * dt;
        kinetic += 0.5 * mass * dot(before, v);
    }
    double work = dot(load, v) * dt;
    if (fx & 1) work -= f.x * v.x * dt;
    if (fx & 2) work -= f.y * v.y * dt;
    return work;
}

template <bool Account>
[[gnu::always_inline]] inline double integrate_block(World& w, int i, const MassDamping& md, double& unbalanced,
                                                   double& taken, double& kinetic) {
    if (w.bodies.removed[i] || w.blocks.deformable[i]) return 0.0;
    const double alpha = w.settings.damping, dt = w.clock.dt;
    const auto& l = w.loads;
    const std::uint8_t fx = l.block_fixed[i];
    contact::BodyState& b = w.bodies.state[i];
    double work = translate<Account>(fx, b.velocity, w.bodies.force[i], l.block_velocity[i], w.bodies.mass[i],
                            l.block_force[i] + w.blocks.real_mass[i] * w.settings.gravity, alpha, dt, md, unbalanced,
                            taken, kinetic);
    const double m = w.bodies.moment[i], omega = b.omega;
    if constexpr (Account)
        b.omega = (fx & 4) ? l.block_omega[i] : md(b.omega, damped(m, b.omega, alpha) / w.bodies.inertia[i] * dt);
    else
        b.omega = (fx & 4) ? l.block_omega[i] : b.omega + damped(m, b.omega, alpha) / w.bodies.inertia[i] * dt;
    if constexpr (Account) {
        if (!(fx & 4)) {
            const double mean = 0.5 * (b.omega + omega);
            taken += (alpha * std::abs(m) * double((omega > 0.0) - (omega < 0.0)) +
                      md.mass_part * w.bodies.inertia[i] * mean) * mean * dt;
        }
        kinetic += 0.5 * w.bodies.inertia[i] * omega * b.omega;
    }
    work += (l.block_moment[i] - ((fx & 4) ? m : 0.0)) * b.omega * dt;
    b.centroid += dt * b.velocity;
    b.theta += dt * b.omega;
    return work;
}

template <bool Account>
[[gnu::always_inline]] inline double integrate_node(World& w, int i, const MassDamping& md, double& unbalanced,
                                                  double& taken, double& kinetic) {
    if (w.bodies.removed[w.nodes.block[i]]) return 0.0;
    const auto& l = w.loads;
    Vec2& v = w.nodes.velocity[i];
    const double work = translate<Account>(l.node_fixed[i], v, w.nodes.force[i], l.node_velocity[i], w.nodes.mass[i],
                                  l.node_force[i] + w.nodes.real_mass[i] * w.settings.gravity, w.settings.damping,
                                  w.clock.dt, md, unbalanced, taken, kinetic);
    w.nodes.position[i] += w.clock.dt * v;
    return work;
}

template <bool Account>
void integrate_chunks(World& w, Range r) {
    // The work and the largest unbalanced force per fixed chunk of bodies, summed
    // over the chunks in order by the next row: the same bits on any thread count.
    constexpr int chunk_size = Team::sum_chunk;
    const int nb = w.bodies.count(), nn = w.nodes.count(), block_chunks = Team::chunks_of(nb);
    const MassDamping md(w.settings.rayleigh_alpha(), w.clock.dt);
    for (int chunk = r.first; chunk < r.last; ++chunk) {
        double work = 0.0, unbalanced = 0.0, taken = 0.0, kinetic = 0.0;
        if (chunk < block_chunks) {
            for (int i = chunk * chunk_size; i < std::min(nb, (chunk + 1) * chunk_size); ++i)
                work += integrate_block<Account>(w, i, md, unbalanced, taken, kinetic);
        } else {
            const int c = chunk - block_chunks;
            for (int i = c * chunk_size; i < std::min(nn, (c + 1) * chunk_size); ++i)
                work += integrate_node<Account>(w, i, md, unbalanced, taken, kinetic);
        }
        w.team.chunk_sums[chunk] = {work, unbalanced, taken, kinetic};
    }
}

/// With the energy account on (core/measures.hpp), integration also sums the
/// damping's work and the step's kinetic energy: a separate instance, as the
/// quasi-static runs that do not ask for it would pay 40 µs a step in the
/// trigon tunnel (its integration's time doubled).
void integrate_stage(World& w, const StepContext&, Range r) {
    if (w.settings.energy_account) integrate_chunks<true>(w, r);
    else integrate_chunks<false>(w, r);
}
Range chunk_share(const World& w, const StepContext& ctx) { return by_cost(w.team.chunk_cost_before, ctx); }

void peak_stage(World& w, const StepContext&, Range r) { record_peak_velocities(w, r.first, r.last); }
bool has_peaks(const World& w) { return w.peak.has_value(); }

// --- 6. the convergence measure -------------------------------------------------------------

} // namespace

void sum_boundary_forces(World& w) {
    const Vec2 g = w.settings.gravity;
    auto& b = w.boundaries;
    for (std::size_t k = 0; k < b.names.size(); ++k) {
        Vec2 sum{};
        for (int e = b.block_first[k]; e < b.block_first[k + 1]; ++e) {
            const int i = b.block_list[e];
            sum += w.bodies.force[i] - w.loads.block_force[i] - w.blocks.real_mass[i] * g;
        }
        for (int e = b.node_first[k]; e < b.node_first[k + 1]; ++e) {
            const int i = b.node_list[e];
            sum += w.nodes.force[i] - w.loads.node_force[i] - w.nodes.real_mass[i] * g;
        }
        b.force[k] = sum;
    }
}

namespace {

void ratio_stage(World& w, const StepContext&, Range) {
    sum_boundary_forces(w);
    double max_unbalanced = 0.0;
    const int chunks = Team::chunks_of(w.bodies.count()) + Team::chunks_of(w.nodes.count());
    w.clock.kinetic = 0.0;
    for (int chunk = 0; chunk < chunks; ++chunk) {
        w.clock.work += w.team.chunk_sums[chunk].work;
        w.clock.damped += w.team.chunk_sums[chunk].damped;
        w.clock.kinetic += w.team.chunk_sums[chunk].kinetic;
        max_unbalanced = std::max(max_unbalanced, w.team.chunk_sums[chunk].unbalanced);
    }
    // Rayleigh's stiffness part, in the contact and zone passes' partial sums.
    if (w.settings.rayleigh_beta() > 0.0) {
        for (double d : w.contacts.partial_damped) w.clock.damped += d;
        for (double d : w.zones.partial_damped) w.clock.damped += d;
    }
    const SupportMotion motion{w.clock.dt, w.settings.damping, w.settings.gravity};
    for_each_support(w.supports, [&](auto type, auto& state) {
        using T = typename decltype(type)::type;
        if (T::tie_count(state) > 0) max_unbalanced = std::max(max_unbalanced, T::integrate(state, motion, w.clock.work));
    });
    const double scale = force_scale(w);
    w.clock.ratio = scale > 0.0 ? max_unbalanced / scale : 0.0;
}

// --- bookkeeping --------------------------------------------------------------------------

void release_relaxation(Loads& l) {
    const std::size_t rows = l.relax_path.size();
    const bool kept = l.relax_keep != 0.0 || (rows > 0 && (l.relax_path[rows - 2] != 0.0 || l.relax_path[rows - 1] != 0.0));
    if (l.relax_left > 0 && --l.relax_left == 0 && !kept) {
        l.relax_block_force.clear();
        l.relax_block_moment.clear();
        l.relax_node_force.clear();
        l.relax_path.clear();
        l.deviator_block_force.clear();
        l.deviator_block_moment.clear();
        l.deviator_node_force.clear();
    }
}

void balance_contact_pass(World& w) {
    // Thread t ran the share s_t of the contacts' estimated cost in C_t seconds
    // (ρ_t = C_t / s_t per unit share) and its equal part of the zones in Z_t.
    // Equal times ρ_t s'_t + Z_t = K with Σ s'_t = 1 give
    //   s'_t = (K − Z_t) / ρ_t,  K = (1 + Σ Z_t / ρ_t) / Σ 1 / ρ_t;
    // the split moves half way there (the rates are local and the clock noisy).
    // The arrays are sized when the world is built: a step allocates nothing.
    const int team = w.settings.threads;
    auto& split = w.contacts.team_split;
    auto& pass_time = w.team.pass_time;
    if (team < 2 || int(pass_time.size()) != team || int(split.size()) != team + 1) return;
    double* rate = w.team.balance_scratch.data();
    double* target = rate + team;
    double inverse_rates = 0.0, zone_terms = 0.0;
    bool measured = true;
    for (int t = 0; t < team; ++t) {
        const double share = split[t + 1] - split[t];
        measured = measured && pass_time[t].contacts > 0.0 && share > 0.0;
        rate[t] = pass_time[t].contacts / std::max(share, 1e-6);
        if (rate[t] <= 0.0) continue;
        inverse_rates += 1.0 / rate[t];
        zone_terms += pass_time[t].zones / rate[t];
    }
    if (measured) {
        const double level = (1.0 + zone_terms) / inverse_rates;
        double total = 0.0;
        for (int t = 0; t < team; ++t) total += target[t] = std::max(0.02, (level - pass_time[t].zones) / rate[t]);
        double at = 0.0;
        for (int t = 1; t < team; ++t) {
            at += target[t - 1] / total;
            split[t] = 0.5 * (split[t] + at);
        }
    }
    std::fill(pass_time.begin(), pass_time.end(), Team::PassTime{});
}

void bookkeeping_stage(World& w, const StepContext&, Range) {
    release_relaxation(w.loads);
    w.clock.time += w.clock.dt;
    ++w.clock.steps;
    if (w.clock.steps % Team::balance_every == 0) balance_contact_pass(w);
}

} // namespace

// The table. SPEC §5: 1 detection, 2 contact forces, 3 zone stresses, 4 loads
// and the sums per body, 5 damping and integration, 6 the convergence measure.
namespace {
const Stage stage_table[] = {
    {"vertices", "—", "world vertices of every body from its position", place_stage, Share::team, place_share, true},
    {"detection", "1", "new contacts, those that left their edges moved on or dropped, when due", detection_stage,
     Share::team},
    {"flow", "—", "water in the joints: apertures, pressures, each contact's fluid pressure (core/joint_flow.hpp)",
     flow_stage, Share::one_thread, nullptr, false, false, has_flow},
    {"face slip", "2", "the mean slip of rigid faces on the far field (face_shear)", face_slip_stage, Share::team,
     face_share, true, true, has_faces},
    {"stress corrosion", "—", "a creep step: the corroding bonds' sections lost over creep time, when a creep stage "
     "found equilibrium (core/creep.hpp)", creep_stage, Share::one_thread, nullptr, false, false, creep_step_due},
    {"supports", "4", "each support type's force pass and its ties' reactions", support_stage,
     Share::one_thread_nowait, nullptr, false, true, has_ties},
    {"contacts", "2", "the joint laws, one dispatch per batch of contacts sharing a law", contact_stage, Share::team,
     contact_share, false, true},
    {"zones", "3", "the constant-strain triangles' stresses and nodal forces", zone_stage, Share::team, zone_share,
     true, true},
    {"seismic events", "—", "bonds that started to fail or broke joined into events, their moment tensors "
     "(core/events.hpp)", events_stage, Share::one_thread, nullptr, false, false, has_events},
    {"gather blocks", "4", "each block's force and moment over its contacts, ties and loads, in a fixed order",
     gather_block_stage, Share::team, gather_block_share, false, true},
    {"gather nodes", "4", "each FE node's force over its zones, contacts and ties, in a fixed order",
     gather_node_stage, Share::team, node_share, true, true},
    {"viscous boundaries", "4", "the dashpots of the absorbing edges and the incident waves, on their nodes' and "
     "rigid faces' forces (core/viscous.hpp)", viscous_stage, Share::one_thread, nullptr, false, false, has_viscous},
    {"integrate", "5", "damping, central differences, prescribed velocities", integrate_stage, Share::team,
     chunk_share, true},
    {"peak velocities", "—", "each body's largest speed, over the run and over the stage: the dynamic mode's PPV "
     "(core/ejecta.hpp)", peak_stage, Share::team, chunk_share, false, false, has_peaks},
    {"unbalanced", "6", "the unbalanced-force ratio, the convergence measure", ratio_stage, Share::one_thread},
    {"bookkeeping", "—", "the relaxation's release, time, the contact pass's thread balance", bookkeeping_stage,
     Share::one_thread},
};
} // namespace

const std::span<const Stage> step_stages{stage_table};

std::string step_stages_markdown() {
    std::string md = "| stage | SPEC §5 | threads | what it does |\n|---|---|---|---|\n";
    for (const Stage& s : step_stages) {
        const char* share = s.share == Share::team ? "team" : "one";
        md += "| " + std::string(s.name) + " | " + std::string(s.spec) + " | " + share + " | " + std::string(s.does) +
              (s.active ? " (only where the model has it)" : "") + " |\n";
    }
    return md;
}

namespace {

/// One row by the calling thread of the team (or of a team of one).
void run_row(const Stage& s, World& w, const StepContext& ctx, std::exception_ptr& error) {
    switch (s.share) {
    case Share::team: s.run(w, ctx, s.range ? s.range(w, ctx) : Range{}); break;
    case Share::one_thread:
#pragma omp single
        {
            // An exception may not leave the parallel region (it would end the
            // program): kept, and thrown again once the region is over.
            try {
                s.run(w, ctx, {});
            } catch (...) {
                error = std::current_exception();
            }
        }
        break;
    case Share::one_thread_nowait:
#pragma omp single nowait
        {
            try {
                s.run(w, ctx, {});
            } catch (...) {
                error = std::current_exception();
            }
        }
        break;
    }
    if (s.barrier) {
#pragma omp barrier
    }
}

} // namespace

void run_step(World& w, StepProfile* profile) {
    // One parallel region per step: each row a share of the team's work, or a
    // serial part, with the barriers between them that the data flow needs. One
    // thread runs the same code serially.
    const bool timing = profile && profile->enabled;
    std::exception_ptr error;
#pragma omp parallel num_threads(w.settings.threads) if (w.settings.threads > 1)
    {
        const StepContext ctx{omp_get_thread_num(), omp_get_num_threads()};
        const bool clock = timing && ctx.thread == 0;
        if (clock) profile->last = omp_get_wtime();
        for (std::size_t k = 0; k < step_stages.size(); ++k) {
            const Stage& s = step_stages[k];
            if (s.active && !s.active(w)) continue;
            run_row(s, w, ctx, error);
            if (clock) {
                const double now = omp_get_wtime();
                profile->seconds[k] += now - profile->last;
                profile->last = now;
            }
        }
        if (clock) ++profile->steps;
    }
    if (error) std::rethrow_exception(error);
}

void evaluate_forces(World& w) {
    const StepContext ctx;
    std::exception_ptr error;
    for (const Stage& s : step_stages)
        if (s.force && (!s.active || s.active(w))) run_row(s, w, ctx, error);
    if (error) std::rethrow_exception(error);
}

void place_bodies(World& w) {
    const StepContext ctx;
    place_stage(w, ctx, {0, w.bodies.count()});
}

namespace {

/// out[i] = the cost of items 0 … i−1, out[n] the total: the prefix a team is
/// shared by (contact::team_share). Sized once; reused without allocating.
template <class Cost>
void fill_cost_before(std::vector<double>& out, int n, Cost cost) {
    out.resize(std::size_t(n) + 1);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        out[i] = sum;
        sum += cost(i);
    }
    out[n] = sum;
}

} // namespace

void reindex_contacts(World& w) {
    const int nb = w.bodies.count(), nn = w.nodes.count();
    const auto& deformable = w.blocks.deformable;
    contact::rebuild_contact_index(w.contacts, int(w.properties.laws.size()), nb, deformable.data(), nn,
                                   w.vertices.node.data());
    // The gather's cost per block: its contacts and its own terms (about two).
    const auto& c = w.contacts;
    fill_cost_before(w.team.gather_cost_before, nb, [&](int i) {
        return 2.0 + (deformable[i] ? 0.0 : double(c.block_first[i + 1] - c.block_first[i]));
    });
    // Placing a block and integrating it: excavated ones (often a contiguous run:
    // the blocks are numbered along a curve) next to nothing, a deformable block's
    // placement its boundary vertices, its integration its nodes' (the node chunks).
    const auto& removed = w.bodies.removed;
    auto live = [&](int i) { return removed[i] ? 0.05 : 1.0; };
    fill_cost_before(w.team.place_cost_before, nb, [&](int i) {
        return deformable[i] ? 0.5 * double(w.blocks.first[i + 1] - w.blocks.first[i]) : live(i);
    });
    const int block_chunks = Team::chunks_of(nb);
    fill_cost_before(w.team.chunk_cost_before, block_chunks + Team::chunks_of(nn), [&](int chunk) {
        double cost = 0.0;
        if (chunk < block_chunks) {
            for (int i = chunk * Team::sum_chunk; i < std::min(nb, (chunk + 1) * Team::sum_chunk); ++i)
                cost += deformable[i] ? 0.05 : live(i);
        } else {
            const int k = chunk - block_chunks;
            for (int n = k * Team::sum_chunk; n < std::min(nn, (k + 1) * Team::sum_chunk); ++n) cost += live(w.nodes.block[n]);
        }
        return cost;
    });
    contact::assign_face_groups(w.contacts, block_view(w), w.properties.face_shear);
}

} // namespace bbm
