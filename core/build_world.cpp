// Building the world (core/build_world.hpp) from a block assembly and an
// analysis, in named steps: bodies (blocks, FE nodes, zones), joint property sets
// and contacts, detection, the team's scratch, boundaries, supports.
#include "core/build_world.hpp"

#include "base/error.hpp"
#include "core/excavation.hpp"
#include "core/state.hpp"
#include "core/step.hpp"
#include "core/supports/ties.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

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
/// strength class, a deformable split), each made once, into the world's
/// Properties (laws, specs, names).
class PropertyTable {
public:
    PropertyTable(const std::vector<JointPropertySpec>& sets, Properties& p)
        : laws_(p.laws), names_(p.names), specs_(p.specs) {
        for (const auto& set : sets) {
            laws_.push_back(contact::make_law(set));
            names_.push_back(set.name);
            specs_.push_back(set);
        }
    }
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
        if (!(base.weibull_modulus > 0.0) || base.law == "elastic") return prop;
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
        unbonded.law = "coulomb";
        unbonded.kn = unbonded.ks = 0.0;
        for (const auto& l : laws_) {
            unbonded.kn = std::max(unbonded.kn, contact::normal_stiffness(l));
            unbonded.ks = std::max(unbonded.ks, contact::shear_stiffness(l));
        }
        if (unbonded.kn <= 0.0) unbonded.kn = unbonded.ks = 1e9;
        unbonded.friction = 30.0;
        return derive(std::move(unbonded));
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
    std::vector<JointPropertySpec>& specs_; ///< behind laws_, derived sets and the built-in one included
    std::map<std::pair<int, double>, int> split_sets_;
    std::map<std::pair<int, int>, int> class_sets_;
};

/// Blocks with exact polygon mass properties, and their vertices.
void build_blocks(World& w, const meshing::BlockAssembly& a, const RegionMaterials& materials) {
    const int nb = a.block_count();
    auto& b = w.blocks;
    auto& x = w.vertices;
    b.first.assign(a.first.begin(), a.first.end());
    x.local.resize(a.points.size());
    x.position = a.points;
    w.bodies.state.resize(nb);
    for (int i = 0; i < nb; ++i) {
        const auto poly = a.block(i);
        const Vec2 c = centroid(poly);
        const double area = signed_area(poly), rho = materials.density[a.region[i]];
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) x.local[v] = a.points[v] - c;
        w.bodies.state[i].centroid = c;
        b.centroid0.push_back(c);
        b.area.push_back(area);
        b.real_mass.push_back(rho * area);
        b.real_inertia.push_back(rho * polar_moment_about_centroid(poly));
        b.region.push_back(a.region[i]);
        b.material.push_back(materials.material[a.region[i]]);
    }
    x.inv_edge_length.resize(a.points.size());
    for (int i = 0; i < nb; ++i)
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v)
            x.inv_edge_length[v] = 1.0 / norm(a.points[contact::next_vertex(a.first.data(), i, int(v))] - a.points[v]);
    w.bodies.mass = b.real_mass;
    w.bodies.inertia = b.real_inertia;
    w.bodies.force.assign(nb, {});
    w.bodies.moment.assign(nb, 0.0);
    w.bodies.removed.assign(nb, 0);
    b.deformable = a.deformable.size() == std::size_t(nb) ? a.deformable : std::vector<std::uint8_t>(nb, 0);
    x.node = a.vertex_node.size() == a.points.size() ? a.vertex_node : std::vector<int>(a.points.size(), -1);
    // Corners: where a deformable block's boundary turns outwards by more than
    // 10° (a polygon's corner, not one of the nodes its mesh put along a face);
    // every vertex of a rigid block.
    x.corner.assign(a.points.size(), 1);
    const double corner_turn = std::sin(10.0 * M_PI / 180.0);
    for (int i = 0; i < nb; ++i) {
        if (!b.deformable[i]) continue;
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) {
            const Vec2 prev = a.points[contact::prev_vertex(a.first.data(), i, int(v))];
            const Vec2 in = a.points[v] - prev, out = a.points[contact::next_vertex(a.first.data(), i, int(v))] - a.points[v];
            x.corner[v] = cross(in, out) > corner_turn * norm(in) * norm(out);
        }
    }
}

