// Helpers of the determinism tests (test_determinism.cpp, and the long suite's
// test_determinism_long.cpp): a model file run on a given number of threads, its
// outcome (state hash, steps, cracks), the shipped example model files.
#pragma once

#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <cstdint>
#include <initializer_list>
#include <filesystem>
#include <string>
#include <vector>

namespace bbm::test {
namespace fs = std::filesystem;

struct Silent : StageObserver {};

struct Outcome {
    std::uint64_t hash;
    long steps;
    int tensile, shear;
    bool operator==(const Outcome&) const = default;
};

inline doctest::String outcome_text(const Outcome& o) {
    return (std::to_string(o.hash) + " after " + std::to_string(o.steps) + " steps, cracks " +
            std::to_string(o.tensile) + " / " + std::to_string(o.shear))
        .c_str();
}

/// Runs a model file's stages on `threads` threads; stages longer than
/// `max_stage_steps` (> 0) are cut there, to keep the slow examples short.
inline Outcome run_model(const io::ModelFile& model, const meshing::BlockAssembly& blocks, int threads,
                         long max_stage_steps = 0) {
    AnalysisSpec analysis = model.analysis;
    analysis.solver.threads = threads;
    if (max_stage_steps > 0)
        for (auto& stage : analysis.stages) {
            stage.steps = std::min(stage.steps, max_stage_steps);
            stage.max_steps = std::min(stage.max_steps, max_stage_steps);
            stage.relax_steps = std::min(stage.relax_steps, max_stage_steps);
        }
    Solver s(blocks, analysis);
    Silent quiet;
    run_stages(s, analysis.stages, quiet);
    return {s.state_hash(), s.steps(), s.cracks(contact::JointState::broken_tension),
            s.cracks(contact::JointState::broken_shear)};
}

/// The example model files with stages (a model without is a mesh only).
/// examples/lab/ holds the lab-test commands' option files (`bbm --config FILE
/// calibrate`), not model files.
inline std::vector<fs::path> examples() {
    std::vector<fs::path> out;
    for (const auto& e : fs::recursive_directory_iterator(fs::path(BBM_SOURCE_DIR) / "examples"))
        if (e.path().extension() == ".toml" && e.path().parent_path().filename() != "lab") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

/// The recorded outcomes (tests/recorded_states.json): what every shipped example
/// and the lab tests of test_determinism.cpp end in, on this code, so that a
/// change meant to keep the answers (a refactoring, an optimisation) is checked
/// to keep them bit for bit. With BBM_RECORD_STATES=1 in the environment the
/// outcomes are written into the file instead of checked (after a change meant to
/// change them, saying so in its commit).
class RecordedStates {
public:
    RecordedStates() {
        std::ifstream in(path());
        if (in) table_ = nlohmann::json::parse(in);
    }
    static bool recording() {
        const char* v = std::getenv("BBM_RECORD_STATES");
        return v && std::string(v) == "1";
    }
    /// Checks (or records) `values` under `key`.
    void check(const std::string& key, const nlohmann::json& values) {
        if (recording()) {
            std::ifstream in(path());
            nlohmann::json now = in ? nlohmann::json::parse(in) : nlohmann::json::object();
            now[key] = values;
            std::ofstream(path()) << now.dump(1) << "\n";
            return;
        }
        INFO(key << ": recorded " << (table_.contains(key) ? table_[key].dump() : std::string("nothing")) << ", now "
                 << values.dump() << " (tests/recorded_states.json; BBM_RECORD_STATES=1 records)");
        CHECK(table_.contains(key));
        if (table_.contains(key)) CHECK(table_[key] == values);
    }

private:
    static std::string path() { return std::string(BBM_SOURCE_DIR) + "/tests/recorded_states.json"; }
    nlohmann::json table_ = nlohmann::json::object();
};

inline nlohmann::json outcome_json(const Outcome& o) {
    return {{"state_hash", o.hash}, {"steps", o.steps}, {"cracks_tensile", o.tensile}, {"cracks_shear", o.shear}};
}

/// The thread counts to run: `threads`, or 1 alone when recording (the recorded
/// state is the one on 1 thread).
inline std::vector<int> threads_to_run(std::initializer_list<int> threads) {
    return RecordedStates::recording() ? std::vector<int>{1} : std::vector<int>(threads);
}

/// Every shipped example with stages (but those whose code paths another covers
/// at a fraction of the cost), each stage cut at 3000 steps (enough to pass
/// excavation, relaxation and the first cracks of every tunnel), run on each of
/// `threads` and checked against the state recorded on 1 thread: the same state
/// hash, steps and cracks. Returns how many were run.
inline int check_examples_on(std::initializer_list<int> threads) {
    int compared = 0;
    RecordedStates recorded;
    for (const auto& path : examples()) {
        if (path.filename() == "tunnel_trigon.toml") continue; // run to its end in test_determinism.cpp
        // 36,333 blocks: the same code paths as mineby_in_situ.toml, four times
        // the work (it alone was most of this test's 404 s in CI).
        if (path.filename() == "mineby_in_situ_fine.toml") continue;
        // mineby_in_situ.toml with bonds that add one arithmetic term (the
        // confined friction, the same on every thread): the same code paths.
        if (path.filename() == "mineby_confined.toml") continue;
        // 10,000 fractures, about 61,000 blocks: tunnel_voronoi_dfn.toml's code paths.
        if (path.filename() == "tunnel_dfn_10000.toml") continue;
        const auto model = io::read_model(path.string());
        if (model.analysis.stages.empty()) continue;
        const auto blocks = meshing::generate_blocks(model.geometry);
        const std::string key =
            "examples/" + fs::relative(path, fs::path(BBM_SOURCE_DIR) / "examples").generic_string();
        for (int n : threads_to_run(threads)) {
            const Outcome o = run_model(model, blocks, n, 3000);
            INFO(key << " on " << n << " threads: " << outcome_text(o));
            recorded.check(key, outcome_json(o));
        }
        ++compared;
    }
    return compared;
}

} // namespace bbm::test
