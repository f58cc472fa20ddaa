#include "core/analysis.hpp"

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
    }
    return "?";
}

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
        auto run = [&](long max_steps, double target) {
            for (long k = cursor.step + 1; k <= max_steps; ++k) {
                s.step();
                ++r.steps;
                cursor.step = k;
                obs.step_done(s, st, k);
                obs.at(s, cursor);
                if (obs.stop_requested()) return;
                // A few steps first: at rest the ratio is 0 before anything moves.
                if (target > 0 && k >= 10 && s.unbalanced_ratio() <= target) return;
            }
        };
        if (!resumed) {
            obs.stage_started(s, st);
            switch (st.kind) {
            case StageSpec::Kind::initialize: s.initialize_stress(st.stress); break;
            case StageSpec::Kind::excavate: s.excavate(st.regions, st.relax_steps); break;
            case StageSpec::Kind::elastic: r.method = s.solve_elastic().method; break;
            case StageSpec::Kind::solve:
            case StageSpec::Kind::cycle: break;
            }
            obs.at(s, cursor);
        }
        switch (st.kind) {
        case StageSpec::Kind::solve:
            if (!(resumed && cursor.step >= 10 && s.unbalanced_ratio() <= st.ratio)) run(st.max_steps, st.ratio);
            r.converged = s.unbalanced_ratio() <= st.ratio;
            break;
        case StageSpec::Kind::excavate: run(st.relax_steps, 0.0); break;
        case StageSpec::Kind::cycle: run(st.steps, 0.0); break;
        case StageSpec::Kind::initialize:
        case StageSpec::Kind::elastic: break;
        }
        r.ratio = s.unbalanced_ratio();
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const bool stopped = obs.stop_requested();
        if (!stopped) obs.stage_done(s, r);
        reports.push_back(r);
        if (stopped) break;
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
        }
        out.push_back(v);
    }
    return out;
}

OpeningMeasures measure_opening(const Solver& s, Vec2 center, Vec2 springline, Vec2 crown) {
    OpeningMeasures m;
    const auto& b = s.blocks();
    const auto& n = s.nodes();
    // The material point (rigid vertex or node, of a block still there) that started nearest p.
    auto displacement_at = [&](Vec2 p) {
        double best = INFINITY;
        Vec2 u{};
        for (int i = 0; i < b.count(); ++i) {
            if (b.removed[i] || b.deformable[i]) continue;
            const Rotation rot = rotation(b.theta[i]);
            for (std::uint32_t v = b.first[i]; v < b.first[i + 1]; ++v) {
                const Vec2 x0 = b.centroid0[i] + b.local[v];
                if (norm(x0 - p) >= best) continue;
                best = norm(x0 - p);
                u = b.centroid[i] + rot(b.local[v]) - x0;
            }
        }
        for (int k = 0; k < n.count(); ++k)
            if (!b.removed[n.block[k]] && norm(n.position0[k] - p) < best)
                best = norm(n.position0[k] - p), u = n.position[k] - n.position0[k];
        return u;
    };
    m.springline_displacement = displacement_at(springline);
    m.crown_displacement = displacement_at(crown);
    const Vec2 ds = (springline - center) / norm(springline - center), dc = (crown - center) / norm(crown - center);
    m.springline_convergence = -dot(m.springline_displacement, ds);
    m.crown_convergence = -dot(m.crown_displacement, dc);
    const double rs = norm(springline - center), rc = norm(crown - center);
    const double cos30 = std::cos(30.0 * 3.141592653589793 / 180.0), cos15 = std::cos(15.0 * 3.141592653589793 / 180.0);
    const auto& c = s.contacts();
    std::vector<double> depth_s, depth_c;
    for (int i = 0; i < c.size(); ++i) {
        const auto mode = c.history[i].broken;
        if (mode != contact::JointState::broken_tension && mode != contact::JointState::broken_shear) continue;
        const Vec2 r = b.vertex[c.vertex_id[i]] - center;
        const double d = norm(r);
        if (d <= 0) continue;
        const double cs = dot(r, ds) / d, cc = dot(r, dc) / d;
        if (cs >= cos30) {
            ++m.cracks_springline_sector;
            (mode == contact::JointState::broken_tension ? m.tensile_springline_sector : m.shear_springline_sector)++;
        }
        if (cc >= cos30) ++m.cracks_crown_sector;
        if (cs >= cos15) depth_s.push_back(d - rs);
        if (cc >= cos15) depth_c.push_back(d - rc);
    }
    // Depth of the failed zone: within it lie 90% of the sector's cracks (a lone
    // crack far from the wall is not a failed zone); fewer than 3 cracks: none.
    auto depth = [](std::vector<double>& v) {
        if (v.size() < 3) return 0.0;
        std::sort(v.begin(), v.end());
        return std::max(0.0, v[std::size_t(std::ceil(0.9 * double(v.size()))) - 1]);
    };
    m.failed_depth_springline = depth(depth_s);
    m.failed_depth_crown = depth(depth_c);
    return m;
}

double hoop_stress_at(const Solver& s, const std::vector<std::array<double, 3>>& block_stress, Vec2 center,
                      Vec2 towards, double r, double band) {
    const Vec2 dir = (towards - center) / norm(towards - center), p = center + r * dir;
    const auto& b = s.blocks();
    double sum = 0.0, weight = 0.0;
    // σθθ = t·σ·t with t the tangent of the circle through x.
    auto add = [&](Vec2 x, const std::array<double, 3>& st, double w) {
        if (norm(x - p) > band) return;
        const Vec2 rad = (x - center) / norm(x - center), t{-rad.y, rad.x};
        sum += w * (st[0] * t.x * t.x + st[1] * t.y * t.y + 2.0 * st[2] * t.x * t.y);
        weight += w;
    };
    for (int i = 0; i < b.count(); ++i)
        if (!b.removed[i] && !b.deformable[i]) add(b.centroid[i], block_stress[i], b.area[i]);
    const auto& z = s.zones();
    const auto& n = s.nodes();
    for (int k = 0; k < z.size(); ++k) {
        if (b.removed[z.block[k]]) continue;
        const auto& t = z.node[k];
        const auto g = fem::gradients(n.position[t[0]], n.position[t[1]], n.position[t[2]]);
        add((n.position[t[0]] + n.position[t[1]] + n.position[t[2]]) / 3.0, z.stress[k], g.area);
    }
    return weight > 0 ? sum / weight : NAN;
}

} // namespace bbm
