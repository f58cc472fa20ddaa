#include "studies/model/sweep.hpp"

#include "base/error.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "studies/cluster/ranks.hpp"
#include "studies/model/run_model.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

namespace bbm::studies {

namespace fs = std::filesystem;

std::pair<std::string, std::vector<std::string>> parse_set(const std::string& text) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InputError("--set", 0, "", "expected KEY=V1,V2,... (e.g. joint_property[0].tensile=2e6,3e6), got '" +
                                              text + "'");
    std::pair<std::string, std::vector<std::string>> out{text.substr(0, eq), {}};
    if (out.first.front() == '+' || out.first.back() == '+' || out.first.find("++") != std::string::npos)
        throw InputError("--set", 0, out.first, "an empty key among those joined by '+'");
    // Split at commas outside brackets and quotes: region[0].outline.min=[0,0],[1,1].
    int depth = 0;
    bool quoted = false;
    std::string current;
    for (char ch : text.substr(eq + 1)) {
        if (ch == '"') quoted = !quoted;
        if (!quoted && (ch == '[' || ch == '{')) ++depth;
        if (!quoted && (ch == ']' || ch == '}')) --depth;
        if (ch == ',' && depth == 0 && !quoted) {
            out.second.push_back(current), current.clear();
        } else {
            current += ch;
        }
    }
    out.second.push_back(current);
    for (const auto& v : out.second)
        if (v.empty()) throw InputError("--set", 0, out.first, "an empty value in '" + text + "'");
    return out;
}

std::vector<std::pair<std::string, std::string>>
split_joined_keys(const std::vector<std::pair<std::string, std::string>>& set) {
    std::vector<std::pair<std::string, std::string>> edits;
    for (const auto& [key, value] : set)
        for (std::size_t at = 0;;) {
            const auto plus = key.find('+', at);
            edits.emplace_back(key.substr(at, plus == std::string::npos ? std::string::npos : plus - at), value);
            if (plus == std::string::npos) break;
            at = plus + 1;
        }
    return edits;
}

namespace {

/// A summary value by dotted path ("opening.failed_depth_springline"); NaN if absent.
double summary_value(const nlohmann::json& s, const std::string& path) {
    // "opening.failed_zone.depth_springline"; an array element by index,
    // "stages[2].steps" or "stages.2.steps".
    std::string p = path;
    for (std::size_t at; (at = p.find('[')) != std::string::npos;) {
        const auto close = p.find(']', at);
        if (close == std::string::npos) return NAN;
        p = p.substr(0, at) + "." + p.substr(at + 1, close - at - 1) + p.substr(close + 1);
    }
    const nlohmann::json* j = &s;
    std::size_t at = 0;
    while (at <= p.size()) {
        const auto end = p.find('.', at);
        const std::string part = p.substr(at, end == std::string::npos ? std::string::npos : end - at);
        if (j->is_array()) {
            if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos) return NAN;
            const std::size_t index = std::stoul(part);
            if (index >= j->size()) return NAN;
            j = &(*j)[index];
        } else {
            if (!j->is_object() || !j->contains(part)) return NAN;
            j = &(*j)[part];
        }
        if (end == std::string::npos) break;
        at = end + 1;
    }
    return j->is_number() ? j->get<double>() : NAN;
}

