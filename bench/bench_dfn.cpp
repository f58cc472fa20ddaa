// Benchmark: cutting a region of 0.5 m Voronoi blocks by a discrete fracture
// network (meshing/cutting.hpp), time and peak memory against the number of
// fractures at a fixed intensity: two power-law sets (0.5-5 m, exponent 2.5, κ 10)
// of 3,125 fracture centres per 1,000 m² each (10,000 in 40 m x 40 m), the second
// ending at the first with probability 0.5; the region grows with the count, from
// 1,000 fractures (12.6 m) to 100,000 (126.5 m). Each size runs in a child process
// of its own, so that its peak memory is its own.
// Usage: bench_dfn [out.json] [largest count]. Targets (issue 51): 10,000 fractures
// in 40 m x 40 m under 30 s, 100,000 in 130 m x 130 m under 10 minutes; the time
// should grow close to n log n. bench/plot_dfn.py draws the JSON.
#include "meshing/blocks.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace bbm::meshing;

namespace {

ModelGeometrySpec network(long fractures) {
    const double per_m2 = 10000.0 / 1600.0, side = std::sqrt(double(fractures) / per_m2);
    ModelGeometrySpec spec;
    spec.max_elements = 1e8;
    RegionSpec reg;
    reg.name = "rock";
    reg.outline.min = {0.0, 0.0};
    reg.outline.max = {side, side};
    reg.pattern.kind = PatternSpec::Kind::voronoi;
    reg.pattern.size = 0.5;
    reg.pattern.seed = 3;
    for (int k = 0; k < 2; ++k) {
        DfnSetSpec s;
        s.name = k == 0 ? "J1" : "J2";
        s.orientation.mean = k == 0 ? 20.0 : 110.0;
        s.orientation.concentration = 10.0;
        s.length.kind = FractureLengthSpec::Kind::power_law;
        s.length.exponent = 2.5;
        s.length.min = 0.5;
        s.length.max = 5.0;
        s.count = fractures / 2;
        s.seed = 4 + std::uint64_t(k);
        if (k == 1) {
            s.terminate_at = {0};
            s.terminate_probability = 0.5;
        }
        reg.dfn.push_back(s);
    }
    spec.regions.push_back(reg);
    return spec;
}

/// One size, in this process: the figures as one JSON line on `fd`.
void run(long fractures, int fd) {
    const auto spec = network(fractures);
    GenerationStats st;
    const auto t0 = std::chrono::steady_clock::now();
    const auto a = generate_blocks(spec, &st);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const nlohmann::json j{{"fractures", fractures},
                           {"side_m", spec.regions[0].outline.max.x},
                           {"traces", a.fracture_traces.size()},
                           {"blocks", a.block_count()},
                           {"joints", a.joints.size()},
                           {"rock_bridges", st.rock_bridges},
                           {"merged_slivers", st.merged_slivers},
                           {"seconds", s},
                           {"seconds_patterns", st.seconds_patterns},
                           {"seconds_topology", st.seconds_topology}};
    const std::string line = j.dump() + "\n";
    if (write(fd, line.data(), line.size()) != ssize_t(line.size())) std::exit(1);
}

} // namespace

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_dfn.json";
    const long largest = argc > 2 ? std::atol(argv[2]) : 100000;
    nlohmann::json runs = nlohmann::json::array();
    std::printf("%10s %8s %9s %9s %10s %9s %10s\n", "fractures", "side m", "blocks", "joints", "seconds",
                "peak MB", "s / n log n");
    for (long n : {1000L, 3000L, 10000L, 30000L, 100000L}) {
        if (n > largest) break;
        int pipe_fd[2];
        if (pipe(pipe_fd) != 0) return 1;
        const pid_t child = fork();
        if (child == 0) {
            close(pipe_fd[0]);
            run(n, pipe_fd[1]);
            _exit(0);
        }
        close(pipe_fd[1]);
        std::string text;
        char buf[4096];
        for (ssize_t r; (r = read(pipe_fd[0], buf, sizeof buf)) > 0;) text.append(buf, std::size_t(r));
        close(pipe_fd[0]);
        int status = 0;
        rusage ru{};
        wait4(child, &status, 0, &ru);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || text.empty()) {
            std::fprintf(stderr, "bench_dfn: %ld fractures failed\n", n);
            return 1;
        }
        auto j = nlohmann::json::parse(text);
        j["peak_rss_mb"] = ru.ru_maxrss / 1024.0;
        const double s = j["seconds"].get<double>();
        std::printf("%10ld %8.1f %9d %9zu %10.2f %9.0f %10.3g\n", n, j["side_m"].get<double>(), j["blocks"].get<int>(),
                    j["joints"].get<std::size_t>(), s, j["peak_rss_mb"].get<double>(), s / (double(n) * std::log(double(n))));
        std::fflush(stdout);
        runs.push_back(j);
    }
    std::ofstream(out) << nlohmann::json{{"benchmark", "dfn_cutting"}, {"threads", 1}, {"runs", runs}}.dump(2) << "\n";
    return 0;
}
