// bbm: the command-line program. Subcommands:
//   bbm mesh MODEL.toml --out DIR   generate the block model, write VTK and a summary
//   bbm run MODEL.toml --out DIR    generate it and run the model file's stages
// Exit status: 0 success, 2 bad input (the message names file, line and key),
// 1 any other failure. Earlier output in DIR is only replaced by complete files.
#include "apps/model_input.hpp"
#include "apps/picture.hpp"
#include "apps/vtk_output.hpp"
#include "core/analysis.hpp"
#include "core/error.hpp"
#include "meshing/blocks.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <vector>

namespace {

using namespace bbm;
namespace fs = std::filesystem;

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
                           {"mean_block_size", meshing::mean_block_size(a, r)}});
    }
    std::map<std::string, int> tags;
    for (const auto& j : a.joints) ++tags[meshing::to_string(j.tag)];
    return {{"blocks", a.block_count()},
            {"joints", a.joints.size()},
            {"joints_by_tag", tags},
            {"total_area", total_area},
            {"inner_blocks", inner_blocks},
            {"mean_block_size",
             inner_blocks ? std::sqrt(4.0 * inner_area / inner_blocks / 3.141592653589793) : 0.0},
            {"min_edge_length", inner_blocks ? min_edge : 0.0},
            {"collapsed_edges", st.collapsed_edges},
            {"short_edges_left", st.short_edges_left},
            {"regions", regions},
            {"seconds", {{"regions", st.seconds_regions},
                         {"patterns", st.seconds_patterns},
                         {"topology", st.seconds_topology},
                         {"total", seconds}}}};
}

int run_mesh(const std::string& model_path, const fs::path& out, const io::PictureOptions& picture,
             bool quiet) {
    const auto t0 = std::chrono::steady_clock::now();
    const io::ModelFile model = io::read_model(model_path);
    meshing::GenerationStats stats;
    meshing::BlockAssembly blocks;
    try {
        blocks = meshing::generate_blocks(model.geometry, &stats);
    } catch (const GeometryError& e) {
        throw io::to_input_error(model.source, e);
    }
    fs::create_directories(out);
    io::write_blocks_vtu(blocks, out / "blocks.vtu");
    io::write_joints_vtu(blocks, out / "joints.vtu");
    io::draw_blocks(blocks, out / "blocks.png", picture);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto summary = mesh_summary(blocks, stats, seconds);
    io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
    if (!quiet) {
        std::printf("%s: %d blocks, %zu joints, area %.6g m², mean inner block size %.4g m (%.2f s)\n",
                    model_path.c_str(), blocks.block_count(), blocks.joints.size(),
                    summary["total_area"].get<double>(), summary["mean_block_size"].get<double>(), seconds);
        for (const auto& r : summary["regions"])
            std::printf("  region %-12s %-9s %7d blocks  %10.4f m²  mean size %.4g m\n",
                        r["name"].get<std::string>().c_str(), r["pattern"].get<std::string>().c_str(),
                        r["blocks"].get<int>(), r["area"].get<double>(), r["mean_block_size"].get<double>());
        std::printf("  wrote %s/{blocks.vtu, joints.vtu, blocks.png, summary.json}\n", out.string().c_str());
    }
    return 0;
}


std::atomic<bool> interrupted{false};

/// Writes the ParaView series, the history and the progress line of a run.
class RunOutput : public StageObserver {
public:
    RunOutput(const fs::path& out, const AnalysisSpec& an, const Solver& s, bool quiet)
        : out_(out), settings_(an.solver), recorder_(s, an.histories), quiet_(quiet) {
        fs::create_directories(out_ / "vtk");
    }

