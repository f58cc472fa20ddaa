#include "core/stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

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
            const bool sampled = s.steps() % StageMonitor::sample_every == 0;
            if (st.until == U::equilibrium) {
                if (!sampled) return false;
                const auto kind = s.monitor().verdict(st.ratio).kind;
                return kind == Verdict::Kind::equilibrium || kind == Verdict::Kind::equilibrium_with_fragments;
            }
            if (k >= 10 && s.unbalanced_ratio() <= st.ratio) return true;
            return st.until == U::rest && sampled && s.monitor().at_rest(st.ratio, st.quiet_steps);
        };
        // A pressurise stage's ramp: the pressure at its step k (1 ... steps).
        // (Plain variables, not a structured binding: lambdas capture them in C++20's clang 14.)
        const std::pair<double, double> before =
            st.kind == StageSpec::Kind::pressurise ? opening_pressures_before(stages, index) : std::pair{0.0, 0.0};
        const double pressure_before = before.first, excavation_pressure = before.second;
        auto run = [&](long max_steps, bool solve) {
            for (long k = cursor.step + 1; k <= max_steps; ++k) {
                if (st.kind == StageSpec::Kind::pressurise)
                    s.set_opening_pressure(pressure_before + (st.pressure - pressure_before) * double(k) / double(max_steps),
                                           excavation_pressure, true);
                s.step();
                ++r.steps;
                cursor.step = k;
                if (judged && s.steps() % StageMonitor::sample_every == 0) s.monitor().sample(s);
                obs.step_done(s, st, k);
                obs.at(s, cursor);
                if (obs.stop_requested() || (solve && solved(k))) return;
            }
        };
        if (!resumed) {
            if (judged) {
                s.monitor().start_stage();
                s.monitor().sample(s);
            }
            obs.stage_started(s, st);
            switch (st.kind) {
            case StageSpec::Kind::initialize: s.initialize_stress(st.stress); break;
            case StageSpec::Kind::excavate:
                s.excavate(st.regions, st.relax_steps, st.keep, st.pressure, support_path_of(stages, index));
                break;
            case StageSpec::Kind::elastic: r.method = s.solve_elastic().method; break;
            case StageSpec::Kind::install: s.install_supports(st.supports); break;
            case StageSpec::Kind::pressurise:
                if (st.steps == 0) s.set_opening_pressure(st.pressure, excavation_pressure, true);
                break;
            case StageSpec::Kind::solve:
            case StageSpec::Kind::cycle: break;
            }
            obs.at(s, cursor);
        }
        switch (st.kind) {
        case StageSpec::Kind::solve:
            if (!(resumed && solved(cursor.step))) run(st.max_steps, true);
            r.converged = s.unbalanced_ratio() <= st.ratio;
            break;
        case StageSpec::Kind::excavate: run(st.steps, false); break;
        case StageSpec::Kind::cycle: run(st.steps, false); break;
        case StageSpec::Kind::pressurise: run(st.steps, false); break;
        case StageSpec::Kind::initialize:
        case StageSpec::Kind::install:
        case StageSpec::Kind::elastic: break;
        }
        r.ratio = s.unbalanced_ratio();
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const bool stopped = obs.stop_requested();
        if (judged && !stopped) {
            const auto& samples = s.monitor().samples();
            if (samples.empty() || samples.back().step != s.steps()) s.monitor().sample(s);
            r.verdict = s.monitor().verdict(st.kind == StageSpec::Kind::solve ? st.ratio : StageSpec{}.ratio);
        }
        if (!stopped) obs.stage_done(s, r);
        reports.push_back(r);
        // A stop asked for at the stage's end (by the observer) holds too.
        if (stopped || obs.stop_requested()) break;
    }
    return reports;
}

HistoryRecorder::HistoryRecorder(const Solver& s, std::vector<HistorySpec> h) : histories_(std::move(h)) {
    const auto& n = s.nodes();
    for (const auto& x : histories_) {
        const int b = x.point ? s.block_at(*x.point) : -1;
        int node = -1;
        if (b >= 0 && s.blocks().deformable[b]) {
            double best = INFINITY;
            for (int k = 0; k < n.count(); ++k)
                if (n.block[k] == b && norm(n.position[k] - *x.point) < best) best = norm(n.position[k] - *x.point), node = k;
        }
        block_.push_back(b);
        node_.push_back(node);
    }
}

std::vector<double> HistoryRecorder::sample(const Solver& s) const {
    using Q = HistorySpec::Quantity;
    const auto& b = s.blocks();
    std::vector<double> out;
    out.reserve(histories_.size());
    for (std::size_t k = 0; k < histories_.size(); ++k) {
        const auto& h = histories_[k];
        const int i = block_[k], nd = node_[k];
        const auto& n = s.nodes();
        double v = 0.0;
        if (nd >= 0) {
            // A point of a deformable block: its nearest node (no rotation).
            switch (h.quantity) {
            case Q::displacement_x: out.push_back(n.position[nd].x - n.position0[nd].x); continue;
            case Q::displacement_y: out.push_back(n.position[nd].y - n.position0[nd].y); continue;
            case Q::velocity_x: out.push_back(n.velocity[nd].x); continue;
            case Q::velocity_y: out.push_back(n.velocity[nd].y); continue;
            case Q::rotation: out.push_back(0.0); continue;
            default: break;
            }
        }
        switch (h.quantity) {
        case Q::unbalanced_ratio: v = s.unbalanced_ratio(); break;
        case Q::displacement_x: v = b.centroid[i].x - b.centroid0[i].x; break;
        case Q::displacement_y: v = b.centroid[i].y - b.centroid0[i].y; break;
        case Q::velocity_x: v = b.velocity[i].x; break;
        case Q::velocity_y: v = b.velocity[i].y; break;
        case Q::rotation: v = b.theta[i]; break;
        case Q::boundary_force_x: v = s.boundary_force(h.boundary).x; break;
        case Q::boundary_force_y: v = s.boundary_force(h.boundary).y; break;
        case Q::cracks_tensile: v = s.cracks(contact::JointState::broken_tension); break;
        case Q::cracks_shear: v = s.cracks(contact::JointState::broken_shear); break;
        case Q::kinetic_energy: v = s.kinetic_energy(); break;
        case Q::strain_energy: v = s.strain_energy(); break;
        case Q::dissipated_energy: v = s.dissipated_energy(); break;
        case Q::work: v = s.external_work(); break;
        case Q::inflow: v = s.flow() ? s.flow()->inflow() : 0.0; break;
        }
        out.push_back(v);
    }
    return out;
}

} // namespace bbm
