#include "core/solver.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <utility>
#include <omp.h>

namespace bbm {

using contact::JointHistory;
using contact::JointState;
using meshing::JointTag;

namespace {

/// out[i] = the cost of items 0 … i−1, out[n] the total: the prefix a team is
/// shared by (contact::team_share). Sized once; reused without allocating.
template <class Cost> void fill_cost_before(std::vector<double>& out, int n, Cost cost) {
    out.resize(std::size_t(n) + 1);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        out[i] = sum;
        sum += cost(i);
    }
    out[n] = sum;
}

bool selected(const std::vector<std::string>& names, const std::string& name) {
    return names.empty() || std::find(names.begin(), names.end(), name) != names.end();
}

bool in_box(const std::optional<Box2>& box, Vec2 p) {
    return !box || (p.x >= box->lo.x && p.x <= box->hi.x && p.y >= box->lo.y && p.y <= box->hi.y);
}

std::array<double, 3> stress_at(const StressFieldSpec& f, double y) {
    const double dy = y - f.y_ref;
    return {f.sxx + f.dsxx_dy * dy, f.syy + f.dsyy_dy * dy, f.sxy + f.dsxy_dy * dy};
}

Vec2 traction(const std::array<double, 3>& s, Vec2 n) {
    return {s[0] * n.x + s[2] * n.y, s[2] * n.x + s[1] * n.y};
}

} // namespace

std::vector<int> Solver::select_blocks(const SelectionSpec& s) const {
    // A block touches the box if one of its edges lies inside it (both ends).
    auto touches = [&](const std::optional<Box2>& box, int i) {
        for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1]; ++v)
            if (in_box(box, b_.vertex[v]) && in_box(box, b_.vertex[contact::next_vertex(b_.first.data(), i, int(v))]))
                return true;
        return false;
    };
    std::vector<int> out;
    for (int i = 0; i < b_.count(); ++i)
        if (selected(s.regions, region_names_[b_.region[i]]) && (s.touching ? touches(s.box, i) : in_box(s.box, b_.centroid[i])))
            out.push_back(i);
    return out;
}

void Solver::apply_boundaries(const AnalysisSpec& an, const meshing::BlockAssembly& a) {
    // Exposed stretches of block edges: the parts no joint record covers.
    std::vector<std::vector<std::pair<double, double>>> covered(a.points.size());
    for (const auto& j : a.joints)
        for (const auto& [blk, e] : {std::pair{j.block_a, j.edge_a}, std::pair{j.block_b, j.edge_b}}) {
            const int v0 = int(a.first[blk]) + e, v1 = contact::next_vertex(a.first.data(), blk, v0);
            const Vec2 p = a.points[v0], d = a.points[v1] - p;
            const double l2 = norm2(d);
            double s0 = dot(j.p0 - p, d) / l2, s1 = dot(j.p1 - p, d) / l2;
            if (s0 > s1) std::swap(s0, s1);
            covered[v0].push_back({s0, s1});
        }
    for (const auto& bc : an.boundaries) {
        std::vector<int> blocks, nodes;
        if (bc.kind == BoundarySpec::Kind::velocity) {
            // Rigid blocks by centroid; deformable blocks by node position.
            for (int i : select_blocks(bc.select)) {
                if (b_.deformable[i]) continue;
                blocks.push_back(i);
                if (bc.select.touching) {
                    Vec2 sum{};
                    double len = 0.0;
                    for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1]; ++v) {
                        const Vec2 p = b_.vertex[v], q = b_.vertex[contact::next_vertex(b_.first.data(), i, int(v))];
                        if (!in_box(bc.select.box, p) || !in_box(bc.select.box, q)) continue;
                        sum += norm(q - p) * 0.5 * (p + q);
                        len += norm(q - p);
                    }
                    if (len > 0) held_points_.push_back({i, sum / len - b_.centroid[i]});
                }
                if (bc.vx) b_.fixed[i] |= 1, b_.fixed_velocity[i].x = *bc.vx;
                if (bc.vy) b_.fixed[i] |= 2, b_.fixed_velocity[i].y = *bc.vy;
                if (bc.omega) b_.fixed[i] |= 4, b_.fixed_omega[i] = *bc.omega;
            }
            for (int k = 0; k < n_.count(); ++k) {
                if (!selected(bc.select.regions, region_names_[b_.region[n_.block[k]]]) ||
                    !in_box(bc.select.box, n_.position[k]))
                    continue;
                nodes.push_back(k);
                if (bc.vx) n_.fixed[k] |= 1, n_.fixed_velocity[k].x = *bc.vx;
                if (bc.vy) n_.fixed[k] |= 2, n_.fixed_velocity[k].y = *bc.vy;
            }
        } else {
            for (int i = 0; i < a.block_count(); ++i) {
                if (!selected(bc.select.regions, region_names_[a.region[i]])) continue;
                bool any = false;
                for (std::uint32_t v0 = a.first[i]; v0 < a.first[i + 1]; ++v0) {
                    const int v1 = contact::next_vertex(a.first.data(), i, int(v0));
                    const Vec2 p = a.points[v0], d = a.points[v1] - p;
                    const Vec2 n = Vec2{d.y, -d.x} / norm(d);
                    auto spans = covered[v0];
                    std::sort(spans.begin(), spans.end());
                    double s = 0.0;
                    spans.push_back({1.0, 1.0});
                    for (const auto& [c0, c1] : spans) {
                        if (c0 > s + 1e-12) {
                            // Exposed [s, c0]: linear traction, consistent end forces.
                            const Vec2 x0 = p + s * d, x1 = p + std::min(c0, 1.0) * d;
                            if (in_box(bc.select.box, 0.5 * (x0 + x1))) {
                                const double l = norm(x1 - x0);
                                const Vec2 t0 = traction(stress_at(bc.stress, x0.y), n);
                                const Vec2 t1 = traction(stress_at(bc.stress, x1.y), n);
                                const Vec2 f0 = (l / 6.0) * (2.0 * t0 + t1), f1 = (l / 6.0) * (t0 + 2.0 * t1);
                                if (b_.deformable[i]) {
                                    // To the edge's two nodes, linearly by position.
                                    const int n0 = b_.vertex_node[v0], n1 = b_.vertex_node[v1];
                                    const double w0 = s, w1 = std::min(c0, 1.0);
                                    n_.applied[n0] += (1.0 - w0) * f0 + (1.0 - w1) * f1;
                                    n_.applied[n1] += w0 * f0 + w1 * f1;
                                    for (int k : {n0, n1})
                                        if (std::find(nodes.begin(), nodes.end(), k) == nodes.end()) nodes.push_back(k);
                                } else {
                                    b_.applied[i] += f0 + f1;
                                    b_.applied_moment[i] +=
                                        cross(x0 - b_.centroid[i], f0) + cross(x1 - b_.centroid[i], f1);
                                    tractions_.push_back({i, x0 - b_.centroid[i], f0});
                                    tractions_.push_back({i, x1 - b_.centroid[i], f1});
                                }
                                any = true;
                            }
                        }
                        s = std::max(s, c1);
                    }
                }
                if (any && !b_.deformable[i]) blocks.push_back(i);
            }
        }
        boundary_blocks_.push_back({bc.name, blocks});
        boundary_nodes_.push_back(nodes);
    }
    boundary_force_.assign(boundary_blocks_.size(), {});
}

