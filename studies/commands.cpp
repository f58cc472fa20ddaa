#include "studies/commands.hpp"

#include "base/progress.hpp"
#include "contact/joint_keys.hpp"
#include "core/material_keys.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "base/error.hpp"
#include "core/solver.hpp"
#include "meshing/blocks.hpp"
#include "studies/calibrate.hpp"
#include "studies/envelope.hpp"
#include "studies/cli_checks.hpp"
#include "studies/labtest.hpp"
#include "studies/model_rock.hpp"
#include "studies/ranks.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>
#include <thread>
#include <vector>

namespace bbm::studies {


using namespace bbm;
namespace cli = bbm::cli;
namespace fs = std::filesystem;



namespace {

nlohmann::json mesh_summary(const meshing::BlockAssembly& a, const meshing::GenerationStats& st,
                            double seconds) {
    using nlohmann::json;
    double total_area = 0.0, inner_area = 0.0;
    int inner_blocks = 0;
    double min_edge = INFINITY;
    for (int b = 0; b < a.block_count(); ++b) {
        total_area += a.area[b];
        if (a.pattern[b] == meshing::PatternSpec::Kind::single) continue;
        inner_area += a.area[b];
        ++inner_blocks;
        const auto p = a.block(b);
        for (std::size_t i = 0; i < p.size(); ++i) min_edge = std::min(min_edge, norm(p[(i + 1) % p.size()] - p[i]));
    }
    json regions = json::array();
    for (int r = 0; r < int(a.region_names.size()); ++r) {
        int n = 0;
        double area = 0.0;
        meshing::PatternSpec::Kind kind{};
        for (int b = 0; b < a.block_count(); ++b)
            if (a.region[b] == r) ++n, area += a.area[b], kind = a.pattern[b];
        regions.push_back({{"name", a.region_names[r]},
                           {"pattern", n ? meshing::to_string(kind) : "none"},
                           {"blocks", n},
                           {"area", area},
                           {"target_size", a.region_size[r]},
                           {"mean_feret_diameter", meshing::mean_feret_diameter(a, r)},
                           {"equal_area_diameter", meshing::mean_block_size(a, r)}});
    }
    std::map<std::string, int> tags;
    for (const auto& j : a.joints) ++tags[meshing::to_string(j.tag)];
    // The fracture network as built against what was asked (meshing/dfn.hpp).
    json fracture_sets = json::array();
    for (std::size_t k = 0; k < a.fracture_stats.size(); ++k) {
        const auto& f = a.fracture_stats[k];
        fracture_sets.push_back({{"name", f.name},
                                 {"source", f.source},
                                 {"region", a.region_names[a.fracture_sets[k].region]},
                                 {"fractures", f.fractures},
                                 {"traces", f.traces},
                                 {"P20", f.p20},
                                 {"P21", f.p21},
                                 {"P21_target", f.p21_target},
                                 {"P10_x", f.p10_x},
                                 {"P10_y", f.p10_y},
                                 {"mean_angle", f.mean_angle},
                                 {"concentration", f.concentration},
                                 {"mean_length", f.mean_length},
                                 {"std_length", f.std_length},
                                 {"mean_length_target", f.mean_length_target},
                                 {"mean_trace_length", f.mean_trace}});
    }
    return {{"blocks", a.block_count()},
            {"joints", a.joints.size()},
            {"joints_by_tag", tags},
            {"total_area", total_area},
            {"inner_blocks", inner_blocks},
            {"equal_area_diameter",
             inner_blocks ? std::sqrt(4.0 * inner_area / inner_blocks / 3.141592653589793) : 0.0},
            {"min_edge_length", inner_blocks ? min_edge : 0.0},
            {"collapsed_edges", st.collapsed_edges},
            {"short_edges_left", st.short_edges_left},
            {"merged_slivers", st.merged_slivers},
            {"slivers_left", st.slivers_left},
            {"merged_trace_length", st.merged_trace_length},
            {"rock_bridges", st.rock_bridges},
            {"hole_cuts", st.hole_cuts},
            {"regions", regions},
            {"fracture_sets", fracture_sets},
            {"seconds", {{"regions", st.seconds_regions},
                         {"patterns", st.seconds_patterns},
                         {"topology", st.seconds_topology},
                         {"total", seconds}}}};
}

} // namespace

int run_mesh(const MeshCommand& command, bool quiet, bool check_only) {
    const std::string& model_path = command.model;
    const fs::path& out = command.out;
    const double max_elements = command.max_elements;
    io::PictureOptions picture;
    if (command.window.size() == 4) {
        const auto& w = command.window;
        if (!(w[2] > w[0] && w[3] > w[1])) throw InputError("--window", 0, "", "needs XMIN < XMAX and YMIN < YMAX");
        picture.window.add({w[0], w[1]});
        picture.window.add({w[2], w[3]});
    }
    const auto t0 = std::chrono::steady_clock::now();
    io::ModelFile model = io::read_model(model_path);
    if (max_elements > 0) model.geometry.max_elements = max_elements;
    meshing::GenerationStats stats;
    meshing::BlockAssembly blocks;
    try {
        blocks = meshing::generate_blocks(model.geometry, &stats);
    } catch (const GeometryError& e) {
        throw io::to_input_error(model.source, e);
    }
    if (check_only) return 0;
    io::make_output_directory(out);
    io::write_blocks_vtu(blocks, out / "blocks.vtu");
    io::write_joints_vtu(blocks, out / "joints.vtu");
    if (!blocks.fracture_traces.empty()) io::write_fractures_vtu(blocks, out / "fractures.vtu");
    io::draw_blocks(blocks, out / "blocks.png", picture);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto summary = mesh_summary(blocks, stats, seconds);
    io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
    if (!quiet) {
        std::printf("%s: %d blocks, %zu joints, area %.6g m² (%.2f s)\n", model_path.c_str(),
                    blocks.block_count(), blocks.joints.size(), summary["total_area"].get<double>(), seconds);
        for (const auto& r : summary["regions"])
            std::printf("  region %-12s %-9s %7d blocks  %10.4f m²  mean Feret diameter %.4g m, equal-area "
                        "diameter %.4g m\n",
                        r["name"].get<std::string>().c_str(), r["pattern"].get<std::string>().c_str(),
                        r["blocks"].get<int>(), r["area"].get<double>(), r["mean_feret_diameter"].get<double>(),
                        r["equal_area_diameter"].get<double>());
        if (stats.slivers_left > 0)
            std::printf("  warning: %d blocks under 1e-8 of a block's area had no neighbour to merge into\n",
                        stats.slivers_left);
        for (const auto& f : summary["fracture_sets"]) {
            std::printf("  fracture set %-8s %6d fractures, P21 %.4g /m", f["name"].get<std::string>().c_str(),
                        f["fractures"].get<int>(), f["P21"].get<double>());
            if (f["P21_target"].get<double>() > 0) std::printf(" (asked %.4g)", f["P21_target"].get<double>());
            std::printf(", P20 %.4g /m², P10 %.4g (x) %.4g (y) /m, mean angle %.1f° (κ %.3g), length %.3g ± %.3g m",
                        f["P20"].get<double>(), f["P10_x"].get<double>(), f["P10_y"].get<double>(),
                        f["mean_angle"].get<double>(), f["concentration"].get<double>(), f["mean_length"].get<double>(),
                        f["std_length"].get<double>());
            if (f["mean_length_target"].get<double>() > 0)
                std::printf(" (asked mean %.3g)", f["mean_length_target"].get<double>());
            if (f["source"] != "generated") std::printf("\n    from %s", f["source"].get<std::string>().c_str());
            std::printf("\n");
        }
        std::printf("  wrote %s/{blocks.vtu, joints.vtu%s, blocks.png, summary.json}\n", out.string().c_str(),
                    blocks.fracture_traces.empty() ? "" : ", fractures.vtu");
    }
    return 0;
}



namespace {

const char* labtest_name(LabTestOptions::Kind kind) {
    switch (kind) {
    case LabTestOptions::Kind::ucs: return "ucs";
    case LabTestOptions::Kind::tension: return "tension";
    case LabTestOptions::Kind::biaxial: return "biaxial";
    case LabTestOptions::Kind::brazilian: return "brazilian";
    }
    return "ucs";
}

} // namespace

LabTestOptions::Kind labtest_kind(const std::string& command) {
    for (auto k : {LabTestOptions::Kind::ucs, LabTestOptions::Kind::tension, LabTestOptions::Kind::biaxial,
                   LabTestOptions::Kind::brazilian})
        if (command == labtest_name(k)) return k;
    throw InputError(command, 0, "", "not a lab test (ucs, tension, biaxial, brazilian)");
}

LabTestCli labtest_defaults(LabTestOptions::Kind kind) {
    LabTestCli c;
    c.o.kind = kind;
    // Direct tension peaks at a tenth of the strain: loaded ten times slower.
    if (kind == LabTestOptions::Kind::tension) c.o.strain_per_step = 5e-9;
    if (kind == LabTestOptions::Kind::brazilian) c.o.width = 4.0, c.o.strain_per_step = 1e-8;
    return c;
}

const char* const max_elements_help =
    "Largest number of blocks plus triangles the model may ask for (estimated before generating; default: what "
    "fits in half of this machine's memory)";

template <class Spec>
void add_key_flags(CLI::App* cmd, Spec& spec, std::span<const Key<Spec>> table, std::span<const std::string_view> keys,
                   std::string_view prefix, std::string_view help_prefix) {
    auto find = [table](std::string_view key) -> const Key<Spec>* {
        for (const Key<Spec>& k : table)
            if (k.key == key) return &k;
        return nullptr;
    };
    for (const std::string_view key : keys) {
        const Key<Spec>* k = find(key);
        if (!k || (k->kind != KeyKind::number && k->kind != KeyKind::integer))
            throw std::logic_error("add_key_flags: " + std::string(key) + " is not a declared number");
        // The key's meaning in the flags' words: other keys named by their flags.
        std::string meaning;
        for (std::size_t at = 0; at < k->meaning.size();) {
            std::size_t end = at;
            while (end < k->meaning.size() &&
                   (std::islower(static_cast<unsigned char>(k->meaning[end])) || k->meaning[end] == '_'))
                ++end;
            const std::string_view word = k->meaning.substr(at, std::max(end, at + 1) - at);
            const bool key_name = word.find('_') != std::string_view::npos && find(word);
            meaning += key_name ? key_flag(word, prefix) : std::string(word);
            at += word.size();
        }
        std::string help = std::string(help_prefix) + meaning;
        if (!k->bounds.unit.empty()) help += " (" + std::string(k->bounds.unit.substr(1)) + ")";
        const double now = k->get(spec);
        const bool has_default = k->bounds.contains(now);
        if (!has_default && !k->absent.empty()) help += "; if not given: " + std::string(k->absent);
        std::string names = key_flag(key, prefix);
        if (key == "weibull_modulus" && prefix.empty()) names += ",--weibull-m"; // its name before the keys were shared
        auto set = k->set;
        CLI::Option* opt = cmd->add_option_function<double>(names, [&spec, set](double v) { set(spec, v); }, help);
        const bool whole = k->kind == KeyKind::integer;
        opt->check(whole ? cli::whole_within(k->bounds) : cli::within(k->bounds));
        opt->type_name(whole ? "INT" : "FLOAT");
        if (has_default) opt->default_str(shortest_text(now));
    }
}
template void add_key_flags(CLI::App*, JointPropertySpec&, std::span<const Key<JointPropertySpec>>,
                            std::span<const std::string_view>, std::string_view, std::string_view);
template void add_key_flags(CLI::App*, MaterialSpec&, std::span<const Key<MaterialSpec>>,
                            std::span<const std::string_view>, std::string_view, std::string_view);

void add_joint_flags(CLI::App* cmd, JointPropertySpec& joint, std::span<const std::string_view> keys,
                     std::string_view prefix, std::string_view help_prefix) {
    add_key_flags(cmd, joint, std::span<const contact::JointKey>(contact::joint_keys), keys, prefix, help_prefix);
}

void check_joint_flags(const JointPropertySpec& joint, std::string_view prefix) {
    if (const auto problem = contact::check_joint_property(joint))
        throw InputError(contact::joint_flag(problem->key, prefix), 0, "", problem->message);
}

namespace {

/// The flags of the rock (its bonds, material and block pattern): given beside
/// --rock, each overrides the file's value.
struct RockFlag {
    const char* flag;
    void (*keep)(LabTestCli& to, const LabTestCli& given);
};
#define BBM_ROCK_FLAG(flag, field) {flag, [](LabTestCli& to, const LabTestCli& given) { to.field = given.field; }}
constexpr RockFlag rock_flags[] = {
    BBM_ROCK_FLAG("--pattern", pattern),
    BBM_ROCK_FLAG("--size", o.size),
    BBM_ROCK_FLAG("--size-measure", size_measure),
    BBM_ROCK_FLAG("--seed", o.seed),
    BBM_ROCK_FLAG("--lloyd", o.lloyd),
    BBM_ROCK_FLAG("--tension-softening", tension_softening),
    BBM_ROCK_FLAG("--shear-softening", shear_softening),
    BBM_ROCK_FLAG("--mesh-size", o.mesh_size),
};
#undef BBM_ROCK_FLAG

} // namespace

void apply_rock_file(const CLI::App& cmd, LabTestCli& c) {
    if (c.rock.empty()) return;
    const LabTestCli given = c;
    const io::RockFile rock = io::read_rock(c.rock);
    if (rock.model) {
        c = labtest_of_model(*rock.model, c.rock, c);
    } else {
        c.o.joint = rock.joint;
        // The file's curves as they are (any number of points; not the flags' b1, a1, a2).
        c.tension_softening.clear();
        c.shear_softening.clear();
        if (rock.material) {
            const MaterialSpec& m = *rock.material;
            c.o.material.density = m.density;
            c.o.material.deformable_fraction = m.deformable_fraction;
            if (m.deformable_fraction > 0.0) c.o.material.young = m.young, c.o.material.poisson = m.poisson;
        }
    }
    // The flags given beside the file (a command may lack some: bbm shear has no deformable blocks).
    auto given_flag = [&cmd](const std::string& flag) {
        const CLI::Option* opt = cmd.get_option_no_throw(flag);
        return opt && opt->count() > 0;
    };
    for (const auto& f : rock_flags)
        if (given_flag(f.flag)) f.keep(c, given);
    auto keep_given = [&given_flag]<class Spec>(std::span<const Key<Spec>> table, auto& keys, Spec& to, const Spec& from) {
        for (const Key<Spec>& k : table)
            if (std::ranges::find(keys, k.key) != std::ranges::end(keys) && given_flag(key_flag(k.key))) k.set(to, k.get(from));
    };
    keep_given(std::span<const contact::JointKey>(contact::joint_keys), labtest_joint_keys, c.o.joint, given.o.joint);
    keep_given(std::span<const MaterialKey>(material_keys), labtest_material_keys, c.o.material, given.o.material);
}

namespace {

/// The specimen: the rock file, the block pattern and the specimen's size.
void add_specimen_options(CLI::App* sub, LabTestCli& c) {
    auto& o = c.o;
    sub->add_option("--rock", c.rock,
                    "The rock from a file: one [[joint_property]] and at most one [[material]] as a model file has "
                    "them (what bbm calibrate writes: joint_property.toml), or a whole model file (its bonded "
                    "region's pattern, bonds and material); the rock's flags given beside it override it")
        ->check(CLI::ExistingFile);
    // After the command's flags are parsed, those of --config too: the file, then
    // the flags given beside it. A final callback, not parse_complete_callback: with
    // one, CLI11 (2.1) reads a --config file after it and never sets the
    // command's flags from the file (fit-curvature = true was silently false).
    sub->final_callback([sub, &c] { apply_rock_file(*sub, c); });
    sub->add_option("--pattern", c.pattern, "Inner-block pattern")
        ->check(CLI::IsMember({"voronoi", "trigon", "delaunay", "hexagonal", "brick"}))
        ->capture_default_str();
    sub->add_option("--size", o.size, "Mean block size d (m), measured as --size-measure says")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--size-measure", c.size_measure,
                    "feret: the blocks' mean Feret (caliper) diameter, perimeter / pi (for trigon, of the triangles); "
                    "area: the diameter of the circle of the mean area of the Voronoi cells (trigon: before "
                    "splitting) or Delaunay triangles")
        ->check(CLI::IsMember({"feret", "area"}))->capture_default_str();
    sub->add_option("--width", o.width, "Specimen width (m); brazilian: disc diameter")->check(cli::positive())->capture_default_str();
    sub->add_option("--height", o.height, "Specimen height (m)")->check(cli::positive())->capture_default_str();
    sub->add_option("--seed", o.seed, "Random seed of the block pattern")->check(cli::whole_at_least(0))->capture_default_str();
    sub->add_option("--lloyd", o.lloyd, "Lloyd relaxation iterations (0: cells of random points; more: more regular cells)")
        ->check(cli::non_negative())->capture_default_str();
}

/// The rock: its bonds, their softening and the blocks' material.
void add_rock_options(CLI::App* sub, LabTestCli& c) {
    auto& o = c.o;
    add_joint_flags(sub, o.joint, labtest_joint_keys, "", "The rock's bonds: ");
    sub->add_option("--tension-softening", c.tension_softening, "Tension softening b1,a1,a2 (SPEC §4)")
        ->delimiter(',')->expected(3)->capture_default_str();
    sub->add_option("--shear-softening", c.shear_softening, "Shear softening b1,a1,a2 (SPEC §4)")
        ->delimiter(',')->expected(3)->capture_default_str();
    add_key_flags(sub, o.material, std::span<const MaterialKey>(material_keys), labtest_material_keys, "",
                  "The rock's blocks: ");
    sub->add_option("--mesh-size", o.mesh_size, "With --deformable-fraction: triangle size (m; default size / 2)")
        ->check(cli::non_negative());
}

/// How the platens load: the rate, the servo, the implicit preload, the platens.
void add_loading_options(CLI::App* sub, LabTestCli& c) {
    auto& o = c.o;
    sub->add_option("--strain-rate", o.strain_per_step,
                    "Platen velocity over specimen height, per step (with the servo: the unit of its rates)")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--servo", o.servo.on,
                    "Servo-controlled platens: slower while cracks form, faster after failure (docs/calibration.md)")
        ->capture_default_str();
    sub->add_option("--servo-cracks", o.servo.cracks, "Servo: new cracks per record (20 steps) per 5,000 contacts it aims at")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--servo-balance", o.servo.balance,
                    "Servo, once cracking has started: largest difference between the top and bottom platen forces, as a fraction of the load (0: off)")
        ->check(cli::non_negative())->capture_default_str();
    sub->add_option("--servo-min", o.servo.min_factor, "Servo: slowest platen speed, times --strain-rate")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--servo-max", o.servo.max_factor, "Servo: fastest platen speed before failure, times --strain-rate")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--servo-post-peak", o.servo.post_peak_factor, "Servo: platen speed after failure, times --strain-rate")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--preload", o.elastic_preload,
                    "The linear part by one implicit solve, up to just below the first joint's yield")
        ->capture_default_str();
    sub->add_option("--platens", c.platens, "rough: the face blocks are held horizontally; smooth: free to slide")
        ->check(CLI::IsMember({"rough", "smooth"}))->capture_default_str();
    sub->add_option("--platen-friction", o.platen_friction,
                    "Rigid platen blocks pressing on the faces through contacts of this friction angle (degrees), "
                    "instead of prescribed face blocks (--platens); ucs and biaxial")
        ->check(cli::within(below(0, 90, degrees)));
}

