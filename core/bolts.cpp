// Rock bolts and cables in the explicit loop (core/bolts.hpp for the model).
#include "core/solver.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bbm {

std::vector<std::array<Vec2, 2>> expand_bolts(const BoltSetSpec& spec) {
    std::vector<std::array<Vec2, 2>> out = spec.bolts;
    if (!spec.ring) return out;
    const auto& r = *spec.ring;
    const double span = r.to - r.from;
    const bool full = std::abs(std::abs(span) - 360.0) < 1e-9;
    int count = r.count;
    if (count <= 0 && r.spacing > 0.0) {
        const double arc = std::abs(span) * std::numbers::pi / 180.0 * r.radius;
        count = std::max(1, int(std::floor(arc / r.spacing + 1e-9)) + (full ? 0 : 1));
    }
    for (int k = 0; k < count; ++k) {
        // A full circle: count intervals; an arc: bolts at both of its ends.
        const double f = full ? double(k) / count : (count > 1 ? double(k) / (count - 1) : 0.5);
        const double a = (r.from + f * span) * std::numbers::pi / 180.0;
        const Vec2 u{std::cos(a), std::sin(a)};
        out.push_back({r.center + r.radius * u, r.center + (r.radius + r.length) * u});
    }
    return out;
}

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

void Solver::tie_reaction(const BoltHost& h, Vec2 x, Vec2 f, Vec2& reaction, double& moment) const {
    reaction = -f;
    moment = h.zone < 0 ? -cross(x - b_.centroid[h.block], f) : 0.0;
}

void Solver::add_tie_stiffness(const BoltHost& h, double stiffness, std::vector<double>& k, std::vector<double>& kr,
                               std::vector<double>& kn) const {
    if (h.zone < 0) {
        k[h.block] += stiffness;
        kr[h.block] += stiffness * norm2(host_position(h) - b_.centroid[h.block]);
    } else {
        for (int j = 0; j < 3; ++j) kn[z_.node[h.zone][j]] += std::abs(h.weight[j]) * stiffness;
    }
}

Vec2 Solver::host_position(const BoltHost& h) const {
    if (h.zone < 0) return b_.centroid[h.block] + rotation(b_.theta[h.block])(h.local);
    const auto& t = z_.node[h.zone];
    return h.weight[0] * n_.position[t[0]] + h.weight[1] * n_.position[t[1]] + h.weight[2] * n_.position[t[2]];
}

void Solver::install_bolts(const std::vector<std::string>& names) {
    auto& B = bolts_;
    for (const auto& name : names) {
        const auto it = std::find(bolt_names_.begin(), bolt_names_.end(), name);
        if (it == bolt_names_.end()) throw InputError("", 0, "stage.supports", "unknown bolt set '" + name + "'");
        const int set = int(it - bolt_names_.begin());
        if (B.installed[set]) throw InputError("", 0, "stage.supports", "bolt set '" + name + "' is already installed");
        B.installed[set] = 1;
        const BoltSetSpec& spec = bolt_specs_[set];
        const auto bolts = expand_bolts(spec);
        for (std::size_t b = 0; b < bolts.size(); ++b) {
            const auto [head, toe] = bolts[b];
            const double length = norm(toe - head);
            const int n = std::max(1, int(std::ceil(length / spec.segment_length - 1e-9)));
            const double segment = length / n;
            const int first = B.node_count();
            for (int j = 0; j <= n; ++j) {
                const Vec2 p = head + (double(j) / n) * (toe - head);
                const BoltHost h = find_host(p, 0.5 * segment);
                // Inner nodes may lie in an open joint (no rock: held by their
                // segments); the head and the toe must be in rock.
                if (h.block < 0 && (j == 0 || j == n))
                    throw InputError("", 0, "bolt[" + std::to_string(set) + "]",
                                     "bolt " + std::to_string(b) + " of set '" + name + "': its point (" +
                                         std::to_string(p.x) + ", " + std::to_string(p.y) +
                                         ") lies in no rock (inside an opening, or outside the model): its " +
                                         (j == 0 ? "head" : "toe") + " must be in a block");
                B.position.push_back(p);
                B.velocity.push_back({});
                B.force.push_back({});
                B.applied.push_back({});
                B.mass.push_back(0.0);
                B.length.push_back(j == 0 || j == n ? 0.5 * segment : segment);
                B.slip.push_back(0.0);
                B.bond.push_back(0.0);
                B.host.push_back(h);
                B.tied.push_back((j == 0 && spec.face_plate) || (j == n && spec.end_anchor));
                B.node_set.push_back(set);
                if (j < n) {
                    B.segment_node.push_back(first + j);
                    B.rest.push_back(segment);
                    B.plastic.push_back(0.0);
                    B.axial.push_back(0.0);
                    B.state.push_back(BoltState::elastic);
                }
            }
            B.first.push_back(B.node_count());
            B.bolt_set.push_back(set);
        }
    }
    index_bolt_hosts();
    update_timestep();
}

