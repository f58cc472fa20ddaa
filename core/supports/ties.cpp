// The supports in the world (core/supports/ties.hpp).
#include "core/supports/ties.hpp"

#include "base/error.hpp"
#include "core/step.hpp"

#include <algorithm>
#include <cmath>

namespace bbm {

SupportRock support_rock(const World& w) {
    return {w.bodies.state.data(), w.bodies.removed.data(), w.nodes.position.data(), w.zones.node.data()};
}

TieHost find_host(const World& w, Vec2 p, double reach) {
    // The rigid block or zone that contains p, else the nearest one within `reach`
    // (a head on the wall lies on an edge).
    TieHost best;
    double best_distance = reach;
    for (int i = 0; i < w.bodies.count(); ++i) {
        if (w.bodies.removed[i] || w.blocks.deformable[i]) continue;
        const auto& b = w.bodies.state[i];
        const Vec2 q = rotation(-b.theta)(p - b.centroid);
        if (norm(q) > w.detection.radius[i] + reach) continue;
        const std::span<const Vec2> poly(w.vertices.local.data() + w.blocks.first[i], w.blocks.first[i + 1] - w.blocks.first[i]);
        double d = 0.0;
        if (!point_in_polygon(q, poly)) {
            d = INFINITY;
            for (std::size_t v = 0; v < poly.size(); ++v)
                d = std::min(d, distance_to_segment(q, poly[v], poly[(v + 1) % poly.size()]));
        }
        if (d == 0.0 || d < best_distance) {
            best = {i, -1, q, {}};
            best_distance = d;
            if (d == 0.0) return best;
        }
    }
    const auto& z = w.zones;
    const auto& x = w.nodes.position;
    for (int k = 0; k < z.size(); ++k) {
        if (w.bodies.removed[z.block[k]]) continue;
        const auto& t = z.node[k];
        const Vec2 a = x[t[0]], b = x[t[1]], c = x[t[2]];
        const double area = cross(b - a, c - a);
        const std::array<double, 3> weight{cross(b - p, c - p) / area, cross(c - p, a - p) / area, cross(a - p, b - p) / area};
        double d = 0.0;
        if (std::min({weight[0], weight[1], weight[2]}) < 0.0)
            d = std::min({distance_to_segment(p, a, b), distance_to_segment(p, b, c), distance_to_segment(p, c, a)});
        if (d == 0.0 || d < best_distance) {
            best = {z.block[k], k, {}, weight};
            best_distance = d;
            if (d == 0.0) return best;
        }
    }
    return best;
}

void install_supports(World& w, const std::vector<std::string>& names) {
    const HostFinder find = [&w](Vec2 p, double reach) { return find_host(w, p, reach); };
    for (const auto& name : names) {
        bool found = false;
        for_each_support(w.supports, [&](auto type, auto& state) {
            using T = typename decltype(type)::type;
            if (found) return;
            const auto& sets = T::set_names(state);
            const auto it = std::find(sets.begin(), sets.end(), name);
            if (it == sets.end()) return;
            found = true;
            const int set = int(it - sets.begin());
            if (T::installed(state, set))
                throw InputError("", 0, "stage.supports", "support set '" + name + "' is already installed");
            T::install(state, set, find);
        });
        if (!found) throw InputError("", 0, "stage.supports", "unknown support set '" + name + "'");
    }
    index_support_ties(w);
    update_timestep(w);
}

void index_support_ties(World& w) {
    // Ties numbered through the support types in registry order; per block and
    // per node, its ties in that order: the gather's order.
    auto& t = w.ties;
    t.first.assign(1, 0);
    std::vector<const TieHost*> host;
    for_each_support(w.supports, [&](auto type, const auto& state) {
        using T = typename decltype(type)::type;
        t.first.push_back(t.first.back() + T::tie_count(state));
        for (int k = 0; k < T::tie_count(state); ++k) host.push_back(&T::host(state, k));
    });
    const int ties = t.first.back();
    t.reaction.assign(ties, {});
    t.moment.assign(ties, 0.0);
    const int nb = w.bodies.count(), nn = w.nodes.count();
    const auto& zone_node = w.zones.node;
    t.block_first.assign(nb + 1, 0);
    t.node_first.assign(nn + 1, 0);
    for (int tie = 0; tie < ties; ++tie) {
        const TieHost& h = *host[tie];
        if (h.block < 0) continue;
        if (h.zone < 0) ++t.block_first[h.block + 1];
        else
            for (int j = 0; j < 3; ++j) ++t.node_first[zone_node[h.zone][j] + 1];
    }
    for (int i = 0; i < nb; ++i) t.block_first[i + 1] += t.block_first[i];
    for (int i = 0; i < nn; ++i) t.node_first[i + 1] += t.node_first[i];
    t.block_tie.assign(t.block_first[nb], 0);
    t.node_tie.assign(t.node_first[nn], {});
    std::vector<int> fill_block(t.block_first.begin(), t.block_first.end() - 1),
        fill_node(t.node_first.begin(), t.node_first.end() - 1);
    for (int k = 0; k < ties; ++k) {
        const TieHost& h = *host[k];
        if (h.block < 0) continue;
        if (h.zone < 0) t.block_tie[fill_block[h.block]++] = k;
        else
            for (int j = 0; j < 3; ++j) {
                const int node = zone_node[h.zone][j];
                t.node_tie[fill_node[node]++] = {k, h.weight[j]};
            }
    }
}

std::vector<std::pair<std::string, std::vector<SupportSetSummary>>> support_summaries(const World& w) {
    std::vector<std::pair<std::string, std::vector<SupportSetSummary>>> out;
    for_each_support(w.supports, [&](auto type, const auto& state) {
        using T = typename decltype(type)::type;
        out.emplace_back(std::string(T::name), T::summary(state));
    });
    return out;
}

std::vector<std::pair<std::string, SupportLines>> support_lines(const World& w) {
    std::vector<std::pair<std::string, SupportLines>> out;
    for_each_support(w.supports, [&](auto type, const auto& state) {
        using T = typename decltype(type)::type;
        if (T::tie_count(state) > 0) out.emplace_back(std::string(T::name), T::lines(state));
    });
    return out;
}

} // namespace bbm
