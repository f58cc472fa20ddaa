#include "core/ejecta.hpp"

#include "core/verdict.hpp"
#include "core/world.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

PeakVelocities start_peak_velocities(const World& w, const ReportSpec& report) {
    PeakVelocities p;
    p.ejection_speed = report.ejection_speed;
    if (report.opening)
        p.opening = {report.center.x, report.center.y,
                     std::min(norm(report.springline - report.center), norm(report.crown - report.center))};
    const auto nb = std::size_t(w.bodies.count()), nn = std::size_t(w.nodes.count());
    p.block_run.assign(nb, 0.0), p.block_time.assign(nb, 0.0), p.block_stage.assign(nb, 0.0);
    p.node_run.assign(nn, 0.0), p.node_stage.assign(nn, 0.0);
    return p;
}

void start_stage_peaks(PeakVelocities& p) {
    std::fill(p.block_stage.begin(), p.block_stage.end(), 0.0);
    std::fill(p.node_stage.begin(), p.node_stage.end(), 0.0);
}

void record_peak_velocities(World& w, int first_chunk, int last_chunk) {
    // The velocities integration just wrote are those of the half step ending now:
    // their time is the step's end.
    PeakVelocities& p = *w.peak;
    constexpr int size = Team::sum_chunk;
    const int nb = w.bodies.count(), nn = w.nodes.count(), block_chunks = Team::chunks_of(nb);
    const double time = w.clock.time + w.clock.dt;
    for (int chunk = first_chunk; chunk < last_chunk; ++chunk) {
        if (chunk < block_chunks) {
            for (int i = chunk * size; i < std::min(nb, (chunk + 1) * size); ++i) {
                const double s = norm(w.bodies.state[i].velocity);
                if (s > p.block_run[i]) p.block_run[i] = s, p.block_time[i] = time;
                p.block_stage[i] = std::max(p.block_stage[i], s);
            }
        } else {
            const int c = chunk - block_chunks;
            for (int i = c * size; i < std::min(nn, (c + 1) * size); ++i) {
                const double s = norm(w.nodes.velocity[i]);
                p.node_run[i] = std::max(p.node_run[i], s);
                p.node_stage[i] = std::max(p.node_stage[i], s);
            }
        }
    }
}

namespace {

/// The ejected blocks' depths and the wall they came off, around a circle.
void measure_around(Ejecta& e, const World& w, const OpeningCircle& o) {
    constexpr int sectors = 360;
    std::vector<std::uint8_t> hit(sectors, 0);
    double weighted = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (!e.ejected[i]) continue;
        const Vec2 r = w.blocks.centroid0[i] - o.center;
        const double depth = std::max(0.0, norm(r) - o.radius);
        e.depth = std::max(e.depth, depth);
        weighted += w.blocks.real_mass[i] * depth;
        const double angle = std::atan2(r.y, r.x) + std::numbers::pi; // 0 … 2π
        hit[std::min(sectors - 1, int(angle / (2.0 * std::numbers::pi) * sectors))] = 1;
    }
    e.around_opening = true;
    e.mean_depth = e.mass > 0.0 ? weighted / e.mass : 0.0;
    e.wall_length = double(std::count(hit.begin(), hit.end(), 1)) * 2.0 * std::numbers::pi * o.radius / sectors;
}

} // namespace

Ejecta measure_ejecta(const World& w, const std::optional<OpeningCircle>& opening, double threshold) {
    const Fragments f = find_fragments(w);
    Ejecta e;
    e.threshold = threshold;
    e.ejected.assign(std::size_t(w.bodies.count()), 0);
    double momentum = 0.0, peak_momentum = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i) {
        // Rigid blocks only: a detached deformable block's speed is its nodes'.
        if (!f.detached[i] || w.blocks.deformable[i]) continue;
        const double m = w.blocks.real_mass[i];
        const auto& b = w.bodies.state[i];
        const double speed = norm(b.velocity);
        ++e.detached_blocks, e.detached_mass += m;
        // Into the opening: towards its centre (any way without one).
        const bool inward = !opening || dot(b.velocity, b.centroid - opening->center) < 0.0;
        if (!inward) continue;
        for (std::size_t k = 0; k < e.mass_faster.size(); ++k)
            if (speed > ejecta_speed_steps[k]) e.mass_faster[k] += m;
        if (!(speed > threshold)) continue;
        e.ejected[i] = 1;
        ++e.blocks;
        const double peak = w.peak ? w.peak->block_run[i] : 0.0;
        e.mass += m;
        momentum += m * speed, peak_momentum += m * peak;
        e.speed_max = std::max(e.speed_max, speed), e.peak_speed_max = std::max(e.peak_speed_max, peak);
        e.kinetic += 0.5 * m * speed * speed + 0.5 * w.blocks.real_inertia[i] * b.omega * b.omega;
        e.kinetic_at_peak += 0.5 * m * peak * peak;
    }
    if (e.mass > 0.0) e.speed_mean = momentum / e.mass, e.peak_speed_mean = peak_momentum / e.mass;
    if (opening && opening->radius > 0.0) measure_around(e, w, *opening);
    return e;
}

Ejecta measure_ejecta(const World& w) {
    if (!w.peak) return measure_ejecta(w, std::nullopt, ReportSpec{}.ejection_speed);
    const auto& o = w.peak->opening;
    std::optional<OpeningCircle> opening;
    if (o.size() == 3) opening = OpeningCircle{{o[0], o[1]}, o[2]};
    return measure_ejecta(w, opening, w.peak->ejection_speed);
}

} // namespace bbm
