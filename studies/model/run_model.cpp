#include "studies/model/run_model.hpp"

#include "base/progress.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "io/binary_stream.hpp"
#include "io/vtk_output.hpp"
#include "core/creep.hpp"
#include "core/stages.hpp"
#include "studies/model/model.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "studies/model/opening.hpp"
#include "studies/cluster/ranks.hpp"
#include "base/error.hpp"
#include "meshing/blocks.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdint>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace bbm::studies {
using namespace bbm::io;

namespace fs = std::filesystem;

namespace {

/// The signal that asked the run to stop (SIGINT, SIGTERM, SIGUSR1), or −1 for
/// --stop-at-step; 0 while none has. The handler only stores it: the stage loop
/// ends after the current step and the checkpoint is written outside the handler.
std::atomic<int> interrupted{0};

// A run checkpoint starts with this tag and the format version. Format 1 (no
// version, model hash or stage reports; its solver state lacked the renumbering
// count) is refused with a reason; so is format 2 (no verdicts in its stage
// reports, and a solver state without the stage monitor). Format 3: docs/theory.md §10.1 (the formats before it: docs/notes/2026-11-28-theory-record.md §10.1).
constexpr std::string_view checkpoint_tag = "bbm-run-checkpoint-";
constexpr std::uint32_t checkpoint_format = 3;

/// FNV-1a of a model file's bytes: a checkpoint resumes only the text it ran.
std::uint64_t text_hash(std::string_view text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    return h;
}

std::string read_file_text(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file.string(), 0, "", "cannot open the model file");
    return {std::istreambuf_iterator<char>(in), {}};
}

/// What a run checkpoint says it is (read before the model is rebuilt).
struct CheckpointHeader {
    std::uint32_t format = checkpoint_format;
    std::string bbm_version;
    std::string model;           ///< absolute path of the model file
    std::uint64_t model_hash = 0; ///< text_hash of its bytes when the run started
    int threads = 1;             ///< informational: results do not depend on it
    long step = 0;               ///< total steps taken
    StageCursor cursor;
    std::string stage;           ///< name of the stage the cursor is in ("" past the last)
    double wall_seconds = 0.0;   ///< run time before this checkpoint
};

void write_header(std::ostream& o, const CheckpointHeader& h) {
    o.write(checkpoint_tag.data(), std::streamsize(checkpoint_tag.size()));
    put(o, 'v'), put(o, h.format);
    put_string(o, h.bbm_version), put_string(o, h.model), put(o, h.model_hash), put(o, h.threads);
    put(o, h.step), put(o, h.cursor.stage), put(o, h.cursor.started), put(o, h.cursor.step);
    put_string(o, h.stage), put(o, h.wall_seconds);
}

CheckpointHeader read_header(std::istream& i, const fs::path& file) {
    std::string tag(checkpoint_tag.size(), '\0');
    i.read(tag.data(), std::streamsize(tag.size()));
    if (!i || tag != checkpoint_tag) throw InputError(file.string(), 0, "", "not a bbm run checkpoint");
    CheckpointHeader h;
    const char mark = get<char>(i);
    if (mark == '1')
        throw InputError(file.string(), 0, "",
                         "checkpoint format 1, written by an older bbm; this bbm reads format " +
                             std::to_string(checkpoint_format) + " only: run the model again from the start");
    if (mark != 'v') throw InputError(file.string(), 0, "", "not a bbm run checkpoint");
    h.format = get<std::uint32_t>(i);
    if (h.format != checkpoint_format)
        throw InputError(file.string(), 0, "",
                         "checkpoint format " + std::to_string(h.format) + "; this bbm (" BBM_VERSION ") reads format " +
                             std::to_string(checkpoint_format) + " only: resume it with the bbm that wrote it, or "
                             "run the model again from the start");
    h.bbm_version = get_string(i), h.model = get_string(i), h.model_hash = get<std::uint64_t>(i);
    h.threads = get<int>(i);
    h.step = get<long>(i), h.cursor.stage = get<int>(i), h.cursor.started = get<bool>(i), h.cursor.step = get<long>(i);
    h.stage = get_string(i), h.wall_seconds = get<double>(i);
    return h;
}

/// Writes the ParaView series, the history, progress and checkpoints of a run.
class RunOutput : public StageObserver {
public:
    RunOutput(const fs::path& out, const AnalysisSpec& an, const Solver& s, const RunOptions& o, std::string model,
              std::uint64_t model_hash)
        : out_(out), settings_(an.solver), stages_(an.stages), recorder_(s.world(), an.histories), options_(o),
          model_(std::move(model)), model_hash_(model_hash) {
        make_output_directory(out_);
        fs::create_directories(out_ / "vtk");
    }

