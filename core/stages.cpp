#include "core/stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
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

} // namespace

std::vector<StageReport> run_stages(Solver& s, const std::vector<StageSpec>& stages, StageObserver& obs,
                                    StageCursor start) {
    World& w = s.world();
    std::vector<StageReport> reports;
    for (int index = start.stage; index < int(stages.size()); ++index) {
        const StageSpec& st = stages[index];
        const bool resumed = index == start.stage && start.started;
        const auto t0 = std::chrono::steady_clock::now();
        StageReport r;
        r.name = st.name;
        r.kind = to_string(st.kind);
        StageCursor cursor{index, true, resumed ? start.step : 0};
        r.steps = cursor.step;
        // Solve and cycle stages are judged (core/verdict.hpp): the monitor samples
        // at fixed steps of the run, so a resumed stage samples where the
        // uninterrupted one does.
        const bool judged = st.kind == StageSpec::Kind::solve || st.kind == StageSpec::Kind::cycle;
        // Where a solve stage ends (StageSpec::Until): its ratio reached (after a
        // few steps: at rest the ratio is 0 before anything moves), or, asked for,
        // the rock at rest, or only the verdict of equilibrium.
        auto solved = [&](long k) {
            using U = StageSpec::Until;
            const bool sampled = w.clock.steps % StageMonitor::sample_every == 0;
            if (st.until == U::equilibrium) {
                if (!sampled) return false;
                const auto kind = verdict(w.monitor, st.ratio).kind;
                return kind == Verdict::Kind::equilibrium || kind == Verdict::Kind::equilibrium_with_fragments;
            }
            if (k >= 10 && w.clock.ratio <= st.ratio) return true;
            return st.until == U::rest && sampled && at_rest(w.monitor, st.ratio, st.quiet_steps);
        };
        // A pressurise stage's ramp: the pressure at its step k (1 ... steps).
        // (Plain variables, not a structured binding: lambdas capture them in C++20's clang 14.)
        const std::pair<double, double> before =
            st.kind == StageSpec::Kind::pressurise ? opening_pressures_before(stages, index) : std::pair{0.0, 0.0};
        const double pressure_before = before.first, excavation_pressure = before.second;
        auto run = [&](long max_steps, bool solve) {
            for (long k = cursor.step + 1; k <= max_steps; ++k) {
                if (st.kind == StageSpec::Kind::pressurise)
                    set_opening_pressure(w, pressure_before + (st.pressure - pressure_before) * double(k) / double(max_steps),
                                         excavation_pressure, true);
                s.step();
                ++r.steps;
                cursor.step = k;
                if (judged && w.clock.steps % StageMonitor::sample_every == 0) sample_monitor(w.monitor, w);
                obs.step_done(s, st, k);
                obs.at(s, cursor);
                if (obs.stop_requested() || (solve && solved(k))) return;
            }
        };
        if (!resumed) {
            if (judged) {
                start_stage(w.monitor);
                sample_monitor(w.monitor, w);
            }
            obs.stage_started(s, st);
            switch (st.kind) {
            case StageSpec::Kind::initialize: initialize_stress(w, st.stress); break;
            case StageSpec::Kind::excavate:
                excavate(w, st.regions, st.relax_steps, st.keep, st.pressure, support_path_of(stages, index));
                break;
            case StageSpec::Kind::elastic: r.method = solve_elastic(w).method; break;
            case StageSpec::Kind::install: install_supports(w, st.supports); break;
            case StageSpec::Kind::pressurise:
                if (st.steps == 0) set_opening_pressure(w, st.pressure, excavation_pressure, true);
                break;
            case StageSpec::Kind::solve:
            case StageSpec::Kind::cycle: break;
            }
            obs.at(s, cursor);
        }
        switch (st.kind) {
        case StageSpec::Kind::solve:
            if (!(resumed && solved(cursor.step))) run(st.max_steps, true);
            r.converged = w.clock.ratio <= st.ratio;
            break;
        case StageSpec::Kind::excavate: run(st.steps, false); break;
        case StageSpec::Kind::cycle: run(st.steps, false); break;
        case StageSpec::Kind::pressurise: run(st.steps, false); break;
        case StageSpec::Kind::initialize:
        case StageSpec::Kind::install:
        case StageSpec::Kind::elastic: break;
        }
        r.ratio = w.clock.ratio;
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const bool stopped = obs.stop_requested();
        if (judged && !stopped) {
            const auto& samples = w.monitor.samples;
            if (samples.empty() || samples.back().step != w.clock.steps) sample_monitor(w.monitor, w);
            r.verdict = verdict(w.monitor, st.kind == StageSpec::Kind::solve ? st.ratio : StageSpec{}.ratio);
        }
        if (!stopped) obs.stage_done(s, r);
        reports.push_back(r);
        // A stop asked for at the stage's end (by the observer) holds too.
        if (stopped || obs.stop_requested()) break;
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