void Solver::install_supports(const std::vector<std::string>& names) {
    std::vector<std::string> bolts;
    for (const auto& name : names) {
        const auto it = std::find(liner_names_.begin(), liner_names_.end(), name);
        if (it == liner_names_.end()) {
            bolts.push_back(name);
            continue;
        }
        const int set = int(it - liner_names_.begin());
        if (liners_.installed[set]) throw InputError("", 0, "stage.supports", "liner '" + name + "' is already installed");
        install_liner(set);
    }
    install_bolts(bolts); // indexes the ties of both and updates the time step
}

void Solver::index_bolt_hosts() {
    auto& B = bolts_;
    B.reaction.assign(B.node_count(), {});
    B.reaction_moment.assign(B.node_count(), 0.0);
    const int nb = b_.count(), nn = n_.count();
    bolt_block_first_.assign(nb + 1, 0);
    bolt_node_first_.assign(nn + 1, 0);
    // Ties: bolt nodes 0 … B.node_count() − 1, then liner nodes.
    auto host_of = [&](int tie) -> const BoltHost& {
        return tie < B.node_count() ? B.host[tie] : liners_.host[tie - B.node_count()];
    };
    const int ties = B.node_count() + liners_.node_count();
    for (int tie = 0; tie < ties; ++tie) {
        const BoltHost& h = host_of(tie);
        if (h.block < 0) continue;
        if (h.zone < 0) ++bolt_block_first_[h.block + 1];
        else
            for (int j = 0; j < 3; ++j) ++bolt_node_first_[z_.node[h.zone][j] + 1];
    }
    for (int i = 0; i < nb; ++i) bolt_block_first_[i + 1] += bolt_block_first_[i];
    for (int i = 0; i < nn; ++i) bolt_node_first_[i + 1] += bolt_node_first_[i];
    bolt_block_tie_.assign(bolt_block_first_[nb], 0);
    bolt_node_tie_.assign(bolt_node_first_[nn], {});
    std::vector<int> fill_block(bolt_block_first_.begin(), bolt_block_first_.end() - 1),
        fill_node(bolt_node_first_.begin(), bolt_node_first_.end() - 1);
    for (int k = 0; k < ties; ++k) { // in tie order: the gather's order
        const BoltHost& h = host_of(k);
        if (h.block < 0) continue;
        if (h.zone < 0) bolt_block_tie_[fill_block[h.block]++] = k;
        else
            for (int j = 0; j < 3; ++j) {
                const int node = z_.node[h.zone][j];
                bolt_node_tie_[fill_node[node]++] = {k, h.weight[j]};
            }
    }
}

void Solver::bolt_pass() {
    auto& B = bolts_;
    std::fill(B.force.begin(), B.force.end(), Vec2{});
    for (int s = 0; s < B.segment_count(); ++s) {
        const int a = B.segment_node[s];
        if (B.state[s] == BoltState::broken) continue;
        const auto& set = B.sets[B.node_set[a]];
        const Vec2 d = B.position[a + 1] - B.position[a];
        const double l = norm(d), strain = l / B.rest[s] - 1.0;
        if (set.rupture_strain > 0.0 && strain > set.rupture_strain) {
            B.state[s] = BoltState::broken;
            B.axial[s] = 0.0;
            continue;
        }
        double axial = set.ea * (strain - B.plastic[s]);
        if (set.cable && axial < 0.0) {
            axial = 0.0;
        } else if (set.yield_force > 0.0 && std::abs(axial) > set.yield_force) {
            axial = support::plastic_return(axial, set.yield_force, set.ea, strain, B.plastic[s]);
            B.state[s] = BoltState::yielded;
        }
        B.axial[s] = axial;
        const Vec2 f = (axial / l) * d;
        B.force[a] += f;
        B.force[a + 1] -= f;
    }
    for (int b = 0; b < B.bolt_count(); ++b) {
        const int first = B.first[b], last = B.first[b + 1] - 1;
        for (int k = first; k <= last; ++k) {
            const BoltHost& h = B.host[k];
            if (h.block < 0 || b_.removed[h.block]) {
                B.bond[k] = 0.0;
                B.reaction[k] = {};
                B.reaction_moment[k] = 0.0;
                continue;
            }
            const auto& set = B.sets[B.node_set[k]];
            const Vec2 x = host_position(h), d = x - B.position[k];
            const Vec2 axis = B.position[std::min(k + 1, last)] - B.position[std::max(k - 1, first)];
            const Vec2 t = axis / norm(axis);
            const double s = dot(d, t);
            double q = set.bond_stiffness * (s - B.slip[k]);
            if (!B.tied[k] && set.bond_strength > 0.0)
                q = support::plastic_return(q, set.bond_strength, set.bond_stiffness, s, B.slip[k]);
            B.bond[k] = q;
            const Vec2 f = B.length[k] * (q * t + set.normal_stiffness * (d - s * t));
            B.force[k] += f;
            tie_reaction(h, x, f, B.reaction[k], B.reaction_moment[k]);
        }
    }
}

