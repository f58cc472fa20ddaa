#include "studies/lab/labtest.hpp"

#include "base/error.hpp"
#include "core/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <tuple>

namespace bbm {

bool uses_platen_blocks(const LabTestOptions& o) {
    return o.platen_friction >= 0.0 && (o.kind == LabTestOptions::Kind::ucs || o.kind == LabTestOptions::Kind::biaxial);
}

std::vector<meshing::SegmentSpec> joint_set_traces(const LabTestOptions& o) {
    const double a = o.joint_set.angle * std::numbers::pi / 180.0;
    const Vec2 t{std::cos(a), std::sin(a)}, n{-t.y, t.x}, centre{0.5 * o.width, 0.5 * o.height};
    const double reach = std::hypot(o.width, o.height);
    const int lines = o.joint_set.spacing > 0 ? int(reach / o.joint_set.spacing) + 1 : 0;
    std::vector<meshing::SegmentSpec> traces;
    for (int k = -lines; k <= lines; ++k) {
        // The line centre + k s n + λ t clipped to the rectangle (Liang–Barsky).
        const Vec2 p = centre + (k * o.joint_set.spacing) * n;
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
        if (hi - lo > o.rock.pattern.size) traces.push_back({p + lo * t, p + hi * t});
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
        r.outline.max_segment = std::max(0.25 * o.rock.pattern.size, 1e-3 * o.width);
    } else {
        r.outline.min = {0.0, 0.0};
        r.outline.max = {o.width, o.height};
    }
    r.pattern.kind = o.rock.pattern.kind;
    r.pattern.size = o.rock.pattern.size;
    r.pattern.size_measure = o.rock.pattern.size_measure;
    r.pattern.lloyd_iterations = o.rock.pattern.lloyd_iterations;
    r.pattern.seed = o.rock.pattern.seed;
    if (o.rock.material.deformable_fraction > 0.0) {
        r.mesh.enabled = true;
        r.mesh.size = o.rock.mesh_size > 0.0 ? o.rock.mesh_size : 0.5 * o.rock.pattern.size;
    }
    if (o.joint_set.on && o.kind != LabTestOptions::Kind::brazilian) r.joints = joint_set_traces(o);
    g.regions.push_back(r);
    if (uses_platen_blocks(o)) {
        // One block each, a block size thick, sharing the specimen's faces.
        for (const auto& [name, y0, y1] : {std::tuple{"platen_bottom", -o.rock.pattern.size, 0.0},
                                           std::tuple{"platen_top", o.height, o.height + o.rock.pattern.size}}) {
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

/// The specimen's material and joint properties: the rock's bonds (drawn with
/// the specimen's seed), the platens' contacts, a joint set, and the unbonded
/// contacts that form during the test.
void add_labtest_materials(AnalysisSpec& an, const LabTestOptions& o) {
    MaterialSpec rock;
    rock.name = "rock";
    rock.density = o.rock.material.density;
    if (o.rock.material.deformable_fraction > 0.0) {
        rock.young = o.rock.material.young;
        rock.poisson = o.rock.material.poisson;
        rock.deformable_fraction = o.rock.material.deformable_fraction;
    }
    an.materials.push_back(rock);
    an.joint_properties.push_back(o.rock.bonds);
    // Heterogeneous bonds are a property of the specimen: drawn with its seed.
    an.joint_properties.back().strength_seed = o.rock.pattern.seed;
    if (uses_platen_blocks(o)) {
        JointPropertySpec platen;
        platen.name = "platen";
        platen.law = "coulomb";
        platen.kn = o.rock.bonds.kn;
        platen.ks = o.rock.bonds.ks;
        platen.friction = o.platen_friction;
        an.joint_properties.push_back(platen);
        an.joint_assignments.push_back({platen.name, {}, {}});
    }
    // The bond between specimen blocks (a later rule wins over the platen one).
    an.joint_assignments.push_back({o.rock.bonds.name, {}, {"specimen"}});
    if (o.joint_set.on) {
        JointPropertySpec set = o.joint_set.joint;
        set.name = "joint_set";
        if (!(set.kn > 0)) set.kn = o.rock.bonds.kn;
        if (!(set.ks > 0)) set.ks = o.rock.bonds.ks;
        an.joint_properties.push_back(set);
        an.joint_assignments.push_back({set.name, {meshing::JointTag::real_joint}, {"specimen"}});
    }
    // Contacts that form during the test (fragments touching anew) are the rock's
    // broken joints: unbonded, with the bond's stiffness and residual friction
    // (not the solver's built-in 30°); with deformable blocks, as stiff as the
    // bonds after the split (SPEC §6).
    const double joint_share = o.rock.material.deformable_fraction > 0.0 ? 1.0 - o.rock.material.deformable_fraction : 1.0;
    JointPropertySpec unbonded;
    unbonded.name = "unbonded";
    unbonded.law = "coulomb";
    unbonded.kn = o.rock.bonds.kn / joint_share;
    unbonded.ks = o.rock.bonds.ks / joint_share;
    unbonded.friction = o.rock.bonds.residual_friction >= 0 ? o.rock.bonds.residual_friction : o.rock.bonds.friction;
    an.joint_properties.push_back(unbonded);
    an.solver.new_contact_property = unbonded.name;
}

/// The platens: bottom held, top moving at the strain rate (apart in tension),
/// as platen blocks, rough faces or smooth ones (these with an anchor).
void add_platen_boundaries(AnalysisSpec& an, const LabTestOptions& o) {
    const bool platen_blocks = uses_platen_blocks(o);
    const double h = specimen_height(o), band = 0.5 * o.rock.pattern.size, v = o.strain_per_step * h;
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
        anchor.select.box->lo.x = 0.5 * o.width - 1.5 * o.rock.pattern.size;
        anchor.select.box->hi.x = 0.5 * o.width + 1.5 * o.rock.pattern.size;
        anchor.vy.reset();
        anchor.omega.reset();
        anchor.vx = 0.0;
        an.boundaries = {bottom, top, anchor};
    }
}

/// A biaxial test's confinement: the lateral stress on the left and right faces.
void add_confining_boundaries(AnalysisSpec& an, const LabTestOptions& o) {
    if (!(o.kind == LabTestOptions::Kind::biaxial && o.confinement > 0)) return;
    const double h = specimen_height(o), band = 0.5 * o.rock.pattern.size;
    const double big = 10.0 * (o.width + h);
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

} // namespace

AnalysisSpec labtest_analysis(const LabTestOptions& o) {
    AnalysisSpec an;
    add_labtest_materials(an, o);
    add_platen_boundaries(an, o);
    add_confining_boundaries(an, o);
    an.solver.mode = SolverSpec::Mode::quasi_static;
    an.solver.damping = 0.8;
    an.solver.threads = o.threads;
    an.events.on = o.events; // the test's acoustic emission (core/events.hpp)
    return an;
}

namespace {

/// The linear part: the implicit preload's line (exact), else the pre-peak
/// points (to `last`) from 10% of the peak to the first broken bond or 50% of
/// the peak, whichever comes first — never past crack initiation.
void measure_linear_part(LabTestResult& r, std::size_t preload_points, double nu_sign, std::size_t last) {
    const auto& c = r.curve;
    const double peak = r.peak_stress;
    if (preload_points >= 2) {
        const auto &a = c.front(), &b = c[preload_points - 1];
        r.E = (b.axial_stress - a.axial_stress) / (b.axial_strain - a.axial_strain);
        r.nu = nu_sign * (b.lateral_strain - a.lateral_strain) / (b.axial_strain - a.axial_strain);
        r.linear_limit_stress = b.axial_stress;
        return;
    }
    std::vector<double> eps, sig, lat;
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

/// ISRM tangent modulus at 50% of the peak: pre-peak points within ±5% of it.
double tangent_modulus_at_half_peak(const std::vector<StressStrainPoint>& c, std::size_t last, double peak) {
    std::vector<double> eps, sig;
    for (std::size_t k = 0; k <= last; ++k)
        if (std::abs(c[k].axial_stress - 0.5 * peak) <= 0.05 * peak)
            eps.push_back(c[k].axial_strain), sig.push_back(c[k].axial_stress);
    return eps.size() >= 2 ? fit_slope(eps, sig) : 0.0;
}

/// Crack initiation and damage (Martin & Chandler 1994), from the loading's start:
/// volumetric strain εv = εa + εl (plane strain, εl = −lateral expansion), its
/// elastic part (1 − ν) Δσ / E, the crack volumetric strain εcv = εv − that.
/// σci: where εcv leaves zero for good — the last pre-peak point (5-point mean)
/// with |εcv| within 0.5% of the elastic volumetric strain at the peak; σcd:
/// where εv reverses (its largest pre-peak value; the peak if it never does).
void measure_crack_thresholds(LabTestResult& r, std::size_t last) {
    const auto& c = r.curve;
    const double peak = r.peak_stress;
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

} // namespace

void measure_rock_mechanics(LabTestResult& r, std::size_t preload_points, bool tension, long peak_step) {
    const auto& c = r.curve;
    if (c.size() < 2 || r.peak_stress <= 0.0) return;
    const double peak = r.peak_stress, nu_sign = tension ? -1.0 : 1.0;
    std::size_t last = 0; // the last pre-peak point
    while (last + 1 < c.size() && c[last + 1].step <= peak_step) ++last;
    measure_linear_part(r, preload_points, nu_sign, last);
    r.E50 = tangent_modulus_at_half_peak(c, last, peak);
    if (tension || !(r.E > 0.0)) return;
    measure_crack_thresholds(r, last);
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
