// bbm apps: `bbm run` — a model file's stages with output, checkpoints and
// numerical health checks.
//
// Output in DIR: result.pvd (ParaView series: one grid of rigid blocks and zones,
// one of contacts, per snapshot), history.csv, summary.json, failure.png/.svg and
// history.png, and checkpoint.bin when asked for or interrupted. Every file is
// written atomically, so a run killed at any moment leaves the previous good
// version of each file. `--resume DIR` rebuilds the model from the file named in
// the checkpoint and continues; the result is identical (same state hash) to an
// uninterrupted run with the same thread count.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace bbm::studies {


struct RunOptions {
    std::string model;              ///< model file (ignored with resume)
    std::filesystem::path out = "out";
    int threads = 1;
    bool quiet = false;
    long checkpoint_every = 0;      ///< steps between checkpoints; 0 = only on Ctrl-C
    bool resume = false;            ///< continue from out/checkpoint.bin
    double max_elements = 0;        ///< overrides [model] max_elements when > 0
    bool check_only = false;        ///< read, generate and set up the model, then stop (--check)
};

/// Exit status: 0 done, 130 interrupted (a checkpoint was written), 3 stopped by a
/// numerical health check (the message names the cause and what to change).
/// Throws InputError for bad input, std::runtime_error for other failures.
int run_model(const RunOptions& options);

/// `bbm compare A.toml B.toml ... --out DIR`: runs each model into DIR/<name>/ and
/// writes DIR/comparison.csv and comparison.md (opening displacements, cracks by
/// mode, failed-zone depths, counts and run time per model) and comparison.png
/// (broken contacts against step, one curve per model). Models with a [report]
/// give the opening columns. Returns the first non-zero exit status of a run, or 0.
int compare_models(const std::vector<std::string>& models, const std::filesystem::path& out, int threads,
                   bool quiet);

} // namespace bbm::studies
