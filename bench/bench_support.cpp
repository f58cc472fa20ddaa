// Benchmark of ground support in the loop (issue 25, item 6): what bolts add to a
// step. examples/support/tunnel_trigon_bolted.toml is run to the moment its bolts
// go in (in-situ, elastic, half the excavation's relaxation); from that one state,
// saved, the failure stage's first steps are timed with the bolts installed and
// without them, on 1 and 2 threads (7 repetitions, interleaved; median and fastest). Both runs start
// from the same bits; they part as the bolts change the failure, so the figure
// is the cost of the bolts plus whatever the different cracking costs.
// Prints a table and writes JSON. Usage: bench_support [out.json] (run from the
// repository root, or set BBM_SOURCE_DIR).
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

using namespace bbm;
using clock_type = std::chrono::steady_clock;

namespace {
struct Quiet : StageObserver {};
} // namespace

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_support.json";
    const char* env = std::getenv("BBM_SOURCE_DIR");
    const std::string root = env ? env : ".";
    const std::string path = root + "/examples/support/tunnel_trigon_bolted.toml";
    const auto model = io::read_model(path);
    const auto blocks = meshing::generate_blocks(model.geometry);
    // The stages before the bolts go in.
    std::vector<StageSpec> before;
    std::vector<std::string> sets;
    for (const auto& st : model.analysis.stages) {
        if (st.kind == StageSpec::Kind::install) {
            sets = st.supports;
            break;
        }
        before.push_back(st);
    }
    std::string state;
    {
        Solver s(blocks, model.analysis);
        Quiet quiet;
        run_stages(s, before, quiet);
        std::ostringstream o;
        save_state(s.world(), o);
        state = o.str();
    }
    const long steps = 2000;
    nlohmann::json results = nlohmann::json::array();
    std::printf("%-8s %-8s %12s %12s %10s\n", "threads", "bolts", "us/step", "bolt nodes", "cracks");
    const int repetitions = 7;
    for (int threads : {1, 2}) {
        // Interleaved (without, with, without, ...): drift of the machine hits both alike.
        std::vector<double> times[2];
        int nodes[2] = {0, 0}, cracks[2] = {0, 0};
        for (int rep = 0; rep < repetitions; ++rep)
            for (int bolted : {0, 1}) {
                AnalysisSpec an = model.analysis;
                an.solver.threads = threads;
                Solver s(blocks, an);
                std::istringstream in(state);
                load_state(s.world(), in);
                if (bolted) install_supports(s.world(), sets);
                const auto t0 = clock_type::now();
                for (long k = 0; k < steps; ++k) s.step();
                times[bolted].push_back(std::chrono::duration<double>(clock_type::now() - t0).count() / steps);
                nodes[bolted] = support_state<Bolts>(s.world().supports).node_count();
                cracks[bolted] = bbm::cracks(s.world(), contact::JointState::broken_tension) +
                                 bbm::cracks(s.world(), contact::JointState::broken_shear);
            }
        double median[2];
        for (int bolted : {0, 1}) {
            std::sort(times[bolted].begin(), times[bolted].end());
            median[bolted] = times[bolted][repetitions / 2];
            std::printf("%-8d %-8s %12.1f %12d %10d\n", threads, bolted ? "yes" : "no", 1e6 * median[bolted],
                        nodes[bolted], cracks[bolted]);
            results.push_back({{"threads", threads},
                               {"bolted", bool(bolted)},
                               {"seconds_per_step_median", median[bolted]},
                               {"seconds_per_step_min", times[bolted].front()},
                               {"repetitions", repetitions},
                               {"bolt_nodes", nodes[bolted]},
                               {"cracks_at_end", cracks[bolted]}});
        }
        std::printf("threads %d: bolts add %.1f%% to a step (median), %.1f%% (fastest)\n", threads,
                    100.0 * (median[1] / median[0] - 1.0), 100.0 * (times[1].front() / times[0].front() - 1.0));
    }
    nlohmann::json j{{"benchmark", "bench_support"},
                     {"model", "examples/support/tunnel_trigon_bolted.toml"},
                     {"what", "failure-stage steps from the state at bolt installation, with and without the bolts"},
                     {"steps_timed", steps},
                     {"results", results}};
    std::ofstream(out) << j.dump(2) << "\n";
    return 0;
}
