// Building the model (core/solver.hpp): the solver's state from a block assembly
// and an analysis, in named steps — bodies (blocks, FE nodes, zones), joint
// property sets and contacts, detection, the team's scratch — that the
// constructor calls in order.
#include "core/solver.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace bbm {

using contact::JointHistory;

namespace {

bool selected(const std::vector<std::string>& names, const std::string& name) {
    return names.empty() || std::find(names.begin(), names.end(), name) != names.end();
}

/// Per region: its material (index, spec) and density; the first material when
/// no region names one.
struct RegionMaterials {
    std::vector<double> density;
    std::vector<int> material;
    std::vector<const MaterialSpec*> spec;
    /// The share of the deformation a block takes (SPEC §6): its material's.
    double fraction(const meshing::BlockAssembly& a, int block) const {
        const MaterialSpec* m = spec[a.region[block]];
        return m ? m->deformable_fraction : 0.0;
    }
};

RegionMaterials region_materials(const std::vector<std::string>& regions, const AnalysisSpec& an) {
    RegionMaterials out{std::vector<double>(regions.size(), 2700.0), std::vector<int>(regions.size(), -1),
                        std::vector<const MaterialSpec*>(regions.size(), nullptr)};
    for (const auto& [region, mat] : an.region_material) {
        const auto r = std::find(regions.begin(), regions.end(), region);
        const std::string& name = mat; // a structured binding is not captured by clang 14
        const auto m = std::find_if(an.materials.begin(), an.materials.end(),
                                    [&](const MaterialSpec& s) { return s.name == name; });
        if (r == regions.end() || m == an.materials.end())
            throw InputError("", 0, "region.material", "region '" + region + "' or material '" + mat + "' unknown");
        out.density[r - regions.begin()] = m->density;
        out.material[r - regions.begin()] = int(m - an.materials.begin());
        out.spec[r - regions.begin()] = &*m;
    }
    if (an.region_material.empty() && !an.materials.empty()) {
        std::fill(out.density.begin(), out.density.end(), an.materials[0].density);
        std::fill(out.material.begin(), out.material.end(), 0);
        std::fill(out.spec.begin(), out.spec.end(), &an.materials[0]);
    }
    return out;
}

/// The joint property sets: the model's, then the sets derived from them (a
/// strength class, a deformable split), each made once; the laws and names are
/// the solver's.
class PropertyTable {
public:
    PropertyTable(const std::vector<JointPropertySpec>& sets, std::vector<contact::JointLaw>& laws,
                  std::vector<std::string>& names)
        : laws_(laws), names_(names), specs_(sets) {
        for (const auto& p : sets) {
            laws_.push_back(contact::make_law(p));
            names_.push_back(p.name);
        }
    }
    const std::vector<JointPropertySpec>& specs() const { return specs_; }
    /// The set of that name; InputError naming `key` if there is none.
    int find(const std::string& name, const char* key) const {
        const auto it = std::find(names_.begin(), names_.end(), name);
        if (it == names_.end()) throw InputError("", 0, key, "unknown joint property '" + name + "'");
        return int(it - names_.begin());
    }
    /// Joints between blocks that take a fraction f of the deformation are stiffer
    /// by 1/(1 − f): one derived set per (set, f).
    int split(int prop, double f) {
        if (f <= 0.0) return prop;
        if (auto it = split_sets_.find({prop, f}); it != split_sets_.end()) return it->second;
        JointPropertySpec p = specs_[prop];
        p.kn /= 1.0 - f;
        p.ks /= 1.0 - f;
        p.name += " (deformable fraction " + std::to_string(f) + ")";
        return split_sets_[{prop, f}] = derive(std::move(p));
    }
    /// Heterogeneous strengths: the joint's class (a derived set with the class's
    /// strength factor) from the set's seed and the joint's index — the same on
    /// every run, thread count and restart.
    int strength_class(int prop, std::size_t joint) {
        const JointPropertySpec& base = specs_[prop];
        if (!(base.weibull_modulus > 0.0) || base.law == JointPropertySpec::Law::elastic) return prop;
        const int classes = std::max(1, base.strength_classes);
        std::uint64_t z = base.strength_seed * 0x9E3779B97F4A7C15ull + joint + 0x632BE59BD9B4E019ull;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull; // splitmix64's finaliser
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        const int k = int(z % std::uint64_t(classes));
        if (auto it = class_sets_.find({prop, k}); it != class_sets_.end()) return it->second;
        const double f = strength_class_factors(base.weibull_modulus, classes)[k];
        JointPropertySpec p = base;
        p.tensile *= f;
        p.cohesion *= f;
        // As without fracture energies (σt·u0 ∝ f²): the set's energy is its mean
        // class's, and a class's scales with its strength squared.
        for (double* energy : {&p.tension_fracture_energy, &p.shear_fracture_energy})
            if (*energy > 0.0) *energy *= f * f;
        p.weibull_modulus = 0.0;
        p.name += " (strength class " + std::to_string(k + 1) + " of " + std::to_string(classes) + ")";
        return class_sets_[{prop, k}] = derive(std::move(p));
    }
    /// The set a joint gets: the last assignment rule that matches it, unless its
    /// fracture set names its own.
    int assigned(const meshing::BlockAssembly& a, const meshing::JointRecord& j, const AnalysisSpec& an,
                 const std::vector<std::string>& regions) const {
        int prop = -1;
        for (const auto& rule : an.joint_assignments) {
            const bool tag_ok = rule.tags.empty() || std::find(rule.tags.begin(), rule.tags.end(), j.tag) != rule.tags.end();
            const bool region_ok = rule.regions.empty() || (selected(rule.regions, regions[a.region[j.block_a]]) &&
                                                            selected(rule.regions, regions[a.region[j.block_b]]));
            if (tag_ok && region_ok) prop = find(rule.property, "joint_assignment.property");
        }
        if (j.fracture_set >= 0 && !a.fracture_sets[j.fracture_set].property.empty())
            prop = find(a.fracture_sets[j.fracture_set].property, "region.dfn.property");
        if (prop < 0)
            throw InputError("", 0, "joint_assignment",
                             std::string("no joint property is assigned to ") + meshing::to_string(j.tag) +
                                 " joints between regions '" + regions[a.region[j.block_a]] + "' and '" +
                                 regions[a.region[j.block_b]] + "'");
        return prop;
    }
    /// Contacts formed during the run: the named set, or a built-in frictional one
    /// (φ 30°, no bond) as stiff as the stiffest set of the model.
    int new_contact_set(const std::string& name) {
        if (!name.empty()) return find(name, "solver.new_contact_property");
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
        laws_.push_back(contact::make_law(unbonded));
        names_.push_back(unbonded.name);
        return int(laws_.size()) - 1;
    }

private:
    int derive(JointPropertySpec p) {
        laws_.push_back(contact::make_law(p));
        names_.push_back(p.name);
        specs_.push_back(std::move(p));
        return int(laws_.size()) - 1;
    }
    std::vector<contact::JointLaw>& laws_;
    std::vector<std::string>& names_;
    std::vector<JointPropertySpec> specs_; ///< behind laws_, derived sets included (not the built-in one)
    std::map<std::pair<int, double>, int> split_sets_;
    std::map<std::pair<int, int>, int> class_sets_;
};

} // namespace

