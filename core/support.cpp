// The rock as supports see it, and the registry of support types (core/support.hpp).
#include "core/support.hpp"

#include "core/bolts.hpp"
#include "core/dowels.hpp"
#include "core/liners.hpp"
#include "core/model_spec.hpp"

#include <stdexcept>

namespace bbm {

Vec2 SupportRock::position(const BoltHost& h) const {
    if (h.zone < 0) return centroid[h.block] + rotation(theta[h.block])(h.local);
    const auto& t = zone_node[h.zone];
    return h.weight[0] * node_position[t[0]] + h.weight[1] * node_position[t[1]] + h.weight[2] * node_position[t[2]];
}

void SupportRock::reaction(const BoltHost& h, Vec2 x, Vec2 f, Vec2& force, double& moment) const {
    force = -f;
    moment = h.zone < 0 ? -cross(x - centroid[h.block], f) : 0.0;
}

void RockStiffness::add_tie(const BoltHost& h, double stiffness) {
    if (h.zone < 0) {
        block[h.block] += stiffness;
        rotation[h.block] += stiffness * norm2(rock.position(h) - rock.centroid[h.block]);
    } else {
        for (int j = 0; j < 3; ++j) node[rock.zone_node[h.zone][j]] += std::abs(h.weight[j]) * stiffness;
    }
}

double SupportSetSummary::figure(const std::string& key) const {
    for (const auto& f : figures)
        if (f.key == key) return f.value;
    throw std::out_of_range("support summary of '" + name + "' has no figure '" + key + "'");
}

std::vector<std::unique_ptr<Support>> make_supports(const AnalysisSpec& analysis) {
    // The registry: one row per support type, in the order of their ties.
    std::vector<std::unique_ptr<Support>> out;
    out.push_back(std::make_unique<BoltSupport>(analysis.bolts));
    out.push_back(std::make_unique<LinerSupport>(analysis.liners));
    out.push_back(std::make_unique<DowelSupport>(analysis.dowels));
    return out;
}

} // namespace bbm
