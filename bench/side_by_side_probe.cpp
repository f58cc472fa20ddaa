// Determinism probe, not a benchmark: runs deformable lab-test realizations alone,
// then side by side in threads of one process (as `bbm ucs --realizations` once
// did), and prints the first record where a side-by-side curve differs in any bit
// from the one run alone (-1: none). `bbm ucs` runs deformable realizations one at
// a time because a 4 x 8 m f = 0.95 specimen side by side once differed in 2 of
// about 40 runs; this is the tool to look for that fault again
// (docs/notes/2026-11-28-calibration-history.md, What the programs do, Output).
//
//   side_by_side_probe [width (m)] [max strain] [trials] [seed] [seed] ...
#include "studies/lab/labtest.hpp"

#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

using namespace bbm;

namespace {

LabTestOptions deformable(std::uint64_t seed, double width, double max_strain) {
    auto o = LabTestOptions::paper_ucs();
    o.width = width, o.height = 2.0 * width;
    o.rock.material.deformable_fraction = 0.95;
    o.stop.max_strain = max_strain;
    o.threads = 1;
    o.rock.pattern.seed = seed;
    return o;
}

/// The step of the first record where the curves differ; -1 if none, -2 if only their lengths do.
long first_difference(const LabTestResult& a, const LabTestResult& b) {
    const std::size_t n = std::min(a.curve.size(), b.curve.size());
    for (std::size_t i = 0; i < n; ++i)
        if (a.curve[i].axial_stress != b.curve[i].axial_stress || a.curve[i].axial_strain != b.curve[i].axial_strain)
            return a.curve[i].step;
    return a.curve.size() == b.curve.size() ? -1 : -2;
}

} // namespace

int main(int argc, char** argv) {
    const double width = argc > 1 ? std::atof(argv[1]) : 2.0, max_strain = argc > 2 ? std::atof(argv[2]) : 3e-3;
    const int trials = argc > 3 ? std::atoi(argv[3]) : 10;
    std::vector<std::uint64_t> seeds;
    for (int i = 4; i < argc; ++i) seeds.push_back(std::uint64_t(std::atoll(argv[i])));
    if (seeds.empty()) seeds = {1, 2, 3};
    std::vector<LabTestResult> alone;
    for (auto s : seeds) alone.push_back(run_labtest(deformable(s, width, max_strain)));
    for (std::size_t k = 0; k < seeds.size(); ++k)
        std::printf("seed %llu alone: peak %.9g MPa, %zu records\n", static_cast<unsigned long long>(seeds[k]),
                    alone[k].peak_stress / 1e6, alone[k].curve.size());
    int differing = 0;
    for (int t = 0; t < trials; ++t) {
        std::vector<LabTestResult> together(seeds.size());
        std::vector<std::thread> pool;
        for (std::size_t k = 0; k < seeds.size(); ++k)
            pool.emplace_back([&, k] { together[k] = run_labtest(deformable(seeds[k], width, max_strain)); });
        for (auto& th : pool) th.join();
        std::printf("trial %d:", t);
        for (std::size_t k = 0; k < seeds.size(); ++k) {
            const long d = first_difference(alone[k], together[k]);
            differing += d != -1;
            std::printf("  seed %llu peak %.9g MPa, first difference at step %ld",
                        static_cast<unsigned long long>(seeds[k]), together[k].peak_stress / 1e6, d);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    std::printf("%d of %d side-by-side runs differed from the same seed alone\n", differing,
                trials * int(seeds.size()));
    return differing == 0 ? 0 : 1;
}