contact::BlockView Solver::view() const {
    return {body_.data(),
            b_.centroid.data(),        b_.velocity.data(),   b_.omega.data(),
            b_.vertex.data(),          b_.first.data(),      b_.inv_edge_length.data(),
            b_.deformable.data(),      b_.vertex_node.data(), n_.velocity.data(),
            b_.corner.data()};
}

void Solver::place_rigid_block(int i) {
    const Rotation rot = rotation(b_.theta[i]);
    const Vec2 c = b_.centroid[i];
    body_[i] = {c, b_.velocity[i], b_.omega[i]};
    for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1]; ++v) b_.vertex[v] = c + rot(b_.local[v]);
}

void Solver::place_deformable_block(int i) {
    // The polygon follows the boundary nodes; edge lengths change.
    const std::uint32_t v0 = b_.first[i], v1 = b_.first[i + 1];
    for (std::uint32_t v = v0; v < v1; ++v) b_.vertex[v] = n_.position[b_.vertex_node[v]];
    for (std::uint32_t v = v0; v < v1; ++v)
        b_.inv_edge_length[v] = 1.0 / norm(b_.vertex[v + 1 == v1 ? v0 : v + 1] - b_.vertex[v]);
}

void Solver::update_vertices() {
    // Blocks in contiguous runs of equal work (excavated ones cost nothing).
    const auto [first, last] = contact::team_share(place_cost_before_, omp_get_thread_num(), omp_get_num_threads());
    for (int i = first; i < last; ++i) {
        if (b_.deformable[i]) place_deformable_block(i);
        else if (!b_.removed[i]) place_rigid_block(i);
    }
#pragma omp barrier
}

