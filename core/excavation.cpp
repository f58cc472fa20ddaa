// The stages that change what loads the rock (core/excavation.hpp).
#include "core/excavation.hpp"

#include "base/error.hpp"
#include "core/measures.hpp"
#include "core/step.hpp"

#include <algorithm>

namespace bbm {

std::array<double, 3> stress_at(const StressFieldSpec& f, double y) {
    const double dy = y - f.y_ref;
    return {f.sxx + f.dsxx_dy * dy, f.syy + f.dsyy_dy * dy, f.sxy + f.dsxy_dy * dy};
}

namespace {

Vec2 traction(const std::array<double, 3>& s, Vec2 n) { return {s[0] * n.x + s[2] * n.y, s[2] * n.x + s[1] * n.y}; }

bool selected(const std::vector<std::string>& names, const std::string& name) {
    return names.empty() || std::find(names.begin(), names.end(), name) != names.end();
}

/// The support forces an excavation leaves on the rock it kept, per block (with
/// the moment about its centroid) and per node.
struct KeptForces {
    std::vector<Vec2>& block_force;
    std::vector<double>& block_moment;
    std::vector<Vec2>& node_force;
};

/// A force on the kept side of contact i at x: to its block, or to the node of
/// its vertex, or shared by its edge's two nodes.
void add_to_kept(const World& w, int i, Vec2 x, Vec2 f, KeptForces out) {
    const auto& c = w.contacts;
    const int A = c.vertex_block[i];
    const int kept = w.bodies.removed[A] ? c.edge_block[i] : A;
    if (!w.blocks.deformable[kept]) {
        out.block_force[kept] += f;
        out.block_moment[kept] += cross(x - w.bodies.state[kept].centroid, f);
    } else if (kept == A) {
        out.node_force[w.vertices.node[c.vertex_id[i]]] += f;
    } else {
        const Vec2 p = w.vertices.position[c.edge_id[i]], q = w.vertices.position[c.edge_end[i]];
        const double s = std::clamp(dot(x - p, q - p) / norm2(q - p), 0.0, 1.0);
        out.node_force[w.vertices.node[c.edge_id[i]]] += (1.0 - s) * f;
        out.node_force[w.vertices.node[c.edge_end[i]]] += s * f;
    }
}

/// The arrays an excavation's loads fill, sized (or emptied when unused).
void size_excavation_loads(World& w, bool relaxing, bool along_path, bool pressure, const SupportPath& path) {
    auto& l = w.loads;
    const int nb = w.bodies.count(), nn = w.nodes.count();
    l.relax_block_force.assign(relaxing ? nb : 0, {});
    l.relax_block_moment.assign(relaxing ? nb : 0, 0.0);
    l.relax_node_force.assign(relaxing ? nn : 0, {});
    l.relax_path.clear();
    if (along_path)
        for (const auto& row : path.rows) l.relax_path.insert(l.relax_path.end(), row.begin(), row.end());
    l.deviator_block_force.assign(along_path ? nb : 0, {});
    l.deviator_block_moment.assign(along_path ? nb : 0, 0.0);
    l.deviator_node_force.assign(along_path ? nn : 0, {});
    l.pressure_block_force.assign(pressure ? nb : 0, {});
    l.pressure_block_moment.assign(pressure ? nb : 0, 0.0);
    l.pressure_node_force.assign(pressure ? nn : 0, {});
}

/// The contacts to a removed block, flagged; the forces they carried become
/// relaxing loads on the kept side, summed per block and node in contact order.
std::vector<std::uint8_t> transfer_removed_contacts(World& w, bool relaxing, bool along_path, double pressure,
                                                    const SupportPath& path) {
    const auto& c = w.contacts;
    auto& l = w.loads;
    const auto& removed = w.bodies.removed;
    std::vector<std::uint8_t> drop(c.size(), 0);
    for (int i = 0; i < c.size(); ++i) {
        const int A = c.vertex_block[i], B = c.edge_block[i];
        if (!removed[A] && !removed[B]) continue;
        drop[i] = 1;
        if (removed[A] && removed[B]) continue;
        const Vec2 x = w.vertices.position[c.vertex_id[i]];
        const double sign = removed[A] ? -1.0 : 1.0; // forces on A, seen from the kept side
        if (relaxing)
            add_to_kept(w, i, x, sign * contact::contact_force(c, i),
                        {l.relax_block_force, l.relax_block_moment, l.relax_node_force});
        // The support's deviatoric part: the in-situ deviator's traction on the kept
        // side (its outward normal is -n on A, n on B) over the contact's length.
        if (along_path) {
            const auto s = stress_at(path.in_situ, x.y);
            const double mean = 0.5 * (s[0] + s[1]);
            const Vec2 deviator_traction = traction({s[0] - mean, s[1] - mean, s[2]}, c.normal[i]);
            add_to_kept(w, i, x, -sign * c.length[i] * deviator_traction,
                        {l.deviator_block_force, l.deviator_block_moment, l.deviator_node_force});
        }
        // The pressure pushes the kept side away from the removed one: along the
        // contact's normal (B's outward normal, towards A) on A, against it on B,
        // over the contact's length.
        if (pressure > 0.0)
            add_to_kept(w, i, x, sign * pressure * c.length[i] * c.normal[i],
                        {l.pressure_block_force, l.pressure_block_moment, l.pressure_node_force});
    }
    return drop;
}

} // namespace

void initialize_stress(World& w, const StressFieldSpec& field) {
    place_bodies(w);
    auto& c = w.contacts;
    contact::update_normals(c, block_view(w), w.detection.corner_radius);
    for (int i = 0; i < c.size(); ++i) {
        const Vec2 x = w.vertices.position[c.vertex_id[i]], n = c.normal[i], t = contact::tangent_of(n);
        const auto s = stress_at(field, x.y);
        const Vec2 sn_vec = traction(s, n);
        contact::JointHistory& h = c.history[i];
        const auto& law = w.properties.laws[c.property[i]];
        // The in-situ stress is total; a law carries the effective part (σn − p).
        h.sn = -dot(n, sn_vec) - (c.wet() ? c.fluid_pressure[i] : 0.0);
        h.tau = dot(t, sn_vec);
        h.un = -h.sn / contact::normal_stiffness(law);
        h.us = h.tau / contact::shear_stiffness(law);
        h.upn = 0.0;
    }
    const auto& x = w.nodes.position;
    for (int k = 0; k < w.zones.size(); ++k) {
        const auto& t = w.zones.node[k];
        const Vec2 centre = (x[t[0]] + x[t[1]] + x[t[2]]) / 3.0;
        w.zones.stress[k] = stress_at(field, centre.y);
    }
}

void excavate(World& w, const std::vector<std::string>& regions, long relax_steps, double keep, double pressure,
              const SupportPath& path) {
    for (int i = 0; i < w.bodies.count(); ++i)
        if (selected(regions, w.region_names[w.blocks.region[i]]) && !regions.empty()) w.bodies.removed[i] = 1;
    contacts(w); // the normals, for the pressure's and the deviator's directions
    const bool relaxing = relax_steps > 0 || keep > 0.0;
    const bool along_path = relaxing && !path.rows.empty();
    size_excavation_loads(w, relaxing, along_path, pressure > 0.0, path);
    const std::vector<std::uint8_t> drop = transfer_removed_contacts(w, relaxing, along_path, pressure, path);
    w.loads.pressure_scale.clear(); // the new opening's pressure is the excavation's
    contact::remove_flagged_contacts(w.contacts, drop);
    if (w.flow) flow_excavated(*w.flow, w.bodies.removed, pressure); // the opening's water pushes on its wall and enters it
    reindex_contacts(w);
    w.detection.detector.grid_valid = false;
    for (int i = 0; i < w.bodies.count(); ++i)
        if (w.bodies.removed[i]) w.bodies.state[i].velocity = {}, w.bodies.state[i].omega = 0.0;
    for (int k = 0; k < w.nodes.count(); ++k)
        if (w.bodies.removed[w.nodes.block[k]]) w.nodes.velocity[k] = {};
    w.loads.relax_total = w.loads.relax_left = relax_steps;
    w.loads.relax_keep = keep;
    update_timestep(w);
}

void set_opening_pressure(World& w, double pressure, double excavation_pressure, bool solve_now) {
    if (!(excavation_pressure > 0.0) || w.loads.pressure_block_force.empty())
        throw InputError("", 0, "stage.pressure", "a pressurise stage changes the pressure of an opening excavated with one: "
                                                  "give the excavate stage before it a pressure > 0");
    w.loads.pressure_scale.assign(1, pressure / excavation_pressure);
    if (w.flow) set_flow_opening_pressure(*w.flow, pressure, solve_now);
}

} // namespace bbm