std::string read_text(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

std::string csv_field(std::string s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

} // namespace

namespace {

/// One run of a sweep: its --set values, seed offset, edited model text and folder.
struct SweepRun {
    std::vector<std::pair<std::string, std::string>> set;
    long seed_offset = 0;
    std::string text, dir;
};

/// The cross product of the --set values and the seeds (the first --set slowest,
/// the seed fastest), every edited model read before anything runs: a wrong key or
/// value is an error now (exit 2, naming it), not a table of failed runs.
std::vector<SweepRun> plan_sweep(const SweepOptions& o, const std::string& base) {
    std::size_t runs = std::size_t(o.seeds);
    for (const auto& s : o.set) runs *= s.second.size();
    if (runs > 100000) throw InputError("--set", 0, "", "more than 100,000 runs in the cross product");
    std::vector<SweepRun> plan(runs);
    for (std::size_t k = 0; k < runs; ++k) {
        std::size_t rest = k;
        auto& r = plan[k];
        r.seed_offset = long(rest % std::size_t(o.seeds));
        rest /= std::size_t(o.seeds);
        r.set.resize(o.set.size());
        for (std::size_t s = o.set.size(); s-- > 0;) {
            const auto& values = o.set[s].second;
            r.set[s] = {o.set[s].first, values[rest % values.size()]};
            rest /= values.size();
        }
        char dir[32];
        std::snprintf(dir, sizeof dir, "run_%03zu", k + 1);
        r.dir = dir;
        r.text = io::edit_model_text(base, o.model, split_joined_keys(r.set), r.seed_offset);
    }
    for (std::size_t k = 0; k < runs; ++k) {
        try {
            (void)io::parse_model(plan[k].text, o.model);
        } catch (const InputError& e) {
            std::string what;
            for (const auto& [key, value] : plan[k].set) what += (what.empty() ? "" : ", ") + key + "=" + value;
            throw InputError(o.model, 0, e.key(),
                             e.message() + (what.empty() ? "" : " (with --set " + what + ")"));
        }
    }
    return plan;
}

/// Runs one (or keeps it, resumed and complete); its summary.json's text.
std::string run_one(const SweepOptions& o, const SweepRun& r, bool quiet) {
    // Interrupted (Ctrl-C, a scheduler's signal): the runs under way stop with a
    // checkpoint, no further run starts; `bbm sweep --resume` runs the rest.
    if (stop_signal_received())
        throw Interrupted("not started: the sweep was interrupted (bbm sweep --resume runs it)");
    const fs::path dir = o.out / r.dir;
    if (o.resume && fs::exists(dir / "summary.json") && read_text(dir / "model.toml") == r.text) {
        const auto s = nlohmann::json::parse(read_text(dir / "summary.json"), nullptr, false);
        if (!s.is_discarded() && s.value("complete", false)) {
            nlohmann::json kept = s;
            kept["resumed"] = true;
            return kept.dump();
        }
    }
    io::make_output_directory(dir);
    io::write_text_atomically(dir / "model.toml", r.text);
    RunOptions run;
    run.model = (dir / "model.toml").string();
    run.out = dir;
    run.threads = o.threads;
    run.quiet = true;
    const int status = run_model(run);
    auto s = nlohmann::json::parse(read_text(dir / "summary.json"));
    s["exit_status"] = status;
    if (!quiet) std::fprintf(stderr, "  %s done: %ld steps, status %d\n", r.dir.c_str(), s.value("steps", 0L), status);
    return s.dump();
}

/// The sweep's table (sweep.csv, sweep.json's runs) and its plot's series.
struct SweepTable {
    std::ostringstream csv;
    nlohmann::json table = nlohmann::json::array();
    int failed = 0;
    /// Series of the plot: one per seed offset and per value of the other swept keys
    /// (a sweep over two keys draws one line per value of the second); the mean
    /// over seeds per value of the other keys.
    std::map<std::pair<std::string, long>, io::Series> by_seed;
    std::map<std::string, std::map<double, std::pair<double, int>>> mean; // others -> x -> (sum, count)
};

/// Run k's row of sweep.json (its keys' values, status, error and summary), its
/// summary (null when the run failed) and the plot's value of it.
struct SweepRow {
    nlohmann::json row, summary;
    std::string status; ///< done, failed or incomplete
    double y = NAN;
};

SweepRow sweep_row(const SweepOptions& o, std::size_t k, const SweepRun& r, const std::string& summary,
                   const std::string& error) {
    SweepRow out;
    nlohmann::json& row = out.row;
    nlohmann::json& s = out.summary;
    row = {{"run", k + 1}, {"folder", r.dir}, {"seed_offset", r.seed_offset}};
    nlohmann::json values = nlohmann::json::object();
    for (const auto& [key, value] : r.set) values[key] = value;
    row["set"] = values;
    out.status = "done";
    if (!error.empty()) {
        out.status = "failed", row["error"] = error;
    } else {
        s = nlohmann::json::parse(summary);
        if (!s.value("complete", false)) out.status = "incomplete";
        if (s.contains("error")) row["error"] = s["error"];
        if (s.value("resumed", false)) row["resumed"] = true;
        row["summary"] = s;
    }
    row["status"] = out.status;
    out.y = s.is_null() ? NAN : summary_value(s, o.plot);
    row["plot_value"] = std::isfinite(out.y) ? nlohmann::json(out.y) : nlohmann::json();
    return out;
}

/// A summary's value for sweep.csv ("" when the run has none).
std::string csv_number(const nlohmann::json& s, const std::string& key) {
    if (s.is_null()) return "";
    const double v = summary_value(s, key);
    if (!std::isfinite(v)) return "";
    char t[40];
    std::snprintf(t, sizeof t, "%.10g", v);
    return t;
}

void add_csv_header(const SweepOptions& o, std::ostringstream& csv) {
    csv << "run";
    for (const auto& s : o.set) csv << ',' << csv_field(s.first);
    csv << ",seed_offset,status,error,steps,cracks_tensile,cracks_shear,wall_seconds,state_hash," << csv_field(o.plot)
        << ",folder\n";
}

void add_csv_row(const SweepOptions& o, std::size_t k, const SweepRun& r, const SweepRow& w, std::ostringstream& csv) {
    const nlohmann::json& s = w.summary;
    csv << k + 1;
    for (const auto& [key, value] : r.set) csv << ',' << csv_field(value);
    csv << ',' << r.seed_offset << ',' << w.status << ',' << csv_field(w.row.value("error", std::string{})) << ','
        << csv_number(s, "steps") << ',' << csv_number(s, "cracks.tensile") << ',' << csv_number(s, "cracks.shear") << ','
        << csv_number(s, "wall_seconds") << ',' << (s.is_null() ? "" : s.value("state_hash", std::string{})) << ','
        << (std::isfinite(w.y) ? csv_number(s, o.plot) : "") << ',' << r.dir << '\n';
}

/// The plot: the value y against the first swept key, if it is a number.
void add_plot_point(const SweepOptions& o, const SweepRun& r, double y, SweepTable& out) {
    char* end = nullptr;
    const double x = std::strtod(r.set.front().second.c_str(), &end);
    if (!(end && *end == '\0')) return;
    std::string others;
    for (std::size_t q = 1; q < r.set.size(); ++q)
        others += (others.empty() ? "" : ", ") + r.set[q].first + " = " + r.set[q].second;
    // Several seeds: each run a point (one series per value of the other
    // keys) beside the mean's line; one seed: a line per value.
    auto& ser = out.by_seed[{others, o.seeds > 1 ? 0L : r.seed_offset}];
    if (o.seeds > 1) {
        ser.label = others.empty() ? "each seed" : others + ", each seed";
        ser.style = io::Series::Style::points;
    } else {
        ser.label = others.empty() ? "seed offset " + std::to_string(r.seed_offset) : others;
    }
    ser.x.push_back(x), ser.y.push_back(y);
    auto& m = out.mean[others][x];
    m.first += y, ++m.second;
}

void tabulate_sweep(const SweepOptions& o, const std::vector<SweepRun>& plan, const std::vector<std::string>& summaries,
                    const std::vector<std::string>& errors, SweepTable& out) {
    add_csv_header(o, out.csv);
    for (std::size_t k = 0; k < plan.size(); ++k) {
        const auto& r = plan[k];
        SweepRow w = sweep_row(o, k, r, summaries[k], errors[k]);
        if (w.status != "done") ++out.failed;
        out.table.push_back(w.row);
        add_csv_row(o, k, r, w, out.csv);
        // The plot of finished runs only (a run stopped early has no answer to average).
        if (!o.set.empty() && std::isfinite(w.y) && w.status == "done") add_plot_point(o, r, w.y, out);
    }
}

} // namespace

int run_sweep(const SweepOptions& o) {
    if (o.seeds < 1) throw InputError("--seeds", 0, "", "needs at least 1");
    const std::string base = read_text(o.model);
    const std::vector<SweepRun> plan = plan_sweep(o, base);
    const std::size_t runs = plan.size();
    if (o.check_only) return 0;
    if (Ranks::root()) io::make_output_directory(o.out);
    const bool quiet = o.quiet || !Ranks::root();
    if (!quiet)
        std::fprintf(stderr, "bbm sweep: %zu runs of %s (%zu values x %d seeds) on %d rank%s, %d at once per rank\n",
                     runs, o.model.c_str(), runs / std::size_t(o.seeds), o.seeds, Ranks::size(),
                     Ranks::size() > 1 ? "s" : "", o.jobs);
    std::vector<std::string> errors;
    const auto summaries = run_spread(int(runs), o.jobs, [&](int k) -> std::string {
        return run_one(o, plan[std::size_t(k)], quiet);
    }, &errors);
    if (!Ranks::root()) return 0;

    SweepTable t;
    tabulate_sweep(o, plan, summaries, errors, t);
    auto& mean = t.mean;
    io::write_text_atomically(o.out / "sweep.csv", t.csv.str());
    io::write_text_atomically(o.out / "sweep.json",
                              nlohmann::json{{"model", o.model},
                                             {"seeds", o.seeds},
                                             {"set", [&] {
                                                  nlohmann::json j = nlohmann::json::object();
                                                  for (const auto& [key, values] : o.set) j[key] = values;
                                                  return j;
                                              }()},
                                             {"plot", o.plot},
                                             {"ranks", Ranks::size()},
                                             {"runs", t.table}}
                                      .dump(2) + "\n");
    if (!mean.empty()) {
        std::vector<io::Series> series;
        if (o.seeds > 1)
            for (const auto& [others, points] : mean) {
                io::Series m{others.empty() ? "mean" : "mean, " + others, {}, {}};
                for (const auto& [x, sum] : points) m.x.push_back(x), m.y.push_back(sum.first / sum.second);
                series.push_back(std::move(m));
            }
        for (auto& [seed, ser] : t.by_seed) series.push_back(std::move(ser));
        io::draw_curves(series, o.set.front().first, o.plot, o.out / "sweep.png", "bbm sweep: " + o.model);
    }
    if (!o.quiet)
        std::fprintf(stderr, "%zu runs, %d failed or incomplete; wrote %s/{sweep.csv, sweep.json%s}\n", runs, t.failed,
                     o.out.string().c_str(), mean.empty() ? "" : ", sweep.png");
    return stop_signal_received() ? 130 : t.failed ? 1 : 0;
}

} // namespace bbm::studies