void Solver::update_timestep() {
    const int nb = b_.count(), nn = n_.count();
    // Scratch kept between calls: detection calls this inside a step.
    auto& k = stiffness_scratch_.block, & kr = stiffness_scratch_.rotation, & kn = stiffness_scratch_.node;
    k.assign(nb, 0.0), kr.assign(nb, 0.0), kn.assign(nn, 0.0);
    for (int i = 0; i < c_.size(); ++i) {
        const auto& law = laws_[c_.property[i]];
        const double kk = (contact::normal_stiffness(law) + contact::shear_stiffness(law)) * c_.length[i];
        const Vec2 x = b_.vertex[c_.vertex_id[i]];
        const int A = c_.vertex_block[i], B = c_.edge_block[i];
        if (b_.deformable[A]) {
            kn[b_.vertex_node[c_.vertex_id[i]]] += kk;
        } else {
            k[A] += kk;
            kr[A] += kk * norm2(x - b_.centroid[A]);
        }
        if (b_.deformable[B]) {
            const Vec2 p = b_.vertex[c_.edge_id[i]], q = b_.vertex[c_.edge_end[i]];
            const double w = std::clamp(dot(x - p, q - p) / norm2(q - p), 0.0, 1.0);
            kn[b_.vertex_node[c_.edge_id[i]]] += (1.0 - w) * kk;
            kn[b_.vertex_node[c_.edge_end[i]]] += w * kk;
        } else {
            k[B] += kk;
            kr[B] += kk * norm2(x - b_.centroid[B]);
        }
    }
    // Zones: half the Gershgorin row sum of each node's rows (the larger of x, y).
    for (int z = 0; z < z_.size(); ++z) {
        if (b_.removed[z_.block[z]]) continue;
        const auto& t = z_.node[z];
        const auto ke =
            fem::element_stiffness(fem::gradients(n_.position[t[0]], n_.position[t[1]], n_.position[t[2]]), z_.elasticity[z]);
        for (int a = 0; a < 3; ++a) {
            double rx = 0.0, ry = 0.0;
            for (int j = 0; j < 6; ++j) rx += std::abs(ke[(2 * a) * 6 + j]), ry += std::abs(ke[(2 * a + 1) * 6 + j]);
            kn[t[a]] += 0.5 * std::max(rx, ry);
        }
    }
    const double s = settings_.safety;
    const bool scaled = settings_.mode == SolverSpec::Mode::quasi_static;
    if (tie_reaction_.size() > 0) {
        const double step = scaled ? (settings_.timestep > 0 ? settings_.timestep : 1.0) : 0.0;
        RockStiffness rock{support_rock(), k, kr, kn, scaled ? (step / (2.0 * s)) * (step / (2.0 * s)) : 0.0};
        for (auto& support : supports_)
            if (support->tie_count() > 0) support->add_stiffness(rock);
    }
    if (scaled) {
        dt_ = settings_.timestep > 0 ? settings_.timestep : 1.0;
        const double f = (dt_ / (2.0 * s)) * (dt_ / (2.0 * s));
        // A block that has lost all its contacts keeps its scaled mass: with the
        // real mass and Δt = 1 s it would fall metres per step.
        for (int i = 0; i < nb; ++i) {
            b_.mass[i] = k[i] > 0 ? k[i] * f : std::max(b_.mass[i], b_.real_mass[i]);
            b_.inertia[i] = kr[i] > 0 ? kr[i] * f : std::max(b_.inertia[i], b_.real_inertia[i]);
        }
        for (int i = 0; i < nn; ++i) n_.mass[i] = kn[i] > 0 ? kn[i] * f : std::max(n_.mass[i], n_.real_mass[i]);
    } else {
        double limit = INFINITY;
        for (int i = 0; i < nb; ++i) {
            if (b_.removed[i] || b_.deformable[i]) continue;
            if (k[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(b_.real_mass[i] / k[i]));
            if (kr[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(b_.real_inertia[i] / kr[i]));
        }
        for (int i = 0; i < nn; ++i)
            if (!b_.removed[n_.block[i]] && kn[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(n_.real_mass[i] / kn[i]));
        for (const auto& support : supports_)
            if (support->tie_count() > 0) limit = std::min(limit, support->time_limit());
        dt_ = settings_.timestep > 0 ? settings_.timestep : (std::isfinite(limit) ? s * limit : 1e-3);
        b_.mass = b_.real_mass;
        b_.inertia = b_.real_inertia;
        n_.mass = n_.real_mass;
    }
    if (first_dt_ == 0.0) first_dt_ = dt_;
}

void Solver::initialize_stress(const StressFieldSpec& field) {
    update_vertices();
    const auto v = view();
    contact::update_normals(c_, v, corner_radius_);
    for (int i = 0; i < c_.size(); ++i) {
        const Vec2 x = b_.vertex[c_.vertex_id[i]], n = c_.normal[i], t = contact::tangent_of(n);
        const auto s = stress_at(field, x.y);
        const Vec2 sn_vec = traction(s, n);
        JointHistory& h = c_.history[i];
        const auto& law = laws_[c_.property[i]];
        // The in-situ stress is total; a law carries the effective part (σn − p).
        h.sn = -dot(n, sn_vec) - (c_.wet() ? c_.fluid_pressure[i] : 0.0);
        h.tau = dot(t, sn_vec);
        h.un = -h.sn / contact::normal_stiffness(law);
        h.us = h.tau / contact::shear_stiffness(law);
        h.upn = 0.0;
    }
    for (int z = 0; z < z_.size(); ++z) {
        const auto& t = z_.node[z];
        const Vec2 c = (n_.position[t[0]] + n_.position[t[1]] + n_.position[t[2]]) / 3.0;
        z_.stress[z] = stress_at(field, c.y);
    }
}

void Solver::excavate(const std::vector<std::string>& regions, long relax_steps, double keep, double pressure,
                      const SupportPath& path) {
    for (int i = 0; i < b_.count(); ++i)
        if (selected(regions, region_names_[b_.region[i]]) && !regions.empty()) b_.removed[i] = 1;
    refresh_normals();
    // Forces the removed blocks exert on the others become relaxing loads, summed
    // per block and node in contact order.
    const bool relaxing = relax_steps > 0 || keep > 0.0;
    relax_block_force_.assign(relaxing ? b_.count() : 0, {});
    relax_block_moment_.assign(relaxing ? b_.count() : 0, 0.0);
    relax_node_force_.assign(relaxing ? n_.count() : 0, {});
    const bool along_path = relaxing && !path.rows.empty();
    relax_path_.clear();
    if (along_path)
        for (const auto& row : path.rows) relax_path_.insert(relax_path_.end(), row.begin(), row.end());
    relax_deviator_block_force_.assign(along_path ? b_.count() : 0, {});
    relax_deviator_block_moment_.assign(along_path ? b_.count() : 0, 0.0);
    relax_deviator_node_force_.assign(along_path ? n_.count() : 0, {});
    pressure_block_force_.assign(pressure > 0.0 ? b_.count() : 0, {});
    pressure_block_moment_.assign(pressure > 0.0 ? b_.count() : 0, 0.0);
    pressure_node_force_.assign(pressure > 0.0 ? n_.count() : 0, {});
    // A force on the kept side of contact i at x: to its block, or to the node of
    // its vertex, or shared by its edge's two nodes.
    auto add_to_kept = [&](int i, Vec2 x, Vec2 fk, std::vector<Vec2>& block_force, std::vector<double>& block_moment,
                           std::vector<Vec2>& node_force) {
        const int A = c_.vertex_block[i];
        const int kept = b_.removed[A] ? c_.edge_block[i] : A;
        if (!b_.deformable[kept]) {
            block_force[kept] += fk;
            block_moment[kept] += cross(x - b_.centroid[kept], fk);
        } else if (kept == A) {
            node_force[b_.vertex_node[c_.vertex_id[i]]] += fk;
        } else {
            const Vec2 p = b_.vertex[c_.edge_id[i]], q = b_.vertex[c_.edge_end[i]];
            const double w = std::clamp(dot(x - p, q - p) / norm2(q - p), 0.0, 1.0);
            node_force[b_.vertex_node[c_.edge_id[i]]] += (1.0 - w) * fk;
            node_force[b_.vertex_node[c_.edge_end[i]]] += w * fk;
        }
    };
    std::vector<std::uint8_t> drop(c_.size(), 0);
    for (int i = 0; i < c_.size(); ++i) {
        const int A = c_.vertex_block[i], B = c_.edge_block[i];
        if (!b_.removed[A] && !b_.removed[B]) continue;
        drop[i] = 1;
        if (b_.removed[A] && b_.removed[B]) continue;
        const Vec2 x = b_.vertex[c_.vertex_id[i]];
        const double sign = b_.removed[A] ? -1.0 : 1.0; // forces on A, seen from the kept side
        if (relaxing)
            add_to_kept(i, x, sign * contact::contact_force(c_, i), relax_block_force_, relax_block_moment_,
                        relax_node_force_);
        // The support's deviatoric part: the in-situ deviator's traction on the kept
        // side (its outward normal is -n on A, n on B) over the contact's length.
        if (along_path) {
            const auto s = stress_at(path.in_situ, x.y);
            const double mean = 0.5 * (s[0] + s[1]);
            const Vec2 deviator_traction = traction({s[0] - mean, s[1] - mean, s[2]}, c_.normal[i]);
            add_to_kept(i, x, -sign * c_.length[i] * deviator_traction, relax_deviator_block_force_,
                        relax_deviator_block_moment_, relax_deviator_node_force_);
        }
        // The pressure pushes the kept side away from the removed one: along the
        // contact's normal (B's outward normal, towards A) on A, against it on B,
        // over the contact's length.
        if (pressure > 0.0)
            add_to_kept(i, x, sign * pressure * c_.length[i] * c_.normal[i], pressure_block_force_,
                        pressure_block_moment_, pressure_node_force_);
    }
    pressure_scale_.clear(); // the new opening's pressure is the excavation's
    c_.remove_if_flagged(drop);
    if (flow_) flow_->excavated(b_.removed, pressure); // the opening's water pushes on its wall and enters it
    rebuild_contact_index();
    detector_.invalidate();
    for (int i = 0; i < b_.count(); ++i)
        if (b_.removed[i]) b_.velocity[i] = {}, b_.omega[i] = 0.0;
    for (int k = 0; k < n_.count(); ++k)
        if (b_.removed[n_.block[k]]) n_.velocity[k] = {};
    relax_total_ = relax_left_ = relax_steps;
    relax_keep_ = keep;
    update_timestep();
}

void Solver::rebuild_contact_index() {
    c_.rebuild_index(int(laws_.size()), b_.count(), b_.deformable.data(), n_.count(), b_.vertex_node.data());
    // The gather's cost per block: its contacts and its own terms (about two).
    fill_cost_before(block_cost_before_, b_.count(), [&](int i) {
        return 2.0 + (b_.deformable[i] ? 0.0 : double(c_.block_first[i + 1] - c_.block_first[i]));
    });
    // Placing a block and integrating it: excavated ones (often a contiguous run:
    // the blocks are numbered along a curve) next to nothing, a deformable block's
    // placement its boundary vertices, its integration its nodes' (the node chunks).
    auto live = [&](int i) { return b_.removed[i] ? 0.05 : 1.0; };
    fill_cost_before(place_cost_before_, b_.count(), [&](int i) {
        return b_.deformable[i] ? 0.5 * double(b_.first[i + 1] - b_.first[i]) : live(i);
    });
    const int nb = b_.count(), nn = n_.count(), block_chunks = chunks_of(nb);
    fill_cost_before(chunk_cost_before_, block_chunks + chunks_of(nn), [&](int chunk) {
        double cost = 0.0;
        if (chunk < block_chunks) {
            for (int i = chunk * sum_chunk; i < std::min(nb, (chunk + 1) * sum_chunk); ++i)
                cost += b_.deformable[i] ? 0.05 : live(i);
        } else {
            const int c = chunk - block_chunks;
            for (int k = c * sum_chunk; k < std::min(nn, (c + 1) * sum_chunk); ++k) cost += live(n_.block[k]);
        }
        return cost;
    });
    contact::assign_face_groups(c_, view(), face_shear_);
}

void Solver::refresh_normals() const {
    if (!normals_stale_) return;
    contact::update_normals(c_, view(), corner_radius_);
    normals_stale_ = false;
}

void Solver::compute_forces() {
    face_slip_stage();
    support_stage();
    contact_and_zone_stage();
    gather_stage();
}

void Solver::face_slip_stage() {
    // Rigid faces against deformable blocks that share their mean slip
    // (face_shear): before the contacts, which read it.
    if (c_.face_du_s.empty()) return;
    contact::face_slip_pass(c_, view(), dt_, corner_radius_);
#pragma omp barrier
}

void Solver::support_stage() {
    // The supports: one thread, no barrier: it goes on to its share of the
    // contacts; their reactions are gathered after the contact and zone passes'
    // barrier.
    if (tie_reaction_.empty()) return;
#pragma omp single nowait
    {
        const SupportRock rock = support_rock();
        for (std::size_t k = 0; k < supports_.size(); ++k)
            if (supports_[k]->tie_count() > 0) {
                const int first = support_tie_first_[k];
                supports_[k]->force_pass(rock, tie_reaction_.data() + first, tie_moment_.data() + first);
            }
    }
}

void Solver::flow_stage() {
    if (!flow_) return;
#pragma omp single
    {
        // An exception may not leave the parallel region (it would end the
        // program): kept, and thrown again by step() once the region is over.
        try {
            flow_->stage(c_, dt_, steps_);
        } catch (...) {
            stage_error_ = std::current_exception();
        }
    }
}

void Solver::contact_and_zone_stage() {
    // Contacts, then zones: independent of each other, no barrier between them.
    // A team times its shares of the two passes: balance_contact_pass() moves the
    // contacts' split toward equal times.
    const bool timed = omp_get_num_threads() > 1 && int(pass_time_.size()) == omp_get_num_threads();
    const double t0 = timed ? omp_get_wtime() : 0.0;
    contact::contact_pass(c_, laws_, view(), dt_, corner_radius_);
    normals_stale_ = true;
    const double t1 = timed ? omp_get_wtime() : 0.0;
    if (z_.size() > 0) fem::zone_pass(z_, n_.position.data(), n_.velocity.data(), dt_, b_.removed.data());
    if (timed) {
        PassTime& mine = pass_time_[omp_get_thread_num()];
        mine.contacts += t1 - t0;
        mine.zones += omp_get_wtime() - t1;
    }
#pragma omp barrier
}

void Solver::gather_stage() {
    // One gather per block and node: its contacts' and zones' forces in a fixed
    // order, plus gravity, boundary loads, relaxing and constant support pressures
    // and the reactions of its support ties.
    const bool ties = !tie_reaction_.empty();
    const Vec2 g = settings_.gravity;
    // The support of the excavated rock: relaxed linearly to the fraction kept (a
    // fictitious support pressure, the convergence–confinement method's 1 − λ), or
    // its mean and deviator each along a path (a face going by, theory.md §6.5).
    // (Plain variables, not a structured binding: clang 14 cannot use one inside
    // the OpenMP loop below.)
    const std::pair<double, double> factors = relaxation_factors();
    const double relax = factors.first, relax_deviator = factors.second;
    const bool pressure = !pressure_block_force_.empty();
    // 1 as excavated (x 1.0 is exact: the same bits as without a scale).
    const double pressure_scale = pressure_scale_.empty() ? 1.0 : pressure_scale_[0];
    const int nn = n_.count();
    // Blocks in contiguous runs of equal work (a block's contacts), no barrier.
    const auto [first_block, last_block] =
        contact::team_share(block_cost_before_, omp_get_thread_num(), omp_get_num_threads());
    for (int i = first_block; i < last_block; ++i) {
        Vec2 f{};
        double m = 0.0;
        if (!b_.deformable[i]) contact::block_contact_force(c_, i, f, m); // deformable: through its nodes
        f += b_.applied[i] + b_.real_mass[i] * g;
        m += b_.applied_moment[i];
        if (relax != 0.0) f += relax * relax_block_force_[i], m += relax * relax_block_moment_[i];
        if (relax_deviator != 0.0)
            f += relax_deviator * relax_deviator_block_force_[i], m += relax_deviator * relax_deviator_block_moment_[i];
        if (pressure) f += pressure_scale * pressure_block_force_[i], m += pressure_scale * pressure_block_moment_[i];
        if (ties)
            for (int t = tie_block_first_[i]; t < tie_block_first_[i + 1]; ++t) {
                const int tie = tie_block_tie_[t];
                f += tie_reaction_[tie], m += tie_moment_[tie];
            }
        b_.force[i] = f;
        b_.moment[i] = m;
    }
#pragma omp for schedule(static)
    for (int k = 0; k < nn; ++k) {
        Vec2 f = contact::node_contact_force(c_, k) + fem::node_zone_force(z_, k) + n_.applied[k] + n_.real_mass[k] * g;
        if (relax != 0.0) f += relax * relax_node_force_[k];
        if (relax_deviator != 0.0) f += relax_deviator * relax_deviator_node_force_[k];
        if (pressure) f += pressure_scale * pressure_node_force_[k];
        if (ties)
            for (int t = tie_node_first_[k]; t < tie_node_first_[k + 1]; ++t) {
                const auto [tie, weight] = tie_node_tie_[t];
                f += weight * tie_reaction_[tie];
            }
        n_.force[k] = f;
    }
}

std::pair<double, double> Solver::relaxation_factors() const {
    if (relax_block_force_.empty() && relax_node_force_.empty()) return {0.0, 0.0};
    if (relax_path_.empty())
        return {relax_left_ > 0 ? relax_keep_ + (1.0 - relax_keep_) * double(relax_left_) / double(relax_total_ + 1)
                                : relax_keep_,
                0.0};
    // Along the path: at t = k / (N + 1) on the k-th step of N (the linear
    // relaxation's factor is 1 − t), then at its last row.
    const double t = relax_left_ > 0 ? 1.0 - double(relax_left_) / double(relax_total_ + 1) : 1.0;
    std::size_t r = 3;
    while (r + 3 < relax_path_.size() && relax_path_[r] < t) r += 3;
    const double t0 = relax_path_[r - 3], t1 = relax_path_[r], w = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    const double k_mean = (1.0 - w) * relax_path_[r - 2] + w * relax_path_[r + 1];
    const double k_deviator = (1.0 - w) * relax_path_[r - 1] + w * relax_path_[r + 2];
    return {k_mean, k_deviator - k_mean};
}

void Solver::release_relaxation() {
    const std::size_t rows = relax_path_.size();
    const bool kept = relax_keep_ != 0.0 || (rows > 0 && (relax_path_[rows - 2] != 0.0 || relax_path_[rows - 1] != 0.0));
    if (relax_left_ > 0 && --relax_left_ == 0 && !kept) {
        relax_block_force_.clear();
        relax_block_moment_.clear();
        relax_node_force_.clear();
        relax_path_.clear();
        relax_deviator_block_force_.clear();
        relax_deviator_block_moment_.clear();
        relax_deviator_node_force_.clear();
    }
}

void Solver::integrate() {
    const double alpha = settings_.damping, dt = dt_;
    const Vec2 gravity = settings_.gravity;
    // Local damping against the velocity, branch-free (the sign of v is as good as
    // random to the branch predictor): sign(v) is 0 at rest.
    auto damped = [alpha](double f, double v) { return f - alpha * std::abs(f) * double((v > 0.0) - (v < 0.0)); };
    // Translation of one body (rigid block or node): damped central difference with
    // its prescribed components held; returns the work of its loads and of the
    // supports on the prescribed components (reaction −F) over the step, and
    // raises `unbalanced` to its largest free force component.
    auto translate = [&](std::uint8_t fx, Vec2& v, Vec2 f, Vec2 fixed_v, double mass, Vec2 load, double& unbalanced) {
        if (!(fx & 1)) unbalanced = std::max(unbalanced, std::abs(f.x));
        if (!(fx & 2)) unbalanced = std::max(unbalanced, std::abs(f.y));
        v.x = (fx & 1) ? fixed_v.x : v.x + damped(f.x, v.x) / mass * dt;
        v.y = (fx & 2) ? fixed_v.y : v.y + damped(f.y, v.y) / mass * dt;
        double w = dot(load, v) * dt;
        if (fx & 1) w -= f.x * v.x * dt;
        if (fx & 2) w -= f.y * v.y * dt;
        return w;
    };
    auto block_work = [&](int i, double& unbalanced) {
        if (b_.removed[i] || b_.deformable[i]) return 0.0;
        const std::uint8_t fx = b_.fixed[i];
        Vec2& v = b_.velocity[i];
        double w = translate(fx, v, b_.force[i], b_.fixed_velocity[i], b_.mass[i],
                             b_.applied[i] + b_.real_mass[i] * gravity, unbalanced);
        b_.omega[i] = (fx & 4) ? b_.fixed_omega[i] : b_.omega[i] + damped(b_.moment[i], b_.omega[i]) / b_.inertia[i] * dt;
        w += (b_.applied_moment[i] - ((fx & 4) ? b_.moment[i] : 0.0)) * b_.omega[i] * dt;
        b_.centroid[i] += dt * v;
        b_.theta[i] += dt * b_.omega[i];
        return w;
    };
    auto node_work = [&](int i, double& unbalanced) {
        if (b_.removed[n_.block[i]]) return 0.0;
        Vec2& v = n_.velocity[i];
        const double w = translate(n_.fixed[i], v, n_.force[i], n_.fixed_velocity[i], n_.mass[i],
                                   n_.applied[i] + n_.real_mass[i] * gravity, unbalanced);
        n_.position[i] += dt * v;
        return w;
    };
    // The work and the largest unbalanced force per fixed chunk of bodies, then
    // over the chunks in order: the same bits on any thread count.
    const int nb = b_.count(), nn = n_.count();
    const int block_chunks = chunks_of(nb), chunks = block_chunks + chunks_of(nn);
    // Chunks in contiguous runs of equal work (excavated blocks cost nothing).
    const auto [first, last] = contact::team_share(chunk_cost_before_, omp_get_thread_num(), omp_get_num_threads());
    for (int chunk = first; chunk < last; ++chunk) {
        double w = 0.0, unbalanced = 0.0;
        if (chunk < block_chunks) {
            for (int i = chunk * sum_chunk; i < std::min(nb, (chunk + 1) * sum_chunk); ++i) w += block_work(i, unbalanced);
        } else {
            const int c = chunk - block_chunks;
            for (int i = c * sum_chunk; i < std::min(nn, (c + 1) * sum_chunk); ++i) w += node_work(i, unbalanced);
        }
        chunk_sums_[chunk] = {w, unbalanced};
    }
#pragma omp barrier
#pragma omp single
    {
        sum_boundary_forces();
        double max_unbalanced = 0.0;
        for (int chunk = 0; chunk < chunks; ++chunk) {
            work_ += chunk_sums_[chunk].work;
            max_unbalanced = std::max(max_unbalanced, chunk_sums_[chunk].unbalanced);
        }
        const SupportMotion motion{dt_, settings_.damping, settings_.gravity};
        for (auto& support : supports_)
            if (support->tie_count() > 0) max_unbalanced = std::max(max_unbalanced, support->integrate(motion, work_));
        const double scale = force_scale();
        ratio_ = scale > 0.0 ? max_unbalanced / scale : 0.0;
    }
}

void Solver::sum_boundary_forces() {
    const Vec2 g = settings_.gravity;
    for (std::size_t k = 0; k < boundary_blocks_.size(); ++k) {
        Vec2 sum{};
        for (int i : boundary_blocks_[k].second) sum += b_.force[i] - b_.applied[i] - b_.real_mass[i] * g;
        for (int i : boundary_nodes_[k]) sum += n_.force[i] - n_.applied[i] - n_.real_mass[i] * g;
        boundary_force_[k] = sum;
    }
}

double Solver::force_scale() const {
    // The root-mean-square contact (and zone nodal) force. SPEC §5 says "mean
    // contact force magnitude"; RMS >= mean, and it needs no square root per contact.
    // Supports add the elements that may be all that holds a block (a bolt's segments).
    double terms = double(c_.size()) + 3.0 * double(z_.size());
    double squares = contact::contact_force_squares(c_) + (z_.size() > 0 ? fem::zone_force_squares(z_) : 0.0);
    for (const auto& support : supports_) support->add_force_scale(terms, squares);
    double mean_force = terms > 0 ? std::sqrt(squares / terms) : 0.0;
    if (mean_force <= 0.0) {
        for (int i = 0; i < b_.count(); ++i) mean_force += norm(b_.applied[i] + b_.real_mass[i] * settings_.gravity);
        for (int i = 0; i < n_.count(); ++i) mean_force += norm(n_.applied[i] + n_.real_mass[i] * settings_.gravity);
        for (const auto& support : supports_) support->add_applied_loads(mean_force);
        mean_force /= std::max(1, b_.count() + n_.count());
    }
    return mean_force;
}

void Solver::detect_if_due() {
    // Every few steps: which blocks have moved a quarter of the tolerance since
    // their last pass? Only they (and their neighbours) are examined. A deformable
    // block counts as moved when any of its boundary vertices has. Called by every
    // thread of the step's team: the scan and the pass's search are shared.
    if (steps_ % 4 != 0) return;
    const double limit = 0.25 * tolerance_;
    const int nb = b_.count();
#pragma omp single
    any_active_ = false;
    bool any = false;
#pragma omp for schedule(static) nowait
    for (int i = 0; i < nb; ++i) {
        bool moved = false;
        if (b_.removed[i]) {
        } else if (b_.deformable[i]) {
            for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1] && !moved; ++v)
                moved = norm2(b_.vertex[v] - detected_vertex_[v]) >= limit * limit;
        } else {
            moved = norm(b_.centroid[i] - detected_at_[i]) + std::abs(b_.theta[i] - detected_theta_[i]) * radius_[i] >= limit;
        }
        active_[i] = moved;
        any = any || moved;
    }
    if (any) {
#pragma omp atomic write
        any_active_ = true;
    }
#pragma omp barrier
    if (any_active_) detection_pass();
}

void Solver::detection_pass() {
    // Called by every thread of the team (or outside one): the detector shares
    // its search among them; what follows it runs on one thread.
    contact::DetectionInput in{view(), b_.count(), b_.removed.data(), active_.data(), tolerance_,
                               new_contact_property_, dt_, &junctions_, corner_radius_,
                               settings_.new_contact_length == SolverSpec::NewContactLength::overlap};
    const auto r = detector_.update(c_, in);
#pragma omp single
    {
        for (int i = 0; i < b_.count(); ++i) {
            if (!active_[i]) continue;
            detected_at_[i] = b_.centroid[i], detected_theta_[i] = b_.theta[i];
            if (b_.deformable[i])
                for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1]; ++v) detected_vertex_[v] = b_.vertex[v];
        }
        detection_totals_.created += r.created;
        detection_totals_.removed += r.removed;
        detection_totals_.transferred += r.transferred;
        detection_totals_.removed_tensile += r.removed_tensile;
        detection_totals_.removed_shear += r.removed_shear;
        // A contact passed to another edge of a deformable block loads that edge's
        // nodes: the per-node index (and the faces of face_shear) must follow it,
        // or its force would go on to the nodes it left, and a resumed run, which
        // builds the index afresh, would part from the uninterrupted one.
        const bool moved_on_nodes = detector_.transferred_on_nodes() > 0;
        if (r.created > 0 || r.removed > 0 || moved_on_nodes) {
            // New contacts are appended; once they are more than a sixteenth of all,
            // renumber the contacts by block again (the loop's locality) — rarely
            // enough that the renumbering costs little.
            unsorted_contacts_ += r.created;
            if (16 * unsorted_contacts_ > c_.size()) {
                c_.sort_by_blocks();
                unsorted_contacts_ = 0;
            }
            rebuild_contact_index();
            update_timestep();
        }
    }
}

