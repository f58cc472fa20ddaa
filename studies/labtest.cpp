#include "studies/labtest.hpp"

#include "base/error.hpp"
#include "core/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
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

std::vector<meshing::SegmentSpec> joint_set_traces(const LabTestOptions& o) {
    const double a = o.joint_set_angle * std::numbers::pi / 180.0;
    const Vec2 t{std::cos(a), std::sin(a)}, n{-t.y, t.x}, centre{0.5 * o.width, 0.5 * o.height};
    const double reach = std::hypot(o.width, o.height);
    const int lines = o.joint_set_spacing > 0 ? int(reach / o.joint_set_spacing) + 1 : 0;
    std::vector<meshing::SegmentSpec> traces;
    for (int k = -lines; k <= lines; ++k) {
        // The line centre + k s n + λ t clipped to the rectangle (Liang–Barsky).
        const Vec2 p = centre + (k * o.joint_set_spacing) * n;
        double lo = -reach, hi = reach;
        const double start[2] = {p.x, p.y}, dir[2] = {t.x, t.y}, box_lo[2] = {0.0, 0.0}, box_hi[2] = {o.width, o.height};
        for (int i = 0; i < 2; ++i) {
            if (std::abs(dir[i]) < 1e-12) {
                if (start[i] <= box_lo[i] || start[i] >= box_hi[i]) lo = hi; // outside
                continue;
            }
            double l0 = (box_lo[i] - start[i]) / dir[i], l1 = (box_hi[i] - start[i]) / dir[i];
            if (l0 > l1) std::swap(l0, l1);
            lo = std::max(lo, l0), hi = std::min(hi, l1);
        }
        // Not the slivers a trace through a corner would cut off.
        if (hi - lo > o.size) traces.push_back({p + lo * t, p + hi * t});
    }
    return traces;
}

