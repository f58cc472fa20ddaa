#include "studies/lab/shear.hpp"

#include "studies/lab/labtest_command.hpp"
#include "base/error.hpp"
#include "base/progress.hpp"
#include "core/material_keys.hpp"
#include "core/solver.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "meshing/blocks.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "studies/cluster/ranks.hpp"
#include "studies/model/run_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numbers>
#include <sstream>
#include <thread>

namespace bbm {

namespace {
/// The joint segments on the plane y = height / 2: one cell per bridge, the bridge
/// centred in it, the joint on both sides of it (the plane's ends are joint).
std::vector<meshing::SegmentSpec> plane_segments(const ShearTestOptions& o) {
    const double y = 0.5 * o.height;
    if (o.persistence >= 1.0) return {{{0.0, y}, {o.width, y}}};
    std::vector<meshing::SegmentSpec> s;
    if (o.persistence <= 0.0) return s;
    const double cell = o.width / o.bridges, bridge = (1.0 - o.persistence) * cell;
    // Joint from each bridge's end to the next one's start.
    double x = 0.0;
    for (int k = 0; k < o.bridges; ++k) {
        const double start = (k + 0.5) * cell - 0.5 * bridge;
        s.push_back({{x, y}, {start, y}});
        x = start + bridge;
    }
    s.push_back({{x, y}, {o.width, y}});
    return s;
}
} // namespace

meshing::ModelGeometrySpec shear_geometry(const ShearTestOptions& o) {
    meshing::ModelGeometrySpec g;
    g.max_elements = o.max_elements;
    meshing::RegionSpec r;
    r.name = "specimen";
    r.outline.min = {0.0, 0.0};
    r.outline.max = {o.width, o.height};
    r.pattern.kind = o.rock.pattern.kind;
    r.pattern.size = o.rock.pattern.size;
    r.pattern.size_measure = o.rock.pattern.size_measure;
    r.pattern.lloyd_iterations = o.rock.pattern.lloyd_iterations;
    r.pattern.seed = o.rock.pattern.seed;
    r.joints = plane_segments(o);
    g.regions.push_back(r);
    return g;
}

AnalysisSpec shear_analysis(const ShearTestOptions& o) {
    AnalysisSpec an;
    MaterialSpec rock;
    rock.name = "rock";
    rock.density = o.rock.material.density;
    an.materials.push_back(rock);
    JointPropertySpec bond = o.rock.bonds, plane = o.plane;
    bond.name = "bond", plane.name = "plane";
    bond.strength_seed = o.rock.pattern.seed; // heterogeneous bonds: drawn with the specimen's seed
    an.joint_properties = {bond, plane};
    an.joint_assignments.push_back({"bond", {}, {}});
    an.joint_assignments.push_back({"plane", {meshing::JointTag::real_joint}, {}});
    // Contacts formed during the test: the rock's broken joints (its residual
    // friction), as long as their overlap — a block sliding along the plane
    // touches its next neighbour over the slip only.
    JointPropertySpec unbonded;
    unbonded.name = "unbonded";
    unbonded.law = "coulomb";
    unbonded.kn = o.rock.bonds.kn, unbonded.ks = o.rock.bonds.ks;
    unbonded.friction = o.rock.bonds.residual_friction >= 0 ? o.rock.bonds.residual_friction : o.rock.bonds.friction;
    an.joint_properties.push_back(unbonded);
    an.solver.new_contact_property = unbonded.name;
    an.solver.new_contact_length = SolverSpec::NewContactLength::overlap;
    an.solver.corner_radius = 0.01 * o.rock.pattern.size;
    // The boxes: blocks with an edge wholly on a face. The side faces are split
    // at the plane, and the top and bottom boxes stop short of the corners, so no
    // block is in two boundaries (the corner blocks go with the top or bottom).
    const double w = o.width, h = o.height, y = 0.5 * h, big = 10.0 * (w + h), face = 1e-9 * (w + h);
    auto box = [&](const char* name, Box2 b) {
        BoundarySpec s;
        s.name = name;
        s.select.box = b;
        s.select.touching = true;
        s.vx = 0.0, s.vy = 0.0, s.omega = 0.0;
        return s;
    };
    an.boundaries = {box("lower_bottom", {{-big, -big}, {big, face}}),
                     box("lower_left", {{-big, face}, {face, y}}),
                     box("lower_right", {{w - face, face}, {big, y}}),
                     box("upper_top", {{-big, h - face}, {big, big}}),
                     box("upper_left", {{-big, y}, {face, h - face}}),
                     box("upper_right", {{w - face, y}, {big, h - face}})};
    an.solver.mode = SolverSpec::Mode::quasi_static;
    an.solver.damping = 0.8;
    an.solver.threads = o.threads;
    return an;
}

namespace {

/// One box: the blocks of its boundaries, moved together.
struct ShearBox {
    std::vector<std::string> names;
    std::vector<int> blocks;
    ShearBox(const Solver& s, const std::string& prefix) {
        const Boundaries& b = s.world().boundaries;
        for (std::size_t k = 0; k < b.names.size(); ++k)
            if (b.names[k].rfind(prefix, 0) == 0)
                names.push_back(b.names[k]),
                    blocks.insert(blocks.end(), b.block_list.begin() + b.block_first[k], b.block_list.begin() + b.block_first[k + 1]);
    }
    Vec2 force(const Solver& s) const {
        Vec2 f{};
        for (const auto& n : names) f += boundary_force(s.world(), n);
        return f;
    }
    void set_velocity(Solver& s, Vec2 v) const {
        for (int i : blocks) s.world().loads.block_velocity[i] = v;
    }
    /// The box's displacement (a rigid body without rotation: any of its blocks).
    Vec2 displacement(const Solver& s) const {
        const World& w = s.world();
        return blocks.empty() ? Vec2{} : w.bodies.state[blocks[0]].centroid - w.blocks.centroid0[blocks[0]];
    }
};

} // namespace

namespace {

/// A run's figures from its curve and its peak: peak, residual (the mean over the
/// last tenth of the displacement), dilation and the steepest dilation angle.
void shear_figures(ShearTestResult& r, const ShearPoint& peak) {
    const auto& c = r.curve;
    r.peak_shear_stress = peak.shear_stress;
    r.displacement_at_peak = peak.displacement;
    r.normal_stress_at_peak = peak.normal_stress;
    r.dilation_at_peak = peak.dilation;
    r.final_dilation = c.back().dilation;
    const double u_end = c.back().displacement;
    int n = 0;
    for (const auto& p : c)
        if (p.displacement >= 0.9 * u_end) r.residual_shear_stress += p.shear_stress, r.residual_normal_stress += p.normal_stress, ++n;
    if (n > 0) r.residual_shear_stress /= n, r.residual_normal_stress /= n;
    // Dilation angle: the steepest least-squares slope dv/du over windows of 5% of the run.
    double steepest = 0.0;
    for (std::size_t a = 0, b = 0; a < c.size(); ++a) {
        while (b < c.size() && c[b].displacement < c[a].displacement + 0.05 * u_end) ++b;
        if (b >= c.size()) break;
        std::vector<double> x, y;
        for (std::size_t k = a; k <= b; ++k) x.push_back(c[k].displacement), y.push_back(c[k].dilation);
        steepest = std::max(steepest, fit_slope(x, y));
    }
    r.peak_dilation_angle = std::atan(steepest) * 180.0 / std::numbers::pi;
}

} // namespace

namespace {

/// The test's machine on a built specimen: the two boxes, the servo on the upper
/// box that holds the normal load (CNL) or follows the normal stiffness (CNS),
/// and what a record measures.
class ShearMachine {
public:
    ShearMachine(Solver& s, const ShearTestOptions& o) : s_(s), o_(o), lower_(s, "lower_"), upper_(s, "upper_") {
        if (lower_.blocks.empty() || upper_.blocks.empty())
            throw std::runtime_error("direct shear: no block on the specimen's faces to hold it");
        const double w = o.width;
        // The servo's stiffness: the rows of bonds of the two halves and the plane in
        // series (per unit area), times the width. The plane is joint over k of its
        // length and bonded rock over the rest.
        const double rows = o.rock.pattern.kind == meshing::PatternSpec::Kind::single ? 0.0 : o.height / o.rock.pattern.size;
        const double plane_kn = o.persistence * o.plane.kn + (1.0 - o.persistence) * o.rock.bonds.kn;
        stiffness_ = w / (rows / o.rock.bonds.kn + 1.0 / plane_kn);
        // Largest box speed, m per step: a thousandth of σn's elastic displacement, or
        // the shear rate itself (a joint dilating at up to 45°, Barton-Bandis's rough
        // joints at low σn, lifts the box about that fast: a slower box let σn run away).
        servo_cap_ = std::max(1e-3 * o.normal_stress * w / stiffness_, o.shear_rate);
    }