/// When a test stops and how its peak is read.
void add_stop_options(CLI::App* sub, LabTestOptions& o) {
    sub->add_option("--stop-fraction", o.stop.fraction, "Stop after the peak once the stress is below this fraction of it")
        ->check(cli::in_range(0.0, 1.0))->capture_default_str();
    sub->add_option("--failure-drop", o.stop.failure_drop,
                    "A drop by this fraction from the peak marks failure; the run stops if the stress then climbs back above the peak")
        ->check(cli::in_range(0.0, 1.0))->capture_default_str();
    sub->add_option("--frame-every", o.frame_every,
                    "Steps between frames of the failure series in result.pvd (0: the final state only)")
        ->check(cli::non_negative())->capture_default_str();
    sub->add_option("--max-strain", o.stop.max_strain,
                    "Stop at this axial strain; a specimen not failed by then loads on up to --strain-cap")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--strain-cap", o.stop.strain_cap,
                    "Hard limit for a specimen still loading at --max-strain (at most --max-strain: stop there); "
                    "reached unfailed, the peak is a lower bound (still_loading)")
        ->check(cli::non_negative())->capture_default_str();
    sub->add_option_function<std::string>(
           "--confined-peak", [&o](const std::string& v) { o.stop.peak_at_first_stall = v == "first-stall"; },
           "Confined tests: lab = the laboratory's peak, the largest stress before a lasting drop by --failure-drop "
           "(a specimen that only hardens loads on to --strain-cap); first-stall = the rule until 2026-11-27, the "
           "first stall of the stress after cracking (docs/calibration.md, The confined peak)")
        ->check(CLI::IsMember({"lab", "first-stall"}))->default_str("lab");
    sub->add_option("--post-peak-strain", o.stop.post_peak_strain,
                    "Confined tests: stop this much axial strain past the failure (the peak's drop; first-stall: past "
                    "the peak) once the specimen has failed (0: go on "
                    "to --max-strain or --stop-fraction; bbm envelope and calibrate use 2e-4)")
        ->check(cli::non_negative());
}

