#include "core/analysis.hpp"

#include <chrono>

namespace bbm {

const char* to_string(StageSpec::Kind k) {
    switch (k) {
    case StageSpec::Kind::initialize: return "initialize";
    case StageSpec::Kind::solve: return "solve";
    case StageSpec::Kind::excavate: return "excavate";
    case StageSpec::Kind::cycle: return "cycle";
    }
    return "?";
}

std::vector<StageReport> run_stages(Solver& s, const std::vector<StageSpec>& stages, StageObserver& obs) {
    std::vector<StageReport> reports;
    for (const auto& st : stages) {
        const auto t0 = std::chrono::steady_clock::now();
        obs.stage_started(s, st);
        StageReport r{st.name, to_string(st.kind)};
        auto run = [&](long max_steps, double target) {
            for (long k = 1; k <= max_steps; ++k) {
                s.step();
                ++r.steps;
                obs.step_done(s, st, k);
                if (obs.stop_requested()) return;
                // A few steps first: at rest the ratio is 0 before anything moves.
                if (target > 0 && k >= 10 && s.unbalanced_ratio() <= target) return;
            }
        };
        switch (st.kind) {
        case StageSpec::Kind::initialize: s.initialize_stress(st.stress); break;
        case StageSpec::Kind::solve:
            run(st.max_steps, st.ratio);
            r.converged = s.unbalanced_ratio() <= st.ratio;
            break;
        case StageSpec::Kind::excavate:
            s.excavate(st.regions, st.relax_steps);
            run(st.relax_steps, 0.0);
            break;
        case StageSpec::Kind::cycle: run(st.steps, 0.0); break;
        }
        r.ratio = s.unbalanced_ratio();
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        obs.stage_done(s, r);
        reports.push_back(r);
        if (obs.stop_requested()) break;
    }
    return reports;
}

HistoryRecorder::HistoryRecorder(const Solver& s, std::vector<HistorySpec> h) : histories_(std::move(h)) {
    for (const auto& x : histories_) block_.push_back(x.point ? s.block_at(*x.point) : -1);
}

std::vector<double> HistoryRecorder::sample(const Solver& s) const {
    using Q = HistorySpec::Quantity;
    const auto& b = s.blocks();
    std::vector<double> out;
    out.reserve(histories_.size());
    for (std::size_t k = 0; k < histories_.size(); ++k) {
        const auto& h = histories_[k];
        const int i = block_[k];
        double v = 0.0;
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
        }
        out.push_back(v);
    }
    return out;
}

} // namespace bbm