    void stage_started(const Solver& s, const StageSpec& st) override {
        if (s.world().clock.steps == 0 && rows_.empty()) {
            record(s);
            snapshot(s);
        }
        (void)st;
    }
    void step_done(const Solver& s, const StageSpec& st, long k) override {
        if (s.world().clock.steps % settings_.history_every == 0) record(s);
        if (settings_.output_every > 0 && s.world().clock.steps % settings_.output_every == 0) snapshot(s);
        if (s.world().clock.steps % 100 == 0) check_run_health(s);
        if (options_.quiet) return;
        if (!progress_.due()) return;
        const auto now = std::chrono::steady_clock::now();
        const World& w = s.world();
        // The stage's model time so far (a dynamic step is constant within a stage).
        const double stage_time = k * w.clock.dt;
        if (stage_name_ != st.name) stage_name_ = st.name, stage_t0_ = now, stage_k0_ = k, stage_time0_ = stage_time;
        const double el = std::chrono::duration<double>(now - stage_t0_).count();
        const double rate = el > 0 ? (k - stage_k0_) / el : 0.0;
        using K = StageSpec::Kind;
        const int tensile = cracks(w, contact::JointState::broken_tension), shear = cracks(w, contact::JointState::broken_shear);
        if (st.kind == K::cycle && st.time > 0.0) { // a dynamic stage runs model time, not steps
            const double time_rate = el > 0 ? (stage_time - stage_time0_) / el : 0.0;
            progress_.line("  %-12s time %9.4g/%-9.4g s  ratio %9.3e  cracks %6d T %6d S  %7.0f steps/s  ETA %5.0f s",
                           st.name.c_str(), stage_time, st.time, w.clock.ratio, tensile, shear, rate,
                           time_rate > 0 ? (st.time - stage_time) / time_rate : 0.0);
            return;
        }
        if (st.kind == K::creep && w.creep) { // creep time does not pass at a steady rate: no ETA
            progress_.line("  %-12s creep %9.4g/%-9.4g years  ratio %9.3e  cracks %6d T %6d S  %7.0f steps/s",
                           st.name.c_str(), w.creep->time / seconds_per_year, w.creep->until / seconds_per_year,
                           w.clock.ratio, tensile, shear, rate);
            return;
        }
        const long total = st.kind == K::cycle || st.kind == K::excavate || st.kind == K::pressurise ? st.steps
                                                                                                       : st.max_steps;
        progress_.line("  %-12s step %9ld/%-9ld ratio %9.3e  cracks %6d T %6d S  %7.0f steps/s  ETA %5.0f s",
                       st.name.c_str(), k, total, w.clock.ratio, tensile, shear, rate, rate > 0 ? (total - k) / rate : 0.0);
    }
    void at(const Solver& s, const StageCursor& c) override {
        cursor_ = c;
        if (c.step == 0) return;
        if (options_.stop_at_step > 0 && s.world().clock.steps >= options_.stop_at_step) interrupted = -1;
        const auto& every = options_.checkpoint_every;
        bool due = every.steps > 0 && s.world().clock.steps % every.steps == 0;
        if (every.seconds > 0 && s.world().clock.steps % 16 == 0) {
            const auto now = std::chrono::steady_clock::now();
            due = due || std::chrono::duration<double>(now - last_checkpoint_).count() >= every.seconds;
        }
        // The interrupted run writes its checkpoint once, at the end.
        if (due && interrupted == 0) write_checkpoint(s);
    }
    void stage_done(const Solver& s, const StageReport& r) override {
        reports_.push_back(r);
        record(s);
        snapshot(s);
        flush_history();
        if (options_.quiet) return;
        // A solve stage ends at its ratio, at rest (until = "rest"), at equilibrium
        // (until = "equilibrium", its ratio reached too) or at its step limit.
        const char* end = r.failed                          ? "  (the rock failed under its held load)"
                        : r.converged || r.kind != "solve" ? ""
                        : r.verdict.at_rest()               ? "  (rock at rest)"
                                                            : "  (step limit reached)";
        progress_.result("  %-12s %-10s %9ld steps  ratio %9.3e  %7.2f s%s%s", r.name.c_str(), r.kind.c_str(), r.steps,
                         r.ratio, r.seconds, end, r.method.empty() ? "" : ("  " + r.method).c_str());
        if (r.verdict.kind != Verdict::Kind::none) std::fprintf(stderr, "  %-12s %s\n", "", describe(r.verdict).c_str());
        if (r.kind == "creep")
            std::fprintf(stderr, "  %-12s creep time %.6g s (%.4g days, %.4g years) in %ld creep steps%s\n", "",
                         r.creep_time, r.creep_time / 86400.0, r.creep_time / seconds_per_year, r.creep_steps,
                         r.failed ? ": its time to failure" : "");
    }
    bool stop_requested() override { return interrupted.load() != 0; }

    /// Wall seconds of the run so far, including those before a resume.
    double wall_seconds() const {
        return earlier_seconds_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    }
    /// Every stage report of the run, those finished before a resume first.
    const std::vector<StageReport>& reports() const { return reports_; }