    /// The normal stress first: ramped, then settled, the box held horizontally.
    /// Where the box then is, is the origin of the displacement and the dilation.
    void apply_normal_stress() {
        constexpr long ramp = 2000, settle_max = 40000;
        for (long k = 1; k <= ramp; ++k) {
            servo(0.0, target(0.0) * double(k) / double(ramp));
            s_.step();
        }
        for (long k = 0; k < settle_max; ++k) {
            servo(0.0, target(0.0));
            s_.step();
            if (k > 200 && std::abs(upper_.force(s_).y - target(0.0)) < 1e-4 * target(0.0) && s_.world().clock.ratio < 1e-5)
                break;
        }
        start_ = s_.world().clock.steps;
        origin_ = upper_.displacement(s_);
        dilation_origin_ = origin_.y;
    }

    /// Shears to the largest displacement, a point of the curve every
    /// record_every steps; the peak.
    ShearPoint shear(ShearTestResult& r, const std::function<void(const ShearPoint&)>& progress,
                     const std::function<void(const Solver&, const ShearPoint&)>& on_frame) {
        const double w = o_.width;
        r.curve.push_back(measure());
        // The peak at the step: a brittle bond lets go between two records.
        ShearPoint peak = r.curve.front();
        double u = 0.0;
        while (u < o_.max_displacement) {
            const double dilation = upper_.displacement(s_).y - dilation_origin_;
            servo(o_.shear_rate, target(dilation));
            s_.step();
            u = upper_.displacement(s_).x - origin_.x;
            if (0.5 * (lower_.force(s_).x - upper_.force(s_).x) / w > peak.shear_stress) peak = measure();
            if ((s_.world().clock.steps - start_) % o_.record_every != 0) continue;
            const ShearPoint p = measure();
            r.curve.push_back(p);
            const double t = target(p.dilation) / w;
            if (t > 0) r.normal_stress_error = std::max(r.normal_stress_error, std::abs(p.normal_stress - t) / t);
            if (progress) progress(p);
            if (studies::stop_signal_received()) throw Interrupted("interrupted during a shear test"); // as a lab test's
            if (on_frame && o_.frame_every > 0 && (s_.world().clock.steps - start_) % o_.frame_every == 0) on_frame(s_, p);
        }
        return peak;
    }

private:
    /// The normal force wanted at a dilation (constant with no normal stiffness).
    double target(double dilation) const {
        return o_.width * std::max(0.0, o_.normal_stress + o_.normal_stiffness * dilation);
    }