    void stage_started(const Solver& s, const StageSpec& st) override {
        stage_t0_ = last_print_ = std::chrono::steady_clock::now();
        stage_steps_ = st.kind == StageSpec::Kind::cycle ? st.steps
                     : st.kind == StageSpec::Kind::excavate ? st.relax_steps : st.max_steps;
        if (s.steps() == 0) {
            record(s);
            snapshot(s);
        }
    }
    void step_done(const Solver& s, const StageSpec& st, long k) override {
        if (s.steps() % settings_.history_every == 0) record(s);
        if (settings_.output_every > 0 && s.steps() % settings_.output_every == 0) snapshot(s);
        if (!quiet_) {
            const auto now = std::chrono::steady_clock::now();
            if (std::chrono::duration<double>(now - last_print_).count() >= 1.0) {
                last_print_ = now;
                const double el = std::chrono::duration<double>(now - stage_t0_).count();
                const double rate = k / el;
                std::fprintf(stderr, "\r  %-12s step %9ld  ratio %9.3e  cracks %6d T %6d S  %8.0f steps/s  %s   ",
                             st.name.c_str(), k, s.unbalanced_ratio(), s.cracks(contact::JointState::broken_tension),
                             s.cracks(contact::JointState::broken_shear), rate,
                             st.kind == StageSpec::Kind::solve ? "" : ("ETA " + std::to_string(long((stage_steps_ - k) / rate)) + " s").c_str());
            }
        }
    }
    void stage_done(const Solver& s, const StageReport& r) override {
        record(s);
        snapshot(s);
        flush_history();
        if (!quiet_)
            std::fprintf(stderr, "\r  %-12s %-10s %9ld steps  ratio %9.3e  %7.2f s%s%s\n", r.name.c_str(), r.kind.c_str(),
                         r.steps, r.ratio, r.seconds, r.converged ? "" : "  (step limit reached)",
                         std::string(40, ' ').c_str());
    }
    bool stop_requested() override { return interrupted.load(); }

private:
    void record(const Solver& s) {
        if (!rows_.empty() && rows_.back().first == s.steps()) return;
        rows_.push_back({s.steps(), recorder_.sample(s)});
        times_.push_back(s.time());
    }
    void snapshot(const Solver& s) {
        if (!series_.empty() && last_snapshot_ == s.steps()) return;
        last_snapshot_ = s.steps();
        char name[64];
        std::snprintf(name, sizeof name, "vtk/blocks_%08ld.vtu", s.steps());
        io::write_state_blocks_vtu(s, out_ / name);
        series_.push_back({s.time(), name});
        std::snprintf(name, sizeof name, "vtk/contacts_%08ld.vtu", s.steps());
        io::write_state_contacts_vtu(s, out_ / name);
        series_.push_back({s.time(), name});
        io::write_pvd(out_ / "result.pvd", series_);
    }
    void flush_history() {
        std::ostringstream csv;
        csv << "step,time";
        for (const auto& h : recorder_.histories()) csv << ',' << h.name;
        csv << '\n';
        csv.precision(10);
        for (std::size_t r = 0; r < rows_.size(); ++r) {
            csv << rows_[r].first << ',' << times_[r];
            for (double v : rows_[r].second) csv << ',' << v;
            csv << '\n';
        }
        io::write_text_atomically(out_ / "history.csv", csv.str());
    }

    fs::path out_;
    SolverSpec settings_;
    HistoryRecorder recorder_;
    bool quiet_;
    std::vector<std::pair<long, std::vector<double>>> rows_;
    std::vector<double> times_;
    std::vector<std::pair<double, std::string>> series_;
    long last_snapshot_ = -1, stage_steps_ = 0;
    std::chrono::steady_clock::time_point stage_t0_, last_print_;
};