Solver::Solver(const meshing::BlockAssembly& a, const AnalysisSpec& an) : settings_(an.solver) {
    region_names_ = a.region_names;
    build_bodies(a, an);
    build_contacts(a, an);
    prepare_detection(a);
    prepare_team();
    rebuild_contact_index();
    apply_boundaries(an, a);
    // Support types (core/support.hpp), their sets installed by stages.
    supports_ = make_supports(an);
    index_support_ties();
    update_vertices();
    update_timestep();
    fingerprint_ = compute_model_fingerprint();
}

void Solver::build_bodies(const meshing::BlockAssembly& a, const AnalysisSpec& an) {
    const RegionMaterials materials = region_materials(region_names_, an);
    const int nb = a.block_count();
    // Blocks: exact polygon mass properties.
    b_.first.assign(a.first.begin(), a.first.end());
    b_.local.resize(a.points.size());
    b_.vertex = a.points;
    for (int i = 0; i < nb; ++i) {
        const auto poly = a.block(i);
        const Vec2 c = centroid(poly);
        const double area = signed_area(poly), rho = materials.density[a.region[i]];
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) b_.local[v] = a.points[v] - c;
        b_.centroid.push_back(c);
        b_.area.push_back(area);
        b_.real_mass.push_back(rho * area);
        b_.real_inertia.push_back(rho * polar_moment_about_centroid(poly));
        b_.region.push_back(a.region[i]);
        b_.material.push_back(materials.material[a.region[i]]);
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
    b_.deformable = a.deformable.size() == std::size_t(nb) ? a.deformable : std::vector<std::uint8_t>(nb, 0);
    b_.vertex_node = a.vertex_node.size() == a.points.size() ? a.vertex_node : std::vector<int>(a.points.size(), -1);
    // Corners: where a deformable block's boundary turns outwards by more than
    // 10° (a polygon's corner, not one of the nodes its mesh put along a face);
    // every vertex of a rigid block.
    b_.corner.assign(a.points.size(), 1);
    const double corner_turn = std::sin(10.0 * M_PI / 180.0);
    for (int i = 0; i < nb; ++i) {
        if (!b_.deformable[i]) continue;
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) {
            const Vec2 prev = a.points[contact::prev_vertex(a.first.data(), i, int(v))];
            const Vec2 in = a.points[v] - prev, out = a.points[contact::next_vertex(a.first.data(), i, int(v))] - a.points[v];
            b_.corner[v] = cross(in, out) > corner_turn * norm(in) * norm(out);
        }
    }

    // FE nodes and zones of deformable blocks: lumped mass ρA/3 per zone corner.
    n_.position = n_.position0 = a.nodes;
    n_.block = a.node_block;
    const int nn = n_.count();
    n_.velocity.assign(nn, {});
    n_.force.assign(nn, {});
    n_.applied.assign(nn, {});
    n_.real_mass.assign(nn, 0.0);
    n_.fixed.assign(nn, 0);
    n_.fixed_velocity.assign(nn, {});
    for (std::size_t k = 0; k < a.zones.size(); ++k) {
        const int blk = a.zone_block[k], reg = a.region[blk];
        const MaterialSpec* m = materials.spec[reg];
        if (!m || m->young <= 0.0)
            throw InputError("", 0, "material.young",
                             "region '" + region_names_[reg] + "' is deformable but its material has no young modulus");
        const auto& t = a.zones[k];
        const auto g = fem::gradients(a.nodes[t[0]], a.nodes[t[1]], a.nodes[t[2]]);
        BBM_ASSERT(g.area > 0.0, "zones are counter-clockwise");
        const double f = m->deformable_fraction > 0.0 ? m->deformable_fraction : 1.0;
        z_.node.push_back(t);
        z_.elasticity.push_back(fem::Elasticity::from_young(m->young / f, m->poisson));
        z_.stress.push_back({0.0, 0.0, 0.0});
        z_.strain.push_back({0.0, 0.0, 0.0});
        z_.block.push_back(blk);
        z_.density.push_back(m->density);
        for (int i : t) n_.real_mass[i] += m->density * g.area / 3.0;
    }
    n_.mass = n_.real_mass;
    z_.index_nodes(nn);
}