    void servo(double horizontal, double target_force) {
        const double n = upper_.force(s_).y;
        const double vy = std::clamp(o_.servo_gain * (n - target_force) / stiffness_, -servo_cap_, servo_cap_);
        upper_.set_velocity(s_, {horizontal, vy});
    }

    ShearPoint measure() const {
        const double w = o_.width;
        ShearPoint p;
        p.step = s_.world().clock.steps;
        const Vec2 d = upper_.displacement(s_);
        p.displacement = d.x - origin_.x;
        p.dilation = d.y - dilation_origin_;
        p.shear_stress = 0.5 * (lower_.force(s_).x - upper_.force(s_).x) / w;
        p.normal_stress = upper_.force(s_).y / w;
        p.cracks_tensile = cracks(s_.world(), contact::JointState::broken_tension);
        p.cracks_shear = cracks(s_.world(), contact::JointState::broken_shear);
        return p;
    }

    Solver& s_;
    const ShearTestOptions& o_;
    const ShearBox lower_, upper_;
    double stiffness_ = 0.0, servo_cap_ = 0.0;
    long start_ = 0;
    Vec2 origin_{};
    double dilation_origin_ = 0.0;
};

} // namespace

ShearTestResult run_shear_test(const ShearTestOptions& o, const std::function<void(const ShearPoint&)>& progress,
                               const std::function<void(const Solver&, const ShearTestResult&)>& on_finish,
                               const std::function<void(const Solver&, const ShearPoint&)>& on_frame) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto assembly = meshing::generate_blocks(shear_geometry(o));
    Solver s(assembly, shear_analysis(o));
    ShearTestResult r;
    r.seed = o.rock.pattern.seed;
    r.normal_stress = o.normal_stress;
    r.blocks = assembly.block_count();
    r.contacts = contacts(s.world()).size();
    for (const auto& j : assembly.joints) r.plane_joints += j.tag == meshing::JointTag::real_joint;
    ShearMachine machine(s, o);
    machine.apply_normal_stress();
    const ShearPoint peak = machine.shear(r, progress, on_frame);
    shear_figures(r, peak);
    r.cracks_tensile = cracks(s.world(), contact::JointState::broken_tension);
    r.cracks_shear = cracks(s.world(), contact::JointState::broken_shear);
    r.steps = s.world().clock.steps;
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (on_finish) on_finish(s, r);
    return r;
}

