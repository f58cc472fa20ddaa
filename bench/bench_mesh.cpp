// Benchmark: generation time of Voronoi bonded-block models of 10k and 100k blocks
// (square region, 0.3 m blocks, no Lloyd relaxation and with 2 iterations),
// broken into region set-up, pattern generation and topology (joint records).
// Usage: bench_mesh [out.json]. Target (issue 2): 100k blocks in under 5 s.
#include "meshing/blocks.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sys/resource.h>

using namespace bbm::meshing;

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_mesh.json";
    nlohmann::json runs = nlohmann::json::array();
    std::printf("%10s %6s %9s %9s %9s %9s %9s %9s\n", "blocks", "lloyd", "joints", "regions", "pattern",
                "topology", "total s", "blocks/s");
    for (int target : {10000, 100000})
        for (int lloyd : {0, 2}) {
            const double d = 0.3, area = target * std::numbers::pi * d * d / 4.0;
            const double w = std::sqrt(area);
            RegionSpec r;
            r.name = "rock";
            r.outline.min = {0, 0};
            r.outline.max = {w, w};
            r.pattern.kind = PatternSpec::Kind::voronoi;
            r.pattern.size = d;
            r.pattern.size_measure = PatternSpec::SizeMeasure::area; // the scene as recorded: `target` cells
            r.pattern.lloyd_iterations = lloyd;
            ModelGeometrySpec spec;
            spec.regions.push_back(r);
            GenerationStats st;
            const auto t0 = std::chrono::steady_clock::now();
            const auto a = generate_blocks(spec, &st);
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::printf("%10d %6d %9zu %9.3f %9.3f %9.3f %9.3f %9.0f\n", a.block_count(), lloyd,
                        a.joints.size(), st.seconds_regions, st.seconds_patterns, st.seconds_topology, s,
                        a.block_count() / s);
            runs.push_back({{"blocks", a.block_count()},
                            {"lloyd", lloyd},
                            {"joints", a.joints.size()},
                            {"seconds", s},
                            {"seconds_regions", st.seconds_regions},
                            {"seconds_patterns", st.seconds_patterns},
                            {"seconds_topology", st.seconds_topology},
                            {"collapsed_edges", st.collapsed_edges}});
        }
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::printf("peak memory %.1f MB\n", ru.ru_maxrss / 1024.0);
    std::ofstream(out) << nlohmann::json{{"benchmark", "mesh_voronoi"},
                                         {"runs", runs},
                                         {"peak_rss_mb", ru.ru_maxrss / 1024.0}}
                              .dump(2)
                       << "\n";
    std::printf("wrote %s\n", out);
}