/// FE nodes and zones of deformable blocks: lumped mass ρA/3 per zone corner.
void build_zones(World& w, const meshing::BlockAssembly& a, const RegionMaterials& materials) {
    auto& n = w.nodes;
    auto& z = w.zones;
    n.position = n.position0 = a.nodes;
    n.block = a.node_block;
    const int nn = n.count();
    n.velocity.assign(nn, {});
    n.force.assign(nn, {});
    n.real_mass.assign(nn, 0.0);
    for (std::size_t k = 0; k < a.zones.size(); ++k) {
        const int blk = a.zone_block[k], reg = a.region[blk];
        const MaterialSpec* m = materials.spec[reg];
        if (!m || m->young <= 0.0)
            throw InputError("", 0, "material.young",
                             "region '" + w.region_names[reg] + "' is deformable but its material has no young modulus");
        const auto& t = a.zones[k];
        const auto g = fem::gradients(a.nodes[t[0]], a.nodes[t[1]], a.nodes[t[2]]);
        BBM_ASSERT(g.area > 0.0, "zones are counter-clockwise");
        const double f = m->deformable_fraction > 0.0 ? m->deformable_fraction : 1.0;
        z.node.push_back(t);
        z.elasticity.push_back(fem::Elasticity::from_young(m->young / f, m->poisson));
        z.stress.push_back({0.0, 0.0, 0.0});
        z.strain.push_back({0.0, 0.0, 0.0});
        z.block.push_back(blk);
        z.density.push_back(m->density);
        for (int i : t) n.real_mass[i] += m->density * g.area / 3.0;
    }
    n.mass = n.real_mass;
    fem::index_zone_nodes(z, nn);
}

/// The contacts at a joint's two ends (new, or an existing one's share grown:
/// collinear edges share one), half its length each.
std::array<int, 2> add_joint_contacts(World& w, const meshing::BlockAssembly& a, const meshing::JointRecord& j, int prop,
                                      std::map<std::pair<int, int>, int>& existing) {
    auto& c = w.contacts;
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
            c.length[it->second] += half;
            return it->second;
        }
        JointHistory h;
        h.bonded = contact::starts_bonded(w.properties.laws[prop]);
        existing[{vertex, edge}] = c.size();
        const int edge_block = a_is_vertex ? j.block_b : j.block_a;
        contact::add_contact(c, a_is_vertex ? j.block_a : j.block_b, vertex, edge_block, edge,
                             contact::next_vertex(a.first.data(), edge_block, edge), half, prop, h);
        return c.size() - 1;
    };
    const int first = add_end(j.p0, true);
    return {first, add_end(j.p1, false)};
}

/// Real time where a law corrodes (core/creep.hpp): the bonds' sections, kept
/// with their contacts from the first; a creep stage needs such a law.
void start_creep(World& w, const AnalysisSpec& an) {
    const bool corroding = std::ranges::any_of(an.joint_properties, [](const JointPropertySpec& p) {
        return p.law == contact::StressCorrosionLaw::name;
    });
    if (corroding) {
        w.contacts.corroding = true;
        w.creep.emplace();
    }
    for (std::size_t k = 0; k < an.stages.size(); ++k)
        if (an.stages[k].kind == StageSpec::Kind::creep && !corroding)
            throw InputError("", 0, "stage[" + std::to_string(k) + "].type",
                             "a creep stage needs bonds that corrode over time: a [[joint_property]] with law = "
                             "\"stress_corrosion\" (docs/input.md, Stress corrosion)");
}

