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

} // namespace

JointFlow::JointFlow(const meshing::BlockAssembly& a, const FlowSpec& spec, Vec2 solver_gravity)
    : spec_(spec), fluid_(spec.fluid), state_(flow::Network{}) {
    if (!spec.gravity_given) fluid_.gravity = solver_gravity;
    const std::vector<std::uint8_t> wet = wet_blocks(a, spec);
    std::vector<std::uint8_t> joint_in(a.joints.size(), 0);
    for (std::size_t j = 0; j < a.joints.size(); ++j) joint_in[j] = wet[a.joints[j].block_a] && wet[a.joints[j].block_b];
    net_ = flow::Network::of_joints(a, 0.0, &joint_in);
    if (net_.pipes() == 0)
        throw InputError("", 0, "flow.regions",
                         "the flow regions have no joint between two of their blocks: no network for water to flow in");
    state_ = flow::State(net_);
    joint_pipe_.assign(a.joints.size(), -1);
    for (int k = 0; k < net_.pipes(); ++k) {
        joint_pipe_[net_.pipe_joint[k]] = k;
        pipe_block_a_.push_back(a.joints[net_.pipe_joint[k]].block_a);
        pipe_block_b_.push_back(a.joints[net_.pipe_joint[k]].block_b);
    }
    pipe_open_.assign(net_.pipes(), 1);
    drained_.assign(net_.domains(), 0);
    aperture_sum_.assign(net_.pipes(), 0.0);
    aperture_count_.assign(net_.pipes(), 0);

    const double g = norm(fluid_.gravity);
    auto boundary_key = [](std::size_t i, const char* key) {
        return "flow_boundary[" + std::to_string(i) + "]." + key;
    };
    for (std::size_t i = 0; i < spec.boundaries.size(); ++i)
        if (spec.boundaries[i].head && !(g > 0.0))
            throw InputError("", 0, boundary_key(i, "head"),
                             "a head needs gravity: give [solver] gravity or [flow] gravity");
    if (spec.water_table && !(g > 0.0))
        throw InputError("", 0, "flow.water_table",
                         "a water table needs gravity: give [solver] gravity or [flow] gravity");
    for (int d = 0; d < net_.domains(); ++d) state_.pressure[d] = initial_pressure(net_.domain_position[d]);

    // The interface with the dry regions: the ends of joints with one wet block.
    if (spec.far_field_held)
        for (std::size_t j = 0; j < a.joints.size(); ++j) {
            const auto& joint = a.joints[j];
            if (wet[joint.block_a] == wet[joint.block_b]) continue;
            for (Vec2 p : {joint.p0, joint.p1})
                if (const int d = net_.domain_at(p); d >= 0) state_.hold(d, state_.pressure[d]);
        }
    for (std::size_t i = 0; i < spec.boundaries.size(); ++i) {
        const auto& b = spec.boundaries[i];
        int held = 0;
        for (int d = 0; d < net_.domains(); ++d) {
            const Vec2 x = net_.domain_position[d];
            if (x.x < b.box.lo.x || x.x > b.box.hi.x || x.y < b.box.lo.y || x.y > b.box.hi.y) continue;
            state_.hold(d, b.pressure ? *b.pressure : fluid_.density * g * (*b.head - x.y));
            ++held;
        }
        if (held == 0)
            throw InputError("", 0, boundary_key(i, "box"),
                             "the box holds no junction of the flow regions' joints: it lies outside the network");
    }
    for (const auto& s : spec.sources) {
        int best = 0;
        for (int d = 1; d < net_.domains(); ++d)
            if (norm(net_.domain_position[d] - s.at) < norm(net_.domain_position[best] - s.at)) best = d;
        state_.source[best] += s.rate;
    }
    if (spec.water_table) {
        bool any_held = false;
        for (auto h : state_.held) any_held = any_held || h;
        if (!any_held && !spec.drain_openings)
            throw InputError("", 0, "flow.water_table",
                             "a water table with no held boundary: hold the far-field interface, give a "
                             "[[flow_boundary]] or drain the openings");
    }
}

double JointFlow::initial_pressure(Vec2 x) const {
    if (!spec_.water_table) return spec_.pressure;
    // Hydrostatic below the table along gravity; dry (atmospheric) above it.
    const double g = norm(fluid_.gravity);
    const double depth = *spec_.water_table - x.y;
    return depth > 0.0 ? fluid_.density * g * depth : 0.0;
}

void JointFlow::link(contact::Contacts& c, int contact, int joint, bool at_p0) const {
    const int k = joint_pipe_[joint];
    if (k < 0) return;
    auto& l = c.flow_link[contact];
    l[0] = at_p0 ? net_.pipe_from[k] : net_.pipe_to[k];
    if (l[1] < 0) l[1] = k;
    else if (l[1] != k) l[2] = k;
}