meshing::ModelGeometrySpec labtest_geometry(const LabTestOptions& o) {
    meshing::ModelGeometrySpec g;
    g.max_elements = o.max_elements;
    meshing::RegionSpec r;
    r.name = "specimen";
    if (o.kind == LabTestOptions::Kind::brazilian) {
        r.outline.kind = meshing::OutlineSpec::Kind::circle;
        r.outline.center = {0.5 * o.width, 0.5 * o.width};
        r.outline.radius = 0.5 * o.width;
        // Not finer than a thousandth of the diameter: the estimate of the model's
        // size comes after the outline is made.
        r.outline.max_segment = std::max(0.25 * o.size, 1e-3 * o.width);
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
    if (o.joint_set && o.kind != LabTestOptions::Kind::brazilian) r.joints = joint_set_traces(o);
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
    // Heterogeneous bonds are a property of the specimen: drawn with its seed.
    an.joint_properties.back().strength_seed = o.seed;
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
    if (o.joint_set) {
        JointPropertySpec set = o.joint_set_joint;
        set.name = "joint_set";
        if (!(set.kn > 0)) set.kn = o.joint.kn;
        if (!(set.ks > 0)) set.ks = o.joint.ks;
        an.joint_properties.push_back(set);
        an.joint_assignments.push_back({set.name, {meshing::JointTag::real_joint}, {"specimen"}});
    }
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
        // Smooth platens leave the specimen free to slide sideways as a whole (a
        // zero-stiffness mode: the preload's matrix is singular, and fragments
        // drift after failure); the bottom face's middle blocks are held in x. A
        // face block is selected by an edge wholly inside the box, so the box spans
        // a few block sizes (a window of one size held none).
        BoundarySpec anchor = bottom;
        anchor.name = "anchor";
        anchor.select.box->lo.x = 0.5 * o.width - 1.5 * o.size;
        anchor.select.box->hi.x = 0.5 * o.width + 1.5 * o.size;
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
/// The moving platen: the blocks and nodes with a prescribed, non-zero vertical
/// velocity (the top face), whose speed the loading sets.
class MovingPlaten {
public:
    explicit MovingPlaten(Solver& s) : s_(s) {
        auto& b = s.blocks();
        auto& n = s.nodes();
        for (int i = 0; i < b.count(); ++i)
            if ((b.fixed[i] & 2) && b.fixed_velocity[i].y != 0.0) blocks_.push_back(i), sign_ = b.fixed_velocity[i].y > 0 ? 1 : -1;
        for (int k = 0; k < n.count(); ++k)
            if ((n.fixed[k] & 2) && n.fixed_velocity[k].y != 0.0) nodes_.push_back(k), sign_ = n.fixed_velocity[k].y > 0 ? 1 : -1;
    }
    /// Vertical speed (m per step), in the loading direction.
    void set_speed(double v) {
        for (int i : blocks_) s_.blocks().fixed_velocity[i].y = sign_ * v;
        for (int k : nodes_) s_.nodes().fixed_velocity[k].y = sign_ * v;
    }

private:
    Solver& s_;
    std::vector<int> blocks_, nodes_;
    double sign_ = -1.0;
};

/// Applies the biaxial confinement gradually with the platens held still, then lets
/// the specimen settle; returns the step at which axial loading starts.
long confine(Solver& s, MovingPlaten& platen) {
    auto& b = s.blocks();
    auto& n = s.nodes();
    const auto block_load = b.applied;
    const auto block_moment = b.applied_moment;
    const auto node_load = n.applied;
    platen.set_speed(0.0);
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
    return s.steps();
}
} // namespace

void measure_rock_mechanics(LabTestResult& r, std::size_t preload_points, bool tension, long peak_step) {
    const auto& c = r.curve;
    if (c.size() < 2 || r.peak_stress <= 0.0) return;
    const double peak = r.peak_stress, nu_sign = tension ? -1.0 : 1.0;
    std::size_t last = 0; // the last pre-peak point
    while (last + 1 < c.size() && c[last + 1].step <= peak_step) ++last;
    // The linear part: the implicit preload's line (exact), else the pre-peak
    // points from 10% of the peak to the first broken bond or 50% of the peak,
    // whichever comes first — never past crack initiation.
    std::vector<double> eps, sig, lat;
    if (preload_points >= 2) {
        const auto &a = c.front(), &b = c[preload_points - 1];
        r.E = (b.axial_stress - a.axial_stress) / (b.axial_strain - a.axial_strain);
        r.nu = nu_sign * (b.lateral_strain - a.lateral_strain) / (b.axial_strain - a.axial_strain);
        r.linear_limit_stress = b.axial_stress;
    } else {
        const int cracks0 = c.front().cracks_tensile + c.front().cracks_shear;
        for (std::size_t k = 0; k <= last; ++k) {
            const auto& p = c[k];
            if (p.cracks_tensile + p.cracks_shear > cracks0 || p.axial_stress > 0.5 * peak) break;
            if (p.axial_stress >= 0.1 * peak)
                eps.push_back(p.axial_strain), sig.push_back(p.axial_stress), lat.push_back(p.lateral_strain);
        }
        r.E = fit_slope(eps, sig);
        r.nu = nu_sign * fit_slope(eps, lat);
        r.linear_limit_stress = sig.empty() ? 0.0 : sig.back();
    }
    // ISRM tangent modulus at 50% of the peak: pre-peak points within ±5% of it.
    eps.clear(), sig.clear();
    for (std::size_t k = 0; k <= last; ++k)
        if (std::abs(c[k].axial_stress - 0.5 * peak) <= 0.05 * peak)
            eps.push_back(c[k].axial_strain), sig.push_back(c[k].axial_stress);
    r.E50 = eps.size() >= 2 ? fit_slope(eps, sig) : 0.0;
    if (tension || !(r.E > 0.0)) return;
    // Crack initiation and damage (Martin & Chandler 1994), from the loading's start:
    // volumetric strain εv = εa + εl (plane strain, εl = −lateral expansion), its
    // elastic part (1 − ν) Δσ / E, the crack volumetric strain εcv = εv − that.
    // σci: where εcv leaves zero for good — the last pre-peak point (5-point mean)
    // with |εcv| within 0.5% of the elastic volumetric strain at the peak; σcd:
    // where εv reverses (its largest pre-peak value; the peak if it never does).
    const auto& o = c.front();
    auto volumetric = [&](std::size_t k) {
        return (c[k].axial_strain - o.axial_strain) - (c[k].lateral_strain - o.lateral_strain);
    };
    auto mean5 = [&](auto f, std::size_t k) {
        const std::size_t a = k >= 2 ? k - 2 : 0, b = std::min(last, k + 2);
        double m = 0.0;
        for (std::size_t j = a; j <= b; ++j) m += f(j);
        return m / double(b - a + 1);
    };
    auto crack_volumetric = [&](std::size_t k) {
        return volumetric(k) - (1.0 - r.nu) * (c[k].axial_stress - o.axial_stress) / r.E;
    };
    const double tolerance = 0.005 * (1.0 - r.nu) * (peak - o.axial_stress) / r.E;
    std::size_t initiation = last, damage = 0;
    for (std::size_t k = last + 1; k-- > 0;)
        if (std::abs(mean5(crack_volumetric, k)) <= tolerance) {
            initiation = k;
            break;
        }
    double best = -INFINITY;
    for (std::size_t k = 0; k <= last; ++k)
        if (const double v = mean5(volumetric, k); v > best) best = v, damage = k;
    r.crack_initiation_stress = c[initiation].axial_stress;
    r.crack_damage_stress = c[damage].axial_stress;
}

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

namespace {

/// The share of the compression the contacts carry (Σ σn L over contacts in
/// compression) that unbonded contacts carry: broken joints and contacts formed
/// during the run.
double unbonded_compression_share(const Solver& s) {
    const auto& c = s.contacts();
    double all = 0.0, unbonded = 0.0;
    for (int i = 0; i < c.size(); ++i) {
        const double f = std::max(0.0, c.history[i].sn) * c.length[i];
        all += f;
        if (!c.history[i].bonded) unbonded += f;
    }
    return all > 0.0 ? unbonded / all : 0.0;
}

} // namespace

LabTestResult run_labtest(const LabTestOptions& o, const std::function<void(const StressStrainPoint&)>& progress,
                          const std::function<void(const Solver&, const LabTestResult&)>& on_finish,
                          const std::function<void(const Solver&, const StressStrainPoint&)>& on_frame) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto blocks = meshing::generate_blocks(labtest_geometry(o));
    Solver s(blocks, labtest_analysis(o));
    if (!o.rough_platens && !uses_platen_blocks(o)) {
        const auto& fixed = s.blocks().fixed;
        if (std::none_of(fixed.begin(), fixed.end(), [](auto f) { return (f & 1) != 0; }))
            throw std::runtime_error("smooth platens: no block on the bottom face's middle to hold the specimen "
                                     "horizontally; use --platens rough or a larger specimen");
    }
    LabTestResult r;
    r.blocks = blocks.block_count();
    r.contacts = s.contacts().size();
    const auto& b = s.blocks();
    const double h = specimen_height(o), band = 0.5 * o.size;
    const bool brazilian = o.kind == LabTestOptions::Kind::brazilian;
    const double sign = o.kind == LabTestOptions::Kind::tension ? -1.0 : 1.0;
    // Side bands for the lateral strain: the middle half of the height, where a lab
    // specimen carries its lateral gauges (ISRM) — away from the platens, whose
    // friction holds the ends in (the whole height read ν of the hexagonal lattice
    // 16% low: 0.144 against 0.171).
    std::vector<int> left, right;
    for (int i = 0; i < b.count(); ++i) {
        const Vec2 c = b.centroid0[i];
        if (c.y < std::max(band, 0.25 * h) || c.y > std::min(h - band, 0.75 * h)) continue;
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
    // The joint set's contacts: the share of their length sliding at its limit.
    int set_property = -1;
    for (std::size_t k = 0; k < s.property_names().size(); ++k)
        if (o.joint_set && s.property_names()[k] == "joint_set") set_property = int(k);
    auto joint_set_sliding = [&] {
        const auto& c = s.contacts();
        double all = 0.0, sliding = 0.0;
        for (int i = 0; i < c.size(); ++i) {
            if (c.property[i] != set_property) continue;
            all += c.length[i];
            if (c.history[i].slipping) sliding += c.length[i];
        }
        return all > 0.0 ? sliding / all : 0.0;
    };
    // Biaxial: the confinement first, ramped with the platens held, then settled
    // (applied at once it is a shock that cracks the specimen before any axial load).
    MovingPlaten platen(s);
    const long start = o.kind == LabTestOptions::Kind::biaxial && o.confinement > 0 ? confine(s, platen) : 0;
    double peak = 0.0, strain = 0.0, strain_at_peak = 0.0;
    long peak_step = 0;
    bool failed = false; ///< the stress has dropped by failure_drop from the peak, or stalled
    const int cracks_at_start = s.cracks(contact::JointState::broken_tension) + s.cracks(contact::JointState::broken_shear);
    // Loading rate: fixed, or (servo) adapted at every record to the cracking.
    const double rate_max = o.strain_per_step * o.servo_max_factor;
    const double rate_min = o.strain_per_step * o.servo_min_factor;
    auto measure = [&](double at_strain, double at_rate) {
        const double force = sign * s.boundary_force("top").y;
        StressStrainPoint p;
        p.step = s.steps();
        p.axial_strain = at_strain;
        p.axial_stress = brazilian ? 2.0 * force / (std::numbers::pi * o.width) : force / o.width;
        p.lateral_strain = (mean_ux(right) - mean_ux(left)) / o.width;
        p.cracks_tensile = s.cracks(contact::JointState::broken_tension);
        p.cracks_shear = s.cracks(contact::JointState::broken_shear);
        p.unbalanced_ratio = s.unbalanced_ratio();
        p.strain_per_step = at_rate;
        return p;
    };
    // Elastic preload: until the first joint yields the specimen is linear, and its
    // quasi-static response is one implicit solve — not thousands of damped steps
    // whose start-up transient would bias E. A trial platen displacement gives the
    // response per unit of load; the first joint to reach its strength gives how
    // far it can go; the specimen is set there (preload_fraction of it) exactly,
    // and the explicit loading takes over just before cracking starts.
    std::size_t preload_points = 0; ///< leading curve points that are the implicit line
    if (o.elastic_preload && !uses_platen_blocks(o)) {
        const auto& c = s.contacts();
        const auto& nd = s.nodes();
        const std::vector<contact::JointHistory> before = c.history;
        const auto centroid0 = b.centroid, position0 = nd.position;
        const auto theta0 = b.theta;
        const StressStrainPoint origin = measure(0.0, 0.0);
        const double trial = 1e-6;
        platen.set_speed(trial * h);
        s.move_supports(s.timestep());
        strain = trial;
        // A specimen the confinement cracked can hold a block by one point or a
        // loose group (a trigon triangle at 71 MPa on Lac du Bonnet's bonds): the
        // implicit matrix is singular there. The preload is a shortcut, not the
        // test: the explicit loading then starts from the trial displacement.
        bool solvable = true;
        try {
            s.solve_elastic();
        } catch (const SingularSystemError&) {
            solvable = false;
            r.preload_skipped = true;
        }
        double lambda = solvable ? 1e6 : 0.0;
        for (int i = 0; i < c.size(); ++i)
            lambda = std::min(lambda, contact::elastic_limit(s.laws()[c.property[i]], before[i], c.history[i], 1e6));
        const double reach = o.preload_fraction * lambda;
        if (solvable && reach > 1.0 && lambda < 1e6) {
            // Every body on by (reach − 1) times its trial displacement: each joint
            // takes the same multiple of its trial increment (no row of joints next
            // to the platen takes the whole of it), then one more solve for the
            // geometric nonlinearity.
            std::vector<Vec2> du(b.count()), dn(nd.count());
            std::vector<double> dtheta(b.count());
            for (int i = 0; i < b.count(); ++i)
                du[i] = (reach - 1.0) * (b.centroid[i] - centroid0[i]), dtheta[i] = (reach - 1.0) * (b.theta[i] - theta0[i]);
            for (int k = 0; k < nd.count(); ++k) dn[k] = (reach - 1.0) * (nd.position[k] - position0[k]);
            s.move_bodies(du, dtheta, dn);
            strain = reach * trial;
            try {
                s.solve_elastic(); // the geometric correction: without it the linear state stands
            } catch (const SingularSystemError&) {
            }
        }
        // The straight line between them, exact for the linear response (none when
        // the specimen could not be solved: E then comes from the explicit curve).
        const StressStrainPoint end = measure(strain, 0.0);
        for (int k = 1; k <= (solvable ? 20 : 0); ++k) {
            const double f = k / 20.0;
            StressStrainPoint p = end;
            p.axial_strain = origin.axial_strain + f * (end.axial_strain - origin.axial_strain);
            p.axial_stress = origin.axial_stress + f * (end.axial_stress - origin.axial_stress);
            p.lateral_strain = origin.lateral_strain + f * (end.lateral_strain - origin.lateral_strain);
            r.curve.push_back(p);
            if (progress) progress(p);
        }
        r.curve.insert(r.curve.begin(), origin);
        preload_points = solvable ? r.curve.size() : 0;
    }
    // The platens start from rest: slowly, then the servo speeds up.
    double rate = o.servo ? rate_min : o.strain_per_step;
    const double target_cracks = o.servo_cracks * std::max(1.0, r.contacts / 5000.0);
    int cracks_last_record = cracks_at_start;
    platen.set_speed(rate * h);
    double ratio_max = 0.0;
    std::size_t stall_from = 0; ///< first record within 2e-4 of strain of the last
    // Locking: the stress above the peak after failure for this many records in a row.
    constexpr int lock_records = 10;
    int records_above_peak = 0;
    // Stopped unfailed with the stress at its peak (within 2%): the peak is a lower
    // bound. 2% down from it the specimen has passed its peak, though the drop
    // rule wants 10%: that peak is a strength.
    auto still_at_peak = [&peak](const StressStrainPoint& p) { return p.axial_stress >= 0.98 * peak; };
    // Confined, the laboratory's peak: only a lasting drop is failure (no stall
    // rule), and a climb back above a dropped peak is loading on.
    const bool lab_peak = o.confinement > 0.0 && !o.confined_peak_at_stall;
    double strain_at_failure = 0.0;
    while (s.steps() - start < o.max_steps) {
        s.step();
        strain += rate;
        ratio_max = std::max(ratio_max, s.unbalanced_ratio());
        if ((s.steps() - start) % o.record_every != 0) continue;
        record_new_cracks();
        StressStrainPoint p = measure(strain, rate);
        p.unbalanced_ratio = ratio_max;
        r.curve.push_back(p);
        if (set_property >= 0 && !(r.joint_slip_stress > 0.0)) {
            const double sliding = joint_set_sliding();
            if (sliding >= 0.5 && !(r.joint_slip_stress_half > 0.0)) r.joint_slip_stress_half = p.axial_stress;
            if (sliding >= 0.9) r.joint_slip_stress = p.axial_stress;
        }
        if (o.servo) {
            const int cracks_now = p.cracks_tensile + p.cracks_shear;
            const double made = cracks_now - cracks_last_record;
            cracks_last_record = cracks_now;
            // Never faster than ×1.1 a record: a change of rate is a change of the
            // specimen's lag behind the platen, which shows in the curve.
            if (failed) {
                rate = std::min(1.1 * rate, o.strain_per_step * o.servo_post_peak_factor);
            } else {
                double f = made <= 0 ? 1.1 : std::clamp(target_cracks / made, 0.5, 1.1);
                if (o.servo_balance > 0 && cracks_now > cracks_at_start) {
                    const double top = s.boundary_force("top").y, bottom = s.boundary_force("bottom").y;
                    const double mismatch = std::abs(top + bottom) / std::max(std::abs(top), 1e-300);
                    if (mismatch > 0) f = std::min(f, std::clamp(o.servo_balance / mismatch, 0.5, 1.1));
                }
                rate = std::clamp(rate * f, rate_min, rate_max);
            }
            platen.set_speed(rate * h);
        }
        ratio_max = 0.0;
        if (progress) progress(p);
        if (on_frame && o.frame_every > 0 && (s.steps() - start) % o.frame_every == 0) on_frame(s, p);
        // After a failure drop the peak is the strength: rigid fragments cannot
        // break further, and a rubble core jammed between the platens can re-stiffen
        // like dry masonry. A jam stays above the peak; a burst of cracks throws a
        // dynamic transient (unbalanced ratio far above 1) that passes within a
        // few records, and is no locking (docs/calibration.md, After the peak).
        if (failed && p.axial_stress > peak) {
            if (++records_above_peak >= lock_records) {
                // Who carries the load now? Bonds still intact: the "failure" was a
                // local burst of cracks in a specimen that had not failed (small
                // specimens, a few blocks across), and loading goes on. Broken and
                // new contacts: fragments jammed between the platens. Confined,
                // the laboratory's peak: loading goes on (a hardening specimen
                // shows itself by its peak against first_stall_stress); the
                // first-stall rule stops here, its peak before the drop.
                if (lab_peak) {
                    failed = false, records_above_peak = 0, ++r.reloads;
                } else if (o.confinement <= 0.0 && unbonded_compression_share(s) < 0.5) {
                    failed = false, records_above_peak = 0;
                } else {
                    r.post_peak_locking = true;
                    r.peak_passed = true;
                    break;
                }
            }
        } else {
            records_above_peak = 0;
        }
        if (!failed && p.axial_stress > peak) {
            peak = p.axial_stress, peak_step = p.step, strain_at_peak = p.axial_strain;
            r.cracks_near_vertical_at_peak = r.cracks_near_vertical;
            r.cracks_near_horizontal_at_peak = r.cracks_near_horizontal;
        }
        // Failure: a drop by failure_drop from the peak, or (confined specimens, whose
        // fragments lock without a drop) a stall — the stress no higher than
        // 2e-4 of strain ago, with the peak inside that stretch. Only with bonds broken
        // under the axial load: the start-up transient of the platens is no failure.
        const bool cracking = p.cracks_tensile + p.cracks_shear > cracks_at_start;
        const bool dropped = peak > 0 && p.axial_stress < (1.0 - o.failure_drop) * peak;
        while (stall_from + 1 < r.curve.size() && r.curve[stall_from + 1].axial_strain <= p.axial_strain - 2e-4)
            ++stall_from;
        bool stalled = false;
        if (r.curve[stall_from].axial_strain <= p.axial_strain - 2e-4 && r.curve.size() - stall_from > 5) {
            const auto& back = r.curve[stall_from];
            stalled = p.axial_stress <= back.axial_stress && peak_step >= back.step;
        }
        if (cracking && (dropped || stalled) && !(r.first_stall_stress > 0.0)) r.first_stall_stress = peak;
        if (lab_peak) stalled = false; // yielding, not failure: the peak is still ahead or here
        if (!failed && cracking && (dropped || stalled)) failed = true, strain_at_failure = p.axial_strain;
        // Past the peak once the stress is clearly down from it (after cracking: not
        // in the start-up transient of the platens).
        if (cracking && peak > 0 && p.step > peak_step && p.axial_stress < o.stop_fraction * peak) {
            r.peak_passed = true;
            break;
        }
        // (The laboratory's peak: past the drop, which gives a burst of cracks the
        // room to be climbed back above.)
        if (failed && o.confinement > 0.0 && o.post_peak_strain > 0.0 &&
            p.axial_strain >= (lab_peak ? strain_at_failure : strain_at_peak) + o.post_peak_strain) {
            r.peak_passed = true;
            break;
        }
        if (p.axial_strain >= o.max_strain) {
            // Not failed yet: the strength is still ahead, load on to the cap.
            // Failed after loading on: stop max_strain past the peak at the latest
            // (the locking check above gets the room it had before max_strain).
            const double cap = std::max(o.max_strain, o.strain_cap);
            if (!failed && p.axial_strain < cap) {
                r.loaded_past_max_strain = true;
            } else if (!failed) {
                r.still_loading = still_at_peak(p);
                break;
            } else if (!r.loaded_past_max_strain || p.axial_strain >= cap ||
                       p.axial_strain >= strain_at_peak + o.max_strain) {
                break;
            }
        }
    }
    // Out of steps while loading on: the peak is a lower bound too.
    if (s.steps() - start >= o.max_steps && r.loaded_past_max_strain && !failed && !r.curve.empty())
        r.still_loading = still_at_peak(r.curve.back());
    r.steps = s.steps();
    r.peak_stress = peak;
    r.strain_at_peak = strain_at_peak;
    if (brazilian) r.tensile_strength = peak;
    if (!brazilian) measure_rock_mechanics(r, preload_points, o.kind == LabTestOptions::Kind::tension, peak_step);
    if (o.kind != LabTestOptions::Kind::tension && !brazilian) measure_residual_strength(r, o.confinement);
    record_new_cracks();
    r.cracks_tensile = s.cracks(contact::JointState::broken_tension);
    r.cracks_shear = s.cracks(contact::JointState::broken_shear);
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (on_finish) on_finish(s, r);
    return r;
}

void measure_residual_strength(LabTestResult& r, double confinement) {
    if (r.curve.empty()) return;
    const double end = r.curve.back().axial_strain;
    if (end - r.strain_at_peak < residual_run_strain) return;
    double sum = 0.0;
    int n = 0;
    for (auto p = r.curve.rbegin(); p != r.curve.rend() && p->axial_strain >= end - residual_window_strain; ++p)
        sum += p->axial_stress, ++n;
    r.residual_stress = sum / n;
    // σ1 / σ3 = (1 + sin φ) / (1 − sin φ) with no cohesion.
    if (confinement > 0.0 && r.residual_stress > confinement)
        r.residual_friction_angle =
            std::asin((r.residual_stress - confinement) / (r.residual_stress + confinement)) * 180.0 / std::numbers::pi;
}

} // namespace bbm