    void write_checkpoint(const Solver& s) {
        std::ostringstream o(std::ios::binary);
        CheckpointHeader h;
        h.bbm_version = BBM_VERSION;
        h.model = model_, h.model_hash = model_hash_, h.threads = options_.threads;
        // A stop that came while a stage's end was written: that stage is done.
        const StageCursor cursor = int(reports_.size()) > cursor_.stage ? StageCursor{int(reports_.size()), false, 0} : cursor_;
        h.step = s.world().clock.steps, h.cursor = cursor, h.wall_seconds = wall_seconds();
        h.stage = cursor.stage < int(stages_.size()) ? stages_[cursor.stage].name : "";
        write_header(o, h);
        put(o, std::uint64_t(reports_.size()));
        for (const auto& r : reports_) {
            put_string(o, r.name), put_string(o, r.kind), put_string(o, r.method);
            put(o, r.steps), put(o, r.ratio), put(o, r.seconds), put(o, r.converged), put(o, r.verdict);
            // A creep stage's time (no checkpoint before creep stages had one).
            if (r.kind == "creep") put(o, r.creep_time), put(o, r.creep_steps), put(o, r.failed);
        }
        put(o, std::uint64_t(rows_.size()));
        for (std::size_t r = 0; r < rows_.size(); ++r) {
            put(o, rows_[r].first), put(o, times_[r]), put(o, std::uint64_t(rows_[r].second.size()));
            for (double v : rows_[r].second) put(o, v);
        }
        put(o, std::uint64_t(series_.size()));
        for (const auto& [t, name] : series_) put(o, t), put_string(o, name);
        put(o, last_snapshot_);
        save_state(s.world(), o);
        flush_history();
        write_text_atomically(out_ / "checkpoint.bin", o.str());
        last_checkpoint_ = std::chrono::steady_clock::now();
    }
    /// Reads the run part of a checkpoint after its header; the solver part follows.
    void restore(std::istream& i, const CheckpointHeader& h) {
        cursor_ = h.cursor;
        earlier_seconds_ = h.wall_seconds;
        const auto reports = get<std::uint64_t>(i);
        if (reports > 100000) throw std::runtime_error("checkpoint is corrupt (stage reports)");
        for (std::uint64_t k = 0; k < reports; ++k) {
            StageReport r;
            r.name = get_string(i), r.kind = get_string(i), r.method = get_string(i);
            r.steps = get<long>(i), r.ratio = get<double>(i), r.seconds = get<double>(i), r.converged = get<bool>(i);
            r.verdict = get<Verdict>(i);
            if (!r.verdict.valid()) throw std::runtime_error("checkpoint is corrupt");
            if (r.kind == "creep")
                r.creep_time = get<double>(i), r.creep_steps = get<long>(i), r.failed = get<bool>(i);
            reports_.push_back(r);
        }
        const auto rows = get<std::uint64_t>(i);
        if (rows > (std::uint64_t(1) << 32)) throw std::runtime_error("checkpoint is corrupt (history rows)");
        for (std::uint64_t r = 0; r < rows; ++r) {
            const long step = get<long>(i);
            times_.push_back(get<double>(i));
            const auto columns = get<std::uint64_t>(i);
            if (columns != recorder_.histories().size())
                throw std::runtime_error("checkpoint is corrupt (history columns)");
            std::vector<double> v(columns);
            for (double& x : v) x = get<double>(i);
            rows_.push_back({step, std::move(v)});
        }
        const auto n = get<std::uint64_t>(i);
        if (n > (std::uint64_t(1) << 32)) throw std::runtime_error("checkpoint is corrupt (snapshots)");
        for (std::uint64_t k = 0; k < n; ++k) {
            const double t = get<double>(i);
            series_.push_back({t, get_string(i)});
        }
        last_snapshot_ = get<long>(i);
    }
    const StageCursor& cursor() const { return cursor_; }
    const std::vector<std::pair<long, std::vector<double>>>& rows() const { return rows_; }
    const std::vector<double>& times() const { return times_; }
    const HistoryRecorder& recorder() const { return recorder_; }
    void snapshot(const Solver& s) {
        const World& w = s.world();
        if (!series_.empty() && last_snapshot_ == w.clock.steps) return;
        last_snapshot_ = w.clock.steps;
        char name[64];
        std::snprintf(name, sizeof name, "vtk/blocks_%08ld.vtu", w.clock.steps);
        write_state_blocks_vtu(w, out_ / name);
        series_.push_back({w.clock.time, name});
        std::snprintf(name, sizeof name, "vtk/contacts_%08ld.vtu", w.clock.steps);
        write_state_contacts_vtu(w, out_ / name);
        series_.push_back({w.clock.time, name});
        if (w.flow) {
            std::snprintf(name, sizeof name, "vtk/flow_%08ld.vtu", w.clock.steps);
            write_flow_vtu(w, out_ / name);
            series_.push_back({w.clock.time, name});
        }
        for (const auto& [type, lines] : support_lines(w)) {
            std::snprintf(name, sizeof name, "vtk/%s_%08ld.vtu", type.c_str(), w.clock.steps);
            write_support_vtu(lines, out_ / name);
            series_.push_back({w.clock.time, name});
        }
        // result.pvd holds every part; blocks.pvd, contacts.pvd (and <type>.pvd
        // per installed support type) one each (for scripts that
        // style them apart, examples/paraview_view.py).
        write_pvd(out_ / "result.pvd", series_);
        // One series per part: "vtk/<part>_<step>.vtu" goes to <part>.pvd.
        std::map<std::string, std::vector<std::pair<double, std::string>>> parts;
        for (const auto& entry : series_) {
            const auto& file = entry.second;
            parts[file.substr(4, file.rfind('_') - 4)].push_back(entry);
        }
        for (const auto& [part, series] : parts) write_pvd(out_ / (part + ".pvd"), series);
    }
    void flush_history() {
        std::ostringstream csv;
        csv << "step,time";
        for (const auto& h : recorder_.histories()) csv << ',' << h.name;
        csv << '\n';
        csv.precision(10);
        for (std::size_t r = 0; r < rows_.size(); ++r) {
            csv << rows_[r].first << ',' << times_[r];
            for (double v : rows_[r].second) csv << ',' << v;
            csv << '\n';
        }
        write_text_atomically(out_ / "history.csv", csv.str());
    }
    void record(const Solver& s) {
        if (!rows_.empty() && rows_.back().first == s.world().clock.steps) return;
        rows_.push_back({s.world().clock.steps, recorder_.sample(s.world())});
        times_.push_back(s.world().clock.time);
    }

private:
    fs::path out_;
    SolverSpec settings_;
    std::vector<StageSpec> stages_;
    HistoryRecorder recorder_;
    RunOptions options_;
    std::string model_;
    std::uint64_t model_hash_ = 0;
    std::vector<StageReport> reports_;
    double earlier_seconds_ = 0.0;
    std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now(), last_checkpoint_ = started_;
    std::vector<std::pair<long, std::vector<double>>> rows_;
    std::vector<double> times_;
    std::vector<std::pair<double, std::string>> series_;
    long last_snapshot_ = -1;
    StageCursor cursor_;
    std::string stage_name_;
    long stage_k0_ = 0;
    double stage_time0_ = 0.0;
    std::chrono::steady_clock::time_point stage_t0_ = std::chrono::steady_clock::now();
    Progress progress_;
};

/// history.png: the unbalanced ratio and the crack counts against the step.
void draw_history(const RunOutput& out, const fs::path& file) {
    const auto& h = out.recorder().histories();
    std::vector<Series> ratio, cracks;
    for (std::size_t k = 0; k < h.size(); ++k) {
        using Q = HistorySpec::Quantity;
        const bool is_ratio = h[k].quantity == Q::unbalanced_ratio;
        const bool is_crack = h[k].quantity == Q::cracks_tensile || h[k].quantity == Q::cracks_shear;
        if (!is_ratio && !is_crack) continue;
        Series ser{h[k].name, {}, {}};
        for (const auto& [step, values] : out.rows())
            if (!is_ratio || values[k] > 0) ser.x.push_back(double(step)), ser.y.push_back(values[k]);
        (is_ratio ? ratio : cracks).push_back(std::move(ser));
    }
    auto stem = file.stem().string();
    if (!ratio.empty()) draw_curves(ratio, "step", "unbalanced-force ratio", file, "convergence", true);
    if (!cracks.empty())
        draw_curves(cracks, "step", "broken contacts", file.parent_path() / (stem + "_cracks.png"), "cracks");
}

} // namespace

