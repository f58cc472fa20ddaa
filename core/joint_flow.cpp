#include "core/joint_flow.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <cmath>

namespace bbm {

namespace {

bool named(const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

/// Per block: 1 if its region carries water.
std::vector<std::uint8_t> wet_blocks(const meshing::BlockAssembly& a, const FlowSpec& spec) {
    for (const auto& r : spec.regions)
        if (!named(a.region_names, r))
            throw InputError("", 0, "flow.regions", "no region named '" + r + "'");
    std::vector<std::uint8_t> wet(a.block_count(), 0);
    for (int b = 0; b < a.block_count(); ++b)
        wet[b] = spec.regions.empty() ? a.pattern[b] != meshing::PatternSpec::Kind::single
                                      : named(spec.regions, a.region_names[a.region[b]]);
    return wet;
}

double initial_pressure(const JointFlow& f, Vec2 x) {
    if (!f.spec.water_table) return f.spec.pressure;
    // Hydrostatic below the table along gravity; dry (atmospheric) above it.
    const double g = norm(f.fluid.gravity);
    const double depth = *f.spec.water_table - x.y;
    return depth > 0.0 ? f.fluid.density * g * depth : 0.0;
}

void update_apertures(JointFlow& f, const contact::Contacts& c) {
    std::fill(f.aperture_sum.begin(), f.aperture_sum.end(), 0.0);
    std::fill(f.aperture_count.begin(), f.aperture_count.end(), 0);
    const double a0 = f.spec.aperture, bond = f.spec.bond_aperture;
    for (int i = 0; i < c.size(); ++i) {
        const auto& l = c.flow_link[i];
        if (l[1] < 0) continue;
        const auto& h = c.history[i];
        const double a = h.bonded ? bond : std::clamp(a0 + h.un, f.fluid.residual_aperture, f.fluid.max_aperture);
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) f.aperture_sum[l[m]] += a, ++f.aperture_count[l[m]];
    }
    // A pipe whose contacts detection has dropped: its blocks have moved apart.
    for (int k = 0; k < f.net.pipes(); ++k)
        f.state.aperture[k] = !f.pipe_open[k]           ? 0.0
                             : f.aperture_count[k] > 0 ? f.aperture_sum[k] / f.aperture_count[k]
                                                      : f.fluid.max_aperture;
}

/// The network of the wet joints (both blocks wet) and the ties of its pipes.
void build_network(JointFlow& f, const meshing::BlockAssembly& a, const std::vector<std::uint8_t>& wet) {
    std::vector<std::uint8_t> joint_in(a.joints.size(), 0);
    for (std::size_t j = 0; j < a.joints.size(); ++j) joint_in[j] = wet[a.joints[j].block_a] && wet[a.joints[j].block_b];
    f.net = flow::Network::of_joints(a, 0.0, &joint_in);
    if (f.net.pipes() == 0)
        throw InputError("", 0, "flow.regions",
                         "the flow regions have no joint between two of their blocks: no network for water to flow in");
    f.state = flow::State(f.net);
    f.joint_pipe.assign(a.joints.size(), -1);
    for (int k = 0; k < f.net.pipes(); ++k) {
        f.joint_pipe[f.net.pipe_joint[k]] = k;
        f.pipe_block_a.push_back(a.joints[f.net.pipe_joint[k]].block_a);
        f.pipe_block_b.push_back(a.joints[f.net.pipe_joint[k]].block_b);
    }
    f.pipe_open.assign(f.net.pipes(), 1);
    f.drained.assign(f.net.domains(), 0);
    f.aperture_sum.assign(f.net.pipes(), 0.0);
    f.aperture_count.assign(f.net.pipes(), 0);
}

std::string boundary_key(std::size_t i, const char* key) { return "flow_boundary[" + std::to_string(i) + "]." + key; }

/// The initial pressures, the far-field interface held at them, and the
/// [[flow_boundary]] boxes held at theirs.
void hold_boundaries(JointFlow& f, const meshing::BlockAssembly& a, const std::vector<std::uint8_t>& wet) {
    const FlowSpec& spec = f.spec;
    const double g = norm(f.fluid.gravity);
    for (std::size_t i = 0; i < spec.boundaries.size(); ++i)
        if (spec.boundaries[i].head && !(g > 0.0))
            throw InputError("", 0, boundary_key(i, "head"),
                             "a head needs gravity: give [solver] gravity or [flow] gravity");
    if (spec.water_table && !(g > 0.0))
        throw InputError("", 0, "flow.water_table",
                         "a water table needs gravity: give [solver] gravity or [flow] gravity");
    for (int d = 0; d < f.net.domains(); ++d) f.state.pressure[d] = initial_pressure(f, f.net.domain_position[d]);
    // The interface with the dry regions: the ends of joints with one wet block.
    if (spec.far_field_held)
        for (const auto& joint : a.joints) {
            if (wet[joint.block_a] == wet[joint.block_b]) continue;
            for (Vec2 p : {joint.p0, joint.p1})
                if (const int d = f.net.domain_at(p); d >= 0) f.state.hold(d, f.state.pressure[d]);
        }
    for (std::size_t i = 0; i < spec.boundaries.size(); ++i) {
        const auto& b = spec.boundaries[i];
        int held = 0;
        for (int d = 0; d < f.net.domains(); ++d) {
            const Vec2 x = f.net.domain_position[d];
            if (x.x < b.box.lo.x || x.x > b.box.hi.x || x.y < b.box.lo.y || x.y > b.box.hi.y) continue;
            f.state.hold(d, b.pressure ? *b.pressure : f.fluid.density * g * (*b.head - x.y));
            ++held;
        }
        if (held == 0)
            throw InputError("", 0, boundary_key(i, "box"),
                             "the box holds no junction of the flow regions' joints: it lies outside the network");
    }
    if (spec.water_table && std::none_of(f.state.held.begin(), f.state.held.end(), [](auto h) { return h != 0; }) &&
        !spec.drain_openings)
        throw InputError("", 0, "flow.water_table",
                         "a water table with no held boundary: hold the far-field interface, give a "
                         "[[flow_boundary]] or drain the openings");
}

/// Each [[flow_source]] at the junction nearest it. One farther from every
/// junction than the longest joint is outside the network (a point given in the
/// wrong unit, or far beside the model), not a junction's: refused.
void place_sources(JointFlow& f) {
    const double longest = *std::max_element(f.net.pipe_length.begin(), f.net.pipe_length.end());
    for (std::size_t i = 0; i < f.spec.sources.size(); ++i) {
        const auto& s = f.spec.sources[i];
        int best = 0;
        for (int d = 1; d < f.net.domains(); ++d)
            if (norm(f.net.domain_position[d] - s.at) < norm(f.net.domain_position[best] - s.at)) best = d;
        const double away = norm(f.net.domain_position[best] - s.at);
        if (!(away <= longest))
            throw InputError("", 0, "flow_source[" + std::to_string(i) + "].at",
                             "the point (" + std::to_string(s.at.x) + ", " + std::to_string(s.at.y) + ") is " +
                                 std::to_string(away) + " m from the nearest junction of the flow regions' joints, "
                                 "farther than their longest joint (" + std::to_string(longest) +
                                 " m): it lies outside the network");
        f.state.source[best] += s.rate;
    }
}

} // namespace

JointFlow make_joint_flow(const meshing::BlockAssembly& a, const FlowSpec& spec, Vec2 solver_gravity) {
    JointFlow f;
    f.spec = spec;
    f.fluid = spec.fluid;
    if (!spec.gravity_given) f.fluid.gravity = solver_gravity;
    const std::vector<std::uint8_t> wet = wet_blocks(a, spec);
    build_network(f, a, wet);
    hold_boundaries(f, a, wet);
    place_sources(f);
    return f;
}

void link_contact(const JointFlow& f, contact::Contacts& c, int contact, int joint, bool at_p0) {
    const int k = f.joint_pipe[joint];
    if (k < 0) return;
    auto& l = c.flow_link[contact];
    l[0] = at_p0 ? f.net.pipe_from[k] : f.net.pipe_to[k];
    if (l[1] < 0) l[1] = k;
    else if (l[1] != k) l[2] = k;
}

void write_contact_pressures(const JointFlow& f, contact::Contacts& c) {
    c.fluid_pressure.resize(c.size());
    for (int i = 0; i < c.size(); ++i) {
        const auto& l = c.flow_link[i];
        double wet_length = 0.0;
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) wet_length += 0.5 * f.net.pipe_length[l[m]];
        // The pressure over the contact's share of its pipes, as a stress over its length.
        c.fluid_pressure[i] = l[0] >= 0 && c.length[i] > 0.0 ? f.state.pressure[l[0]] * wet_length / c.length[i] : 0.0;
    }
}

