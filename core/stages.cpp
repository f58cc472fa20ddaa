#include "core/stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

namespace bbm {

const char* to_string(StageSpec::Kind k) {
    switch (k) {
    case StageSpec::Kind::initialize: return "initialize";
    case StageSpec::Kind::solve: return "solve";
    case StageSpec::Kind::excavate: return "excavate";
    case StageSpec::Kind::cycle: return "cycle";
    case StageSpec::Kind::elastic: return "elastic";
    case StageSpec::Kind::install: return "install";
    case StageSpec::Kind::pressurise: return "pressurise";
    case StageSpec::Kind::creep: return "creep";
    }
    return "?";
}

namespace {

/// The latest opening's pressure before stage `index`, and its excavation's: from
/// the stages themselves (a pressurise stage ends at its target), so a resumed
/// ramp is where the uninterrupted one was.
std::pair<double, double> opening_pressures_before(const std::vector<StageSpec>& stages, int index) {
    double now = 0.0, excavated = 0.0;
    for (int k = 0; k < index; ++k) {
        if (stages[k].kind == StageSpec::Kind::excavate) now = excavated = stages[k].pressure;
        if (stages[k].kind == StageSpec::Kind::pressurise) now = stages[k].pressure;
    }
    return {now, excavated};
}

/// An excavate stage's support path with the in-situ stress of the latest
/// initialize stage before it (the reader requires one).
SupportPath support_path_of(const std::vector<StageSpec>& stages, int index) {
    SupportPath path{stages[index].support_path, {}};
    for (int k = 0; k < index; ++k)
        if (stages[k].kind == StageSpec::Kind::initialize) path.in_situ = stages[k].stress;
    return path;
}

/// The creep time at the end of creep stage `index`: the durations of the creep
/// stages up to it (so a resumed stage ends where the uninterrupted one does).
double creep_end(const std::vector<StageSpec>& stages, int index) {
    double end = 0.0;
    for (int k = 0; k <= index; ++k)
        if (stages[k].kind == StageSpec::Kind::creep) end += stages[k].duration;
    return end;
}

/// One stage of run_stages: started (unless resumed inside it), stepped to its
/// end, judged, and reported.
class StageRun {
public:
    StageRun(Solver& s, const std::vector<StageSpec>& stages, int index, StageObserver& obs, const StageCursor& start)
        : s_(s), w_(s.world()), stages_(stages), index_(index), st_(stages[index]), obs_(obs),
          resumed_(index == start.stage && start.started), t0_(std::chrono::steady_clock::now()),
          cursor_{index, true, resumed_ ? start.step : 0},
          // Solve and cycle stages are judged (core/verdict.hpp): the monitor samples
          // at fixed steps of the run, so a resumed stage samples where the
          // uninterrupted one does.
          judged_(st_.kind == StageSpec::Kind::solve || st_.kind == StageSpec::Kind::cycle ||
                  st_.kind == StageSpec::Kind::creep) {
        r_.name = st_.name;
        r_.kind = to_string(st_.kind);
        r_.steps = cursor_.step;
        // A pressurise stage's ramp: the pressure at its step k (1 ... steps).
        const std::pair<double, double> before =
            st_.kind == StageSpec::Kind::pressurise ? opening_pressures_before(stages, index) : std::pair{0.0, 0.0};
        pressure_before_ = before.first, excavation_pressure_ = before.second;
    }

    /// The stage from its start, or from where it was resumed; its report.
    StageReport run() {
        if (!resumed_) start();
        step_to_end();
        r_.ratio = w_.clock.ratio;
        r_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        stopped_ = obs_.stop_requested();
        if (judged_ && !stopped_) judge();
        if (!stopped_) obs_.stage_done(s_, r_);
        return r_;
    }

    /// Stopped by the observer before the stage's end.
    bool stopped() const { return stopped_; }

private:
    /// What the stage does before its steps.
    void start() {
        if (judged_) {
            start_stage(w_.monitor);
            sample_monitor(w_.monitor, w_);
        }
        obs_.stage_started(s_, st_);
        switch (st_.kind) {
        case StageSpec::Kind::initialize: initialize_stress(w_, st_.stress); break;
        case StageSpec::Kind::excavate:
            excavate(w_, st_.regions, st_.relax_steps, st_.keep, st_.pressure, support_path_of(stages_, index_));
            break;
        case StageSpec::Kind::elastic: r_.method = solve_elastic(w_).method; break;
        case StageSpec::Kind::install: install_supports(w_, st_.supports); break;
        case StageSpec::Kind::pressurise:
            if (st_.steps == 0) set_opening_pressure(w_, st_.pressure, excavation_pressure_, true);
            break;
        case StageSpec::Kind::creep:
            w_.creep->until = creep_end(stages_, index_);
            w_.creep->loss = st_.loss;
            w_.creep->since = 0;
            break;
        case StageSpec::Kind::solve:
        case StageSpec::Kind::cycle: break;
        }
        start_energy_account(w_);
        if (w_.peak) start_stage_peaks(*w_.peak);
        obs_.at(s_, cursor_);
    }