namespace {

/// With --resume: the checkpoint's header, or why there is nothing to resume.
/// Returns false (and says so) when the run in DIR had already finished.
bool open_checkpoint(const RunOptions& opt, std::ifstream& in, CheckpointHeader& header) {
    const fs::path file = opt.out / "checkpoint.bin", summary_file = opt.out / "summary.json";
    // A finished run: its summary says complete, and no checkpoint is newer.
    long finished_at = -1;
    if (fs::exists(summary_file)) {
        std::ifstream f(summary_file);
        const auto j = nlohmann::json::parse(f, nullptr, false);
        if (!j.is_discarded() && j.value("complete", false)) finished_at = j.value("steps", 0L);
    }
    in.open(file, std::ios::binary);
    try {
        if (in) header = read_header(in, file);
    } catch (const InputError&) {
        throw;
    } catch (const std::runtime_error& e) {
        throw InputError(file.string(), 0, "", e.what());
    }
    if (finished_at >= 0 && (!in || header.step <= finished_at)) {
        if (!opt.quiet)
            std::fprintf(stderr, "%s: the run finished (step %ld; %s says complete): nothing to resume\n",
                         opt.out.string().c_str(), finished_at, summary_file.string().c_str());
        return false;
    }
    if (!in)
        throw InputError(file.string(), 0, "",
                         "no checkpoint to resume from (run with --checkpoint-every N, or stop a run with Ctrl-C)");
    return true;
}

} // namespace

CheckpointInterval parse_checkpoint_interval(const std::string& text) {
    CheckpointInterval every;
    std::size_t used = 0;
    double value = -1.0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    const std::string unit = text.substr(used);
    const double scale = unit.empty() ? 0.0
                       : (unit == "s" || unit == "sec")                   ? 1.0
                       : (unit == "m" || unit == "min")                   ? 60.0
                       : (unit == "h")                                    ? 3600.0
                                                                          : -1.0;
    if (used == 0 || !(value >= 0.0) || !std::isfinite(value) || scale < 0.0 ||
        (unit.empty() && value != std::floor(value)))
        throw InputError("bbm run", 0, "--checkpoint-every",
                         "'" + text + "' is not an interval: give steps (5000) or wall time (30min, 2h, 90s)");
    if (unit.empty()) every.steps = long(value);
    else every.seconds = value * scale;
    return every;
}

void catch_stop_signals() {
    for (int sig : {SIGINT, SIGTERM, SIGUSR1}) std::signal(sig, [](int signal) { interrupted = signal; });
}

bool stop_signal_received() { return interrupted.load() > 0; }

/// `--profile`: the time per stage of the step, printed as a table and returned for
/// summary.json.
nlohmann::json report_profile(const StepProfile& p, int contacts) {
    double total = 0.0;
    for (double t : p.seconds) total += t;
    std::fprintf(stderr, "\nprofile: %ld steps, %.3f s in step() (first thread; a stage includes its wait at the barrier "
                         "that ends it)\n  %-20s %10s %7s %14s\n",
                 p.steps, total, "stage", "seconds", "share", "us per step");
    nlohmann::json stages = nlohmann::json::object();
    double contact_seconds = 0.0;
    for (std::size_t k = 0; k < step_stages.size(); ++k) {
        const double t = p.seconds[k];
        const std::string name(step_stages[k].name);
        std::fprintf(stderr, "  %-20s %10.3f %6.1f%% %14.2f\n", name.c_str(), t, total > 0 ? 100.0 * t / total : 0.0,
                     p.steps > 0 ? 1e6 * t / double(p.steps) : 0.0);
        stages[name] = t;
        if (name == "contacts") contact_seconds = t;
    }
    const double contact_ns = p.steps > 0 && contacts > 0 ? 1e9 * contact_seconds / double(p.steps) / contacts : 0.0;
    std::fprintf(stderr, "  contacts per contact (at the end: %d contacts): %.1f ns per step\n", contacts, contact_ns);
    return {{"steps", p.steps}, {"seconds", stages}, {"total_seconds", total}};
}

