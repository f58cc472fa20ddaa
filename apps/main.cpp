// bbm: the command-line program. Subcommands:
//   bbm mesh MODEL.toml --out DIR   generate the block model, write VTK and a summary
// Exit status: 0 success, 2 bad input (the message names file, line and key),
// 1 any other failure. Earlier output in DIR is only replaced by complete files.
#include "apps/model_input.hpp"
#include "apps/picture.hpp"
#include "apps/vtk_output.hpp"
#include "core/error.hpp"
#include "meshing/blocks.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
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

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    try {
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