/// Property sets (with their derived strength classes and deformable splits),
/// the contacts of the assembly's joints, and the water in them.
void build_contacts(World& w, const meshing::BlockAssembly& a, const AnalysisSpec& an, const RegionMaterials& materials) {
    // Property sets; the last, built in, serves contacts formed unbonded if the
    // model names none.
    PropertyTable table(an.joint_properties, w.properties);
    // Joint records -> point contacts, one at each end with half the joint length.
    double mean_edge = 0.0;
    std::map<std::pair<int, int>, int> existing; // (vertex id, edge id) -> contact
    if (an.flow.on) {
        w.flow = make_joint_flow(a, an.flow, w.settings.gravity);
        w.contacts.flow_on = true;
    }
    start_creep(w, an);
    for (const auto& j : a.joints) {
        int prop = table.assigned(a, j, an, w.region_names);
        prop = table.strength_class(prop, std::size_t(&j - a.joints.data()));
        prop = table.split(prop, std::min(materials.fraction(a, j.block_a), materials.fraction(a, j.block_b)));
        mean_edge += j.length();
        const auto ends = add_joint_contacts(w, a, j, prop, existing);
        if (w.flow) {
            const int joint = int(&j - a.joints.data());
            link_contact(*w.flow, w.contacts, ends[0], joint, true), link_contact(*w.flow, w.contacts, ends[1], joint, false);
        }
    }
    if (!a.joints.empty()) mean_edge /= double(a.joints.size());
    contact::sort_contacts_by_blocks(w.contacts);
    if (w.flow) write_contact_pressures(*w.flow, w.contacts);
    w.detection.corner_radius = w.settings.corner_radius > 0.0 ? w.settings.corner_radius : 0.05 * mean_edge;
    w.properties.new_contact = table.new_contact_set(w.settings.new_contact_property);
    w.properties.face_shear.assign(w.properties.laws.size(), 0);
    for (std::size_t k = 0; k < w.properties.specs.size(); ++k) w.properties.face_shear[k] = w.properties.specs[k].face_shear;
}

/// The detection's tolerance and reach, where every body starts, and the
/// junctions of the tessellation (detection.hpp).
void prepare_detection(World& w, const meshing::BlockAssembly& a) {
    const int nb = w.bodies.count();
    auto& d = w.detection;
    // Mean size of the rigid blocks (the few large deformable ones would swamp it).
    double mean_area = 0.0;
    int counted = 0;
    for (int i = 0; i < nb; ++i)
        if (!w.blocks.deformable[i]) mean_area += w.blocks.area[i], ++counted;
    if (counted == 0)
        for (int i = 0; i < nb; ++i) mean_area += w.blocks.area[i], ++counted;
    mean_area /= std::max(1, counted);
    d.tolerance = w.settings.detection_tolerance > 0 ? w.settings.detection_tolerance
                                                     : 0.02 * std::sqrt(4.0 * mean_area / 3.141592653589793);
    d.radius.assign(nb, 0.0);
    for (int i = 0; i < nb; ++i)
        for (std::uint32_t v = a.first[i]; v < a.first[i + 1]; ++v) d.radius[i] = std::max(d.radius[i], norm(w.vertices.local[v]));
    d.detected_at = w.blocks.centroid0;
    d.detected_theta.assign(nb, 0.0);
    d.detected_vertex = w.vertices.position;
    // Vertices on the boundary of a block they have no joint with (detection.hpp).
    std::vector<std::uint64_t> joined;
    for (const auto& j : a.joints) joined.push_back(contact::block_pair_key(j.block_a, j.block_b));
    std::sort(joined.begin(), joined.end());
    Box2 all;
    for (Vec2 p : a.points) all.add(p);
    d.junctions = contact::find_junctions(a.points, a.first, joined, 1e-9 * std::max(all.width(), all.height()));
    d.active.assign(nb, 0);
}

/// The step's per-thread scratch, and the contact pass's balance (equal shares to start).
void prepare_team(World& w) {
    w.team.chunk_sums.resize(Team::chunks_of(w.bodies.count()) + Team::chunks_of(w.nodes.count()));
    if (w.settings.threads > 1) {
        const int team = w.settings.threads;
        w.team.pass_time.assign(team, {});
        w.team.balance_scratch.assign(2 * team, 0.0);
        w.contacts.team_split.resize(team + 1);
        for (int t = 0; t <= team; ++t) w.contacts.team_split[t] = double(t) / double(team);
    }
}

bool in_box(const std::optional<Box2>& box, Vec2 p) {
    return !box || (p.x >= box->lo.x && p.x <= box->hi.x && p.y >= box->lo.y && p.y <= box->hi.y);
}

Vec2 traction(const std::array<double, 3>& s, Vec2 n) { return {s[0] * n.x + s[2] * n.y, s[2] * n.x + s[1] * n.y}; }

