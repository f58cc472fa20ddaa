// `bbm mesh`: a model file's blocks, their files and summary (studies/model/mesh_command.hpp).
#include "studies/model/mesh_command.hpp"

#include "base/error.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "meshing/blocks.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

namespace bbm::studies {

namespace fs = std::filesystem;

namespace {

/// The blocks' areas, and those of the block patterns (not single blocks): how
/// many, their area, their shortest edge.
struct BlockSizes {
    double total_area = 0.0, inner_area = 0.0;
    int inner_blocks = 0;
    double min_edge = INFINITY;
};

BlockSizes block_sizes(const meshing::BlockAssembly& a) {
    BlockSizes s;
    for (int b = 0; b < a.block_count(); ++b) {
        s.total_area += a.area[b];
        if (a.pattern[b] == meshing::PatternSpec::Kind::single) continue;
        s.inner_area += a.area[b];
        ++s.inner_blocks;
        const auto p = a.block(b);
        for (std::size_t i = 0; i < p.size(); ++i) s.min_edge = std::min(s.min_edge, norm(p[(i + 1) % p.size()] - p[i]));
    }
    return s;
}

/// Per region: its pattern, blocks, area and block sizes.
nlohmann::json regions_json(const meshing::BlockAssembly& a) {
    nlohmann::json regions = nlohmann::json::array();
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
    return regions;
}

/// The fracture network as built against what was asked (meshing/dfn.hpp).
nlohmann::json fracture_sets_json(const meshing::BlockAssembly& a) {
    nlohmann::json fracture_sets = nlohmann::json::array();
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
    return fracture_sets;
}

nlohmann::json mesh_summary(const meshing::BlockAssembly& a, const meshing::GenerationStats& st,
                            double seconds) {
    const BlockSizes s = block_sizes(a);
    std::map<std::string, int> tags;
    for (const auto& j : a.joints) ++tags[meshing::to_string(j.tag)];
    return {{"blocks", a.block_count()},
            {"joints", a.joints.size()},
            {"joints_by_tag", tags},
            {"total_area", s.total_area},
            {"inner_blocks", s.inner_blocks},
            {"equal_area_diameter",
             s.inner_blocks ? std::sqrt(4.0 * s.inner_area / s.inner_blocks / 3.141592653589793) : 0.0},
            {"min_edge_length", s.inner_blocks ? s.min_edge : 0.0},
            {"collapsed_edges", st.collapsed_edges},
            {"short_edges_left", st.short_edges_left},
            {"merged_slivers", st.merged_slivers},
            {"slivers_left", st.slivers_left},
            {"merged_trace_length", st.merged_trace_length},
            {"rock_bridges", st.rock_bridges},
            {"hole_cuts", st.hole_cuts},
            {"regions", regions_json(a)},
            {"fracture_sets", fracture_sets_json(a)},
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



} // namespace bbm::studies
