#include "core/solver.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>

namespace bbm {

using contact::JointHistory;
using contact::JointState;
using meshing::JointTag;

namespace {

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

Solver::Solver(const meshing::BlockAssembly& a, const AnalysisSpec& an) : settings_(an.solver) {
    region_names_ = a.region_names;
    const int nb = a.block_count();

    // Materials per region.
    std::vector<double> density(a.region_names.size(), 2700.0);
    std::vector<int> material(a.region_names.size(), -1);
    for (const auto& [region, mat] : an.region_material) {
        const auto r = std::find(region_names_.begin(), region_names_.end(), region);
        const auto m = std::find_if(an.materials.begin(), an.materials.end(),
                                    [&](const MaterialSpec& s) { return s.name == mat; });
        if (r == region_names_.end() || m == an.materials.end())
            throw InputError("", 0, "region.material", "region '" + region + "' or material '" + mat + "' unknown");
        density[r - region_names_.begin()] = m->density;
        material[r - region_names_.begin()] = int(m - an.materials.begin());
    }
    if (an.region_material.empty() && !an.materials.empty()) {
        std::fill(density.begin(), density.end(), an.materials[0].density);
        std::fill(material.begin(), material.end(), 0);
    }

    // Blocks: exact polygon mass properties.
    b_.first.assign(a.first.begin(), a.first.end());
    b_.local.resize(a.points.size());
    b_.vertex = a.points;
    for (int i = 0; i < nb; ++i) {
        const auto poly = a.block(i);
        const Vec2 c = centroid(poly);
        const double area = signed_area(poly), rho = density[a.region[i]];
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) b_.local[v] = a.points[v] - c;
        b_.centroid.push_back(c);
        b_.area.push_back(area);
        b_.real_mass.push_back(rho * area);
        b_.real_inertia.push_back(rho * polar_moment_about_centroid(poly));
        b_.region.push_back(a.region[i]);
        b_.material.push_back(material[a.region[i]]);
    }
    b_.centroid0 = b_.centroid;
    b_.inv_edge_length.resize(a.points.size());
    for (int i = 0; i < nb; ++i)
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v)
            b_.inv_edge_length[v] = 1.0 / norm(a.points[contact::next_vertex(a.first.data(), i, int(v))] - a.points[v]);
    b_.mass = b_.real_mass;
    b_.inertia = b_.real_inertia;
    b_.velocity.assign(nb, {});
    b_.force.assign(nb, {});
    b_.applied.assign(nb, {});
    b_.theta.assign(nb, 0.0);
    b_.omega.assign(nb, 0.0);
    b_.moment.assign(nb, 0.0);
    b_.applied_moment.assign(nb, 0.0);
    b_.fixed.assign(nb, 0);
    b_.fixed_velocity.assign(nb, {});
    b_.fixed_omega.assign(nb, 0.0);
    b_.removed.assign(nb, 0);

    // Property sets; the last, built in, serves contacts formed unbonded if the
    // model names none: Coulomb, φ 30°, stiffness of the stiffest set.
    for (const auto& p : an.joint_properties) {
        laws_.push_back(contact::make_law(p));
        property_names_.push_back(p.name);
    }