void Solver::balance_contact_pass() {
    // Thread t ran the share s_t of the contacts' estimated cost in C_t seconds
    // (ρ_t = C_t / s_t per unit share) and its equal part of the zones in Z_t.
    // Equal times ρ_t s'_t + Z_t = K with Σ s'_t = 1 give
    //   s'_t = (K − Z_t) / ρ_t,  K = (1 + Σ Z_t / ρ_t) / Σ 1 / ρ_t;
    // the split moves half way there (the rates are local and the clock noisy).
    // The arrays are sized by the constructor: a step allocates nothing.
    const int team = settings_.threads;
    auto& split = c_.team_split;
    if (team < 2 || int(pass_time_.size()) != team || int(split.size()) != team + 1) return;
    double* rate = balance_scratch_.data();
    double* target = rate + team;
    double inverse_rates = 0.0, zone_terms = 0.0;
    bool measured = true;
    for (int t = 0; t < team; ++t) {
        const double share = split[t + 1] - split[t];
        measured = measured && pass_time_[t].contacts > 0.0 && share > 0.0;
        rate[t] = pass_time_[t].contacts / std::max(share, 1e-6);
        if (rate[t] <= 0.0) continue;
        inverse_rates += 1.0 / rate[t];
        zone_terms += pass_time_[t].zones / rate[t];
    }
    if (measured) {
        const double level = (1.0 + zone_terms) / inverse_rates;
        double total = 0.0;
        for (int t = 0; t < team; ++t) total += target[t] = std::max(0.02, (level - pass_time_[t].zones) / rate[t]);
        double at = 0.0;
        for (int t = 1; t < team; ++t) {
            at += target[t - 1] / total;
            split[t] = 0.5 * (split[t] + at);
        }
    }
    std::fill(pass_time_.begin(), pass_time_.end(), PassTime{});
}