namespace {

/// --resume: the checkpoint opened and its model file checked (the same path, the
/// same text); the model file to run. None: nothing to resume (said already).
std::optional<std::string> model_to_run(const RunOptions& opt, std::ifstream& checkpoint, CheckpointHeader& header) {
    if (!opt.resume) return opt.model;
    if (!open_checkpoint(opt, checkpoint, header)) return std::nullopt;
    const fs::path file = opt.out / "checkpoint.bin";
    if (!opt.model.empty() && fs::absolute(opt.model).lexically_normal() != fs::path(header.model).lexically_normal())
        throw InputError(file.string(), 0, "",
                         "the checkpoint is of the model " + header.model + ", not " + opt.model +
                             " (resume without a model file, or run " + opt.model + " into another --out)");
    if (!fs::exists(header.model))
        throw InputError(file.string(), 0, "", "the checkpoint's model file " + header.model + " is gone");
    if (text_hash(read_file_text(header.model)) != header.model_hash)
        throw InputError(header.model, 0, "",
                         "the model file changed since " + file.string() +
                             " was written (its text no longer matches the checkpoint's model hash): resume "
                             "with the file as it was, or run the edited model from the start");
    return header.model;
}

/// failure.png's window (around the opening, or the report's) and the failed zone's outline.
FailurePlotOptions failure_plot_options(const io::ModelFile& model, const meshing::BlockAssembly& blocks,
                                        const Solver& solver, const std::string& model_path) {
    const auto& rep = model.analysis.report;
    FailurePlotOptions fo;
    fo.title = model_path;
    if (rep.opening) {
        const double r = std::max(norm(rep.springline - rep.center), norm(rep.crown - rep.center));
        Box2 all;
        for (Vec2 p : blocks.points) all.add(p);
        fo.window.add({std::max(all.lo.x, rep.center.x - 2.2 * r), std::max(all.lo.y, rep.center.y - 2.2 * r)});
        fo.window.add({std::min(all.hi.x, rep.center.x + 2.2 * r), std::min(all.hi.y, rep.center.y + 2.2 * r)});
        const auto zone = measure_failed_zone(solver.world(), rep.center, rep.springline, rep.crown);
        if (zone.area > 0) fo.outline = zone.outline();
    }
    if (rep.window) fo.window = *rep.window;
    return fo;
}

/// failure.png, failure.svg and history.png. They are independent: with a second
/// thread, failure.png is drawn beside the other two (after the one lazy cache a
/// drawing reads, the contact normals, is refreshed here, so that both only read
/// the solver).
void draw_pictures(const Solver& solver, const RunOutput& output, const RunOptions& opt, const FailurePlotOptions& fo) {
    auto svg_and_history = [&] {
        draw_failure(solver.world(), opt.out / "failure.svg", fo);
        draw_history(output, opt.out / "history.png");
    };
    if (opt.threads > 1) {
        (void)contacts(solver.world());
        auto other = std::async(std::launch::async, svg_and_history);
        draw_failure(solver.world(), opt.out / "failure.png", fo);
        other.get();
    } else {
        draw_failure(solver.world(), opt.out / "failure.png", fo);
        svg_and_history();
    }
}

/// What the run did, on stderr: steps, cracks, the opening, the supports' loads.
void print_run_report(const Solver& solver, const nlohmann::json& summary, const io::ModelFile& model,
                      const RunOptions& opt, double seconds) {
    const auto& rep = model.analysis.report;
    std::fprintf(stderr, "%ld steps in %.2f s; cracks %d tensile, %d shear\n", solver.world().clock.steps, seconds,
                 cracks(solver.world(), contact::JointState::broken_tension),
                 cracks(solver.world(), contact::JointState::broken_shear));
    if (rep.opening)
        std::fprintf(stderr, "opening: convergence %.2f mm at the springline, %.2f mm at the crown; cracks in the "
                             "±30° sectors %d (springline) vs %d (crown)\n",
                     1e3 * summary["opening"]["springline_convergence"].get<double>(),
                     1e3 * summary["opening"]["crown_convergence"].get<double>(),
                     summary["opening"]["cracks_springline_sector"].get<int>(),
                     summary["opening"]["cracks_crown_sector"].get<int>());
    if (rep.opening) {
        const auto& zone = summary["opening"]["failed_zone"];
        if (zone.value("reaches_region_edge", false)) {
            const auto& p = zone["region_edge_point"];
            std::fprintf(stderr, "warning: the failed zone reaches the edge of the opening's region at (%.2f, %.2f) "
                                 "m, its interface with the elastic far field: the failure there is the model "
                                 "boundary's as much as the rock's; enlarge the bonded region\n",
                         p[0].get<double>(), p[1].get<double>());
        } else if (zone.value("region_edge_cells_damaged", 0) >= 2) {
            std::fprintf(stderr, "warning: the rock is damaged along the edge of the opening's region (%d of its "
                                 "%d cells there), where it meets the elastic far field: the boundary, not only "
                                 "the opening, breaks rock; enlarge the bonded region\n",
                         zone["region_edge_cells_damaged"].get<int>(), zone["region_edge_cells"].get<int>());
        }
    }
    if (summary.contains("ejecta")) {
        const auto& e = summary["ejecta"];
        std::fprintf(stderr, "ejecta: %.3g t/m in %d blocks, at %.2f m/s (mass-weighted; fastest %.2f, peaks %.2f), "
                             "kinetic energy %.3g kJ/m",
                     e["mass_t_per_m"].get<double>(), e["blocks"].get<int>(), e["speed_mean"].get<double>(),
                     e["speed_max"].get<double>(), e["peak_speed_mean"].get<double>(),
                     e["kinetic_energy"].get<double>() / 1e3);
        if (e.contains("wall_length") && e["wall_length"].get<double>() > 0.0)
            std::fprintf(stderr, "; %.3g kN/m² and %.3g kJ/m² of the %.2f m of wall it came off, from up to %.2f m "
                                 "deep",
                         e["weight_kN_per_m2"].get<double>(), e["kinetic_energy_kJ_per_m2"].get<double>(),
                         e["wall_length"].get<double>(), e["depth"].get<double>());
        std::fprintf(stderr, "; PPV %.2f m/s\n", e["peak_particle_velocity_max"].get<double>());
    }
    // Each installed set of every support type, its figures as summary.json has them.
    for (const auto& [type, sets] : support_summaries(solver.world()))
        for (const auto& set : sets) {
            std::string figures;
            char value[64];
            for (const auto& f : set.figures) {
                std::snprintf(value, sizeof value, f.count ? "%.0f" : "%.4g", f.value);
                figures += (figures.empty() ? "" : ", ") + f.key + " " + value;
            }
            std::fprintf(stderr, "%s '%s': %s\n", type.c_str(), set.name.c_str(), figures.c_str());
        }
    std::fprintf(stderr, "wrote %s/{result.pvd, history.csv, history.png, failure.png, summary.json}\n",
                 opt.out.string().c_str());
}

/// The model a run steps: its file read, its blocks generated and its solver
/// built, each failure reported as bad input at the model file's line.
struct BuiltModel {
    io::ModelFile model;
    meshing::BlockAssembly blocks;
    meshing::GenerationStats gen;
    std::unique_ptr<Solver> solver;
};

BuiltModel build_model_to_run(const std::string& model_path, const RunOptions& opt) {
    BuiltModel b;
    b.model = io::read_model(model_path);
    b.model.analysis.solver.threads = opt.threads;
    if (opt.max_elements > 0) b.model.geometry.max_elements = opt.max_elements;
    if (b.model.analysis.stages.empty())
        throw InputError(model_path, 0, "stage", "the model has no [[stage]] to run (bbm mesh only generates blocks)");
    try {
        b.blocks = meshing::generate_blocks(b.model.geometry, &b.gen);
    } catch (const GeometryError& e) {
        throw io::to_input_error(b.model.source, e);
    }
    try {
        b.solver = std::make_unique<Solver>(b.blocks, b.model.analysis);
    } catch (const InputError& e) {
        throw InputError(model_path, b.model.source.line_of(e.key()), e.key(), e.message());
    }
    return b;
}

/// Says why the run stopped before its end and how to continue it.
void report_stop(int stop_signal, long step, const fs::path& out) {
    std::fprintf(stderr, "\n%s at step %ld: wrote %s; continue with: bbm run --resume --out %s\n",
                 stop_signal < 0 ? "stopped (--stop-at-step)"
                 : stop_signal == SIGINT ? "interrupted (SIGINT)"
                 : stop_signal == SIGTERM ? "interrupted (SIGTERM)" : "interrupted (SIGUSR1)",
                 step, (out / "checkpoint.bin").string().c_str(), out.string().c_str());
}

/// What was built, on stderr: rigid and deformable blocks, zones, contacts, the time step.
void print_model_built(const std::string& model_path, const BuiltModel& built) {
    const meshing::BlockAssembly& blocks = built.blocks;
    const Solver& solver = *built.solver;
    int rigid = 0;
    for (int i = 0; i < blocks.block_count(); ++i) rigid += !solver.world().blocks.deformable[i];
    std::fprintf(stderr, "%s: %d rigid blocks, %d deformable blocks with %d zones, %d contacts; time step %.3g s (%s)\n",
                 model_path.c_str(), rigid, blocks.block_count() - rigid, solver.world().zones.size(),
                 contacts(solver.world()).size(), solver.world().clock.dt,
                 built.model.analysis.solver.mode == SolverSpec::Mode::quasi_static ? "quasi-static" : "dynamic");
}

/// --resume: the output's records and the world's state from the checkpoint;
/// where in the stages the run goes on.
StageCursor resume_from_checkpoint(RunOutput& output, Solver& solver, std::ifstream& checkpoint,
                                   const CheckpointHeader& header, const RunOptions& opt, const std::string& model_path) {
    const fs::path file = opt.out / "checkpoint.bin";
    try {
        output.restore(checkpoint, header);
        load_state(solver.world(), checkpoint);
    } catch (const std::runtime_error& e) {
        // A checkpoint that does not fit this model or this bbm is bad input, not a crash.
        throw InputError(file.string(), 0, "", e.what());
    }
    const StageCursor start = output.cursor();
    if (!opt.quiet)
        std::fprintf(stderr,
                     "resuming %s at step %ld (stage %d '%s', step %ld in it; checkpoint format %u, written by bbm %s "
                     "on %d thread%s)\n",
                     model_path.c_str(), solver.world().clock.steps, start.stage + 1, header.stage.c_str(), start.step,
                     header.format, header.bbm_version.c_str(), header.threads, header.threads == 1 ? "" : "s");
    return start;
}

/// The stages run from `start`: the reports of this part of the run, and the
/// message of the health check that stopped it (empty if none did).
struct StagesRun {
    std::vector<StageReport> this_part;
    std::string health;
};

StagesRun run_model_stages(Solver& solver, const io::ModelFile& model, RunOutput& output, StageCursor start,
                           const std::string& model_path) {
    StagesRun run;
    try {
        run.this_part = run_stages(solver, model.analysis.stages, output, start);
    } catch (const NumericalError& e) {
        run.health = e.what();
    } catch (const InputError& e) {
        // Found by a stage (a support installed where there is no rock): the model's line.
        if (!e.file().empty()) throw;
        throw InputError(model_path, model.source.line_of(e.key()), e.key(), e.message());
    }
    return run;
}

/// summary.json, and the pictures of the state — or, when a health check stopped
/// the run, its history so far instead; the summary.
nlohmann::json write_run_output(const BuiltModel& built, RunOutput& output, const RunOptions& opt,
                                const std::string& model_path, const std::vector<StageReport>& reports,
                                const std::string& health, int stop_signal, double seconds) {
    const Solver& solver = *built.solver;
    nlohmann::json summary = run_summary(model_path, built.model, built.blocks, built.gen, solver, reports, seconds,
                                         stop_signal != 0, health.empty() && stop_signal == 0);
    if (opt.profile) summary["profile"] = report_profile(solver.profile(), contacts(solver.world()).size());
    FailurePlotOptions fo = failure_plot_options(built.model, built.blocks, solver, model_path);
    fo.shade_pressure = opt.shade_pressure;
    if (!health.empty()) {
        summary["error"] = health; // pictures of a broken state would mislead: the last good VTK stays
        output.flush_history();    // its rows so far: how the stage went wrong
    } else {
        draw_pictures(solver, output, opt, fo);
    }
    if (const auto& events = solver.world().events) {
        // The catalogue (core/events.hpp): a table and points for ParaView.
        const std::vector<SeismicEvent> catalogue = event_catalogue(*events);
        write_text_atomically(opt.out / "events.csv", events_csv(catalogue));
        write_events_vtu(catalogue, opt.out / "events.vtu");
    }
    write_text_atomically(opt.out / "summary.json", summary.dump(2) + "\n");
    return summary;
}

} // namespace