    // Joint records -> point contacts, one at each end with half the joint length.
    double mean_edge = 0.0;
    std::map<std::pair<int, int>, int> existing; // (vertex id, edge id) -> contact
    for (const auto& j : a.joints) {
        int prop = -1;
        for (const auto& rule : an.joint_assignments) {
            const bool tag_ok = rule.tags.empty() || std::find(rule.tags.begin(), rule.tags.end(), j.tag) != rule.tags.end();
            const bool region_ok = rule.regions.empty() || (selected(rule.regions, region_names_[a.region[j.block_a]]) &&
                                                            selected(rule.regions, region_names_[a.region[j.block_b]]));
            if (tag_ok && region_ok) {
                const auto it = std::find(property_names_.begin(), property_names_.end(), rule.property);
                if (it == property_names_.end())
                    throw InputError("", 0, "joint_assignment.property", "unknown joint property '" + rule.property + "'");
                prop = int(it - property_names_.begin());
            }
        }
        if (prop < 0)
            throw InputError("", 0, "joint_assignment",
                             std::string("no joint property is assigned to ") + meshing::to_string(j.tag) +
                                 " joints between regions '" + region_names_[a.region[j.block_a]] + "' and '" +
                                 region_names_[a.region[j.block_b]] + "'");
        const double half = 0.5 * j.length();
        mean_edge += j.length();
        auto vertex_of = [&](int block, Vec2 p) {
            for (std::uint32_t v = a.first[block]; v < a.first[block + 1]; ++v)
                if (a.points[v] == p) return int(v);
            return -1;
        };
        const int ea = int(a.first[j.block_a]) + j.edge_a, eb = int(a.first[j.block_b]) + j.edge_b;
        auto add_end = [&](Vec2 p, bool prefer_a) {
            int va = vertex_of(j.block_a, p), vb = vertex_of(j.block_b, p);
            if (va >= 0 && vb >= 0) (prefer_a ? vb : va) = -1;
            const bool a_is_vertex = va >= 0;
            const int vertex = a_is_vertex ? va : vb, edge = a_is_vertex ? eb : ea;
            BBM_ASSERT(vertex >= 0, "a joint ends at a vertex of one of its blocks");
            if (auto it = existing.find({vertex, edge}); it != existing.end()) {
                c_.length[it->second] += half; // collinear edges: one contact, summed share
                return;
            }
            JointHistory h;
            h.bonded = contact::starts_bonded(laws_[prop]);
            existing[{vertex, edge}] = c_.size();
            const int edge_block = a_is_vertex ? j.block_b : j.block_a;
            c_.add(a_is_vertex ? j.block_a : j.block_b, vertex, edge_block, edge,
                   contact::next_vertex(a.first.data(), edge_block, edge), half, prop, h);
        };
        add_end(j.p0, true);
        add_end(j.p1, false);
    }
    if (!a.joints.empty()) mean_edge /= double(a.joints.size());
    corner_radius_ = 0.05 * mean_edge;

    // Contacts formed during the run: the named set, or a built-in frictional one
    // (φ 30°, no bond) as stiff as the stiffest set of the model.
    if (!settings_.new_contact_property.empty()) {
        const auto it = std::find(property_names_.begin(), property_names_.end(), settings_.new_contact_property);
        if (it == property_names_.end())
            throw InputError("", 0, "solver.new_contact_property",
                             "unknown joint property '" + settings_.new_contact_property + "'");
        new_contact_property_ = int(it - property_names_.begin());
    } else {
        JointPropertySpec unbonded;
        unbonded.name = "unbonded (built-in)";
        unbonded.law = JointPropertySpec::Law::coulomb;
        unbonded.kn = unbonded.ks = 0.0;
        for (const auto& l : laws_) {
            unbonded.kn = std::max(unbonded.kn, contact::normal_stiffness(l));
            unbonded.ks = std::max(unbonded.ks, contact::shear_stiffness(l));
        }
        if (unbonded.kn <= 0.0) unbonded.kn = unbonded.ks = 1e9;
        unbonded.friction = 30.0;
        new_contact_property_ = int(laws_.size());
        laws_.push_back(contact::make_law(unbonded));
        property_names_.push_back(unbonded.name);
    }
    double mean_area = 0.0;
    for (double x : b_.area) mean_area += x;
    mean_area /= std::max(1, nb);
    tolerance_ = settings_.detection_tolerance > 0 ? settings_.detection_tolerance
                                                   : 0.02 * std::sqrt(4.0 * mean_area / 3.141592653589793);
    radius_.assign(nb, 0.0);
    for (int i = 0; i < nb; ++i)
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) radius_[i] = std::max(radius_[i], norm(b_.local[v]));
    detected_at_ = b_.centroid;
    detected_theta_.assign(nb, 0.0);
    active_.assign(nb, 0);
    c_.rebuild_batches(int(laws_.size()));

    apply_boundaries(an, a);
    update_vertices();
    update_timestep();
}