/// The blocks a selection names: by region, and by centroid in its box (or, with
/// `touching`, with an edge inside it: both ends).
std::vector<int> select_blocks(const World& w, const SelectionSpec& s) {
    const auto& x = w.vertices.position;
    const auto& first = w.blocks.first;
    auto touches = [&](const std::optional<Box2>& box, int i) {
        for (std::uint32_t v = first[i]; v < first[i + 1]; ++v)
            if (in_box(box, x[v]) && in_box(box, x[contact::next_vertex(first.data(), i, int(v))])) return true;
        return false;
    };
    std::vector<int> out;
    for (int i = 0; i < w.bodies.count(); ++i)
        if (selected(s.regions, w.region_names[w.blocks.region[i]]) &&
            (s.touching ? touches(s.box, i) : in_box(s.box, w.bodies.state[i].centroid)))
            out.push_back(i);
    return out;
}

/// A velocity boundary: its rigid blocks by centroid (or touching edges), its
/// nodes by position; the prescribed components fixed.
void apply_velocity_boundary(World& w, const BoundarySpec& bc, std::vector<int>& blocks, std::vector<int>& nodes) {
    auto& l = w.loads;
    const auto& x = w.vertices.position;
    const auto& first = w.blocks.first;
    for (int i : select_blocks(w, bc.select)) {
        if (w.blocks.deformable[i]) continue;
        blocks.push_back(i);
        if (bc.select.touching) {
            Vec2 sum{};
            double len = 0.0;
            for (std::uint32_t v = first[i]; v < first[i + 1]; ++v) {
                const Vec2 p = x[v], q = x[contact::next_vertex(first.data(), i, int(v))];
                if (!in_box(bc.select.box, p) || !in_box(bc.select.box, q)) continue;
                sum += norm(q - p) * 0.5 * (p + q);
                len += norm(q - p);
            }
            if (len > 0) w.boundaries.held.push_back({i, sum / len - w.bodies.state[i].centroid});
        }
        if (bc.vx) l.block_fixed[i] |= 1, l.block_velocity[i].x = *bc.vx;
        if (bc.vy) l.block_fixed[i] |= 2, l.block_velocity[i].y = *bc.vy;
        if (bc.omega) l.block_fixed[i] |= 4, l.block_omega[i] = *bc.omega;
    }
    for (int k = 0; k < w.nodes.count(); ++k) {
        if (!selected(bc.select.regions, w.region_names[w.blocks.region[w.nodes.block[k]]]) ||
            !in_box(bc.select.box, w.nodes.position[k]))
            continue;
        nodes.push_back(k);
        if (bc.vx) l.node_fixed[k] |= 1, l.node_velocity[k].x = *bc.vx;
        if (bc.vy) l.node_fixed[k] |= 2, l.node_velocity[k].y = *bc.vy;
    }
}

/// Per vertex, the stretches [s0, s1] of its edge that joint records cover.
std::vector<std::vector<std::pair<double, double>>> covered_edges(const meshing::BlockAssembly& a) {
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
    return covered;
}

/// The traction of a stress boundary on the exposed stretch [x0, x1] of block i's
/// edge (outward normal n, from its parameter w0 to w1 along edge v0 → v1):
/// linear, as consistent end forces; to the edge's two nodes of a deformable block.
void load_exposed_stretch(World& w, const BoundarySpec& bc, int i, int v0, int v1, Vec2 x0, Vec2 x1, double w0,
                          double w1, Vec2 n, std::vector<int>& nodes) {
    auto& l = w.loads;
    const double len = norm(x1 - x0);
    const Vec2 t0 = traction(stress_at(bc.stress, x0.y), n), t1 = traction(stress_at(bc.stress, x1.y), n);
    const Vec2 f0 = (len / 6.0) * (2.0 * t0 + t1), f1 = (len / 6.0) * (t0 + 2.0 * t1);
    if (w.blocks.deformable[i]) {
        // To the edge's two nodes, linearly by position.
        const int n0 = w.vertices.node[v0], n1 = w.vertices.node[v1];
        l.node_force[n0] += (1.0 - w0) * f0 + (1.0 - w1) * f1;
        l.node_force[n1] += w0 * f0 + w1 * f1;
        for (int k : {n0, n1})
            if (std::find(nodes.begin(), nodes.end(), k) == nodes.end()) nodes.push_back(k);
    } else {
        const Vec2 c = w.bodies.state[i].centroid;
        l.block_force[i] += f0 + f1;
        l.block_moment[i] += cross(x0 - c, f0) + cross(x1 - c, f1);
        l.tractions.push_back({i, x0 - c, f0});
        l.tractions.push_back({i, x1 - c, f1});
    }
}