namespace studies {

ShearValues::ShearValues() {
    o.plane.name = "plane";
    o.plane.law = "coulomb";
    o.plane.friction = 30.0;
}

namespace {

nlohmann::json shear_json(const ShearTestResult& r) {
    return {{"seed", r.seed},
            {"normal_stress", r.normal_stress},
            {"peak_shear_stress", r.peak_shear_stress},
            {"displacement_at_peak", r.displacement_at_peak},
            {"normal_stress_at_peak", r.normal_stress_at_peak},
            {"residual_shear_stress", r.residual_shear_stress},
            {"residual_normal_stress", r.residual_normal_stress},
            {"dilation_at_peak", r.dilation_at_peak},
            {"final_dilation", r.final_dilation},
            {"peak_dilation_angle_deg", r.peak_dilation_angle},
            {"normal_stress_error", r.normal_stress_error},
            {"blocks", r.blocks},
            {"contacts", r.contacts},
            {"plane_joints", r.plane_joints},
            {"cracks", {{"tensile", r.cracks_tensile}, {"shear", r.cracks_shear}}},
            {"steps", r.steps},
            {"wall_seconds", r.wall_seconds}};
}

nlohmann::json shear_record(const ShearTestResult& r) {
    nlohmann::json j = shear_json(r), curve = nlohmann::json::array();
    for (const auto& p : r.curve)
        curve.push_back({p.step, p.displacement, p.shear_stress, p.normal_stress, p.dilation, p.cracks_tensile, p.cracks_shear});
    j["curve"] = std::move(curve);
    return j;
}

ShearTestResult shear_from_record(const nlohmann::json& j) {
    ShearTestResult r;
    r.seed = j["seed"], r.normal_stress = j["normal_stress"], r.peak_shear_stress = j["peak_shear_stress"];
    r.displacement_at_peak = j["displacement_at_peak"], r.normal_stress_at_peak = j["normal_stress_at_peak"];
    r.residual_shear_stress = j["residual_shear_stress"], r.residual_normal_stress = j["residual_normal_stress"];
    r.dilation_at_peak = j["dilation_at_peak"], r.final_dilation = j["final_dilation"];
    r.peak_dilation_angle = j["peak_dilation_angle_deg"], r.normal_stress_error = j["normal_stress_error"];
    r.blocks = j["blocks"], r.contacts = j["contacts"], r.plane_joints = j["plane_joints"];
    r.cracks_tensile = j["cracks"]["tensile"], r.cracks_shear = j["cracks"]["shear"];
    r.steps = j["steps"], r.wall_seconds = j["wall_seconds"];
    for (const auto& p : j["curve"])
        r.curve.push_back({p[0].get<long>(), p[1].get<double>(), p[2].get<double>(), p[3].get<double>(),
                           p[4].get<double>(), p[5].get<int>(), p[6].get<int>()});
    return r;
}

std::string run_name(double sigma_n, std::uint64_t seed) {
    char b[96];
    std::snprintf(b, sizeof b, "sn_%gMPa_seed_%llu", sigma_n / 1e6, static_cast<unsigned long long>(seed));
    return b;
}

/// A Coulomb line τ = c + σn tan φ through (σn, τ) points.
nlohmann::json coulomb_fit(const std::vector<double>& sn, const std::vector<double>& tau) {
    const LineFit f = fit_line(sn, tau);
    if (!f.valid) return nullptr;
    return {{"cohesion", f.intercept}, {"friction_deg", std::atan(f.slope) * 180.0 / std::numbers::pi}, {"rms", f.rms}};
}

void check_shear_options(ShearValues& v) {
    auto& o = v.o;
    check_joint_flags(o.rock.bonds);
    if (o.rock.material.deformable_fraction > 0.0)
        throw InputError("--deformable-fraction", 0, "",
                         "bbm shear's blocks are rigid: the rock's deformable blocks (its material's "
                         "deformable_fraction) are not tested here");
    // The plane's stiffnesses are the rock's unless given; a softening plane softens as the rock's bonds.
    if (!(o.plane.kn > 0)) o.plane.kn = o.rock.bonds.kn;
    if (!(o.plane.ks > 0)) o.plane.ks = o.rock.bonds.ks;
    if (o.plane.law == "softening") {
        if (o.plane.tension_softening.empty()) o.plane.tension_softening = o.rock.bonds.tension_softening;
        if (o.plane.shear_softening.empty()) o.plane.shear_softening = o.rock.bonds.shear_softening;
    }
    check_joint_flags(o.plane, "joint-");
    const bool single = o.rock.pattern.kind == meshing::PatternSpec::Kind::single;
    if (single && o.persistence < 1.0)
        throw InputError("--persistence", 0, "",
                         "the single pattern has no rock between the joint segments to bridge them: give a block "
                         "pattern (--pattern voronoi) or --persistence 1");
    if (!single && std::min(o.width, 0.5 * o.height) < 3.0 * o.rock.pattern.size * (1.0 - 1e-9))
        throw InputError("--size", 0, "",
                         "blocks of " + fmt_number(o.rock.pattern.size) + " m do not fit: each half needs at least 3 "
                         "blocks across (--size <= " + fmt_number(std::min(o.width, 0.5 * o.height) / 3.0) + ")");
    if (o.persistence > 0 && o.persistence < 1 && o.width / o.bridges * std::min(o.persistence, 1 - o.persistence) < 1e-3 * o.width)
        throw InputError("--bridges", 0, "", "joint segments or bridges shorter than a thousandth of the width");
    if (o.max_displacement <= 10.0 * o.shear_rate)
        throw InputError("--max-displacement", 0, "", "must be many steps of --shear-rate");
    if (!single) {
        meshing::RegionSpec r = shear_geometry(o).regions.front();
        const auto e = meshing::estimate_region(r, o.width * o.height, 0.0);
        const double limit = o.max_elements > 0 ? o.max_elements : meshing::default_max_elements();
        if (!(e.blocks <= limit))
            throw InputError("--size", 0, "", "the specimen asks for about " + fmt_number(std::round(e.blocks)) +
                                                  " blocks, over the limit of " + fmt_number(std::round(limit)));
    }
}

void write_run_files(const ShearTestResult& r, const Solver& s, const std::filesystem::path& dir,
                     std::vector<std::pair<double, std::string>> frames) {
    std::filesystem::create_directories(dir / "vtk");
    io::FailurePlotOptions fo;
    char title[128];
    std::snprintf(title, sizeof title, "direct shear, sigma_n %g MPa, seed %llu: peak %.3g MPa", r.normal_stress / 1e6,
                  static_cast<unsigned long long>(r.seed), r.peak_shear_stress / 1e6);
    fo.title = title;
    io::draw_failure(s.world(), dir / "failure.png", fo);
    io::write_state_blocks_vtu(s.world(), dir / "vtk/blocks_final.vtu");
    io::write_state_contacts_vtu(s.world(), dir / "vtk/contacts_final.vtu");
    frames.push_back({double(r.steps), "vtk/blocks_final.vtu"});
    frames.push_back({double(r.steps), "vtk/contacts_final.vtu"});
    io::write_pvd(dir / "result.pvd", frames);
}

} // namespace

namespace {

/// summary.json of a series: per normal stress the mean and spread of the peak,
/// residual and dilation; the Coulomb lines through the peaks (at the normal
/// stress there, which constant normal stiffness moves) and the residuals; every run.
nlohmann::json shear_summary(const ShearValues& v, const std::vector<ShearTestResult>& results) {
    const int per = v.lab.realizations;
    // The Coulomb lines over the normal stresses (at the peak: σn there, which CNS moves).
    std::vector<double> sn_peak, tau_peak, sn_res, tau_res;
    nlohmann::json runs = nlohmann::json::array();
    for (const auto& r : results) {
        sn_peak.push_back(r.normal_stress_at_peak), tau_peak.push_back(r.peak_shear_stress);
        sn_res.push_back(r.residual_normal_stress), tau_res.push_back(r.residual_shear_stress);
        runs.push_back(shear_json(r));
    }
    auto stats = [&](std::size_t level, auto get) {
        double m = 0, s2 = 0;
        for (int k = 0; k < per; ++k) m += get(results[level * per + k]);
        m /= per;
        for (int k = 0; k < per; ++k) s2 += std::pow(get(results[level * per + k]) - m, 2);
        return nlohmann::json{{"mean", m}, {"std", per > 1 ? std::sqrt(s2 / (per - 1)) : 0.0}};
    };
    nlohmann::json levels = nlohmann::json::array();
    for (std::size_t l = 0; l < v.normal_stresses.size(); ++l)
        levels.push_back({{"normal_stress", v.normal_stresses[l]},
                          {"peak_shear_stress", stats(l, [](const auto& r) { return r.peak_shear_stress; })},
                          {"residual_shear_stress", stats(l, [](const auto& r) { return r.residual_shear_stress; })},
                          {"dilation_at_peak", stats(l, [](const auto& r) { return r.dilation_at_peak; })},
                          {"peak_dilation_angle_deg", stats(l, [](const auto& r) { return r.peak_dilation_angle; })}});
    return nlohmann::json{{"test", "shear"},
                           {"boundary", v.o.normal_stiffness > 0 ? "constant normal stiffness" : "constant normal load"},
                           {"normal_stiffness", v.o.normal_stiffness},
                           {"persistence", v.o.persistence},
                           {"bridges", v.o.bridges},
                           {"width", v.o.width},
                           {"realizations", per},
                           {"levels", levels},
                           {"peak_coulomb", coulomb_fit(sn_peak, tau_peak)},
                           {"residual_coulomb", coulomb_fit(sn_res, tau_res)},
                           {"runs", runs}};
}

/// shear.csv (every run's curve), shear_stress.png and dilation.png.
void write_shear_curves(const std::vector<ShearTestResult>& results, const std::filesystem::path& out) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "normal_stress_Pa,seed,step,shear_displacement_m,shear_stress_Pa,normal_stress_now_Pa,dilation_m,"
           "cracks_tensile,cracks_shear\n";
    std::vector<io::Series> tau, dil;
    for (const auto& r : results) {
        io::Series a{run_name(r.normal_stress, r.seed), {}, {}}, b = a;
        for (const auto& p : r.curve) {
            csv << r.normal_stress << ',' << r.seed << ',' << p.step << ',' << p.displacement << ',' << p.shear_stress
                << ',' << p.normal_stress << ',' << p.dilation << ',' << p.cracks_tensile << ',' << p.cracks_shear << '\n';
            a.x.push_back(1e3 * p.displacement), a.y.push_back(1e-6 * p.shear_stress);
            b.x.push_back(1e3 * p.displacement), b.y.push_back(1e3 * p.dilation);
        }
        tau.push_back(std::move(a)), dil.push_back(std::move(b));
    }
    io::write_text_atomically(out / "shear.csv", csv.str());
    io::draw_curves(tau, "shear displacement (mm)", "shear stress (MPa)", out / "shear_stress.png", "direct shear");
    io::draw_curves(dil, "shear displacement (mm)", "dilation (mm)", out / "dilation.png", "direct shear: dilation");
}

/// The series' figures on the console.
void print_shear_summary(const nlohmann::json& summary) {
    for (const auto& l : summary["levels"])
        std::fprintf(stderr, "sigma_n %6.2f MPa: peak %.3f +- %.3f MPa, residual %.3f MPa\n",
                     l["normal_stress"].get<double>() / 1e6, l["peak_shear_stress"]["mean"].get<double>() / 1e6,
                     l["peak_shear_stress"]["std"].get<double>() / 1e6, l["residual_shear_stress"]["mean"].get<double>() / 1e6);
    if (!summary["peak_coulomb"].is_null())
        std::fprintf(stderr, "peak: c %.3f MPa, phi %.2f deg; residual: c %.3f MPa, phi %.2f deg\n",
                     summary["peak_coulomb"]["cohesion"].get<double>() / 1e6,
                     summary["peak_coulomb"]["friction_deg"].get<double>(),
                     summary["residual_coulomb"]["cohesion"].get<double>() / 1e6,
                     summary["residual_coulomb"]["friction_deg"].get<double>());
}

/// The series on the console: the specimen, the normal stresses and realizations, the mode.
void print_shear_series(const ShearValues& v) {
    const int per = v.lab.realizations;
    std::fprintf(stderr, "bbm shear: %s blocks of %.3g m, %g m x %g m, persistence %g, %zu normal stress%s x %d "
                         "realization%s, %s\n",
                 meshing::to_string(v.o.rock.pattern.kind), v.o.rock.pattern.size, v.o.width, v.o.height, v.o.persistence, v.normal_stresses.size(),
                 v.normal_stresses.size() > 1 ? "es" : "", per, per > 1 ? "s" : "",
                 v.o.normal_stiffness > 0 ? "constant normal stiffness" : "constant normal load");
}

/// The runs of a series, per normal stress and seed (run k: normal stress k / per,
/// seed k % per): each run's test, its files, its lines on the console.
struct ShearSeries {
    const ShearValues& v;
    std::filesystem::path out;
    bool write = false, quiet = false;
    int per = 1, n = 1, available = 1;
    std::mutex print;
    Progress lines; // progress of a single run; every run's result