void Solver::build_contacts(const meshing::BlockAssembly& a, const AnalysisSpec& an) {
    // Property sets; the last, built in, serves contacts formed unbonded if the
    // model names none.
    PropertyTable table(an.joint_properties, laws_, property_names_);
    const RegionMaterials materials = region_materials(region_names_, an);
    // Joint records -> point contacts, one at each end with half the joint length.
    double mean_edge = 0.0;
    std::map<std::pair<int, int>, int> existing; // (vertex id, edge id) -> contact
    if (an.flow.on) {
        flow_ = std::make_unique<JointFlow>(a, an.flow, settings_.gravity);
        c_.flow_on = true;
    }
    for (const auto& j : a.joints) {
        int prop = table.assigned(a, j, an, region_names_);
        prop = table.strength_class(prop, std::size_t(&j - a.joints.data()));
        prop = table.split(prop, std::min(materials.fraction(a, j.block_a), materials.fraction(a, j.block_b)));
        mean_edge += j.length();
        const auto ends = add_joint_contacts(a, j, prop, existing);
        if (flow_) {
            const int joint = int(&j - a.joints.data());
            flow_->link(c_, ends[0], joint, true), flow_->link(c_, ends[1], joint, false);
        }
    }
    if (!a.joints.empty()) mean_edge /= double(a.joints.size());
    c_.sort_by_blocks();
    if (flow_) flow_->write_contact_pressures(c_);
    corner_radius_ = settings_.corner_radius > 0.0 ? settings_.corner_radius : 0.05 * mean_edge;
    new_contact_property_ = table.new_contact_set(settings_.new_contact_property);
    face_shear_.assign(laws_.size(), 0);
    for (std::size_t k = 0; k < table.specs().size(); ++k) face_shear_[k] = table.specs()[k].face_shear;
}