/// Calls f(i, v0, v1, x0, x1, w0, w1, n) for every exposed (unjointed) stretch
/// [x0, x1] of an edge v0 → v1 of block i (outward normal n, parameters w0 to w1
/// along the edge) that a boundary selects: in its regions, its midpoint in its box.
template <class F>
void for_each_exposed_stretch(const World& w, const BoundarySpec& bc, const meshing::BlockAssembly& a,
                              const std::vector<std::vector<std::pair<double, double>>>& covered, F&& f) {
    for (int i = 0; i < a.block_count(); ++i) {
        if (!selected(bc.select.regions, w.region_names[a.region[i]])) continue;
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
                    // Exposed [s, c0].
                    const Vec2 x0 = p + s * d, x1 = p + std::min(c0, 1.0) * d;
                    if (in_box(bc.select.box, 0.5 * (x0 + x1))) f(i, int(v0), v1, x0, x1, s, std::min(c0, 1.0), n);
                }
                s = std::max(s, c1);
            }
        }
    }
}

/// A stress boundary: its traction σ·n on the exposed (unjointed) block edges selected.
void apply_stress_boundary(World& w, const BoundarySpec& bc, const meshing::BlockAssembly& a,
                           const std::vector<std::vector<std::pair<double, double>>>& covered, std::vector<int>& blocks,
                           std::vector<int>& nodes) {
    for_each_exposed_stretch(w, bc, a, covered, [&](int i, int v0, int v1, Vec2 x0, Vec2 x1, double w0, double w1, Vec2 n) {
        load_exposed_stretch(w, bc, i, v0, v1, x0, x1, w0, w1, n, nodes);
        if (!w.blocks.deformable[i] && (blocks.empty() || blocks.back() != i)) blocks.push_back(i);
    });
}

/// A viscous boundary (core/viscous.hpp): dashpots on the exposed edges of the
/// blocks selected, of their material: a deformable block's stretch to its two
/// nodes by position, a rigid block's at the stretch's two ends as points of the
/// body (its region's material must give E for the wave speeds).
void apply_viscous_boundary(World& w, const BoundarySpec& bc, int index, const meshing::BlockAssembly& a,
                            const std::vector<std::vector<std::pair<double, double>>>& covered,
                            const RegionMaterials& materials, std::vector<int>& blocks, std::vector<int>& nodes) {
    const std::string key = "boundary[" + std::to_string(index) + "]";
    if (w.settings.mode != SolverSpec::Mode::dynamic)
        throw InputError("", 0, key + ".type",
                         "a viscous boundary absorbs waves, which a quasi-static run has none of: set [solver] mode = "
                         "\"dynamic\"");
    auto& vb = w.viscous;
    const int k = int(vb.names.size());
    vb.names.push_back(bc.name), vb.waves.push_back(bc.incident), vb.absorbed.push_back(0.0), vb.supplied.push_back(0.0);
    std::vector<int> zone_of_block(std::size_t(a.block_count()), -1);
    for (int z = w.zones.size() - 1; z >= 0; --z) zone_of_block[std::size_t(w.zones.block[z])] = z;
    for_each_exposed_stretch(w, bc, a, covered, [&](int i, int v0, int v1, Vec2 x0, Vec2 x1, double w0, double w1, Vec2 n) {
        if (!w.blocks.deformable[i]) {
            const MaterialSpec* m = materials.spec[std::size_t(a.region[i])];
            if (m == nullptr || !(m->young > 0.0))
                throw InputError("", 0, key + ".box",
                                 "viscous boundary '" + bc.name + "' selects a face of rigid block " + std::to_string(i) +
                                     " near (" + std::to_string(x0.x) + ", " + std::to_string(x0.y) +
                                     "), whose region's material gives no young: its wave speeds need E and ν");
            const auto el = fem::Elasticity::from_young(m->young, m->poisson);
            const Vec2 c0 = w.blocks.centroid0[i];
            const double half = 0.5 * norm(x1 - x0);
            for (const Vec2 x : {x0, x1})
                add_face_dashpot(vb, k, i, x - c0, half, n, m->density, el.p_modulus(), el.shear);
            if (blocks.empty() || blocks.back() != i) blocks.push_back(i);
            return;
        }
        const int z = zone_of_block[std::size_t(i)];
        const double rho = w.zones.density[z], pm = w.zones.elasticity[z].p_modulus(), g = w.zones.elasticity[z].shear;
        const double length = norm(x1 - x0), along = 0.5 * (w0 + w1);
        const int n0 = w.vertices.node[v0], n1 = w.vertices.node[v1];
        add_dashpot(vb, k, n0, (1.0 - along) * length, n, rho, pm, g);
        add_dashpot(vb, k, n1, along * length, n, rho, pm, g);
        for (int m : {n0, n1})
            if (std::find(nodes.begin(), nodes.end(), m) == nodes.end()) nodes.push_back(m);
    });
    if (nodes.empty() && blocks.empty())
        throw InputError("", 0, key + ".box", "viscous boundary '" + bc.name + "' selects no exposed edge");
}