    ShearSeries(const ShearValues& values, std::filesystem::path dir, bool write_files, bool no_lines, int runs_per_stress,
                int runs, int threads)
        : v(values), out(std::move(dir)), write(write_files), quiet(no_lines), per(runs_per_stress), n(runs),
          available(threads) {}

    /// Run k, its result as the record that travels between ranks.
    std::string run(int k) {
        ShearTestOptions o = v.o;
        o.normal_stress = v.normal_stresses[k / per];
        o.rock.pattern.seed = v.o.rock.pattern.seed + std::uint64_t(k % per);
        o.threads = n == 1 ? available : 1;
        const auto dir = n == 1 ? out : out / run_name(o.normal_stress, o.rock.pattern.seed);
        std::vector<std::pair<double, std::string>> frames;
        const ShearTestResult r = run_shear_test(
            o,
            [&](const ShearPoint& p) {
                if (quiet || n > 1 || !lines.due()) return;
                lines.line("  step %8ld  u %.3e m  tau %7.3f MPa  sigma_n %7.3f MPa  cracks %d", p.step, p.displacement,
                           p.shear_stress / 1e6, p.normal_stress / 1e6, p.cracks_tensile + p.cracks_shear);
            },
            [&](const Solver& s, const ShearTestResult& res) {
                if (write) write_run_files(res, s, dir, frames);
            },
            [&](const Solver& s, const ShearPoint&) {
                if (!write) return;
                std::filesystem::create_directories(dir / "vtk");
                char name[64];
                std::snprintf(name, sizeof name, "vtk/blocks_%08ld.vtu", s.world().clock.steps);
                io::write_state_blocks_vtu(s.world(), dir / name);
                frames.push_back({double(s.world().clock.steps), name});
            });
        if (!quiet) {
            std::lock_guard lock(print);
            lines.result("  sigma_n %6.2f MPa seed %llu: peak %.3f MPa at %.3g mm, residual %.3f MPa, "
                         "dilation %.3g mm (%.1f deg), cracks %d, %ld steps, %.1f s",
                         o.normal_stress / 1e6, static_cast<unsigned long long>(o.rock.pattern.seed), r.peak_shear_stress / 1e6,
                         1e3 * r.displacement_at_peak, r.residual_shear_stress / 1e6, 1e3 * r.final_dilation,
                         r.peak_dilation_angle, r.cracks_tensile + r.cracks_shear, r.steps, r.wall_seconds);
        }
        return shear_record(r).dump();
    }
};

/// A run whose servo missed the normal stress by more than 5%, said on the console.
void warn_servo_misses(const std::vector<ShearTestResult>& results) {
    for (const auto& r : results)
        if (r.normal_stress_error > 0.05 && Ranks::root())
            std::fprintf(stderr,
                         "bbm shear: warning: at sigma_n %g MPa the servo missed the normal stress by up to %.0f%% "
                         "(normal_stress_error in summary.json): the peak is at another normal stress than asked; "
                         "lower --shear-rate or raise --servo-gain\n",
                         r.normal_stress / 1e6, 100.0 * r.normal_stress_error);
}

} // namespace