void Solver::set_opening_pressure(double pressure, double excavation_pressure, bool solve_now) {
    if (!(excavation_pressure > 0.0) || pressure_block_force_.empty())
        throw InputError("", 0, "stage.pressure", "a pressurise stage changes the pressure of an opening excavated with one: "
                                           "give the excavate stage before it a pressure > 0");
    pressure_scale_.assign(1, pressure / excavation_pressure);
    if (flow_) flow_->set_opening_pressure(pressure, solve_now);
}

void Solver::step() {
    // One parallel region per step: each stage is a work-sharing loop of the team
    // (or a `single` for the serial parts), with the barriers between them that
    // the data flow needs. One thread, or a call from outside a region (the
    // implicit stage), runs the same code serially.
#pragma omp parallel num_threads(settings_.threads) if (settings_.threads > 1)
    {
        // The stages of SPEC §5, each timed under `bbm run --profile` (StepProfile).
        profile_.start();
        update_vertices();          // world vertices from the bodies' positions
        profile_.lap(StepProfile::vertices);
        detect_if_due();            // 1. contact detection, when due
        profile_.lap(StepProfile::detection);
        flow_stage();               //    water in the joints (core/joint_flow.hpp)
        profile_.lap(StepProfile::flow);
        face_slip_stage();          // 2. (rigid faces on deformable blocks)
        profile_.lap(StepProfile::face_slip);
        support_stage();            // 4. (bolts and liners: forces and reactions)
        profile_.lap(StepProfile::supports);
        contact_and_zone_stage();   // 2. contact forces, 3. zone stresses
        profile_.lap(StepProfile::contacts_and_zones);
        gather_stage();             // 4. loads and the sum per block and node
        profile_.lap(StepProfile::gather);
        integrate();                // 5. damping, integration; 6. the ratio
        profile_.lap(StepProfile::integrate);
#pragma omp single
        {
            release_relaxation();
            time_ += dt_;
            ++steps_;
            if (steps_ % balance_every == 0) balance_contact_pass();
        }
        profile_.lap(StepProfile::bookkeeping);
    }
    if (stage_error_) std::rethrow_exception(std::exchange(stage_error_, nullptr));
}