/// The model's boundaries: prescribed velocities and stress tractions.
void apply_boundaries(World& w, const AnalysisSpec& an, const meshing::BlockAssembly& a, const RegionMaterials& materials) {
    const int nb = w.bodies.count(), nn = w.nodes.count();
    auto& l = w.loads;
    l.block_fixed.assign(nb, 0), l.block_velocity.assign(nb, {}), l.block_omega.assign(nb, 0.0);
    l.block_force.assign(nb, {}), l.block_moment.assign(nb, 0.0);
    l.node_fixed.assign(nn, 0), l.node_velocity.assign(nn, {}), l.node_force.assign(nn, {});
    const auto covered = covered_edges(a);
    for (const auto& bc : an.boundaries) {
        std::vector<int> blocks, nodes;
        if (bc.kind == BoundarySpec::Kind::velocity) apply_velocity_boundary(w, bc, blocks, nodes);
        else if (bc.kind == BoundarySpec::Kind::stress) apply_stress_boundary(w, bc, a, covered, blocks, nodes);
        else apply_viscous_boundary(w, bc, int(&bc - an.boundaries.data()), a, covered, materials, blocks, nodes);
        auto& b = w.boundaries;
        b.names.push_back(bc.name);
        b.block_list.insert(b.block_list.end(), blocks.begin(), blocks.end());
        b.block_first.push_back(int(b.block_list.size()));
        b.node_list.insert(b.node_list.end(), nodes.begin(), nodes.end());
        b.node_first.push_back(int(b.node_list.size()));
    }
    w.boundaries.force.assign(w.boundaries.names.size(), {});
    sort_dashpots(w.viscous);
}

} // namespace

World build_world(const meshing::BlockAssembly& a, const AnalysisSpec& an) {
    World w;
    w.settings = an.solver;
    // The energy account where it is asked for or a dynamic run reports it.
    w.settings.energy_account = w.settings.energy_account || w.settings.mode == SolverSpec::Mode::dynamic ||
                                std::ranges::any_of(an.histories, [](const HistorySpec& h) {
                                    return h.quantity == HistorySpec::Quantity::damping_energy ||
                                           h.quantity == HistorySpec::Quantity::energy_error;
                                });
    w.region_names = a.region_names;
    const RegionMaterials materials = region_materials(w.region_names, an);
    build_blocks(w, a, materials);
    build_zones(w, a, materials);
    build_contacts(w, a, an, materials);
    prepare_detection(w, a);
    start_events(w, an.events);
    prepare_team(w);
    if (w.settings.mode == SolverSpec::Mode::dynamic) w.peak = start_peak_velocities(w, an.report);
    reindex_contacts(w);
    apply_boundaries(w, an, a, materials);
    // Support types (core/supports/registry.hpp), their sets installed by stages.
    for_each_support(w.supports, [&](auto type, auto& state) {
        using T = typename decltype(type)::type;
        state = T::make(support_state<T>(an.supports));
    });
    index_support_ties(w);
    place_bodies(w);
    update_timestep(w);
    w.fingerprint = model_fingerprint(w);
    return w;
}

} // namespace bbm