int run_model(const std::string& model_path, const fs::path& out, bool quiet) {
    const auto t0 = std::chrono::steady_clock::now();
    const io::ModelFile model = io::read_model(model_path);
    if (model.analysis.stages.empty())
        throw InputError(model_path, 0, "stage", "the model has no [[stage]] to run (bbm mesh only generates blocks)");
    meshing::BlockAssembly blocks;
    try {
        blocks = meshing::generate_blocks(model.geometry);
    } catch (const GeometryError& e) {
        throw io::to_input_error(model.source, e);
    }
    std::unique_ptr<Solver> solver;
    try {
        solver = std::make_unique<Solver>(blocks, model.analysis);
    } catch (const InputError& e) {
        throw InputError(model_path, model.source.line_of(e.key()), e.key(), e.message());
    }
    if (!quiet)
        std::fprintf(stderr, "%s: %d blocks, %d contacts, time step %.3g s (%s)\n", model_path.c_str(),
                     blocks.block_count(), solver->contacts().size(), solver->timestep(),
                     model.analysis.solver.mode == SolverSpec::Mode::quasi_static ? "quasi-static" : "dynamic");
    std::signal(SIGINT, [](int) { interrupted = true; });
    std::signal(SIGTERM, [](int) { interrupted = true; });
    RunOutput output(out, model.analysis, *solver, quiet);
    const auto reports = run_stages(*solver, model.analysis.stages, output);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    nlohmann::json stages = nlohmann::json::array();
    for (const auto& r : reports)
        stages.push_back({{"name", r.name}, {"kind", r.kind}, {"steps", r.steps}, {"unbalanced_ratio", r.ratio},
                          {"seconds", r.seconds}, {"converged", r.converged}});
    const nlohmann::json summary{
        {"model", model_path},
        {"blocks", blocks.block_count()},
        {"contacts", solver->contacts().size()},
        {"steps", solver->steps()},
        {"time", solver->time()},
        {"timestep", solver->timestep()},
        {"wall_seconds", seconds},
        {"cracks", {{"tensile", solver->cracks(contact::JointState::broken_tension)},
                    {"shear", solver->cracks(contact::JointState::broken_shear)}}},
        {"unbalanced_ratio", solver->unbalanced_ratio()},
        {"energy", {{"kinetic", solver->kinetic_energy()}, {"strain", solver->strain_energy()},
                    {"dissipated", solver->dissipated_energy()}, {"external_work", solver->external_work()}}},
        {"state_hash", std::to_string(solver->state_hash())},
        {"interrupted", interrupted.load()},
        {"stages", stages}};
    io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
    if (!quiet)
        std::fprintf(stderr, "%ld steps in %.2f s; cracks %d tensile, %d shear; wrote %s/{result.pvd, history.csv, summary.json}\n",
                     solver->steps(), seconds, solver->cracks(contact::JointState::broken_tension),
                     solver->cracks(contact::JointState::broken_shear), out.string().c_str());
    return interrupted ? 130 : 0;
}
} // namespace

int main(int argc, char** argv) {
    CLI::App app{"bbm — bonded-block models of rock failure (2D, plane strain).\n"
                 "Rigid or deformable blocks bonded by softening joints, one explicit loop.",
                 "bbm"};
    app.require_subcommand(1);
    bool quiet = false;
    app.add_flag("-q,--quiet", quiet, "Print nothing but errors");

    std::string model_path;
    std::string out_dir = "out";
    auto* mesh = app.add_subcommand(
        "mesh", "Generate the blocks of a model file and write DIR/blocks.vtu (polygons: block id, "
                "region, area, pattern), DIR/joints.vtu (lines: joint tag, the two blocks) and "
                "DIR/blocks.png (a picture of blocks and joints) and DIR/summary.json (counts, areas, "
                "mean block size).");
    mesh->add_option("model", model_path, "Model file (TOML; keys in docs/input.md)")
        ->required()
        ->check(CLI::ExistingFile);
    mesh->add_option("-o,--out", out_dir, "Output directory (created if missing)")->capture_default_str();
    mesh->add_flag("-q,--quiet", quiet, "Print nothing but errors");
    std::vector<double> window;
    mesh->add_option("--window", window, "Part of the model drawn in blocks.png: XMIN YMIN XMAX YMAX (m)")
        ->expected(4);

    std::string run_model_path;
    std::string run_out = "out";
    auto* run = app.add_subcommand(
        "run", "Generate the blocks of a model file and run its stages (initialize, solve, excavate, "
               "cycle). Writes DIR/result.pvd (ParaView series of blocks and contacts), DIR/history.csv "
               "and DIR/summary.json. Ctrl-C stops after the current step and writes the output.");
    run->add_option("model", run_model_path, "Model file (TOML; keys in docs/input.md)")
        ->required()
        ->check(CLI::ExistingFile);
    run->add_option("-o,--out", run_out, "Output directory (created if missing)")->capture_default_str();
    run->add_flag("-q,--quiet", quiet, "No progress, only errors");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    try {
        if (*run) return run_model(run_model_path, run_out, quiet);
        if (*mesh) {
            io::PictureOptions picture;
            if (window.size() == 4) {
                if (!(window[2] > window[0] && window[3] > window[1]))
                    throw InputError("--window", 0, "", "needs XMIN < XMAX and YMIN < YMAX");
                picture.window.add({window[0], window[1]});
                picture.window.add({window[2], window[3]});
            }
            return run_mesh(model_path, out_dir, picture, quiet);
        }
    } catch (const InputError& e) {
        std::fprintf(stderr, "bbm: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bbm: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