void StepProfile::start() {
    if (enabled && omp_get_thread_num() == 0) last = omp_get_wtime();
}

void StepProfile::lap(Stage stage) {
    if (!enabled || omp_get_thread_num() != 0) return;
    const double now = omp_get_wtime();
    seconds[stage] += now - last;
    last = now;
    if (stage == bookkeeping) ++steps;
}

double Solver::kinetic_energy() const {
    double e = 0.0;
    for (int i = 0; i < b_.count(); ++i)
        if (!b_.removed[i] && !b_.deformable[i])
            e += 0.5 * b_.real_mass[i] * norm2(b_.velocity[i]) + 0.5 * b_.real_inertia[i] * b_.omega[i] * b_.omega[i];
    for (int i = 0; i < n_.count(); ++i)
        if (!b_.removed[n_.block[i]]) e += 0.5 * n_.real_mass[i] * norm2(n_.velocity[i]);
    return e;
}

double Solver::strain_energy() const {
    double e = 0.0;
    for (int i = 0; i < c_.size(); ++i) {
        const auto& h = c_.history[i];
        const auto& law = laws_[c_.property[i]];
        e += c_.length[i] * (h.sn * h.sn / (2.0 * contact::normal_stiffness(law)) +
                             h.tau * h.tau / (2.0 * contact::shear_stiffness(law)));
    }
    return e + zone_strain_energy();
}