int run_model(const RunOptions& opt) {
    // From the start: a scheduler's signal during meshing or the elastic solve
    // must not kill the run either (it stops after the first step).
    // The handlers stay installed after the run: a scheduler's signal that comes
    // once the run has written its results (a job's time limit while the process
    // exits) must not turn a finished run into one killed by a signal (status
    // 138 for SIGUSR1: the requeued job would then fail). `bbm compare` reads the
    // flag between models.
    // A signal that came before (during start-up) is kept: the run stops after
    // its first step. Only an earlier run's --stop-at-step is forgotten.
    if (interrupted.load() < 0) interrupted = 0;
    catch_stop_signals();
    std::ifstream checkpoint;
    CheckpointHeader header;
    const auto to_run = model_to_run(opt, checkpoint, header);
    if (!to_run) return 0;
    const std::string& model_path = *to_run;
    BuiltModel built = build_model_to_run(model_path, opt);
    Solver& solver = *built.solver;
    if (opt.check_only) return 0;
    solver.profile().enabled = opt.profile;
    if (!opt.quiet) print_model_built(model_path, built);
    RunOutput output(opt.out, built.model.analysis, solver, opt, fs::absolute(model_path).lexically_normal().string(),
                     text_hash(read_file_text(model_path)));
    StageCursor start;
    if (opt.resume) start = resume_from_checkpoint(output, solver, checkpoint, header, opt, model_path);
    const StagesRun run = run_model_stages(solver, built.model, output, start, model_path);
    const int stop_signal = interrupted.load();
    if (stop_signal != 0) {
        output.write_checkpoint(solver);
        if (!opt.quiet) report_stop(stop_signal, solver.world().clock.steps, opt.out);
    }
    // The stages finished (before a resume too) and, if the run stopped inside one, that stage so far.
    std::vector<StageReport> reports = output.reports();
    if (stop_signal != 0 && !run.this_part.empty() && int(reports.size()) == output.cursor().stage)
        reports.push_back(run.this_part.back());
    const double seconds = output.wall_seconds();
    const nlohmann::json summary =
        write_run_output(built, output, opt, model_path, reports, run.health, stop_signal, seconds);
    if (!run.health.empty()) {
        std::fprintf(stderr, "\nbbm: stopped: %s\nThe output of the last good step is kept in %s.\n",
                     run.health.c_str(), opt.out.string().c_str());
        return 3;
    }
    if (!opt.quiet) print_run_report(solver, summary, built.model, opt, seconds);
    return stop_signal != 0 ? 130 : 0;
}