void advance_flow(JointFlow& f, contact::Contacts& c, double dt, long step) {
    if (f.spec.mode == FlowSpec::Mode::transient) {
        update_apertures(f, c);
        flow::advance(f.net, f.fluid, f.state, dt);
        write_contact_pressures(f, c);
        return;
    }
    // Steady: nothing changes between solves. The contacts' pressures move with
    // their contacts when detection removes or renumbers them, and a contact it
    // makes has no pipe (0).
    if (!f.pending_solve && !(step % f.spec.steady_every == 0)) return;
    update_apertures(f, c);
    flow::solve_steady(f.net, f.fluid, f.state);
    f.pending_solve = 0;
    ++f.solves;
    write_contact_pressures(f, c);
}

void flow_excavated(JointFlow& f, const std::vector<std::uint8_t>& removed, double wall_pressure) {
    // This excavation's number: one past the latest opening's (saturating: a
    // pressurise stage acts on the latest opening only).
    const std::uint8_t latest = f.drained.empty() ? 0 : *std::max_element(f.drained.begin(), f.drained.end());
    const std::uint8_t number = latest == 255 ? latest : std::uint8_t(latest + 1);
    for (int k = 0; k < f.net.pipes(); ++k) {
        const bool ra = removed[f.pipe_block_a[k]], rb = removed[f.pipe_block_b[k]];
        if (!ra && !rb) continue;
        f.pipe_open[k] = 0;
        if (ra != rb && f.spec.drain_openings)
            for (int d : {f.net.pipe_from[k], f.net.pipe_to[k]}) {
                if (!f.drained[d]) f.drained[d] = number;
                f.state.hold(d, wall_pressure);
            }
    }
    f.pending_solve = 1;
}

void set_flow_opening_pressure(JointFlow& f, double wall_pressure, bool solve_now) {
    const std::uint8_t latest = f.drained.empty() ? 0 : *std::max_element(f.drained.begin(), f.drained.end());
    if (latest == 0) return; // no opening has a wall in the flow regions
    for (int d = 0; d < f.net.domains(); ++d)
        if (f.drained[d] == latest) f.state.hold(d, wall_pressure);
    if (solve_now) f.pending_solve = 1;
}

double inflow(const JointFlow& f) {
    if (std::none_of(f.drained.begin(), f.drained.end(), [](auto d) { return d != 0; })) return 0.0;
    return flow::outflow_at_held(f.net, f.fluid, f.state, f.drained);
}

std::vector<double> contact_apertures(const JointFlow& f, const contact::Contacts& c) {
    std::vector<double> a(c.size(), 0.0);
    for (int i = 0; i < c.size() && i < int(c.flow_link.size()); ++i) {
        const auto& l = c.flow_link[i];
        double sum = 0.0;
        int n = 0;
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) sum += flow::hydraulic_aperture(f.fluid, f.state.aperture[l[m]]), ++n;
        a[i] = n ? sum / n : 0.0;
    }
    return a;
}


} // namespace bbm