std::vector<int> Solver::select_blocks(const SelectionSpec& s) const {
    std::vector<int> out;
    for (int i = 0; i < b_.count(); ++i)
        if (selected(s.regions, region_names_[b_.region[i]]) && in_box(s.box, b_.centroid[i])) out.push_back(i);
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
        std::vector<int> blocks;
        if (bc.kind == BoundarySpec::Kind::velocity) {
            blocks = select_blocks(bc.select);
            for (int i : blocks) {
                if (bc.vx) b_.fixed[i] |= 1, b_.fixed_velocity[i].x = *bc.vx;
                if (bc.vy) b_.fixed[i] |= 2, b_.fixed_velocity[i].y = *bc.vy;
                if (bc.omega) b_.fixed[i] |= 4, b_.fixed_omega[i] = *bc.omega;
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
                                b_.applied[i] += f0 + f1;
                                b_.applied_moment[i] += cross(x0 - b_.centroid[i], f0) + cross(x1 - b_.centroid[i], f1);
                                tractions_.push_back({i, x0 - b_.centroid[i], f0});
                                tractions_.push_back({i, x1 - b_.centroid[i], f1});
                                any = true;
                            }
                        }
                        s = std::max(s, c1);
                    }
                }
                if (any) blocks.push_back(i);
            }
        }
        boundary_blocks_.push_back({bc.name, blocks});
    }
    boundary_force_.assign(boundary_blocks_.size(), {});
}

contact::BlockView Solver::view() const {
    return {b_.centroid.data(), b_.velocity.data(), b_.omega.data(), b_.vertex.data(), b_.first.data(),
            b_.inv_edge_length.data()};
}

void Solver::update_vertices() {
    for (int i = 0; i < b_.count(); ++i) {
        const double cs = std::cos(b_.theta[i]), sn = std::sin(b_.theta[i]);
        const Vec2 c = b_.centroid[i];
        for (std::uint32_t v = b_.first[i]; v < b_.first[i + 1]; ++v) {
            const Vec2 r = b_.local[v];
            b_.vertex[v] = {c.x + cs * r.x - sn * r.y, c.y + sn * r.x + cs * r.y};
        }
    }
}

void Solver::update_timestep() {
    const int nb = b_.count();
    std::vector<double> k(nb, 0.0), kr(nb, 0.0);
    for (int i = 0; i < c_.size(); ++i) {
        const auto& law = laws_[c_.property[i]];
        const double kk = (contact::normal_stiffness(law) + contact::shear_stiffness(law)) * c_.length[i];
        const Vec2 x = b_.vertex[c_.vertex_id[i]];
        for (int blk : {c_.vertex_block[i], c_.edge_block[i]}) {
            k[blk] += kk;
            kr[blk] += kk * norm2(x - b_.centroid[blk]);
        }
    }
    const double s = settings_.safety;
    if (settings_.mode == SolverSpec::Mode::quasi_static) {
        dt_ = settings_.timestep > 0 ? settings_.timestep : 1.0;
        const double f = (dt_ / (2.0 * s)) * (dt_ / (2.0 * s));
        for (int i = 0; i < nb; ++i) {
            b_.mass[i] = k[i] > 0 ? k[i] * f : b_.real_mass[i];
            b_.inertia[i] = kr[i] > 0 ? kr[i] * f : b_.real_inertia[i];
        }
    } else {
        double limit = INFINITY;
        for (int i = 0; i < nb; ++i) {
            if (b_.removed[i]) continue;
            if (k[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(b_.real_mass[i] / k[i]));
            if (kr[i] > 0) limit = std::min(limit, 2.0 * std::sqrt(b_.real_inertia[i] / kr[i]));
        }
        dt_ = settings_.timestep > 0 ? settings_.timestep : (std::isfinite(limit) ? s * limit : 1e-3);
        b_.mass = b_.real_mass;
        b_.inertia = b_.real_inertia;
    }
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
        h.sn = -dot(n, sn_vec);
        h.tau = dot(t, sn_vec);
        h.un = -h.sn / contact::normal_stiffness(law);
        h.us = h.tau / contact::shear_stiffness(law);
        h.upn = 0.0;
    }
}

