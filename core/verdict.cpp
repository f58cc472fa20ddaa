#include "core/verdict.hpp"

#include "core/measures.hpp"
#include "core/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace bbm {

namespace {

int find_root(std::vector<int>& parent, int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

} // namespace

Fragments find_fragments(const World& w) {
    const auto& n = w.nodes;
    const auto& c = w.contacts;
    const auto& removed = w.bodies.removed;
    const int nb = w.bodies.count();
    // Groups of bodies joined by contacts that carry force: bonded, or touching
    // with a stress (a broken contact that has opened carries none).
    std::vector<int> parent(nb);
    std::iota(parent.begin(), parent.end(), 0);
    for (int k = 0; k < c.size(); ++k) {
        const auto& h = c.history[k];
        if (!(h.bonded || h.sn != 0.0 || h.tau != 0.0)) continue;
        const int ra = find_root(parent, c.vertex_block[k]), rb = find_root(parent, c.edge_block[k]);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
    // A group is the rock mass if a body of it is supported, or if it is the heaviest.
    std::vector<std::uint8_t> anchored(nb, 0);
    std::vector<double> mass(nb, 0.0);
    for (int i = 0; i < nb; ++i) {
        if (removed[i]) continue;
        const int r = find_root(parent, i);
        if (w.loads.block_fixed[i]) anchored[r] = 1;
        mass[r] += w.blocks.real_mass[i];
    }
    for (int k = 0; k < n.count(); ++k) {
        const int i = n.block[k];
        if (removed[i]) continue;
        const int r = find_root(parent, i);
        if (w.loads.node_fixed[k]) anchored[r] = 1;
        mass[r] += n.real_mass[k];
    }
    int heaviest = -1;
    for (int i = 0; i < nb; ++i)
        if (!removed[i] && parent[i] == i && (heaviest < 0 || mass[i] > mass[heaviest])) heaviest = i;
    Fragments f;
    f.detached.assign(nb, 0);
    for (int i = 0; i < nb; ++i) {
        if (removed[i]) continue;
        const int r = find_root(parent, i);
        if (anchored[r] || r == heaviest) continue;
        f.detached[i] = 1;
        ++f.blocks;
        if (r == i) ++f.groups, f.mass += mass[i];
    }
    return f;
}

void sample_monitor(StageMonitor& monitor, const World& w) {
    const auto fragments = find_fragments(w);
    const auto& n = w.nodes;
    const auto& fixed = w.loads.block_fixed;
    MonitorSample m;
    m.step = w.clock.steps;
    m.time = w.clock.time;
    m.cracks = cracks(w, contact::JointState::broken_tension) + cracks(w, contact::JointState::broken_shear);
    m.ratio = w.clock.ratio;
    m.fragments = fragments.groups, m.fragment_blocks = fragments.blocks, m.fragment_mass = fragments.mass;
    // The rock mass's largest unbalanced force over its free components, as the
    // step measures the model's (the integrate row of core/step.cpp).
    double unbalanced = 0.0, kinetic = 0.0, speed = 0.0;
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i] || fragments.detached[i]) continue;
        const auto& b = w.bodies.state[i];
        const Vec2 force = w.bodies.force[i];
        if (!(fixed[i] & 1)) unbalanced = std::max(unbalanced, std::abs(force.x));
        if (!(fixed[i] & 2)) unbalanced = std::max(unbalanced, std::abs(force.y));
        kinetic += 0.5 * w.blocks.real_mass[i] * norm2(b.velocity) + 0.5 * w.blocks.real_inertia[i] * b.omega * b.omega;
        speed = std::max(speed, norm(b.velocity));
    }
    for (int k = 0; k < n.count(); ++k) {
        const int i = n.block[k];
        if (w.bodies.removed[i] || fragments.detached[i]) continue;
        if (!(w.loads.node_fixed[k] & 1)) unbalanced = std::max(unbalanced, std::abs(n.force[k].x));
        if (!(w.loads.node_fixed[k] & 2)) unbalanced = std::max(unbalanced, std::abs(n.force[k].y));
        kinetic += 0.5 * n.real_mass[k] * norm2(n.velocity[k]);
        speed = std::max(speed, norm(n.velocity[k]));
    }
    const double scale = force_scale(w);
    m.rock_ratio = scale > 0.0 ? unbalanced / scale : 0.0;
    m.rock_kinetic = kinetic;
    m.rock_speed = speed * w.clock.dt;
    monitor.samples.push_back(m);
}