namespace {

/// Per registered support type, its compare columns (core/supports/support.hpp)
/// over its sets in a run's summary.json: counts summed, loads their largest;
/// none when the run had no set of the type installed.
std::vector<std::optional<std::vector<double>>> support_columns(const nlohmann::json& j) {
    std::vector<std::optional<std::vector<double>>> out;
    for_each_support_type([&](auto type) {
        using T = typename decltype(type)::type;
        const std::string name(T::name);
        if (!j.contains(name) || j[name].empty()) {
            out.emplace_back();
            return;
        }
        std::vector<double> values;
        for (const CompareColumn& c : T::compare) {
            double v = 0.0;
            for (const auto& set : j[name]) {
                const double x = set.value(std::string(c.figure), 0.0);
                v = c.sum ? v + x : std::max(v, x);
            }
            values.push_back(v);
        }
        out.emplace_back(std::move(values));
    });
    return out;
}

/// The support columns' CSV header (`<type>_<figure>`) and Markdown headings.
std::string support_csv_header() {
    std::string h;
    for_each_support_type([&](auto type) {
        using T = typename decltype(type)::type;
        for (const CompareColumn& c : T::compare) h += "," + std::string(T::name) + "_" + std::string(c.figure);
    });
    return h;
}
std::string support_markdown_header() {
    std::string h;
    for_each_support_type([&](auto type) {
        using T = typename decltype(type)::type;
        std::string cell = std::string(T::name) + ":";
        for (std::size_t k = 0; k < T::compare.size(); ++k) cell += (k ? ", " : " ") + std::string(T::compare[k].heading);
        h += " " + cell + " |";
    });
    return h;
}

std::string number_text(double v, bool count) {
    char buf[32];
    std::snprintf(buf, sizeof buf, count ? "%.0f" : "%.1f", v);
    return buf;
}

/// What `bbm compare` tabulates of one run, read from its summary.json.
struct ComparedRun {
    nlohmann::json j, op;
    std::string kind;
    double crack_rate = 0.0, rock_ratio = 0.0, zone_springline = 0.0, zone_crown = 0.0;
    int fragments = 0;
    bool at_edge = false;
    std::vector<std::optional<std::vector<double>>> supports; ///< per registered type (support_columns)

    explicit ComparedRun(const fs::path& summary) {
        std::ifstream f(summary);
        j = nlohmann::json::parse(f);
        op = j.contains("opening") ? j["opening"] : nlohmann::json::object();
        const auto verdict = j.contains("verdict") ? j["verdict"] : nlohmann::json::object();
        kind = verdict.value("kind", std::string("-"));
        crack_rate = verdict.value("cracks_per_1000_steps", 0.0), rock_ratio = verdict.value("rock_mass_ratio", 0.0);
        fragments = verdict.value("fragments", 0);
        const auto zone = op.contains("failed_zone") ? op["failed_zone"] : nlohmann::json::object();
        zone_springline = zone.value("depth_springline", 0.0), zone_crown = zone.value("depth_crown", 0.0);
        at_edge = zone.value("reaches_region_edge", false) || zone.value("region_edge_cells_damaged", 0) >= 2;
        supports = support_columns(j);
    }
    double opening(const char* k) const { return op.contains(k) ? op[k].get<double>() : 0.0; }

    /// The support types' CSV cells (0 for a type the run has not) and Markdown cells ("-").
    std::string support_cells(bool markdown) const {
        std::string out;
        std::size_t t = 0;
        for_each_support_type([&](auto type) {
            using T = typename decltype(type)::type;
            const auto& values = supports[t++];
            if (markdown) {
                std::string cell;
                for (std::size_t k = 0; values && k < T::compare.size(); ++k)
                    cell += (k ? ", " : "") + number_text((*values)[k], T::compare[k].sum);
                out += " " + (values ? cell : std::string("-")) + " |";
            } else {
                for (std::size_t k = 0; k < T::compare.size(); ++k)
                    out += "," + number_text(values ? (*values)[k] : 0.0, T::compare[k].sum);
            }
        });
        return out;
    }

    std::string csv_row(const std::string& name) const {
        char row[1024];
        std::snprintf(row, sizeof row,
                      "%s,%d,%d,%d,%d,%ld,%.2f,%d,%d,%.3f,%.3f,%.3f,%.3f,%d,%d,%.3f,%.3f,%s,%.3f,%d,%.3e,%d",
                      name.c_str(), j["blocks"].get<int>(), j["deformable_blocks"].get<int>(), j["zones"].get<int>(),
                      j["contacts"].get<int>(), j["steps"].get<long>(), j["wall_seconds"].get<double>(),
                      j["cracks"]["tensile"].get<int>(), j["cracks"]["shear"].get<int>(),
                      1e3 * opening("springline_convergence"), 1e3 * opening("crown_convergence"),
                      opening("failed_depth_springline"), opening("failed_depth_crown"),
                      int(opening("cracks_springline_sector")), int(opening("cracks_crown_sector")), zone_springline,
                      zone_crown, kind.c_str(), crack_rate, fragments, rock_ratio, int(at_edge));
        return row + support_cells(false) + "\n";
    }

