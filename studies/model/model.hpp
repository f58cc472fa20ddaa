// bbm studies: a model file as an object one can drive step by step — what the
// Python module's bbm.Model is, and what `bbm run` builds.
//
// A Model reads a model file (or its text) exactly as `bbm run` does, generates the
// blocks and sets up the solver; then runs all stages, one named stage, or a
// number of steps, and can be checkpointed and resumed. Its summary has the keys
// of the summary.json `bbm run` writes. A checkpoint holds the model's text, so a
// model built from a Python dict resumes as well as one read from a file.
#pragma once

#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"

#include <nlohmann/json_fwd.hpp>

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace bbm::studies {

class Model;

/// Called every `every` steps (and at the end of each stage) while a model runs;
/// returning false stops the run after that step (the stage stays open: run() or
/// run_stage() continue it).
struct ModelProgress {
    std::function<bool(const Model&)> callback;
    long every = 0; ///< 0 = only at stage ends
};

class Model {
public:
    /// Reads and checks `path` and builds the model. Throws InputError (file, line, key).
    static Model from_file(const std::string& path, int threads = 1, double max_elements = 0);
    /// The same from model-file text; `name` stands for the file in messages.
    static Model from_text(const std::string& text, const std::string& name, int threads = 1,
                           double max_elements = 0);
    /// A model saved by checkpoint(), continuing where it stopped (same state hash
    /// as the uninterrupted run).
    static Model resume(const std::filesystem::path& checkpoint, int threads = 1);

    using Progress = ModelProgress;

    /// Runs the stages not yet done.
    void run(const Progress& progress = {});
    /// Runs the stages up to and including the one named; throws InputError if
    /// there is none of that name, or it is already done.
    void run_stage(const std::string& name, const Progress& progress = {});
    /// n explicit steps with the boundary conditions as they stand (no stage).
    void step(long n, const Progress& progress = {});
    void checkpoint(const std::filesystem::path& file) const;

    /// The summary, keys as in the summary.json of `bbm run`.
    nlohmann::json summary() const;
    /// Writes DIR/blocks.vtu and DIR/contacts.vtu of the current state (and the
    /// series so far in DIR/result.pvd).
    void write_vtk(const std::filesystem::path& dir) const;

    const Solver& solver() const { return *solver_; }
    Solver& solver() { return *solver_; }
    const io::ModelFile& file() const { return file_; }
    const meshing::BlockAssembly& assembly() const { return *assembly_; }
    const std::string& name() const { return name_; }
    /// Stages done (reports), and where the next one starts.
    const std::vector<StageReport>& reports() const { return reports_; }
    const StageCursor& cursor() const { return cursor_; }
    std::vector<std::string> stage_names() const;

private:
    Model() = default;
    void build(int threads, double max_elements);
    void run_until(int last_stage, const Progress& progress);

    std::string text_, name_;
    io::ModelFile file_;
    std::unique_ptr<meshing::BlockAssembly> assembly_;
    meshing::GenerationStats generation_{};
    std::unique_ptr<Solver> solver_;
    std::vector<StageReport> reports_;
    StageCursor cursor_;
    double run_seconds_ = 0;
};

/// The numerical health checks of a run, every 100 steps: NaN, a collapsing time
/// step, runaway motion (farther than the detection tolerance in a step) and,
/// every 1,000 steps, overlaps beyond it. Throws NumericalError naming the cause
/// and what to change.
void check_run_health(const Solver& solver);

/// A stage verdict (core/verdict.hpp) as summary.json gives it.
nlohmann::json verdict_json(const Verdict& v);

/// The summary of a run, keys as in `bbm run`'s summary.json: counts, steps,
/// cracks, energies, state hash, the stages with their verdicts and the run's
/// verdict, and with a [report] the opening's measures and hoop-stress profiles.
/// `wall_seconds`, `interrupted` and `complete` describe how the run went.
nlohmann::json run_summary(const std::string& model_name, const io::ModelFile& file,
                           const meshing::BlockAssembly& blocks, const meshing::GenerationStats& generation,
                           const Solver& solver, const std::vector<StageReport>& reports, double wall_seconds,
                           bool interrupted, bool complete);

} // namespace bbm::studies