/// A persistent joint set across the specimen.
void add_joint_set_options(CLI::App* sub, LabTestOptions& o) {
    sub->add_option_function<double>(
           "--joint-set-angle", [&o](const double& a) { o.joint_set.on = true, o.joint_set.angle = a; },
           "A persistent joint set across the specimen at this angle from horizontal (degrees; a single plane "
           "of weakness through the centre unless --joint-set-spacing), a Coulomb joint (--joint-set-friction, "
           "--joint-set-cohesion, --joint-set-tensile: a brittle weak bond when > 0)")
        ->check(cli::in_range(0.0, 180.0));
    sub->add_option("--joint-set-spacing", o.joint_set.spacing, "Joint set: spacing along the normal (m; 0 = one joint)")
        ->check(cli::non_negative())->capture_default_str();
    static constexpr std::string_view joint_set_keys[] = {"friction", "residual_friction", "cohesion", "tensile"};
    add_joint_flags(sub, o.joint_set.joint, joint_set_keys, "joint-set-", "Joint set: ");
}

} // namespace

void add_labtest_options(CLI::App* sub, LabTestCli& c, bool& quiet) {
    add_specimen_options(sub, c);
    add_rock_options(sub, c);
    add_loading_options(sub, c);
    add_stop_options(sub, c.o);
    add_joint_set_options(sub, c.o);
    auto& o = c.o;
    sub->add_option("--realizations", c.realizations, "Number of random realizations (seeds seed, seed+1, ...)")
        ->check(cli::positive())->capture_default_str();
    sub->add_option("--threads", c.threads,
                    "Threads (0 = all cores): realizations run in parallel; a single one uses them in its contact loop")
        ->check(cli::non_negative());
    sub->add_option("--max-elements", o.max_elements, max_elements_help)->check(cli::positive());
    sub->add_option("-o,--out", c.out, "Output directory")->capture_default_str();
    sub->add_flag("-q,--quiet", quiet, "No progress, only errors");
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
                         p.unbalanced_ratio, p.strain_per_step});
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
    const auto& o = j["crack_orientation"];
    r.crack_orientation = o["counts"].get<std::array<int, 12>>();
    r.cracks_near_vertical = o["within_30_of_vertical"], r.cracks_near_horizontal = o["within_30_of_horizontal"];
    r.cracks_near_vertical_at_peak = o["within_30_of_vertical_at_peak"];
    r.cracks_near_horizontal_at_peak = o["within_30_of_horizontal_at_peak"];
    for (const auto& p : j["curve"])
        r.curve.push_back({p[0].get<long>(), p[1].get<double>(), p[2].get<double>(), p[3].get<double>(),
                           p[4].get<int>(), p[5].get<int>(), p[6].get<double>(), p[7].get<double>()});
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
           "strain_per_step\n";
    csv.precision(10);
    // Stress against the axial, lateral (expansion negative) and volumetric strains,
    // as Martin & Chandler draw them, with σci and σcd marked.
    io::Series axial{"axial", {}, {}}, lateral{"lateral", {}, {}}, volumetric{"volumetric", {}, {}};
    for (const auto& p : r.curve) {
        csv << p.step << ',' << p.axial_strain << ',' << p.axial_stress << ',' << p.lateral_strain << ','
            << p.cracks_tensile << ',' << p.cracks_shear << ',' << p.unbalanced_ratio << ',' << p.strain_per_step
            << '\n';
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

/// --pattern and --size-measure -> the options' pattern.
void apply_pattern_flags(LabTestCli& c) {
    const std::map<std::string, meshing::PatternSpec::Kind> kinds{
        {"voronoi", meshing::PatternSpec::Kind::voronoi}, {"trigon", meshing::PatternSpec::Kind::trigon},
        {"delaunay", meshing::PatternSpec::Kind::delaunay}, {"hexagonal", meshing::PatternSpec::Kind::hexagonal},
        {"brick", meshing::PatternSpec::Kind::brick}, {"single", meshing::PatternSpec::Kind::single}};
    c.o.pattern = kinds.at(c.pattern);
    c.o.size_measure =
        c.size_measure == "area" ? meshing::PatternSpec::SizeMeasure::area : meshing::PatternSpec::SizeMeasure::feret;
}

/// --tension-softening / --shear-softening b1,a1,a2 -> the points (a1, b1), (a2, 0)
/// of the joint's curves, checked. Empty values keep the joint's own curves (a
/// model file's, which may have any number of points: labtest_of_model).
void apply_softening_flags(LabTestCli& c) {
    auto curve = [](const std::vector<double>& v, const char* flag) {
        const double b1 = v[0], a1 = v[1], a2 = v[2];
        if (!(b1 > 0 && b1 < 1 && a1 > 1 && a2 > a1 && a2 > 0 && a1 - b1 < a2))
            throw InputError(flag, 0, "", "needs 0 < b1 < 1, 1 < a1 < a2 (points (a1, b1), (a2, 0) after the peak)");
        return std::vector<std::pair<double, double>>{{a1, b1}, {a2, 0.0}};
    };
    if (!c.tension_softening.empty()) c.o.joint.tension_softening = curve(c.tension_softening, "--tension-softening");
    if (!c.shear_softening.empty()) c.o.joint.shear_softening = curve(c.shear_softening, "--shear-softening");
    check_joint_flags(c.o.joint);
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
void check_specimen_size(const LabTestCli& c) {
    const auto& o = c.o;
    const bool disc = o.kind == LabTestOptions::Kind::brazilian;
    const double width = o.width, height = disc ? o.width : o.height;
    if (std::min(width, height) < 3.0 * o.size)
        throw InputError("--size", 0, "",
                         "blocks of " + fmt_number(o.size) + " m do not fit a specimen " + fmt_number(width) + " m x " +
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


void apply_specimen_flags(LabTestCli& c) {
    apply_pattern_flags(c);
    apply_softening_flags(c);
}

void prepare_labtest(LabTestCli& c, LabTestOptions::Kind kind) {
    auto& o = c.o;
    o.kind = kind;
    apply_specimen_flags(c);
    o.rough_platens = c.platens == "rough";
    if (o.platen_friction >= 0.0 && (kind == LabTestOptions::Kind::tension || kind == LabTestOptions::Kind::brazilian))
        throw InputError("--platen-friction", 0, "",
                         std::string("applies to ucs and biaxial only: ") + labtest_name(kind) +
                             " needs platens that hold the specimen (use --platens rough or smooth)");
    if (o.joint_set.on && kind == LabTestOptions::Kind::brazilian)
        throw InputError("--joint-set-angle", 0, "", "a joint set crosses rectangular specimens: not the brazilian disc");
    if (o.joint_set.on && o.joint_set.spacing > 0 && o.joint_set.spacing < o.size)
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
                 static_cast<unsigned long long>(ok.seed), r.E / 1e9, r.E50 / 1e9, r.nu, r.peak_stress / 1e6,
                 r.strain_at_peak, r.crack_initiation_stress / 1e6, r.crack_damage_stress / 1e6,
                 r.cracks_tensile, r.cracks_shear, r.steps, r.wall_seconds);
    if (r.preload_skipped)
        std::fprintf(stderr, "  seed %llu: the confinement left blocks the implicit preload cannot solve "
                             "(held at one point, or loose): loaded explicitly from the start\n",
                     static_cast<unsigned long long>(ok.seed));
    if (r.still_loading)
        std::fprintf(stderr, "  seed %llu: still loading at the strain cap %g, not failed: the peak is a "
                             "lower bound of the strength (jammed blocks, or raise --strain-cap)\n",
                     static_cast<unsigned long long>(ok.seed), std::max(ok.stop.max_strain, ok.stop.strain_cap));
    else if (r.loaded_past_max_strain)
        std::fprintf(stderr, "  seed %llu: not failed at --max-strain %g: loaded on, failed at strain %.4g\n",
                     static_cast<unsigned long long>(ok.seed), ok.stop.max_strain, r.strain_at_peak);
    if (ok.confinement > 0.0 && r.hardened_past_yield())
        std::fprintf(stderr, "  seed %llu: yielded at %.2f MPa (the stress's first stall) and hardened to its "
                             "peak, %.0f%% higher: broken blocks interlocking (a residual friction below "
                             "the joints' lets them slide; docs/calibration.md, The confined peak)\n",
                     static_cast<unsigned long long>(ok.seed), r.first_stall_stress / 1e6,
                     100.0 * (r.peak_stress / r.first_stall_stress - 1.0));
    if (r.reloads > 0)
        std::fprintf(stderr, "  seed %llu: the stress dropped by --failure-drop and climbed back above its "
                             "peak %d time%s (bursts of cracks): loaded on to the peak that lasted\n",
                     static_cast<unsigned long long>(ok.seed), r.reloads, r.reloads == 1 ? "" : "s");
    if (r.residual_stress > 0.0) {
        std::fprintf(stderr, "  seed %llu: residual strength %.2f MPa (the last %.1f%% of axial strain, %.2g%% "
                             "to %.2g%%)",
                     static_cast<unsigned long long>(ok.seed), r.residual_stress / 1e6,
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
                     static_cast<unsigned long long>(ok.seed));
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

} // namespace

int run_labtest_command(LabTestCli& c, LabTestOptions::Kind kind, bool quiet, bool check_only, LabTestStudy* study) {
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
    const bool one_at_a_time = o.material.deformable_fraction > 0.0;
    const int threads = one_at_a_time ? 1 : std::max(1, std::min(n, available));
    const int threads_for_loop = available;
    const int shown_threads = n > 1 && !one_at_a_time ? threads : threads_for_loop;
    std::mutex print;
    // Progress from rank 0 only; the others run quietly.
    quiet = quiet || !Ranks::root();
    if (!quiet)
        std::fprintf(stderr, "bbm %s: %s blocks of %.3g m, %g m x %g m, %d realization%s on %d thread%s%s\n", name,
                     c.pattern.c_str(), o.size, o.width, kind == LabTestOptions::Kind::brazilian ? o.width : o.height, n,
                     n > 1 ? "s" : "", shown_threads, shown_threads > 1 ? "s" : "",
                     Ranks::size() > 1 ? (" per rank, " + std::to_string(Ranks::size()) + " ranks").c_str() : "");
    Progress lines; // progress of a single realization; every realization's result
    auto realization = [&](int k) -> std::string {
        try {
            LabTestOptions ok = o;
            ok.seed = o.seed + k;
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
                    std::snprintf(title, sizeof title, "%s, seed %llu", name, static_cast<unsigned long long>(ok.seed));
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
    };
    // Realizations over ranks (k mod ranks) and threads; every rank gets them all.
    std::vector<LabTestResult> results;
    for (const auto& text : run_spread(n, n > 1 ? threads : 1, realization))
        results.push_back(labtest_from_record(nlohmann::json::parse(text)));
    nlohmann::json summary = n == 1 ? labtest_json(results[0]) : nlohmann::json();
    if (n > 1) {
        summary = realizations_summary(name, results);
        if (write && Ranks::root()) io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
        if (!quiet)
            std::fprintf(stderr, "mean of %d: E %.2f GPa, nu %.3f, peak %.2f MPa%s%s\n", n,
                         summary["E"]["mean"].get<double>() / 1e9, summary["nu"]["mean"].get<double>(),
                         summary["peak_stress"]["mean"].get<double>() / 1e6, write ? "; wrote " : "",
                         write ? (out / "summary.json").string().c_str() : "");
    }
    if (study) {
        study->results = std::move(results);
        study->summary_json = summary.dump();
    }
    return 0;
}

LabTestStudy run_labtest_args(const std::string& command, const std::vector<std::string>& args, bool quiet,
                              const std::function<void(const Solver&, const StressStrainPoint&, int)>& on_frame) {
    const auto kind = labtest_kind(command);
    LabTestCli values = labtest_defaults(kind);
    values.write_files = false;
    CLI::App app{command, command};
    bool quiet_flag = quiet;
    add_labtest_options(&app, values, quiet_flag);
    if (kind == LabTestOptions::Kind::biaxial)
        app.add_option("--confinement", values.o.confinement, "Lateral stress (Pa, compression positive)")
            ->required()
            ->check(cli::non_negative());
    cli::parse_args(app, command, args);
    values.write_files = app.count("--out") > 0;
    values.on_frame = on_frame;
    LabTestStudy study;
    run_labtest_command(values, kind, quiet_flag, false, &study);
    return study;
}

} // namespace bbm::studies