namespace {

/// The window a verdict is taken over: the last quarter of the stage, between
/// 1,000 and 5,000 steps (all of a shorter stage).
long window_of(const std::vector<MonitorSample>& v) {
    const long span = v.back().step - v.front().step;
    return std::min(span, std::clamp(span / 4, 1000L, 5000L));
}

/// The first sample at or after `step`.
std::size_t first_from(const std::vector<MonitorSample>& v, long step) {
    return std::size_t(std::lower_bound(v.begin(), v.end(), step,
                                        [](const MonitorSample& m, long s) { return m.step < s; }) -
                       v.begin());
}

double mean_speed(const std::vector<MonitorSample>& v, std::size_t from, std::size_t to) {
    double sum = 0.0;
    for (std::size_t k = from; k < to; ++k) sum += v[k].rock_speed;
    return to > from ? sum / double(to - from) : 0.0;
}

} // namespace

namespace {

/// What a verdict is read from: the window's cracks, the last sample's ratios,
/// fragments and speed, the kinetic energy's trend over the window; and whether
/// the rock's fastest body sped up through each of the window's four quarters (a
/// collapse accelerates through all four; a burst of cracks rises and falls).
Verdict evidence(const std::vector<MonitorSample>& samples, double target, bool& rising) {
    Verdict v;
    v.target_ratio = target;
    const auto& last = samples.back();
    v.window_steps = window_of(samples);
    const std::size_t begin = first_from(samples, last.step - v.window_steps);
    const auto& first = samples[begin];
    v.cracks_in_window = last.cracks - first.cracks;
    v.crack_rate = v.window_steps > 0 ? 1000.0 * double(v.cracks_in_window) / double(v.window_steps) : 0.0;
    v.ratio = last.ratio, v.rock_ratio = last.rock_ratio;
    v.fragments = last.fragments, v.fragment_blocks = last.fragment_blocks, v.fragment_mass = last.fragment_mass;
    v.rock_speed = 1000.0 * last.rock_speed;
    v.model_time = last.time;
    const double ke_first = first.rock_kinetic;
    v.kinetic_trend = ke_first > 0.0 ? last.rock_kinetic / ke_first : (last.rock_kinetic > 0.0 ? INFINITY : 1.0);
    double quarter[4];
    rising = true;
    for (int q = 0; q < 4; ++q) {
        const std::size_t from = first_from(samples, last.step - v.window_steps + q * v.window_steps / 4);
        const std::size_t to = q == 3 ? samples.size() : first_from(samples, last.step - v.window_steps + (q + 1) * v.window_steps / 4);
        quarter[q] = mean_speed(samples, from, to);
        if (q > 0 && !(quarter[q] > quarter[q - 1])) rising = false;
    }
    v.speed_trend = quarter[0] > 0.0 ? quarter[3] / quarter[0] : (quarter[3] > 0.0 ? INFINITY : 1.0);
    return v;
}

/// The rock accelerating: its fastest body faster in each quarter of the window,
/// by 10% or more in all, and its kinetic energy rising.
bool collapsing(const Verdict& v, bool rising) { return rising && v.speed_trend > 1.1 && v.kinetic_trend > 1.0; }

} // namespace

Verdict judge(const std::vector<MonitorSample>& samples, double target) {
    // Fewer than 5 samples (500 steps) say nothing about a trend.
    if (samples.size() < 5) {
        Verdict none;
        none.target_ratio = target;
        return none;
    }
    bool rising = false;
    Verdict v = evidence(samples, target, rising);
    const auto& last = samples.back();
    using K = Verdict::Kind;
    if (v.cracks_in_window == 0 && last.ratio <= target) v.kind = K::equilibrium;
    else if (v.cracks_in_window == 0 && last.fragments > 0 && last.rock_ratio <= target) v.kind = K::equilibrium_with_fragments;
    else if (collapsing(v, rising)) v.kind = K::collapsing;
    else if (v.cracks_in_window > 0) v.kind = K::failing;
    else v.kind = K::not_converged;
    return v;
}