void Solver::excavate(const std::vector<std::string>& regions, long relax_steps) {
    for (int i = 0; i < b_.count(); ++i)
        if (selected(regions, region_names_[b_.region[i]]) && !regions.empty()) b_.removed[i] = 1;
    // Forces the removed blocks exert on the others become relaxing loads.
    std::vector<std::uint8_t> drop(c_.size(), 0);
    for (int i = 0; i < c_.size(); ++i) {
        const int A = c_.vertex_block[i], B = c_.edge_block[i];
        if (!b_.removed[A] && !b_.removed[B]) continue;
        drop[i] = 1;
        if (b_.removed[A] && b_.removed[B]) continue;
        const Vec2 x = b_.vertex[c_.vertex_id[i]];
        const Vec2 f = contact::contact_force(c_, i);
        const int kept = b_.removed[A] ? B : A;
        const Vec2 fk = b_.removed[A] ? -1.0 * f : f;
        if (relax_steps > 0) relaxing_.push_back({kept, fk, cross(x - b_.centroid[kept], fk)});
    }
    c_.remove_if_flagged(drop);
    c_.rebuild_batches(int(laws_.size()));
    for (int i = 0; i < b_.count(); ++i)
        if (b_.removed[i]) b_.velocity[i] = {}, b_.omega[i] = 0.0;
    relax_total_ = relax_left_ = relax_steps;
    update_timestep();
}

void Solver::update_contact_forces() {
    std::fill(b_.force.begin(), b_.force.end(), Vec2{});
    std::fill(b_.moment.begin(), b_.moment.end(), 0.0);
    contact_force_sum_ = contact::step_contacts(c_, laws_, view(), dt_, corner_radius_, b_.force.data(), b_.moment.data(),
                                                b_.count(), settings_.threads, thread_forces_);
}

void Solver::add_external_forces() {
    const Vec2 g = settings_.gravity;
    for (int i = 0; i < b_.count(); ++i) {
        b_.force[i] += b_.applied[i] + b_.real_mass[i] * g;
        b_.moment[i] += b_.applied_moment[i];
    }
    if (relax_left_ > 0) {
        const double f = double(relax_left_) / double(relax_total_ + 1);
        for (const auto& r : relaxing_) {
            b_.force[r.block] += f * r.force;
            b_.moment[r.block] += f * r.moment;
        }
        if (--relax_left_ == 0) relaxing_.clear();
    }
}

void Solver::integrate() {
    const double alpha = settings_.damping, dt = dt_;
    double max_unbalanced = 0.0;
    auto damped = [alpha](double f, double v) { return v != 0.0 ? f - alpha * std::abs(f) * (v > 0 ? 1.0 : -1.0) : f; };
    for (std::size_t k = 0; k < boundary_blocks_.size(); ++k) {
        Vec2 sum{};
        for (int i : boundary_blocks_[k].second) sum += b_.force[i] - b_.applied[i] - b_.real_mass[i] * settings_.gravity;
        boundary_force_[k] = sum;
    }
    double work = 0.0;
    for (int i = 0; i < b_.count(); ++i) {
        if (b_.removed[i]) continue;
        const std::uint8_t fx = b_.fixed[i];
        Vec2& v = b_.velocity[i];
        const Vec2 f = b_.force[i];
        if (!(fx & 1)) max_unbalanced = std::max(max_unbalanced, std::abs(f.x));
        if (!(fx & 2)) max_unbalanced = std::max(max_unbalanced, std::abs(f.y));
        v.x = (fx & 1) ? b_.fixed_velocity[i].x : v.x + damped(f.x, v.x) / b_.mass[i] * dt;
        v.y = (fx & 2) ? b_.fixed_velocity[i].y : v.y + damped(f.y, v.y) / b_.mass[i] * dt;
        b_.omega[i] = (fx & 4) ? b_.fixed_omega[i]
                               : b_.omega[i] + damped(b_.moment[i], b_.omega[i]) / b_.inertia[i] * dt;
        // Work of loads, and of the supports on prescribed components (reaction −F).
        const Vec2 load = b_.applied[i] + b_.real_mass[i] * settings_.gravity;
        work += (dot(load, v) + b_.applied_moment[i] * b_.omega[i]) * dt;
        if (fx & 1) work -= f.x * v.x * dt;
        if (fx & 2) work -= f.y * v.y * dt;
        if (fx & 4) work -= b_.moment[i] * b_.omega[i] * dt;
        b_.centroid[i] += dt * v;
        b_.theta[i] += dt * b_.omega[i];
    }
    work_ += work;
    // Scale: the root-mean-square contact force (SPEC §5 says "mean contact force
    // magnitude"; RMS >= mean, and it needs no square root per contact).
    double mean_force = c_.size() > 0 ? std::sqrt(contact_force_sum_ / c_.size()) : 0.0;
    if (mean_force <= 0.0) {
        for (int i = 0; i < b_.count(); ++i) mean_force += norm(b_.applied[i] + b_.real_mass[i] * settings_.gravity);
        mean_force /= std::max(1, b_.count());
    }
    ratio_ = mean_force > 0.0 ? max_unbalanced / mean_force : 0.0;
}

