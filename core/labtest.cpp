#include "core/labtest.hpp"

#include "core/solver.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <tuple>

namespace bbm {

LabTestOptions LabTestOptions::paper_ucs() {
    LabTestOptions o;
    o.joint.name = "bond";
    o.joint.law = JointPropertySpec::Law::softening;
    o.joint.kn = 96.6e9;
    o.joint.ks = 40.3e9;
    o.joint.tensile = 3e6;
    o.joint.cohesion = 9.5e6;
    o.joint.friction = 25.0;
    o.joint.tension_softening = {{1.7, 0.5}, {4.0, 0.0}};
    o.joint.shear_softening = {{1.3, 0.5}, {2.1, 0.0}};
    return o;
}

bool uses_platen_blocks(const LabTestOptions& o) {
    return o.platen_friction >= 0.0 && (o.kind == LabTestOptions::Kind::ucs || o.kind == LabTestOptions::Kind::biaxial);
}

meshing::ModelGeometrySpec labtest_geometry(const LabTestOptions& o) {
    meshing::ModelGeometrySpec g;
    meshing::RegionSpec r;
    r.name = "specimen";
    if (o.kind == LabTestOptions::Kind::brazilian) {
        r.outline.kind = meshing::OutlineSpec::Kind::circle;
        r.outline.center = {0.5 * o.width, 0.5 * o.width};
        r.outline.radius = 0.5 * o.width;
        r.outline.max_segment = 0.25 * o.size;
    } else {
        r.outline.min = {0.0, 0.0};
        r.outline.max = {o.width, o.height};
    }
    r.pattern.kind = o.pattern;
    r.pattern.size = o.size;
    r.pattern.size_measure = o.size_measure;
    r.pattern.lloyd_iterations = o.lloyd;
    r.pattern.seed = o.seed;
    if (o.deformable_fraction > 0.0) {
        r.mesh.enabled = true;
        r.mesh.size = o.mesh_size > 0.0 ? o.mesh_size : 0.5 * o.size;
    }
    g.regions.push_back(r);
    if (uses_platen_blocks(o)) {
        // One block each, a block size thick, sharing the specimen's faces.
        for (const auto& [name, y0, y1] : {std::tuple{"platen_bottom", -o.size, 0.0},
                                           std::tuple{"platen_top", o.height, o.height + o.size}}) {
            meshing::RegionSpec p;
            p.name = name;
            p.outline.min = {0.0, y0};
            p.outline.max = {o.width, y1};
            p.pattern.kind = meshing::PatternSpec::Kind::single;
            g.regions.push_back(p);
        }
    }
    return g;
}

namespace {
double specimen_height(const LabTestOptions& o) {
    return o.kind == LabTestOptions::Kind::brazilian ? o.width : o.height;
}
} // namespace

AnalysisSpec labtest_analysis(const LabTestOptions& o) {
    AnalysisSpec an;
    MaterialSpec rock;
    rock.name = "rock";
    rock.density = o.density;
    if (o.deformable_fraction > 0.0) {
        rock.young = o.young;
        rock.poisson = o.poisson;
        rock.deformable_fraction = o.deformable_fraction;
    }
    an.materials.push_back(rock);
    an.joint_properties.push_back(o.joint);
    const bool platen_blocks = uses_platen_blocks(o);
    if (platen_blocks) {
        JointPropertySpec platen;
        platen.name = "platen";
        platen.law = JointPropertySpec::Law::coulomb;
        platen.kn = o.joint.kn;
        platen.ks = o.joint.ks;
        platen.friction = o.platen_friction;
        an.joint_properties.push_back(platen);
        an.joint_assignments.push_back({platen.name, {}, {}});
    }
    // The bond between specimen blocks (a later rule wins over the platen one).
    an.joint_assignments.push_back({o.joint.name, {}, {"specimen"}});
    // Contacts that form during the test (fragments touching anew) are the rock's
    // broken joints: unbonded, with the bond's stiffness and residual friction
    // (not the solver's built-in 30°); with deformable blocks, as stiff as the
    // bonds after the split (SPEC §6).
    const double joint_share = o.deformable_fraction > 0.0 ? 1.0 - o.deformable_fraction : 1.0;
    JointPropertySpec unbonded;
    unbonded.name = "unbonded";
    unbonded.law = JointPropertySpec::Law::coulomb;
    unbonded.kn = o.joint.kn / joint_share;
    unbonded.ks = o.joint.ks / joint_share;
    unbonded.friction = o.joint.residual_friction >= 0 ? o.joint.residual_friction : o.joint.friction;
    an.joint_properties.push_back(unbonded);
    an.solver.new_contact_property = unbonded.name;
    const double h = specimen_height(o), band = 0.5 * o.size, v = o.strain_per_step * h;
    const double big = 10.0 * (o.width + h);
    // Rectangular specimens: every block with an edge on the loaded face moves with
    // the platen, so the face is loaded evenly. (Selecting a row by centroid left
    // face blocks outside the row, unloaded, between loaded ones: the uneven load
    // started cracks at the platens and made the peak scatter by ±17% between
    // realizations; loading the whole face brings that to ±3%.) A disc has no
    // face: its loading strips are the blocks within half a block size of its poles.
    const bool disc = o.kind == LabTestOptions::Kind::brazilian;
    const double face = 1e-9 * h;
    BoundarySpec bottom;
    bottom.name = "bottom";
    bottom.select.box = Box2{{-big, -big}, {big, disc ? band : face}};
    bottom.select.touching = !disc;
    bottom.vy = 0.0;
    bottom.omega = 0.0;
    BoundarySpec top = bottom;
    top.name = "top";
    top.select.box = Box2{{-big, disc ? h - band : h - face}, {big, big}};
    top.vy = o.kind == LabTestOptions::Kind::tension ? v : -v;
    if (platen_blocks) {
        bottom.select = {{"platen_bottom"}, std::nullopt, false};
        top.select = {{"platen_top"}, std::nullopt, false};
        bottom.vx = top.vx = 0.0;
        an.boundaries = {bottom, top};
    } else if (o.rough_platens) {
        bottom.vx = top.vx = 0.0;
        an.boundaries = {bottom, top};
    } else {
        BoundarySpec anchor = bottom;
        anchor.name = "anchor";
        anchor.select.box->lo.x = 0.5 * o.width - band;
        anchor.select.box->hi.x = 0.5 * o.width + band;
        anchor.vy.reset();
        anchor.omega.reset();
        anchor.vx = 0.0;
        an.boundaries = {bottom, top, anchor};
    }
    if (o.kind == LabTestOptions::Kind::biaxial && o.confinement > 0) {
        BoundarySpec left;
        left.name = "left";
        left.kind = BoundarySpec::Kind::stress;
        left.select.box = Box2{{-big, band}, {1e-6 * o.width, h - band}};
        left.stress.sxx = -o.confinement;
        BoundarySpec right = left;
        right.name = "right";
        right.select.box = Box2{{o.width * (1 - 1e-6), band}, {big, h - band}};
        an.boundaries.push_back(left);
        an.boundaries.push_back(right);
    }
    an.solver.mode = SolverSpec::Mode::quasi_static;
    an.solver.damping = 0.8;
    an.solver.threads = o.threads;
    return an;
}

namespace {
/// Applies the biaxial confinement gradually with the platens held still, then lets
/// the specimen settle; returns the step at which axial loading starts.
long confine(Solver& s) {
    auto& b = s.blocks();
    auto& n = s.nodes();
    const auto block_load = b.applied;
    const auto block_moment = b.applied_moment;
    const auto node_load = n.applied;
    // The moving platen: what has a prescribed, non-zero vertical velocity.
    std::vector<int> moving_blocks, moving_nodes;
    std::vector<double> vy_blocks, vy_nodes;
    for (int i = 0; i < b.count(); ++i)
        if ((b.fixed[i] & 2) && b.fixed_velocity[i].y != 0.0)
            moving_blocks.push_back(i), vy_blocks.push_back(b.fixed_velocity[i].y), b.fixed_velocity[i].y = 0.0;
    for (int k = 0; k < n.count(); ++k)
        if ((n.fixed[k] & 2) && n.fixed_velocity[k].y != 0.0)
            moving_nodes.push_back(k), vy_nodes.push_back(n.fixed_velocity[k].y), n.fixed_velocity[k].y = 0.0;
    auto scale = [&](double f) {
        for (int i = 0; i < b.count(); ++i) b.applied[i] = f * block_load[i], b.applied_moment[i] = f * block_moment[i];
        for (int k = 0; k < n.count(); ++k) n.applied[k] = f * node_load[k];
    };
    constexpr long ramp = 3000, settle_max = 20000;
    for (long k = 1; k <= ramp; ++k) {
        scale(double(k) / double(ramp));
        s.step();
    }
    for (long k = 0; k < settle_max && !(k > 200 && s.unbalanced_ratio() < 1e-5); ++k) s.step();
    for (std::size_t j = 0; j < moving_blocks.size(); ++j) b.fixed_velocity[moving_blocks[j]].y = vy_blocks[j];
    for (std::size_t j = 0; j < moving_nodes.size(); ++j) n.fixed_velocity[moving_nodes[j]].y = vy_nodes[j];
    return s.steps();
}
} // namespace

double fit_slope(const std::vector<double>& x, const std::vector<double>& y) {
    const std::size_t n = x.size();
    if (n < 2) return 0.0;
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
    mx /= n, my /= n;
    double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < n; ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    return sxx > 0 ? sxy / sxx : 0.0;
}

LabTestResult run_labtest(const LabTestOptions& o, const std::function<void(const StressStrainPoint&)>& progress,
                          const std::function<void(const Solver&, const LabTestResult&)>& on_finish,
                          const std::function<void(const Solver&, const StressStrainPoint&)>& on_frame) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto blocks = meshing::generate_blocks(labtest_geometry(o));
    Solver s(blocks, labtest_analysis(o));
    LabTestResult r;
    r.blocks = blocks.block_count();
    r.contacts = s.contacts().size();
    const auto& b = s.blocks();
    const double h = specimen_height(o), band = 0.5 * o.size;
    const bool brazilian = o.kind == LabTestOptions::Kind::brazilian;
    const double sign = o.kind == LabTestOptions::Kind::tension ? -1.0 : 1.0;
    // Side bands for the lateral strain (platen rows excluded).
    std::vector<int> left, right;
    for (int i = 0; i < b.count(); ++i) {
        const Vec2 c = b.centroid0[i];
        if (c.y < band || c.y > h - band) continue;
        if (c.x < o.size) left.push_back(i);
        if (c.x > o.width - o.size) right.push_back(i);
    }
    // A deformable block moves with its nodes: the mean of its boundary nodes.
    const auto& nodes = s.nodes();
    auto ux_of = [&](int i) {
        if (!b.deformable[i]) return b.centroid[i].x - b.centroid0[i].x;
        double u = 0.0;
        for (std::uint32_t v = b.first[i]; v < b.first[i + 1]; ++v) {
            const int nd = b.vertex_node[v];
            u += nodes.position[nd].x - nodes.position0[nd].x;
        }
        return u / double(b.first[i + 1] - b.first[i]);
    };
    auto mean_ux = [&](const std::vector<int>& ids) {
        double u = 0;
        for (int i : ids) u += ux_of(i);
        return ids.empty() ? 0.0 : u / ids.size();
    };
    // Crack orientation when each crack forms (later the fragments rotate): the
    // angle of its joint from horizontal, 0–180°.
    auto record_new_cracks = [&] {
        auto& c = s.contacts();
        for (int i = 0; i < c.size(); ++i) {
            auto& hist = c.history[i];
            if (hist.broken == contact::JointState::intact || hist.counted) continue;
            hist.counted = true;
            const Vec2 t = contact::tangent_of(c.normal[i]);
            double angle = std::atan2(t.y, t.x) * 180.0 / std::numbers::pi;
            while (angle < 0) angle += 180.0;
            while (angle >= 180.0) angle -= 180.0;
            ++r.crack_orientation[std::min(11, int(angle / 15.0))];
            if (std::abs(angle - 90.0) <= 30.0) ++r.cracks_near_vertical;
            if (angle <= 30.0 || angle >= 150.0) ++r.cracks_near_horizontal;
        }
    };
    const double v = o.strain_per_step * h;
    // Biaxial: the confinement first, ramped with the platens held, then settled
    // (applied at once it is a shock that cracks the specimen before any axial load).
    const long start = o.kind == LabTestOptions::Kind::biaxial && o.confinement > 0 ? confine(s) : 0;
    double peak = 0.0;
    long peak_step = 0;
    bool failed = false; ///< the stress has dropped by failure_drop from the peak, or stalled
    const int cracks_at_start = s.cracks(contact::JointState::broken_tension) + s.cracks(contact::JointState::broken_shear);
    // A stall: no net rise of the stress over this many records (2e-4 of strain).
    const std::size_t stall_records =
        std::max<std::size_t>(5, std::size_t(std::lround(2e-4 / (o.strain_per_step * o.record_every))));
    while (s.steps() - start < o.max_steps) {
        s.step();
        if ((s.steps() - start) % o.record_every != 0) continue;
        record_new_cracks();
        const double force = sign * s.boundary_force("top").y;
        StressStrainPoint p;
        p.step = s.steps();
        p.axial_strain = v * double(s.steps() - start) / h;
        p.axial_stress = brazilian ? 2.0 * force / (std::numbers::pi * o.width) : force / o.width;
        p.lateral_strain = (mean_ux(right) - mean_ux(left)) / o.width;
        p.cracks_tensile = s.cracks(contact::JointState::broken_tension);
        p.cracks_shear = s.cracks(contact::JointState::broken_shear);
        r.curve.push_back(p);
        if (progress) progress(p);
        if (on_frame && o.frame_every > 0 && (s.steps() - start) % o.frame_every == 0) on_frame(s, p);
        // After a failure drop the peak is the strength: rigid fragments cannot
        // break further, and a rubble core jammed between the platens can re-stiffen
        // like dry masonry (trigon: new corner contacts carry most of the load).
        if (failed && p.axial_stress > peak) {
            r.post_peak_locking = true;
            r.peak_passed = true;
            break;
        }
        if (p.axial_stress > peak) peak = p.axial_stress, peak_step = p.step;
        // Failure: a drop by failure_drop from the peak, or (confined specimens, whose
        // fragments lock without a drop) a stall — the stress no higher than
        // 2e-4 of strain ago, with the peak inside that stretch. Only with bonds broken
        // under the axial load: the start-up transient of the platens is no failure.
        const bool cracking = p.cracks_tensile + p.cracks_shear > cracks_at_start;
        const bool dropped = peak > 0 && p.axial_stress < (1.0 - o.failure_drop) * peak;
        bool stalled = false;
        if (r.curve.size() > stall_records) {
            const auto& back = r.curve[r.curve.size() - 1 - stall_records];
            stalled = p.axial_stress <= back.axial_stress && peak_step >= back.step;
        }
        failed = failed || (cracking && (dropped || stalled));
        // Past the peak once the stress is clearly down from it.
        if (peak > 0 && p.step > peak_step && p.axial_stress < o.stop_fraction * peak) {
            r.peak_passed = true;
            break;
        }
        if (p.axial_strain >= o.max_strain) break;
    }
    r.steps = s.steps();
    r.peak_stress = peak;
    r.strain_at_peak = v * double(peak_step - start) / h;
    if (brazilian) r.tensile_strength = peak;
    // E and ν on the initial linear part: pre-peak points between 10% and 50% of the peak.
    std::vector<double> eps, sig, lat;
    for (const auto& p : r.curve) {
        if (p.step > peak_step) break;
        if (p.axial_stress >= 0.1 * peak && p.axial_stress <= 0.5 * peak) {
            eps.push_back(p.axial_strain), sig.push_back(p.axial_stress), lat.push_back(p.lateral_strain);
        }
    }
    if (!brazilian) {
        r.E = fit_slope(eps, sig);
        // Compression: the sides move out as the specimen shortens (both strains
        // positive); tension: they move in as it lengthens.
        r.nu = fit_slope(eps, lat) * (o.kind == LabTestOptions::Kind::tension ? -1.0 : 1.0);
    }
    record_new_cracks();
    r.cracks_tensile = s.cracks(contact::JointState::broken_tension);
    r.cracks_shear = s.cracks(contact::JointState::broken_shear);
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (on_finish) on_finish(s, r);
    return r;
}

} // namespace bbm
