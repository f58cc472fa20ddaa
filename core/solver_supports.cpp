// The solver's side of the supports (core/support.hpp): installing sets of any
// registered type, and numbering their ties for the force gather.
#include "core/solver.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>

namespace bbm {

BoltHost Solver::find_host(Vec2 p, double reach) const {
    // The rigid block or zone that contains p, else the nearest one within `reach`
    // (a head on the wall lies on an edge). Install-time only: a linear scan.
    BoltHost best;
    double best_distance = reach;
    for (int i = 0; i < b_.count(); ++i) {
        if (b_.removed[i] || b_.deformable[i]) continue;
        const Vec2 q = rotation(-b_.theta[i])(p - b_.centroid[i]);
        if (norm(q) > radius_[i] + reach) continue;
        const std::span<const Vec2> poly(b_.local.data() + b_.first[i], b_.first[i + 1] - b_.first[i]);
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
    for (int z = 0; z < z_.size(); ++z) {
        if (b_.removed[z_.block[z]]) continue;
        const auto& t = z_.node[z];
        const Vec2 a = n_.position[t[0]], b = n_.position[t[1]], c = n_.position[t[2]];
        const double area = cross(b - a, c - a);
        const std::array<double, 3> w{cross(b - p, c - p) / area, cross(c - p, a - p) / area, cross(a - p, b - p) / area};
        double d = 0.0;
        if (std::min({w[0], w[1], w[2]}) < 0.0)
            d = std::min({distance_to_segment(p, a, b), distance_to_segment(p, b, c), distance_to_segment(p, c, a)});
        if (d == 0.0 || d < best_distance) {
            best = {z_.block[z], z, {}, w};
            best_distance = d;
            if (d == 0.0) return best;
        }
    }
    return best;
}

SupportRock Solver::support_rock() const {
    return {b_.centroid.data(), b_.theta.data(), b_.removed.data(), n_.position.data(), z_.node.data()};
}

void Solver::install_supports(const std::vector<std::string>& names) {
    const HostFinder find = [this](Vec2 p, double reach) { return find_host(p, reach); };
    for (const auto& name : names) {
        Support* owner = nullptr;
        int set = -1;
        for (auto& support : supports_) {
            const auto& sets = support->set_names();
            if (const auto it = std::find(sets.begin(), sets.end(), name); it != sets.end()) {
                owner = support.get(), set = int(it - sets.begin());
                break;
            }
        }
        if (!owner) throw InputError("", 0, "stage.supports", "unknown support set '" + name + "'");
        if (owner->installed(set))
            throw InputError("", 0, "stage.supports", "support set '" + name + "' is already installed");
        owner->install(set, find);
    }
    index_support_ties();
    update_timestep();
}

void Solver::index_support_ties() {
    // Ties numbered through the support types in registry order; per block and
    // per node, its ties in that order: the gather's order.
    support_tie_first_.assign(1, 0);
    for (const auto& support : supports_) support_tie_first_.push_back(support_tie_first_.back() + support->tie_count());
    const int ties = support_tie_first_.back();
    tie_reaction_.assign(ties, {});
    tie_moment_.assign(ties, 0.0);
    std::vector<const BoltHost*> host(ties);
    for (std::size_t s = 0; s < supports_.size(); ++s)
        for (int k = 0; k < supports_[s]->tie_count(); ++k) host[support_tie_first_[s] + k] = &supports_[s]->host(k);
    const int nb = b_.count(), nn = n_.count();
    tie_block_first_.assign(nb + 1, 0);
    tie_node_first_.assign(nn + 1, 0);
    for (int tie = 0; tie < ties; ++tie) {
        const BoltHost& h = *host[tie];
        if (h.block < 0) continue;
        if (h.zone < 0) ++tie_block_first_[h.block + 1];
        else
            for (int j = 0; j < 3; ++j) ++tie_node_first_[z_.node[h.zone][j] + 1];
    }
    for (int i = 0; i < nb; ++i) tie_block_first_[i + 1] += tie_block_first_[i];
    for (int i = 0; i < nn; ++i) tie_node_first_[i + 1] += tie_node_first_[i];
    tie_block_tie_.assign(tie_block_first_[nb], 0);
    tie_node_tie_.assign(tie_node_first_[nn], {});
    std::vector<int> fill_block(tie_block_first_.begin(), tie_block_first_.end() - 1),
        fill_node(tie_node_first_.begin(), tie_node_first_.end() - 1);
    for (int k = 0; k < ties; ++k) {
        const BoltHost& h = *host[k];
        if (h.block < 0) continue;
        if (h.zone < 0) tie_block_tie_[fill_block[h.block]++] = k;
        else
            for (int j = 0; j < 3; ++j) {
                const int node = z_.node[h.zone][j];
                tie_node_tie_[fill_node[node]++] = {k, h.weight[j]};
            }
    }
}

} // namespace bbm
