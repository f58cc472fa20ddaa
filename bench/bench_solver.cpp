// Benchmark: the explicit loop on a bonded Voronoi assembly in uniaxial
// compression (issue 3): a W × 2W specimen of ~N blocks with the paper's joint
// properties (SPEC §8), bottom row fixed, top row pushed down at a constant
// velocity, quasi-static mode. Prints and writes JSON: blocks, contacts, steps,
// seconds, steps/s and contact-updates/s (contacts × steps / s), peak memory.
// Each scene is timed 3 times (the machine is a shared VM: run-to-run spread is
// large); best and median are reported.
// Each size runs with 1 and 2 threads of the contact loop.
// Usage: bench_solver [out.json] [steps]
#include "core/labtest.hpp"
#include "core/solver.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <vector>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sys/resource.h>

using namespace bbm;

namespace {

AnalysisSpec paper_analysis(double width, double height, double rows) {
    AnalysisSpec an;
    an.joint_properties.push_back(LabTestOptions::paper_ucs().joint);
    an.joint_assignments.push_back({"bond", {}, {}});
    BoundarySpec bottom;
    bottom.name = "bottom";
    bottom.select.box = Box2{{-1, -1}, {width + 1, rows}};
    bottom.vx = bottom.vy = bottom.omega = 0.0;
    BoundarySpec top = bottom;
    top.name = "top";
    top.select.box = Box2{{-1, height - rows}, {width + 1, height + 1}};
    top.vy = -1e-7;
    an.boundaries = {bottom, top};
    return an;
}

} // namespace

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_solver.json";
    const long steps = argc > 2 ? std::atol(argv[2]) : 2000;
    nlohmann::json runs = nlohmann::json::array();
    std::printf("%8s %9s %7s %7s %9s %10s %14s %14s\n", "blocks", "contacts", "threads", "steps", "best s", "steps/s",
                "c-upd/s best", "c-upd/s median");
    for (int target : {2500, 10000, 40000})
    for (int threads : {1, 2}) {
        const double d = 0.3, width = std::sqrt(target * std::numbers::pi * d * d / 4.0 / 2.0);
        meshing::RegionSpec r;
        r.name = "specimen";
        r.outline.min = {0, 0};
        r.outline.max = {width, 2 * width};
        r.pattern.kind = meshing::PatternSpec::Kind::voronoi;
        r.pattern.size = d;
        r.pattern.size_measure = meshing::PatternSpec::SizeMeasure::area; // the scenes as recorded
        r.pattern.lloyd_iterations = 2;
        meshing::ModelGeometrySpec g;
        g.regions.push_back(r);
        const auto blocks = meshing::generate_blocks(g);
        auto analysis = paper_analysis(width, 2 * width, 0.5 * d);
        analysis.solver.threads = threads;
        Solver s(blocks, analysis);
        for (int k = 0; k < 20; ++k) s.step(); // warm up
        std::vector<double> secs;
        for (int rep = 0; rep < 3; ++rep) {
            const auto t0 = std::chrono::steady_clock::now();
            for (long k = 0; k < steps; ++k) s.step();
            secs.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        std::sort(secs.begin(), secs.end());
        const double best = secs[0], median = secs[1];
        const double updates = double(s.contacts().size()) * double(steps);
        std::printf("%8d %9d %7d %7ld %9.3f %10.1f %14.3e %14.3e\n", blocks.block_count(), s.contacts().size(),
                    threads, steps, best, steps / best, updates / best, updates / median);
        runs.push_back({{"blocks", blocks.block_count()},
                        {"threads", threads},
                        {"contacts", s.contacts().size()},
                        {"steps", steps},
                        {"seconds_best", best},
                        {"seconds_median", median},
                        {"steps_per_second_best", steps / best},
                        {"contact_updates_per_second_best", updates / best},
                        {"contact_updates_per_second_median", updates / median},
                        {"ratio", s.unbalanced_ratio()}});
    }
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::printf("peak memory %.1f MB\n", ru.ru_maxrss / 1024.0);
    std::ofstream(out) << nlohmann::json{{"benchmark", "solver_bonded_voronoi_uniaxial"},
                                         {"runs", runs},
                                         {"peak_rss_mb", ru.ru_maxrss / 1024.0}}
                              .dump(2)
                       << "\n";
}
