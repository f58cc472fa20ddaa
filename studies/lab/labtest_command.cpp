// Running a lab-test command: its realizations over threads and ranks, their
// console lines, files and summary (studies/lab/labtest_command.hpp).
#include "studies/lab/labtest_command.hpp"

#include "base/error.hpp"
#include "base/keys.hpp"
#include "base/progress.hpp"
#include "contact/joint_keys.hpp"
#include "core/solver.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "meshing/blocks.hpp"
#include "studies/cluster/ranks.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <numbers>
#include <sstream>
#include <thread>
#include <vector>

namespace bbm::studies {

namespace fs = std::filesystem;

const char* labtest_name(LabTestOptions::Kind kind) {
    switch (kind) {
    case LabTestOptions::Kind::ucs: return "ucs";
    case LabTestOptions::Kind::tension: return "tension";
    case LabTestOptions::Kind::biaxial: return "biaxial";
    case LabTestOptions::Kind::brazilian: return "brazilian";
    }
    return "ucs";
}

LabTestOptions::Kind labtest_kind(const std::string& command) {
    for (auto k : {LabTestOptions::Kind::ucs, LabTestOptions::Kind::tension, LabTestOptions::Kind::biaxial,
                   LabTestOptions::Kind::brazilian})
        if (command == labtest_name(k)) return k;
    throw InputError(command, 0, "", "not a lab test (ucs, tension, biaxial, brazilian)");
}

LabTestValues labtest_defaults(LabTestOptions::Kind kind) {
    LabTestValues c;
    c.o.kind = kind;
    // Direct tension peaks at a tenth of the strain: loaded ten times slower.
    if (kind == LabTestOptions::Kind::tension) c.o.strain_per_step = 5e-9;
    if (kind == LabTestOptions::Kind::brazilian) c.o.width = 4.0, c.o.strain_per_step = 1e-8;
    return c;
}

namespace {

nlohmann::json labtest_json(const LabTestResult& r) {
    return {{"E", r.E}, {"nu", r.nu}, {"E50", r.E50}, {"linear_limit_stress", r.linear_limit_stress},
            {"peak_stress", r.peak_stress}, {"strain_at_peak", r.strain_at_peak},
            {"crack_initiation_stress", r.crack_initiation_stress}, {"crack_damage_stress", r.crack_damage_stress},
            {"tensile_strength", r.tensile_strength}, {"blocks", r.blocks}, {"contacts", r.contacts},
            {"steps", r.steps}, {"wall_seconds", r.wall_seconds}, {"peak_passed", r.peak_passed}, {"still_loading", r.still_loading},
            {"loaded_past_max_strain", r.loaded_past_max_strain},
            {"post_peak_locking", r.post_peak_locking}, {"reloads", r.reloads}, {"first_stall_stress", r.first_stall_stress}, {"preload_skipped", r.preload_skipped},
            {"residual_stress", r.residual_stress}, {"residual_friction_angle", r.residual_friction_angle},
            {"joint_slip_stress", r.joint_slip_stress}, {"joint_slip_stress_half", r.joint_slip_stress_half},
            {"cracks", {{"tensile", r.cracks_tensile}, {"shear", r.cracks_shear}}},
            {"events", {{"count", r.events}, {"at_peak", r.events_at_peak}, {"b_value", r.b_value},
                        {"crack_initiation_stress", r.crack_initiation_events}}},
            {"crack_orientation", {{"bin_degrees", 15}, {"counts", r.crack_orientation},
                                   {"within_30_of_vertical", r.cracks_near_vertical},
                                   {"within_30_of_horizontal", r.cracks_near_horizontal},
                                   {"within_30_of_vertical_at_peak", r.cracks_near_vertical_at_peak},
                                   {"within_30_of_horizontal_at_peak", r.cracks_near_horizontal_at_peak}}}};
}

/// A realization's result as it travels between ranks: the summary fields and the
/// curve (doubles as JSON numbers round-trip exactly).
nlohmann::json labtest_record(const LabTestResult& r) {
    nlohmann::json j = labtest_json(r);
    j["linear_limit_stress"] = r.linear_limit_stress;
    nlohmann::json curve = nlohmann::json::array();
    for (const auto& p : r.curve)
        curve.push_back({p.step, p.axial_strain, p.axial_stress, p.lateral_strain, p.cracks_tensile, p.cracks_shear,
                         p.unbalanced_ratio, p.strain_per_step, p.events});
    j["curve"] = std::move(curve);
    return j;
}

LabTestResult labtest_from_record(const nlohmann::json& j) {
    LabTestResult r;
    r.E = j["E"], r.nu = j["nu"], r.E50 = j["E50"], r.linear_limit_stress = j["linear_limit_stress"];
    r.peak_stress = j["peak_stress"], r.strain_at_peak = j["strain_at_peak"];
    r.crack_initiation_stress = j["crack_initiation_stress"], r.crack_damage_stress = j["crack_damage_stress"];
    r.tensile_strength = j["tensile_strength"], r.blocks = j["blocks"], r.contacts = j["contacts"];
    r.steps = j["steps"], r.wall_seconds = j["wall_seconds"], r.peak_passed = j["peak_passed"];
    r.post_peak_locking = j["post_peak_locking"], r.preload_skipped = j["preload_skipped"];
    r.still_loading = j.value("still_loading", false);
    r.loaded_past_max_strain = j.value("loaded_past_max_strain", false);
    r.reloads = j.value("reloads", 0);
    r.first_stall_stress = j.value("first_stall_stress", 0.0);
    r.residual_stress = j.value("residual_stress", 0.0);
    r.residual_friction_angle = j.value("residual_friction_angle", 0.0);
    r.joint_slip_stress = j["joint_slip_stress"], r.joint_slip_stress_half = j["joint_slip_stress_half"];
    r.cracks_tensile = j["cracks"]["tensile"], r.cracks_shear = j["cracks"]["shear"];
    if (j.contains("events")) {
        const auto& e = j["events"];
        r.events = e["count"], r.events_at_peak = e["at_peak"], r.b_value = e["b_value"];
        r.crack_initiation_events = e["crack_initiation_stress"];
    }
    const auto& o = j["crack_orientation"];
    r.crack_orientation = o["counts"].get<std::array<int, 12>>();
    r.cracks_near_vertical = o["within_30_of_vertical"], r.cracks_near_horizontal = o["within_30_of_horizontal"];
    r.cracks_near_vertical_at_peak = o["within_30_of_vertical_at_peak"];
    r.cracks_near_horizontal_at_peak = o["within_30_of_horizontal_at_peak"];
    for (const auto& p : j["curve"])
        r.curve.push_back({p[0].get<long>(), p[1].get<double>(), p[2].get<double>(), p[3].get<double>(),
                           p[4].get<int>(), p[5].get<int>(), p[6].get<double>(), p[7].get<double>(),
                           p.size() > 8 ? p[8].get<int>() : 0});
    return r;
}

/// The failure series: one frame of blocks and contacts every `frame_every` steps,
/// named by step; `frames` collects them for result.pvd.
void write_labtest_frame(const Solver& s, const fs::path& dir, std::vector<std::pair<double, std::string>>& frames) {
    fs::create_directories(dir / "vtk");
    char name[64];
    std::snprintf(name, sizeof name, "vtk/blocks_%08ld.vtu", s.world().clock.steps);
    io::write_state_blocks_vtu(s.world(), dir / name);
    frames.push_back({double(s.world().clock.steps), name});
    std::snprintf(name, sizeof name, "vtk/contacts_%08ld.vtu", s.world().clock.steps);
    io::write_state_contacts_vtu(s.world(), dir / name);
    frames.push_back({double(s.world().clock.steps), name});
}

void write_labtest_files(const LabTestResult& r, const Solver& s, const fs::path& dir, const std::string& title,
                         std::vector<std::pair<double, std::string>> frames) {
    fs::create_directories(dir / "vtk");
    std::ostringstream csv;
    csv << "step,axial_strain,axial_stress_Pa,lateral_strain,cracks_tensile,cracks_shear,unbalanced_ratio,"
           "strain_per_step,events\n";
    csv.precision(10);
    // Stress against the axial, lateral (expansion negative) and volumetric strains,
    // as Martin & Chandler draw them, with σci and σcd marked.
    io::Series axial{"axial", {}, {}}, lateral{"lateral", {}, {}}, volumetric{"volumetric", {}, {}};
    for (const auto& p : r.curve) {
        csv << p.step << ',' << p.axial_strain << ',' << p.axial_stress << ',' << p.lateral_strain << ','
            << p.cracks_tensile << ',' << p.cracks_shear << ',' << p.unbalanced_ratio << ',' << p.strain_per_step
            << ',' << p.events << '\n';
        const double sigma = 1e-6 * p.axial_stress;
        axial.x.push_back(1e3 * p.axial_strain), axial.y.push_back(sigma);
        lateral.x.push_back(-1e3 * p.lateral_strain), lateral.y.push_back(sigma);
        volumetric.x.push_back(1e3 * (p.axial_strain - p.lateral_strain)), volumetric.y.push_back(sigma);
    }
    io::write_text_atomically(dir / "stress_strain.csv", csv.str());
    std::vector<io::Series> curves{axial};
    if (r.crack_initiation_stress > 0.0) {
        curves.push_back(lateral), curves.push_back(volumetric);
        double x0 = 0.0, x1 = 0.0;
        for (const auto& c : curves) x0 = std::min(x0, *std::min_element(c.x.begin(), c.x.end())), x1 = std::max(x1, *std::max_element(c.x.begin(), c.x.end()));
        for (const auto& [name, stress] : {std::pair{"sigma_ci", r.crack_initiation_stress}, std::pair{"sigma_cd", r.crack_damage_stress}})
            curves.push_back({name, {x0, x1}, {1e-6 * stress, 1e-6 * stress}});
    }
    char label[200];
    std::snprintf(label, sizeof label, "%s: E = %.2f GPa, peak = %.2f MPa, sigma_ci %.1f, sigma_cd %.1f MPa", title.c_str(),
                  r.E / 1e9, r.peak_stress / 1e6, r.crack_initiation_stress / 1e6, r.crack_damage_stress / 1e6);
    io::draw_curves(curves, "strain (1e-3): axial, lateral, volumetric", "axial stress (MPa)", dir / "stress_strain.png",
                    label);
    io::FailurePlotOptions fo;
    fo.title = title;
    io::draw_failure(s.world(), dir / "failure.png", fo);
    io::draw_failure(s.world(), dir / "failure.svg", fo);
    io::write_state_blocks_vtu(s.world(), dir / "vtk/blocks_final.vtu");
    io::write_state_contacts_vtu(s.world(), dir / "vtk/contacts_final.vtu");
    if (!frames.empty() && frames.back().first == double(r.steps)) frames.resize(frames.size() - 2);
    frames.push_back({double(r.steps), "vtk/blocks_final.vtu"});
    frames.push_back({double(r.steps), "vtk/contacts_final.vtu"});
    io::write_pvd(dir / "result.pvd", frames);
    io::write_text_atomically(dir / "summary.json", labtest_json(r).dump(2) + "\n");
}

} // namespace

void check_joint_flags(const JointPropertySpec& joint, std::string_view prefix) {
    if (const auto problem = contact::check_joint_property(joint))
        throw InputError(key_flag(problem->key, prefix), 0, "", problem->message);
}

std::string fmt_number(double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", v);
    return b;
}


namespace {
/// The flag behind a key of the specimen's region (GeometryError from the generator).
std::string labtest_flag(const std::string& key) {
    if (key == "pattern.size") return "--size";
    if (key == "mesh.size") return "--mesh-size";
    return "--width/--height";
}
} // namespace

/// Refuses, before anything is generated, a specimen narrower than a few blocks or
/// asking for more blocks and triangles than the limit.
void check_specimen_size(const LabTestValues& c) {
    const auto& o = c.o;
    const bool disc = o.kind == LabTestOptions::Kind::brazilian;
    const double width = o.width, height = disc ? o.width : o.height;
    if (std::min(width, height) < 3.0 * o.rock.pattern.size)
        throw InputError("--size", 0, "",
                         "blocks of " + fmt_number(o.rock.pattern.size) + " m do not fit a specimen " + fmt_number(width) + " m x " +
                             fmt_number(height) + " m: give at least 3 blocks across (--size <= " +
                             fmt_number(std::min(width, height) / 3.0) + ")");
    const auto geometry = labtest_geometry(o);
    const double area = disc ? std::numbers::pi / 4.0 * width * width : width * height;
    const auto e = meshing::estimate_region(geometry.regions.front(), area, 0.0);
    const double limit = o.max_elements > 0 ? o.max_elements : meshing::default_max_elements();
    if (!(e.blocks + e.zones <= limit)) {
        const bool zones = e.zones > e.blocks;
        throw InputError(zones ? "--mesh-size" : "--size", 0, "",
                         "the specimen asks for about " + fmt_number(std::round(e.blocks)) + " blocks and " +
                             fmt_number(std::round(e.zones)) + " triangles (about " + fmt_number(std::round(e.bytes() / 1e8) / 10) +
                             " GB), over the limit of " + fmt_number(std::round(limit)) +
                             (o.max_elements > 0 ? " (--max-elements)" : " (half of this machine's memory)") +
                             ": give a larger size, or raise --max-elements if the machine has the memory");
    }
}


void prepare_labtest(LabTestValues& c, LabTestOptions::Kind kind) {
    auto& o = c.o;
    o.kind = kind;
    if (o.rock.pattern.kind == meshing::PatternSpec::Kind::single)
        throw InputError("--pattern", 0, "", "a lab specimen is cut from bonded blocks: give a block pattern (voronoi, "
                                             "trigon, delaunay, hexagonal, brick), not single");
    check_joint_flags(o.rock.bonds);
    if (o.joint_set.on) check_joint_flags(o.joint_set.joint, "joint-set-");
    if (o.platen_friction >= 0.0 && (kind == LabTestOptions::Kind::tension || kind == LabTestOptions::Kind::brazilian))
        throw InputError("--platen-friction", 0, "",
                         std::string("applies to ucs and biaxial only: ") + labtest_name(kind) +
                             " needs platens that hold the specimen (use --platens rough or smooth)");
    if (o.joint_set.on && kind == LabTestOptions::Kind::brazilian)
        throw InputError("--joint-set-angle", 0, "", "a joint set crosses rectangular specimens: not the brazilian disc");
    if (o.joint_set.on && o.joint_set.spacing > 0 && o.joint_set.spacing < o.rock.pattern.size)
        throw InputError("--joint-set-spacing", 0, "", "closer than a block size (--size)");
    check_specimen_size(c);
}

std::string labtest_record_text(const LabTestResult& r) { return labtest_record(r).dump(); }

LabTestResult labtest_from_record_text(const std::string& text) {
    return labtest_from_record(nlohmann::json::parse(text));
}

namespace {

/// One realization's result on the console, with what a reader needs to know
/// about it (a preload skipped, still loading at the strain cap, hardened past
/// yield, reloads, the residual strength, post-peak locking).
void print_realization(Progress& lines, const LabTestOptions& ok, const LabTestResult& r) {
    lines.result("  seed %llu: E %.2f GPa (E50 %.2f)  nu %.3f  peak %.2f MPa at strain %.3e  "
                 "sigma_ci %.2f  sigma_cd %.2f MPa  cracks %d T %d S  %ld steps  %.1f s",
                 static_cast<unsigned long long>(ok.rock.pattern.seed), r.E / 1e9, r.E50 / 1e9, r.nu, r.peak_stress / 1e6,
                 r.strain_at_peak, r.crack_initiation_stress / 1e6, r.crack_damage_stress / 1e6,
                 r.cracks_tensile, r.cracks_shear, r.steps, r.wall_seconds);
    if (r.preload_skipped)
        std::fprintf(stderr, "  seed %llu: the confinement left blocks the implicit preload cannot solve "
                             "(held at one point, or loose): loaded explicitly from the start\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed));
    if (r.still_loading)
        std::fprintf(stderr, "  seed %llu: still loading at the strain cap %g, not failed: the peak is a "
                             "lower bound of the strength (jammed blocks, or raise --strain-cap)\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed), std::max(ok.stop.max_strain, ok.stop.strain_cap));
    else if (r.loaded_past_max_strain)
        std::fprintf(stderr, "  seed %llu: not failed at --max-strain %g: loaded on, failed at strain %.4g\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed), ok.stop.max_strain, r.strain_at_peak);
    if (ok.confinement > 0.0 && r.hardened_past_yield())
        std::fprintf(stderr, "  seed %llu: yielded at %.2f MPa (the stress's first stall) and hardened to its "
                             "peak, %.0f%% higher: broken blocks interlocking (a residual friction below "
                             "the joints' lets them slide; docs/calibration.md, The confined peak)\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed), r.first_stall_stress / 1e6,
                     100.0 * (r.peak_stress / r.first_stall_stress - 1.0));
    if (r.reloads > 0)
        std::fprintf(stderr, "  seed %llu: the stress dropped by --failure-drop and climbed back above its "
                             "peak %d time%s (bursts of cracks): loaded on to the peak that lasted\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed), r.reloads, r.reloads == 1 ? "" : "s");
    if (r.residual_stress > 0.0) {
        std::fprintf(stderr, "  seed %llu: residual strength %.2f MPa (the last %.1f%% of axial strain, %.2g%% "
                             "to %.2g%%)",
                     static_cast<unsigned long long>(ok.rock.pattern.seed), r.residual_stress / 1e6,
                     100.0 * residual_window_strain, 100.0 * (r.curve.back().axial_strain - residual_window_strain),
                     100.0 * r.curve.back().axial_strain);
        if (r.residual_friction_angle > 0.0)
            std::fprintf(stderr, "; with no cohesion left it mobilises a friction of %.1f degrees",
                         r.residual_friction_angle);
        std::fprintf(stderr, "\n");
    }
    if (r.post_peak_locking)
        std::fprintf(stderr, "  seed %llu: after failing, the stress climbed back above the peak (fragments "
                             "jammed between the platens): stopped there; peak is the strength before failure\n",
                     static_cast<unsigned long long>(ok.rock.pattern.seed));
}

/// The summary of several realizations: the mean and standard deviation of each
/// figure, and every realization's own.
nlohmann::json realizations_summary(const char* name, const std::vector<LabTestResult>& results) {
    const int n = int(results.size());
    auto stats = [&](auto get) {
        double m = 0, v = 0;
        for (const auto& r : results) m += get(r);
        m /= n;
        for (const auto& r : results) v += (get(r) - m) * (get(r) - m);
        return nlohmann::json{{"mean", m}, {"std", n > 1 ? std::sqrt(v / (n - 1)) : 0.0}};
    };
    nlohmann::json per = nlohmann::json::array();
    for (const auto& r : results) per.push_back(labtest_json(r));
    return nlohmann::json{{"test", name},
                          {"realizations", n},
                          {"E", stats([](const LabTestResult& r) { return r.E; })},
                          {"nu", stats([](const LabTestResult& r) { return r.nu; })},
                          {"E50", stats([](const LabTestResult& r) { return r.E50; })},
                          {"peak_stress", stats([](const LabTestResult& r) { return r.peak_stress; })},
                          {"strain_at_peak", stats([](const LabTestResult& r) { return r.strain_at_peak; })},
                          {"crack_initiation_stress", stats([](const LabTestResult& r) { return r.crack_initiation_stress; })},
                          {"crack_damage_stress", stats([](const LabTestResult& r) { return r.crack_damage_stress; })},
                          {"per_realization", per}};
}

/// A lab test's realizations (seeds from the pattern's on): each one's test, its
/// files, its lines on the console.
struct Realizations {
    const LabTestValues& c;
    const char* name;
    fs::path out;
    bool write = false, quiet = false, one_at_a_time = false;
    int n = 1, threads_for_loop = 1;
    std::mutex print;
    Progress lines; // progress of a single realization; every realization's result

    Realizations(const LabTestValues& values, const char* test, bool no_lines, bool deformable, int threads)
        : c(values), name(test), out(values.out), write(values.write_files), quiet(no_lines), one_at_a_time(deformable),
          n(values.realizations), threads_for_loop(threads) {}

    /// Realization k, its result as the record that travels between ranks.
    std::string run(int k) {
        const LabTestOptions& o = c.o;
        try {
            LabTestOptions ok = o;
            ok.rock.pattern.seed = o.rock.pattern.seed + k;
            // One realization (or one at a time): its threads go to the contact loop;
            // several side by side: one each.
            ok.threads = n == 1 || one_at_a_time ? threads_for_loop : 1;
            const fs::path dir = n > 1 ? out / ("realization_" + std::to_string(k + 1)) : out;
            auto progress = [&](const StressStrainPoint& p) {
                if (quiet || n > 1 || !lines.due()) return;
                lines.line("  step %8ld  strain %.3e  stress %7.2f MPa  cracks %5d T %5d S", p.step, p.axial_strain,
                           p.axial_stress / 1e6, p.cracks_tensile, p.cracks_shear);
            };
            std::vector<std::pair<double, std::string>> frames;
            using Finish = std::function<void(const Solver&, const LabTestResult&)>;
            using Frame = std::function<void(const Solver&, const StressStrainPoint&)>;
            const LabTestResult r = run_labtest(
                ok, progress,
                write ? Finish([&](const Solver& s, const LabTestResult& res) {
                    char title[64];
                    std::snprintf(title, sizeof title, "%s, seed %llu", name, static_cast<unsigned long long>(ok.rock.pattern.seed));
                    write_labtest_files(res, s, dir, title, frames);
                })
                      : Finish(),
                write || c.on_frame ? Frame([&](const Solver& s, const StressStrainPoint& p) {
                    if (write) write_labtest_frame(s, dir, frames);
                    if (c.on_frame) c.on_frame(s, p, k);
                })
                                    : Frame());
            if (!quiet) {
                std::lock_guard lock(print);
                print_realization(lines, ok, r);
            }
            return labtest_record(r).dump();
        } catch (const GeometryError& e) {
            throw InputError(labtest_flag(e.key()), 0, "", e.what());
        }
    }
};

/// The summary of several realizations, written to summary.json and its means said.
nlohmann::json summarise_realizations(const char* name, const std::vector<LabTestResult>& results, const fs::path& out,
                                      bool write, bool quiet) {
    const int n = int(results.size());
    nlohmann::json summary = realizations_summary(name, results);
    if (write && Ranks::root()) io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
    if (!quiet)
        std::fprintf(stderr, "mean of %d: E %.2f GPa, nu %.3f, peak %.2f MPa%s%s\n", n,
                     summary["E"]["mean"].get<double>() / 1e9, summary["nu"]["mean"].get<double>(),
                     summary["peak_stress"]["mean"].get<double>() / 1e6, write ? "; wrote " : "",
                     write ? (out / "summary.json").string().c_str() : "");
    return summary;
}

} // namespace

int run_labtest_command(LabTestValues& c, LabTestOptions::Kind kind, bool quiet, bool check_only, LabTestStudy* study) {
    const char* name = labtest_name(kind);
    auto& o = c.o;
    prepare_labtest(c, kind);
    if (check_only) return 0;
    const fs::path out = c.out;
    const bool write = c.write_files;
    if (write) io::make_output_directory(out);
    const int n = c.realizations;
    const int available = c.threads > 0 ? c.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    // Deformable specimens: realizations one at a time, each with the threads in its
    // contact loop. Side by side in one process a 4 x 8 m f = 0.95 specimen gave,
    // rarely (2 runs of about 40), another answer than alone — a thread-safety
    // fault around meshing not found yet (docs/notes/2026-11-28-calibration-history.md,
    // What the programs do).
    const bool one_at_a_time = o.rock.material.deformable_fraction > 0.0;
    const int threads = one_at_a_time ? 1 : std::max(1, std::min(n, available));
    const int threads_for_loop = available;
    const int shown_threads = n > 1 && !one_at_a_time ? threads : threads_for_loop;
    // Progress from rank 0 only; the others run quietly.
    quiet = quiet || !Ranks::root();
    if (!quiet)
        std::fprintf(stderr, "bbm %s: %s blocks of %.3g m, %g m x %g m, %d realization%s on %d thread%s%s\n", name,
                     meshing::to_string(o.rock.pattern.kind), o.rock.pattern.size, o.width, kind == LabTestOptions::Kind::brazilian ? o.width : o.height, n,
                     n > 1 ? "s" : "", shown_threads, shown_threads > 1 ? "s" : "",
                     Ranks::size() > 1 ? (" per rank, " + std::to_string(Ranks::size()) + " ranks").c_str() : "");
    Realizations realizations(c, name, quiet, one_at_a_time, threads_for_loop);
    // Realizations over ranks (k mod ranks) and threads; every rank gets them all.
    std::vector<LabTestResult> results;
    for (const auto& text : run_spread(n, n > 1 ? threads : 1, [&](int k) { return realizations.run(k); }))
        results.push_back(labtest_from_record(nlohmann::json::parse(text)));
    const nlohmann::json summary = n == 1  ? labtest_json(results[0])
                                   : n > 1 ? summarise_realizations(name, results, out, write, quiet)
                                           : nlohmann::json();
    if (study) {
        study->results = std::move(results);
        study->summary_json = summary.dump();
    }
    return 0;
}

} // namespace bbm::studies