int run_shear(ShearValues& v, bool quiet, bool check_only, ShearStudy* study) {
    check_shear_options(v);
    if (check_only) return 0;
    const std::filesystem::path out = v.lab.out;
    const bool write = v.lab.write_files;
    if (write) io::make_output_directory(out);
    const int per = v.lab.realizations, n = per * int(v.normal_stresses.size());
    const int available = v.lab.threads > 0 ? v.lab.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    const int side_by_side = std::max(1, std::min(n, available));
    quiet = quiet || !Ranks::root();
    if (!quiet) print_shear_series(v);
    ShearSeries series(v, out, write, quiet, per, n, available);
    std::vector<ShearTestResult> results;
    try {
        for (const auto& text : run_spread(n, n > 1 ? side_by_side : 1, [&](int k) { return series.run(k); }))
            results.push_back(shear_from_record(nlohmann::json::parse(text)));
    } catch (const GeometryError& e) {
        throw InputError("--size", 0, "", e.what());
    }
    warn_servo_misses(results);
    const nlohmann::json summary = shear_summary(v, results);
    if (write && Ranks::root()) {
        write_shear_curves(results, out);
        io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
    }
    if (!quiet) {
        print_shear_summary(summary);
        if (write) std::fprintf(stderr, "wrote %s\n", (out / "summary.json").string().c_str());
    }
    if (study) {
        study->results = std::move(results);
        study->summary_json = summary.dump();
    }
    return 0;
}

} // namespace studies
} // namespace bbm