void JointFlow::update_apertures(const contact::Contacts& c) {
    std::fill(aperture_sum_.begin(), aperture_sum_.end(), 0.0);
    std::fill(aperture_count_.begin(), aperture_count_.end(), 0);
    const double a0 = spec_.aperture, bond = spec_.bond_aperture;
    for (int i = 0; i < c.size(); ++i) {
        const auto& l = c.flow_link[i];
        if (l[1] < 0) continue;
        const auto& h = c.history[i];
        const double a = h.bonded ? bond : std::clamp(a0 + h.un, fluid_.residual_aperture, fluid_.max_aperture);
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) aperture_sum_[l[m]] += a, ++aperture_count_[l[m]];
    }
    // A pipe whose contacts detection has dropped: its blocks have moved apart.
    for (int k = 0; k < net_.pipes(); ++k)
        state_.aperture[k] = !pipe_open_[k]           ? 0.0
                             : aperture_count_[k] > 0 ? aperture_sum_[k] / aperture_count_[k]
                                                      : fluid_.max_aperture;
}

void JointFlow::write_contact_pressures(contact::Contacts& c) const {
    c.fluid_pressure.resize(c.size());
    for (int i = 0; i < c.size(); ++i) {
        const auto& l = c.flow_link[i];
        double wet_length = 0.0;
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) wet_length += 0.5 * net_.pipe_length[l[m]];
        // The pressure over the contact's share of its pipes, as a stress over its length.
        c.fluid_pressure[i] = l[0] >= 0 && c.length[i] > 0.0 ? state_.pressure[l[0]] * wet_length / c.length[i] : 0.0;
    }
}

void JointFlow::stage(contact::Contacts& c, double dt, long step) {
    if (spec_.mode == FlowSpec::Mode::transient) {
        update_apertures(c);
        flow::advance(net_, fluid_, state_, dt);
        write_contact_pressures(c);
        return;
    }
    // Steady: nothing changes between solves. The contacts' pressures move with
    // their contacts when detection removes or renumbers them, and a contact it
    // makes has no pipe (0).
    if (!pending_solve_ && !(step % spec_.steady_every == 0)) return;
    update_apertures(c);
    flow::solve_steady(net_, fluid_, state_);
    pending_solve_ = 0;
    ++solves_;
    write_contact_pressures(c);
}

void JointFlow::excavated(const std::vector<std::uint8_t>& removed, double wall_pressure) {
    // This excavation's number: one past the latest opening's (saturating: a
    // pressurise stage acts on the latest opening only).
    const std::uint8_t latest = drained_.empty() ? 0 : *std::max_element(drained_.begin(), drained_.end());
    const std::uint8_t number = latest == 255 ? latest : std::uint8_t(latest + 1);
    for (int k = 0; k < net_.pipes(); ++k) {
        const bool ra = removed[pipe_block_a_[k]], rb = removed[pipe_block_b_[k]];
        if (!ra && !rb) continue;
        pipe_open_[k] = 0;
        if (ra != rb && spec_.drain_openings)
            for (int d : {net_.pipe_from[k], net_.pipe_to[k]}) {
                if (!drained_[d]) drained_[d] = number;
                state_.hold(d, wall_pressure);
            }
    }
    pending_solve_ = 1;
}

void JointFlow::set_opening_pressure(double wall_pressure, bool solve_now) {
    const std::uint8_t latest = drained_.empty() ? 0 : *std::max_element(drained_.begin(), drained_.end());
    if (latest == 0) return; // no opening has a wall in the flow regions
    for (int d = 0; d < net_.domains(); ++d)
        if (drained_[d] == latest) state_.hold(d, wall_pressure);
    if (solve_now) pending_solve_ = 1;
}

double JointFlow::inflow() const {
    if (std::none_of(drained_.begin(), drained_.end(), [](auto d) { return d != 0; })) return 0.0;
    return flow::outflow_at_held(net_, fluid_, state_, drained_);
}

std::vector<double> JointFlow::contact_apertures(const contact::Contacts& c) const {
    std::vector<double> a(c.size(), 0.0);
    for (int i = 0; i < c.size() && i < int(c.flow_link.size()); ++i) {
        const auto& l = c.flow_link[i];
        double sum = 0.0;
        int n = 0;
        for (int m = 1; m <= 2; ++m)
            if (l[m] >= 0) sum += flow::hydraulic_aperture(fluid_, state_.aperture[l[m]]), ++n;
        a[i] = n ? sum / n : 0.0;
    }
    return a;
}


} // namespace bbm