    /// The stage's steps: a solve stage's until solved, the others' all of them.
    void step_to_end() {
        switch (st_.kind) {
        case StageSpec::Kind::solve:
            if (!(resumed_ && solved(cursor_.step))) run_steps(st_.max_steps, true);
            r_.converged = w_.clock.ratio <= st_.ratio;
            break;
        case StageSpec::Kind::excavate: run_steps(st_.steps, false); break;
        case StageSpec::Kind::cycle: run_steps(st_.time > 0.0 ? std::numeric_limits<long>::max() : st_.steps, false); break;
        case StageSpec::Kind::pressurise: run_steps(st_.steps, false); break;
        case StageSpec::Kind::creep: {
            const long creep_steps = w_.creep->steps;
            run_steps(st_.max_steps, false);
            r_.converged = creep_finished();
            r_.creep_time = w_.creep->time;
            r_.creep_steps = w_.creep->steps - creep_steps;
            break;
        }
        case StageSpec::Kind::initialize:
        case StageSpec::Kind::install:
        case StageSpec::Kind::elastic: break;
        }
    }

    /// Where a solve stage ends (StageSpec::Until): its ratio reached (after a
    /// few steps: at rest the ratio is 0 before anything moves), or, asked for,
    /// the rock at rest, or only the verdict of equilibrium.
    bool solved(long k) const {
        using U = StageSpec::Until;
        const bool sampled = w_.clock.steps % StageMonitor::sample_every == 0;
        if (st_.until == U::equilibrium) {
            if (!sampled) return false;
            const auto kind = verdict(w_.monitor, st_.ratio).kind;
            return kind == Verdict::Kind::equilibrium || kind == Verdict::Kind::equilibrium_with_fragments;
        }
        if (k >= 10 && w_.clock.ratio <= st_.ratio) return true;
        return st_.until == U::rest && sampled && at_rest(w_.monitor, st_.ratio, st_.quiet_steps);
    }

    /// A creep stage at mechanical equilibrium: a few steps since the last creep
    /// step and the ratio reached.
    bool creep_at_rest() const { return w_.creep->since >= 10 && w_.clock.ratio <= st_.ratio; }
    bool creep_finished() const { return creep_at_rest() && w_.creep->time >= w_.creep->until; }
    /// A rock failing under its held load: a body moving a quarter of the
    /// detection tolerance in one step (a quasi-static model at rest moves by
    /// elastic amounts only; the run's health check stops one at the whole
    /// tolerance), where a creep stage ends with its time to failure; so does one
    /// that finds no rest within settle_steps of a creep step (run_steps).
    bool creep_collapsing() const {
        const double limit = 0.25 * w_.detection.tolerance / w_.clock.dt;
        for (int i = 0; i < w_.bodies.count(); ++i)
            if (!w_.bodies.removed[i] && !w_.blocks.deformable[i] && norm(w_.bodies.state[i].velocity) > limit)
                return true;
        for (int k = 0; k < w_.nodes.count(); ++k)
            if (!w_.bodies.removed[w_.nodes.block[k]] && norm(w_.nodes.velocity[k]) > limit) return true;
        return false;
    }

    /// Steps up to max_steps from the cursor, the observer told of each; stops
    /// early when it asks, or (`solve`) once solved, or (`creep`) at rest at its
    /// end. A creep stage arms a creep step (core/creep.hpp) for the step after
    /// each equilibrium.
    void run_steps(long max_steps, bool solve) {
        const bool creep = st_.kind == StageSpec::Kind::creep;
        for (long k = cursor_.step + 1; k <= max_steps; ++k) {
            if (st_.kind == StageSpec::Kind::pressurise)
                set_opening_pressure(w_, pressure_before_ + (st_.pressure - pressure_before_) * double(k) / double(max_steps),
                                     excavation_pressure_, true);
            if (creep) {
                if (creep_finished()) return;
                w_.creep->due = creep_at_rest() ? 1 : 0;
            }
            s_.step();
            if (creep) {
                w_.creep->due = 0, ++w_.creep->since;
                if (creep_collapsing() || w_.creep->since > st_.settle_steps) {
                    r_.failed = true;
                    ++r_.steps, cursor_.step = k;
                    return;
                }
            }
            ++r_.steps;
            cursor_.step = k;
            if (judged_ && w_.clock.steps % StageMonitor::sample_every == 0) sample_monitor(w_.monitor, w_);
            obs_.step_done(s_, st_, k);
            obs_.at(s_, cursor_);
            if (obs_.stop_requested() || (solve && solved(k)) || time_reached()) return;
        }
    }

    /// A cycle stage given in model time has run it (to within a part in 10⁹ of a
    /// step: the clock's sum of steps is not exact).
    bool time_reached() const {
        return st_.time > 0.0 && w_.clock.time >= stage_start_time(w_.monitor) + st_.time - 1e-9 * w_.clock.dt;
    }

