// bbm studies: `bbm sweep` — a model file run over the cross product of key
// overrides and seeds, locally or spread over MPI ranks (studies/cluster/ranks.hpp).
//
// Run k of the cross product (the first --set varying slowest, the seed fastest)
// gets its own folder DIR/run_NNN with the edited model (model.toml) and the
// whole output of `bbm run`. DIR/sweep.csv and sweep.json tabulate every run — the
// values set, the seed offset, status ("done", "failed" with the error,
// "incomplete" when a health check stopped it) and its summary's figures — and
// DIR/sweep.png plots a chosen summary value against the first swept key, one
// curve per seed and their mean. A run that fails does not stop the others;
// --resume keeps runs whose folder holds a complete summary of the same model.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace bbm::studies {

struct SweepOptions {
    std::string model;
    /// Each --set: the key and its values (KEY=V1,V2,...; commas inside [] or "" do not split).
    std::vector<std::pair<std::string, std::vector<std::string>>> set;
    int seeds = 1;                ///< seed offsets 0 .. seeds-1
    std::filesystem::path out = "out/sweep";
    int threads = 1;              ///< of each run's loop
    int jobs = 1;                 ///< runs at once per rank
    bool resume = false;
    std::string plot = "cracks.tensile"; ///< a summary.json value, dotted ("opening.failed_depth_springline")
    bool quiet = false;
    bool check_only = false;
};

/// "KEY=V1,V2,..." -> key and values; throws InputError naming --set.
std::pair<std::string, std::vector<std::string>> parse_set(const std::string& text);

/// The edits of one run: a key joined by '+' ("region[1].dfn[0].p21+region[1].dfn[1].p21")
/// becomes one edit per key, each with the same value.
std::vector<std::pair<std::string, std::string>>
split_joined_keys(const std::vector<std::pair<std::string, std::string>>& set);

/// Runs the sweep; returns 0 if every run finished, 1 if any failed (the table says which).
int run_sweep(const SweepOptions& options);

} // namespace bbm::studies
