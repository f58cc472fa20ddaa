#include "studies/opening.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace bbm {

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
