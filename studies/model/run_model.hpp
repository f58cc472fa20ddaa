// bbm studies: `bbm run` — a model file's stages with output, checkpoints and
// numerical health checks.
//
// Output in DIR: result.pvd (ParaView series: one grid of rigid blocks and zones,
// one of contacts, per snapshot), history.csv, summary.json, failure.png/.svg and
// history.png, and checkpoint.bin when asked for or interrupted. Every file is
// written atomically, so a run killed at any moment leaves the previous good
// version of each file. `--resume DIR` rebuilds the model from the file named in
// the checkpoint (refusing it if the file changed since) and continues; the result
// is identical (same state hash) to an uninterrupted run, on any thread count.
// What a checkpoint holds: docs/theory.md §10.1 (the full list: docs/notes/2026-11-28-theory-record.md §10.1).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace bbm::studies {


/// How often a run writes its checkpoint: every `steps` steps, or every
/// `seconds` of wall time (the first that is due), besides when interrupted.
struct CheckpointInterval {
    long steps = 0;
    double seconds = 0.0;
};
/// "5000" (steps), "30min" or "30m" (wall minutes), "2h", "90s": throws InputError
/// naming `--checkpoint-every` for anything else.
CheckpointInterval parse_checkpoint_interval(const std::string& text);

struct RunOptions {
    std::string model;              ///< model file (with resume: checked against the checkpoint's)
    std::filesystem::path out = "out";
    int threads = 1;
    bool quiet = false;
    CheckpointInterval checkpoint_every; ///< none set: only when interrupted
    /// Stop after this total step as if interrupted (checkpoint, output, exit 130):
    /// an exact, repeatable interruption for tests and scripted runs. 0 = never.
    long stop_at_step = 0;
    bool resume = false;            ///< continue from out/checkpoint.bin
    double max_elements = 0;        ///< overrides [model] max_elements when > 0
    bool check_only = false;        ///< read, generate and set up the model, then stop (--check)
    bool profile = false;           ///< time each stage of the step (--profile): a table, and summary.json "profile"
    bool shade_pressure = false;    ///< failure.png shaded by the water's pressure (--shade pressure)
};

/// Exit status: 0 done (with resume: also when the run had already finished), 130
/// interrupted (SIGINT, SIGTERM, SIGUSR1 or --stop-at-step; a checkpoint was
/// written), 3 stopped by a numerical health check (the message names the cause
/// and what to change), 2 (InputError) a checkpoint of another model, format or
/// thread-independent state that cannot be resumed.
/// Throws InputError for bad input, std::runtime_error for other failures.
int run_model(const RunOptions& options);

/// Installs the handlers of SIGINT, SIGTERM and SIGUSR1 that ask a run to stop
/// after its current step (with a checkpoint). `bbm` installs them first thing, so
/// that a scheduler's signal during start-up (loading, meshing) is not fatal.
void catch_stop_signals();

/// Whether SIGINT, SIGTERM or SIGUSR1 has come: `bbm compare` and `bbm sweep` then
/// start no further run.
bool stop_signal_received();

/// `bbm compare A.toml B.toml ... --out DIR`: runs each model into DIR/<name>/ and
/// writes DIR/comparison.csv and comparison.md (opening displacements, cracks by
/// mode, failed-zone depths, counts and run time per model) and comparison.png
/// (broken contacts against step, one curve per model). Models with a [report]
/// give the opening columns. With `envelope` (enabled), the strength envelope of
/// each model's rock too (studies/model/compare_envelopes.hpp): DIR/<name>/envelope/, DIR/envelopes.csv
/// and a second table in comparison.md. Returns the first non-zero exit status of
/// a run, or 0.
struct CompareEnvelopeOptions;
int compare_models(const std::vector<std::string>& models, const std::filesystem::path& out, int threads,
                   bool quiet, const CompareEnvelopeOptions* envelope = nullptr);

} // namespace bbm::studies