Verdict judge_dynamic(const std::vector<MonitorSample>& samples) {
    if (samples.size() < 5) return Verdict{};
    bool rising = false;
    Verdict v = evidence(samples, 0.0, rising);
    // The window's largest kinetic energy: a ringing body passes through none twice
    // a period.
    double peak = 0.0, in_window = 0.0;
    for (const auto& m : samples) peak = std::max(peak, m.rock_kinetic);
    for (std::size_t k = first_from(samples, samples.back().step - v.window_steps); k < samples.size(); ++k)
        in_window = std::max(in_window, samples[k].rock_kinetic);
    v.kinetic_fraction = peak > 0.0 ? in_window / peak : 0.0;
    using K = Verdict::Kind;
    if (v.cracks_in_window == 0 && v.kinetic_fraction <= settled_kinetic_fraction) v.kind = K::settled;
    // A wave in transit keeps its kinetic energy and may speed up where it
    // reflects: a dynamic collapse gains energy too (a block sliding under gravity
    // 78% over the stage's last quarter).
    else if (collapsing(v, rising) && v.kinetic_trend > 1.1) v.kind = K::collapsing;
    else if (v.cracks_in_window > 0) v.kind = K::failing;
    else v.kind = K::moving;
    return v;
}

bool at_rest(const StageMonitor& m, double target, long quiet_steps) {
    const auto& samples = m.samples;
    if (samples.empty()) return false;
    const auto& last = samples.back();
    if (last.step - samples.front().step < quiet_steps) return false;
    const auto& then = samples[first_from(samples, last.step - quiet_steps)];
    return last.cracks == then.cracks && last.rock_ratio <= target;
}

const char* to_string(Verdict::Kind k) {
    switch (k) {
    case Verdict::Kind::none: return "none";
    case Verdict::Kind::equilibrium: return "equilibrium";
    case Verdict::Kind::equilibrium_with_fragments: return "equilibrium with fragments";
    case Verdict::Kind::not_converged: return "not converged";
    case Verdict::Kind::failing: return "failing";
    case Verdict::Kind::collapsing: return "collapsing";
    case Verdict::Kind::settled: return "settled";
    case Verdict::Kind::moving: return "moving";
    }
    return "?";
}

std::string describe(const Verdict& v) {
    if (v.kind == Verdict::Kind::none) return "too short to judge";
    char line[512];
    if (v.kind == Verdict::Kind::settled || v.kind == Verdict::Kind::moving) {
        std::snprintf(line, sizeof line,
                      "%s: at %.4g s, the rock's kinetic energy %.3g%% of its peak in the stage, %ld cracks in the last "
                      "%ld steps, fastest rock %.3g mm per 1000 steps",
                      to_string(v.kind), v.model_time, 100.0 * v.kinetic_fraction, v.cracks_in_window, v.window_steps,
                      1000.0 * v.rock_speed);
        return line;
    }
    int n = std::snprintf(line, sizeof line, "%s: %ld cracks in the last %ld steps (%.2f per 1000), ratio %.2e",
                          to_string(v.kind), v.cracks_in_window, v.window_steps, v.crack_rate, v.ratio);
    if (v.fragments > 0)
        n += std::snprintf(line + n, sizeof line - std::size_t(n), " (rock mass %.2e; %d fragments of %d blocks, %.3g t/m)",
                           v.rock_ratio, v.fragments, v.fragment_blocks, v.fragment_mass / 1000.0);
    std::snprintf(line + n, sizeof line - std::size_t(n), ", fastest rock %.3g mm per 1000 steps, speed trend %.2f",
                  1000.0 * v.rock_speed, v.speed_trend);
    return line;
}

} // namespace bbm