double Solver::zone_strain_energy() const {
    double e = 0.0;
    for (int z = 0; z < z_.size(); ++z) {
        if (b_.removed[z_.block[z]]) continue;
        const auto& t = z_.node[z];
        const double area = fem::gradients(n_.position[t[0]], n_.position[t[1]], n_.position[t[2]]).area;
        // ½ σ·D⁻¹σ, plane strain: D⁻¹ from the Lamé constants (σzz = λ(εxx + εyy)).
        const auto& s = z_.stress[z];
        const double l = z_.elasticity[z].lambda, G = z_.elasticity[z].shear;
        const double tr = s[0] + s[1];
        const double exx = (s[0] - l / (2.0 * (l + G)) * tr) / (2.0 * G);
        const double eyy = (s[1] - l / (2.0 * (l + G)) * tr) / (2.0 * G);
        const double exy = s[2] / (2.0 * G);
        e += 0.5 * area * (s[0] * exx + s[1] * eyy + 2.0 * s[2] * exy);
    }
    return e;
}

double Solver::dissipated_energy() const {
    double e = 0.0;
    for (int i = 0; i < c_.size(); ++i) e += c_.length[i] * c_.history[i].dissipated;
    return e;
}

int Solver::cracks(JointState mode) const {
    // Broken contacts still present plus those detection removed since.
    int n = mode == JointState::broken_tension ? detection_totals_.removed_tensile
          : mode == JointState::broken_shear   ? detection_totals_.removed_shear
                                               : 0;
    for (const auto& h : c_.history) n += h.broken == mode;
    return n;
}