double Solver::integrate_bolts(double& work) {
    auto& B = bolts_;
    const double alpha = settings_.damping, dt = dt_;
    const Vec2 g = settings_.gravity;
    double unbalanced = 0.0;
    for (int k = 0; k < B.node_count(); ++k) {
        const Vec2 weight = (B.sets[B.node_set[k]].line_mass * B.length[k]) * g;
        const Vec2 f = B.force[k] + weight + B.applied[k];
        unbalanced = std::max({unbalanced, std::abs(f.x), std::abs(f.y)});
        Vec2& v = B.velocity[k];
        v.x += support::damped(f.x, v.x, alpha) / B.mass[k] * dt;
        v.y += support::damped(f.y, v.y, alpha) / B.mass[k] * dt;
        B.position[k] += dt * v;
        work += dot(weight + B.applied[k], v) * dt;
    }
    return unbalanced;
}

void Solver::add_bolt_stiffness(std::vector<double>& k, std::vector<double>& kr, std::vector<double>& kn,
                                double mass_factor) {
    auto& B = bolts_;
    auto& own = bolt_stiffness_;
    own.assign(B.node_count(), 0.0);
    for (int s = 0; s < B.segment_count(); ++s) {
        if (B.state[s] == BoltState::broken) continue;
        const int a = B.segment_node[s];
        const double ks = B.sets[B.node_set[a]].ea / B.rest[s];
        own[a] += ks, own[a + 1] += ks;
    }
    for (int i = 0; i < B.node_count(); ++i) {
        const auto& set = B.sets[B.node_set[i]];
        const BoltHost& h = B.host[i];
        if (h.block < 0 || b_.removed[h.block]) continue;
        const double kg = B.length[i] * std::max(set.bond_stiffness, set.normal_stiffness);
        own[i] += kg;
        add_tie_stiffness(h, kg, k, kr, kn);
    }
    for (int i = 0; i < B.node_count(); ++i) {
        const double real = B.sets[B.node_set[i]].line_mass * B.length[i];
        B.mass[i] = mass_factor > 0.0 ? std::max(own[i] * mass_factor, 1e-300) : real;
    }
}

double Solver::bolt_time_limit() const {
    double limit = INFINITY;
    for (int i = 0; i < bolts_.node_count(); ++i)
        if (bolt_stiffness_[i] > 0.0) limit = std::min(limit, 2.0 * std::sqrt(bolts_.mass[i] / bolt_stiffness_[i]));
    return limit;
}

std::vector<BoltSetSummary> Solver::bolt_summary() const {
    const auto& B = bolts_;
    std::vector<BoltSetSummary> out;
    for (std::size_t set = 0; set < B.sets.size(); ++set) {
        if (!B.installed[set]) continue;
        BoltSetSummary s;
        s.name = bolt_names_[set];
        const double spacing = B.sets[set].spacing;
        for (int b = 0; b < B.bolt_count(); ++b) {
            if (B.bolt_set[b] != int(set)) continue;
            ++s.bolts;
            bool yielded = false, broken = false;
            // The grout's load (a plate's or anchor's tie is not grout).
            for (int k = B.first[b]; k < B.first[b + 1]; ++k)
                if (!B.tied[k]) s.max_bond = std::max(s.max_bond, std::abs(B.bond[k]) * spacing);
            for (int seg = 0; seg < B.segment_count(); ++seg) {
                const int a = B.segment_node[seg];
                if (a < B.first[b] || a >= B.first[b + 1]) continue;
                s.max_axial = std::max(s.max_axial, B.axial[seg] * spacing);
                s.min_axial = std::min(s.min_axial, B.axial[seg] * spacing);
                yielded |= B.state[seg] == BoltState::yielded;
                broken |= B.state[seg] == BoltState::broken;
            }
            s.yielded += yielded;
            s.broken += broken;
        }
        out.push_back(s);
    }
    return out;
}

} // namespace bbm
