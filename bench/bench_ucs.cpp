// Benchmark: wall time of one numerical UCS test with the paper's calibration
// parameters (Voronoi 0.3 m, 8 m × 16 m, SPEC §8), with 1 and 2 threads of the
// contact loop. Target (issue 5): under 30 s on this 2-core machine.
// Usage: bench_ucs [out.json]
#include "core/labtest.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>

using namespace bbm;

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_ucs.json";
    nlohmann::json runs = nlohmann::json::array();
    for (int threads : {1, 2}) {
        auto o = LabTestOptions::paper_ucs();
        o.threads = threads;
        const auto r = run_labtest(o);
        std::printf("threads %d: %d blocks, %d contacts, %ld steps, %.1f s (%.0f steps/s); E %.2f GPa, peak %.2f MPa\n",
                    threads, r.blocks, r.contacts, r.steps, r.wall_seconds, r.steps / r.wall_seconds, r.E / 1e9,
                    r.peak_stress / 1e6);
        runs.push_back({{"threads", threads}, {"blocks", r.blocks}, {"contacts", r.contacts}, {"steps", r.steps},
                        {"wall_seconds", r.wall_seconds}, {"E", r.E}, {"peak_stress", r.peak_stress}});
    }
    std::ofstream(out) << nlohmann::json{{"benchmark", "ucs_paper_voronoi"}, {"runs", runs}}.dump(2) << "\n";
}