Vec2 Solver::boundary_force(const std::string& name) const {
    for (std::size_t k = 0; k < boundary_blocks_.size(); ++k)
        if (boundary_blocks_[k].first == name) return boundary_force_[k];
    return {};
}

std::vector<std::array<double, 3>> Solver::block_stresses() const {
    refresh_normals();
    std::vector<std::array<double, 3>> m(b_.count(), {0.0, 0.0, 0.0});
    auto add = [&](int blk, Vec2 r, Vec2 f) {
        if (b_.deformable[blk]) return;
        m[blk][0] += r.x * f.x;
        m[blk][1] += r.y * f.y;
        m[blk][2] += 0.5 * (r.x * f.y + r.y * f.x);
    };
    for (int i = 0; i < c_.size(); ++i) {
        const int A = c_.vertex_block[i], B = c_.edge_block[i];
        const Vec2 x = b_.vertex[c_.vertex_id[i]], f = contact::contact_force(c_, i);
        add(A, x - b_.centroid[A], f);
        add(B, x - b_.centroid[B], -1.0 * f);
    }
    // Boundary tractions are surface forces too (at their points, rotating with the
    // block); gravity, uniform over the block, has no first moment about the centroid.
    for (const auto& t : tractions_) {
        add(t.block, rotation(b_.theta[t.block])(t.offset), t.force);
    }
    // Supports (reaction = minus the force on the prescribed components), where a
    // `touching` boundary holds the block: without them a block on a symmetry
    // plane would show half its stress across the plane.
    for (const auto& sp : held_points_) {
        const int i = sp.block;
        const Vec2 reaction{(b_.fixed[i] & 1) ? -b_.force[i].x : 0.0, (b_.fixed[i] & 2) ? -b_.force[i].y : 0.0};
        add(i, rotation(b_.theta[i])(sp.offset), reaction);
    }
    // Deformable blocks: area-weighted mean of their zone stresses.
    for (int z = 0; z < z_.size(); ++z) {
        const auto& t = z_.node[z];
        const double a = fem::gradients(n_.position[t[0]], n_.position[t[1]], n_.position[t[2]]).area;
        for (int k = 0; k < 3; ++k) m[z_.block[z]][k] += a * z_.stress[z][k];
    }
    for (int b = 0; b < b_.count(); ++b)
        for (double& v : m[b]) v /= b_.area[b];
    return m;
}

int Solver::block_at(Vec2 p) const {
    int best = -1;
    double dmin = INFINITY;
    for (int i = 0; i < b_.count(); ++i) {
        const double d = norm(b_.centroid[i] - p);
        if (d < dmin) dmin = d, best = i;
    }
    return best;
}

double Solver::time_contact_passes(long passes, int threads) const {
    contact::Contacts copy = c_;
    const auto view_now = view();
    const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads) if (threads > 1)
    for (long k = 0; k < passes; ++k) {
        contact::contact_pass(copy, laws_, view_now, dt_, corner_radius_);
#pragma omp barrier
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace bbm