    /// The stage's verdict, from a last sample at its end: a dynamic cycle's on
    /// its energy, the others' on their unbalanced force.
    void judge() {
        const auto& samples = w_.monitor.samples;
        if (samples.empty() || samples.back().step != w_.clock.steps) sample_monitor(w_.monitor, w_);
        if (st_.kind == StageSpec::Kind::cycle && w_.settings.mode == SolverSpec::Mode::dynamic) {
            r_.verdict = judge_dynamic(w_.monitor.samples);
            return;
        }
        const bool own_ratio = st_.kind == StageSpec::Kind::solve || st_.kind == StageSpec::Kind::creep;
        r_.verdict = verdict(w_.monitor, own_ratio ? st_.ratio : StageSpec{}.ratio);
    }

    Solver& s_;
    World& w_;
    const std::vector<StageSpec>& stages_;
    int index_;
    const StageSpec& st_;
    StageObserver& obs_;
    bool resumed_;
    std::chrono::steady_clock::time_point t0_;
    StageCursor cursor_;
    bool judged_;
    double pressure_before_ = 0.0, excavation_pressure_ = 0.0;
    StageReport r_;
    bool stopped_ = false;
};

} // namespace

std::vector<StageReport> run_stages(Solver& s, const std::vector<StageSpec>& stages, StageObserver& obs,
                                    StageCursor start) {
    std::vector<StageReport> reports;
    for (int index = start.stage; index < int(stages.size()); ++index) {
        StageRun stage(s, stages, index, obs, start);
        reports.push_back(stage.run());
        // A stop asked for at the stage's end (by the observer) holds too.
        if (stage.stopped() || obs.stop_requested()) break;
    }
    return reports;
}

HistoryRecorder::HistoryRecorder(const World& w, std::vector<HistorySpec> h) : histories_(std::move(h)) {
    const auto& n = w.nodes;
    for (const auto& x : histories_) {
        const int b = x.point ? block_at(w, *x.point) : -1;
        int node = -1;
        if (b >= 0 && w.blocks.deformable[b]) {
            double best = INFINITY;
            for (int k = 0; k < n.count(); ++k)
                if (n.block[k] == b && norm(n.position[k] - *x.point) < best) best = norm(n.position[k] - *x.point), node = k;
        }
        block_.push_back(b);
        node_.push_back(node);
    }
}

namespace {

/// A point's quantity at its nearest node (a deformable block: no rotation), if
/// it is one a node has.
std::optional<double> node_quantity(const World& w, HistorySpec::Quantity q, int nd) {
    using Q = HistorySpec::Quantity;
    const auto& n = w.nodes;
    switch (q) {
    case Q::displacement_x: return n.position[nd].x - n.position0[nd].x;
    case Q::displacement_y: return n.position[nd].y - n.position0[nd].y;
    case Q::velocity_x: return n.velocity[nd].x;
    case Q::velocity_y: return n.velocity[nd].y;
    case Q::rotation: return 0.0;
    default: return std::nullopt;
    }
}

double quantity(const World& w, const HistorySpec& h, int i) {
    using Q = HistorySpec::Quantity;
    switch (h.quantity) {
    case Q::unbalanced_ratio: return w.clock.ratio;
    case Q::displacement_x: return w.bodies.state[i].centroid.x - w.blocks.centroid0[i].x;
    case Q::displacement_y: return w.bodies.state[i].centroid.y - w.blocks.centroid0[i].y;
    case Q::velocity_x: return w.bodies.state[i].velocity.x;
    case Q::velocity_y: return w.bodies.state[i].velocity.y;
    case Q::rotation: return w.bodies.state[i].theta;
    case Q::boundary_force_x: return boundary_force(w, h.boundary).x;
    case Q::boundary_force_y: return boundary_force(w, h.boundary).y;
    case Q::cracks_tensile: return cracks(w, contact::JointState::broken_tension);
    case Q::cracks_shear: return cracks(w, contact::JointState::broken_shear);
    case Q::kinetic_energy: return kinetic_energy(w);
    case Q::strain_energy: return strain_energy(w);
    case Q::dissipated_energy: return dissipated_energy(w);
    case Q::work: return w.clock.work;
    case Q::inflow: return w.flow ? inflow(*w.flow) : 0.0;
    case Q::absorbed_energy: return absorbed_energy(w);
    case Q::wave_energy: return wave_energy(w);
    case Q::creep_time: return w.creep ? w.creep->time : 0.0;
    case Q::damping_energy: return w.clock.damped;
    case Q::energy_error: return energy_account(w).error;
    case Q::ejected_mass: return measure_ejecta(w).mass;
    case Q::ejection_speed: return measure_ejecta(w).speed_mean;
    }
    return 0.0;
}

} // namespace

std::vector<double> HistoryRecorder::sample(const World& w) const {
    std::vector<double> out;
    out.reserve(histories_.size());
    for (std::size_t k = 0; k < histories_.size(); ++k) {
        const auto& h = histories_[k];
        const std::optional<double> at_node = node_[k] >= 0 ? node_quantity(w, h.quantity, node_[k]) : std::nullopt;
        out.push_back(at_node ? *at_node : quantity(w, h, block_[k]));
    }
    return out;
}

} // namespace bbm