    std::string markdown_row(const std::string& name) const {
        const std::string shown = name + (j.value("interrupted", false) ? " (interrupted: bbm run --resume)" : "");
        char row[1024];
        std::snprintf(row, sizeof row,
                      "| %s | %d | %d | %ld | %.1f | %d | %d | %.2f | %.2f | %.2f | %.2f | %d / %d | %.2f / %.2f%s | %s | %.2f | %d | "
                      "%.2e |",
                      shown.c_str(), j["blocks"].get<int>(), j["zones"].get<int>(), j["steps"].get<long>(),
                      j["wall_seconds"].get<double>(), j["cracks"]["tensile"].get<int>(),
                      j["cracks"]["shear"].get<int>(), 1e3 * opening("springline_convergence"),
                      1e3 * opening("crown_convergence"), opening("failed_depth_springline"),
                      opening("failed_depth_crown"), int(opening("cracks_springline_sector")),
                      int(opening("cracks_crown_sector")), zone_springline, zone_crown,
                      at_edge ? " (damage at the region's edge)" : "", kind.c_str(), crack_rate, fragments, rock_ratio);
        return row + support_cells(true) + "\n";
    }
};

/// Cracks against step from a run's history.csv (the columns whose quantity is a
/// crack count, summed); none if it has no such column.
std::optional<Series> crack_curve(const std::string& name, const fs::path& history) {
    Series ser{name, {}, {}};
    std::ifstream h(history);
    std::string line;
    std::getline(h, line);
    std::vector<int> crack_columns;
    {
        std::stringstream head(line);
        std::string col;
        for (int k = 0; std::getline(head, col, ','); ++k)
            if (col.find("crack") != std::string::npos) crack_columns.push_back(k);
    }
    if (crack_columns.empty()) return std::nullopt;
    while (std::getline(h, line)) {
        std::stringstream row_in(line);
        std::string cell;
        double step = 0, cracks = 0;
        for (int k = 0; std::getline(row_in, cell, ','); ++k) {
            if (k == 0) step = std::stod(cell);
            if (std::find(crack_columns.begin(), crack_columns.end(), k) != crack_columns.end())
                cracks += std::stod(cell);
        }
        ser.x.push_back(step), ser.y.push_back(cracks);
    }
    return ser;
}

/// Runs the models over ranks under mpirun (one after another within a rank, each
/// on `threads` threads): each one's exit status, or "not started" once
/// interrupted (Ctrl-C, a scheduler's signal: the model running checkpoints and
/// the rest of this rank's models are not started; `bbm run --resume --out
/// DIR/<model>` continues each). `stopped`: whether that happened.
std::vector<std::string> run_compared_models(const std::vector<std::string>& models, const fs::path& out, int threads,
                                             bool quiet, bool& stopped) {
    const bool parallel = Ranks::size() > 1;
    stopped = false;
    return run_spread(int(models.size()), 1, [&](int k) {
        if (stopped) return std::string("not started");
        const std::string name = fs::path(models[k]).stem().string();
        RunOptions o;
        o.model = models[k];
        o.out = out / name;
        o.threads = threads;
        o.quiet = quiet || parallel;
        if (!o.quiet) std::fprintf(stderr, "== %s\n", name.c_str());
        const int rc = run_model(o);
        // Stopped in this model, or by a signal that came after it had finished.
        stopped = stopped || rc == 130 || interrupted.load() != 0;
        return std::to_string(rc);
    });
}

} // namespace

int compare_models(const std::vector<std::string>& models, const fs::path& out, int threads, bool quiet,
                   const CompareEnvelopeOptions* envelope) {
    // A rock a specimen cannot carry is refused before any model runs.
    if (envelope && envelope->enabled)
        for (const auto& m : models) (void)io::rock_of_model(io::read_model(m), m);
    make_output_directory(out);
    std::ostringstream csv, md;
    csv << "model,blocks,deformable_blocks,zones,contacts,steps,wall_seconds,cracks_tensile,cracks_shear,"
           "springline_convergence_mm,crown_convergence_mm,failed_depth_springline_m,failed_depth_crown_m,"
           "cracks_springline_sector,cracks_crown_sector,failed_zone_depth_springline_m,failed_zone_depth_crown_m,"
           "verdict,cracks_per_1000_steps_at_end,fragments,rock_mass_ratio,damage_at_region_edge"
        << support_csv_header() << "\n";
    md << "| model | rigid blocks | zones | steps | wall s | tensile | shear | springline mm | crown mm | "
          "crack depth (90%) springline m | crack depth (90%) crown m | sector cracks springline / crown | "
          "failed zone springline / crown m | verdict | cracks / 1000 steps at the end | fragments | rock-mass ratio |"
       << support_markdown_header() << "\n|";
    for (std::size_t k = 0; k < 17 + support_type_count; ++k) md << "---|";
    md << "\n";
    bool stopped = false;
    const auto codes = run_compared_models(models, out, threads, quiet, stopped);
    // The rocks' envelopes after the models (each spreads its own runs over the ranks).
    std::string envelope_table;
    if (envelope && envelope->enabled && !stopped && interrupted.load() == 0)
        envelope_table = compare_envelopes(models, out, threads, quiet, *envelope);
    if (!Ranks::root()) return 0;
    std::vector<Series> curves;
    int status = 0;
    for (std::size_t m = 0; m < models.size(); ++m) {
        const std::string name = fs::path(models[m]).stem().string();
        const fs::path dir = out / name;
        if (codes[m] == "not started") { // the comparison was interrupted before it
            if (status == 0) status = 130;
            continue;
        }
        const int rc = std::stoi(codes[m]);
        if (rc != 0 && status == 0) status = rc;
        const ComparedRun run(dir / "summary.json");
        csv << run.csv_row(name);
        md << run.markdown_row(name);
        if (auto ser = crack_curve(name, dir / "history.csv")) curves.push_back(std::move(*ser));
    }
    md << envelope_table;
    write_text_atomically(out / "comparison.csv", csv.str());
    write_text_atomically(out / "comparison.md", md.str());
    if (!curves.empty()) draw_curves(curves, "step", "broken contacts", out / "comparison.png", "cracks by model");
    if (!quiet) std::fprintf(stderr, "%swrote %s/{comparison.csv, comparison.md, comparison.png%s}\n", md.str().c_str(),
                             out.string().c_str(), envelope_table.empty() ? "" : ", envelopes.csv");
    return status;
}

} // namespace bbm::studies