void Solver::detect_if_due() {
    // Every few steps: which blocks have moved a quarter of the tolerance since
    // their last pass? Only they (and their neighbours) are examined.
    if (steps_ % 4 != 0) return;
    bool any = false;
    for (int i = 0; i < b_.count(); ++i) {
        const bool moved = !b_.removed[i] && norm(b_.centroid[i] - detected_at_[i]) +
                                                     std::abs(b_.theta[i] - detected_theta_[i]) * radius_[i] >=
                                                 0.25 * tolerance_;
        active_[i] = moved;
        any = any || moved;
    }
    if (!any) return;
    contact::DetectionInput in{view(), b_.count(), b_.removed.data(), active_.data(), tolerance_,
                               new_contact_property_, dt_};
    const auto r = contact::update_contacts(c_, in);
    for (int i = 0; i < b_.count(); ++i)
        if (active_[i]) detected_at_[i] = b_.centroid[i], detected_theta_[i] = b_.theta[i];
    detection_totals_.created += r.created;
    detection_totals_.removed += r.removed;
    detection_totals_.transferred += r.transferred;
    detection_totals_.removed_tensile += r.removed_tensile;
    detection_totals_.removed_shear += r.removed_shear;
    if (r.created > 0 || r.removed > 0) {
        c_.rebuild_batches(int(laws_.size()));
        update_timestep();
    }
}

void Solver::step() {
    update_vertices();
    detect_if_due();
    update_contact_forces();
    add_external_forces();
    integrate();
    time_ += dt_;
    ++steps_;
}

double Solver::kinetic_energy() const {
    double e = 0.0;
    for (int i = 0; i < b_.count(); ++i)
        if (!b_.removed[i])
            e += 0.5 * b_.real_mass[i] * norm2(b_.velocity[i]) + 0.5 * b_.real_inertia[i] * b_.omega[i] * b_.omega[i];
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
    std::vector<std::array<double, 3>> m(b_.count(), {0.0, 0.0, 0.0});
    auto add = [&](int blk, Vec2 r, Vec2 f) {
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
        const double cs = std::cos(b_.theta[t.block]), sn = std::sin(b_.theta[t.block]);
        add(t.block, {cs * t.offset.x - sn * t.offset.y, sn * t.offset.x + cs * t.offset.y}, t.force);
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

std::uint64_t Solver::state_hash() const {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](double v) {
        std::uint64_t bits;
        std::memcpy(&bits, &v, 8);
        h = (h ^ bits) * 1099511628211ull;
    };
    for (int i = 0; i < b_.count(); ++i) {
        mix(b_.centroid[i].x), mix(b_.centroid[i].y), mix(b_.theta[i]);
        mix(b_.velocity[i].x), mix(b_.velocity[i].y), mix(b_.omega[i]);
    }
    for (const auto& c : c_.history) mix(c.sn), mix(c.tau), mix(c.upn), mix(c.ups);
    return h;
}

} // namespace bbm