std::array<int, 2> Solver::add_joint_contacts(const meshing::BlockAssembly& a, const meshing::JointRecord& j, int prop,
                                              std::map<std::pair<int, int>, int>& existing) {
    const double half = 0.5 * j.length();
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
            return it->second;
        }
        JointHistory h;
        h.bonded = contact::starts_bonded(laws_[prop]);
        existing[{vertex, edge}] = c_.size();
        const int edge_block = a_is_vertex ? j.block_b : j.block_a;
        c_.add(a_is_vertex ? j.block_a : j.block_b, vertex, edge_block, edge,
               contact::next_vertex(a.first.data(), edge_block, edge), half, prop, h);
        return c_.size() - 1;
    };
    const int first = add_end(j.p0, true);
    return {first, add_end(j.p1, false)};
}

void Solver::prepare_detection(const meshing::BlockAssembly& a) {
    const int nb = b_.count();
    // Mean size of the rigid blocks (the few large deformable ones would swamp it).
    double mean_area = 0.0;
    int counted = 0;
    for (int i = 0; i < nb; ++i)
        if (!b_.deformable[i]) mean_area += b_.area[i], ++counted;
    if (counted == 0)
        for (int i = 0; i < nb; ++i) mean_area += b_.area[i], ++counted;
    mean_area /= std::max(1, counted);
    tolerance_ = settings_.detection_tolerance > 0 ? settings_.detection_tolerance
                                                   : 0.02 * std::sqrt(4.0 * mean_area / 3.141592653589793);
    radius_.assign(nb, 0.0);
    for (int i = 0; i < nb; ++i)
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) radius_[i] = std::max(radius_[i], norm(b_.local[v]));
    detected_at_ = b_.centroid;
    detected_theta_.assign(nb, 0.0);
    detected_vertex_ = b_.vertex;
    // Vertices on the boundary of a block they have no joint with (detection.hpp).
    std::vector<std::uint64_t> joined;
    for (const auto& j : a.joints) joined.push_back(contact::block_pair_key(j.block_a, j.block_b));
    std::sort(joined.begin(), joined.end());
    Box2 all;
    for (Vec2 p : a.points) all.add(p);
    junctions_ = contact::find_junctions(a.points, a.first, joined, 1e-9 * std::max(all.width(), all.height()));
    active_.assign(nb, 0);
}

void Solver::prepare_team() {
    body_.resize(b_.count());
    chunk_sums_.resize(chunks_of(b_.count()) + chunks_of(n_.count()));
    if (settings_.threads > 1) {
        // The contact pass's balance (balance_contact_pass): equal shares to start.
        const int team = settings_.threads;
        pass_time_.assign(team, {});
        balance_scratch_.assign(2 * team, 0.0);
        c_.team_split.resize(team + 1);
        for (int t = 0; t <= team; ++t) c_.team_split[t] = double(t) / double(team);
    }
}

} // namespace bbm
