// bbm core: the world — the whole state of a simulation as plain data.
//
// Everything a step reads or writes, and everything the model file fixed, is in
// the parts below: flat arrays (structure of arrays, indexed by block, vertex,
// node, zone or contact) and a few scalars, no behaviour beyond sizes. What acts
// on them are free functions (build_world, the stage table of core/step.hpp,
// excavate, solve_elastic, the measures of core/measures.hpp, the supports' rows
// of core/supports/registry.hpp) — a new capability adds fields to a part and
// rows to a table, never members to a class.
//
// Hot and cold data live apart. A rigid block's motion, the one record the
// contact loop reads per block and integration writes, is `Bodies::state`
// (contact::BodyState: centroid, velocity, ω, θ in 48 bytes), stored as the loop
// reads it: no step copies it. The blocks' model data (areas, real masses,
// regions, body-frame vertices) sit in other arrays the step seldom touches.
//
// Each part lists its own fields (base/fields.hpp) in a visit_fields beside it;
// the world's list (for_each_field, below) is theirs joined, and
// the checkpoint, the state hash, the model fingerprint, the memory report and
// the Python views all walk it: a field added to a part's list is saved, hashed,
// fingerprinted, counted and viewed with no other line.
#pragma once

#include "contact/contacts.hpp"
#include "contact/detection.hpp"
#include "core/creep.hpp"
#include "core/ejecta.hpp"
#include "core/events.hpp"
#include "core/joint_flow.hpp"
#include "core/model_spec.hpp"
#include "core/supports/registry.hpp"
#include "core/verdict.hpp"
#include "core/viscous.hpp"
#include "fem/cst.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bbm {

/// Per block, what every step reads and writes. Deformable blocks keep their
/// entry (their region, removal, polygon) but move through their FE nodes.
struct Bodies {
    std::vector<contact::BodyState> state; ///< centroid, velocity, ω, θ: the contact loop's record
    std::vector<Vec2> force;               ///< this step's total force (the gather's, integration's)
    std::vector<double> moment;
    std::vector<double> mass, inertia;     ///< as integrated: scaled in quasi-static mode
    std::vector<std::uint8_t> removed;     ///< excavated: out of the model
    int count() const { return static_cast<int>(state.size()); }
};
template <part_of<Bodies> P, class V>
void visit_fields(P& b, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    using contact::BodyState;
    auto centroid = column(b.state, &BodyState::centroid), velocity = column(b.state, &BodyState::velocity);
    auto theta = column(b.state, &BodyState::theta), omega = column(b.state, &BodyState::omega);
    v(FieldInfo{"blocks.centroid", G::blocks, E}, centroid);
    v(FieldInfo{"blocks.velocity", G::blocks, E}, velocity);
    v(FieldInfo{"blocks.theta", G::blocks, E}, theta);
    v(FieldInfo{"blocks.omega", G::blocks, E}, omega);
    v(FieldInfo{"blocks.mass", G::blocks, E}, b.mass);
    v(FieldInfo{"blocks.inertia", G::blocks, E}, b.inertia);
    v(FieldInfo{"blocks.removed", G::blocks, E}, b.removed);
    v(FieldInfo{"blocks.force", G::blocks, R}, b.force);
    v(FieldInfo{"blocks.moment", G::blocks, R}, b.moment);
}

/// Per block, what the model fixes.
struct Blocks {
    std::vector<Vec2> centroid0;              ///< as built
    std::vector<double> real_mass, real_inertia, area;
    std::vector<std::uint8_t> deformable;     ///< moves through FE nodes (core/step.hpp)
    std::vector<int> region, material;
    std::vector<std::uint32_t> first;         ///< its vertices [first[i], first[i + 1]) (CSR)
    int count() const { return static_cast<int>(area.size()); }
};
template <part_of<Blocks> P, class V>
void visit_fields(P& b, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"blocks.centroid0", G::blocks, M}, b.centroid0);
    v(FieldInfo{"blocks.real_mass", G::blocks, M}, b.real_mass);
    v(FieldInfo{"blocks.real_inertia", G::blocks, R}, b.real_inertia);
    v(FieldInfo{"blocks.area", G::blocks, R}, b.area);
    v(FieldInfo{"blocks.deformable", G::blocks, R}, b.deformable);
    v(FieldInfo{"blocks.region", G::blocks, R}, b.region);
    v(FieldInfo{"blocks.material", G::blocks, R}, b.material);
    v(FieldInfo{"blocks.first", G::blocks, R}, b.first);
}

/// Per vertex of every block (CSR by Blocks::first): its body-frame position
/// (cold) and its world position this step (hot: placed from the body's state at
/// the start of every step).
struct Vertices {
    std::vector<Vec2> local;              ///< relative to the centroid, at zero rotation
    std::vector<Vec2> position;           ///< world, this step
    std::vector<double> inv_edge_length;  ///< 1 / length of the edge it starts (deformable: this step's)
    std::vector<int> node;                ///< its FE node, −1 on rigid blocks
    /// 1 at a corner of its block (every vertex of a rigid block), 0 at a node
    /// along a deformable block's face (contact::BlockView::corner).
    std::vector<std::uint8_t> corner;
    int count() const { return static_cast<int>(local.size()); }
};
/// Recomputed at the start of every step and by load_state (a value saved after
/// a step's integration would be stale): rebuilt, but the body frame.
template <part_of<Vertices> P, class V>
void visit_fields(P& x, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"blocks.local", G::vertices, M}, x.local);
    v(FieldInfo{"blocks.vertex", G::vertices, R}, x.position);
    v(FieldInfo{"blocks.inv_edge_length", G::vertices, R}, x.inv_edge_length);
    v(FieldInfo{"blocks.vertex_node", G::vertices, R}, x.node);
    v(FieldInfo{"blocks.corner", G::vertices, R}, x.corner);
}

/// FE nodes of deformable blocks: hot motion, then the model's.
struct Nodes {
    std::vector<Vec2> position, velocity, force;
    std::vector<double> mass; ///< as integrated: scaled in quasi-static mode
    std::vector<Vec2> position0;
    std::vector<double> real_mass;
    std::vector<int> block;
    int count() const { return static_cast<int>(position.size()); }
};
template <part_of<Nodes> P, class V>
void visit_fields(P& n, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"nodes.position", G::nodes, E}, n.position);
    v(FieldInfo{"nodes.velocity", G::nodes, E}, n.velocity);
    v(FieldInfo{"nodes.mass", G::nodes, E}, n.mass);
    v(FieldInfo{"nodes.position0", G::nodes, M}, n.position0);
    v(FieldInfo{"nodes.real_mass", G::nodes, M}, n.real_mass);
    v(FieldInfo{"nodes.block", G::nodes, R}, n.block);
    v(FieldInfo{"nodes.force", G::nodes, R}, n.force);
}

/// The joint property sets: the model's, the sets derived from them (strength
/// classes, deformable splits) and the built-in set of contacts formed unbonded.
struct Properties {
    std::vector<contact::JointLaw> laws;   ///< per set: the law the contact pass calls
    std::vector<JointPropertySpec> specs;  ///< per set: its parameters (the fingerprint hashes them all)
    std::vector<std::string> names;
    std::vector<std::uint8_t> face_shear;  ///< per set: JointPropertySpec::face_shear
    int new_contact = 0;                   ///< the set of contacts formed during the run
};
/// The laws' parameters enter the model fingerprint through their specs
/// (model_fingerprint, core/state.cpp: every declared key's value), not as a field.
template <part_of<Properties> P, class V>
void visit_fields(P& p, V&& v) {
    v(FieldInfo{"properties.face_shear", MemoryGroup::other, field_use::model}, p.face_shear);
    v(FieldInfo{"properties.new_contact", MemoryGroup::other, field_use::model}, p.new_contact);
}

/// A point load on a rigid block from a stress boundary, in the block's frame
/// (block stresses count it as a surface force where it acts).
struct Traction {
    int block;
    Vec2 offset, force;
};

/// Everything the model is loaded by: the prescribed velocities, the applied
/// forces (stress boundaries, a study's loads), and an excavation's support of
/// the rock it removed, relaxing (with a deviatoric part along a face's path) and
/// a constant pressure on the opening's wall.
struct Loads {
    // Prescribed velocities: bits 0 vx, 1 vy, 2 ω of a block; 0 vx, 1 vy of a node.
    std::vector<std::uint8_t> block_fixed, node_fixed;
    std::vector<Vec2> block_velocity, node_velocity;
    std::vector<double> block_omega;
    // Applied forces, per block (with the moment about its centroid) and per node.
    std::vector<Vec2> block_force, node_force;
    std::vector<double> block_moment;
    std::vector<Traction> tractions; ///< the stress boundaries' point loads on rigid blocks
    // An excavation's support forces being relaxed, per block and node (empty when none).
    std::vector<Vec2> relax_block_force, relax_node_force;
    std::vector<double> relax_block_moment;
    long relax_total = 0, relax_left = 0;
    double relax_keep = 0.0; ///< fraction of the excavated rock's support kept for good
    /// With a support path: its rows flattened (t, k_mean, k_deviator, ...), and
    /// the deviatoric part of the support forces above (empty without one).
    std::vector<double> relax_path;
    std::vector<Vec2> deviator_block_force, deviator_node_force;
    std::vector<double> deviator_block_moment;
    /// A constant support pressure on the excavated boundary, as forces per block
    /// and per node (empty when none).
    std::vector<Vec2> pressure_block_force, pressure_node_force;
    std::vector<double> pressure_block_moment;
    /// The opening's pressure over the excavation's: one value once a pressurise
    /// stage has changed it, else empty (1: as excavated; hashed only when set).
    std::vector<double> pressure_scale;
};
/// The excavation's loads (in format A's order, before the clock's fields).
template <part_of<Loads> P, class V>
void visit_excavation_fields(P& l, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving;
    v(FieldInfo{"relax.block_force", G::blocks, E}, l.relax_block_force);
    v(FieldInfo{"relax.block_moment", G::blocks, E}, l.relax_block_moment);
    v(FieldInfo{"relax.node_force", G::nodes, E}, l.relax_node_force);
    v(FieldInfo{"relax.total_steps", G::other, E}, l.relax_total);
    v(FieldInfo{"relax.steps_left", G::other, E}, l.relax_left);
    v(FieldInfo{"relax.keep", G::other, E}, l.relax_keep);
    v(FieldInfo{"relax.path", G::other, E}, l.relax_path);
    v(FieldInfo{"relax.deviator_block_force", G::blocks, E}, l.deviator_block_force);
    v(FieldInfo{"relax.deviator_block_moment", G::blocks, E}, l.deviator_block_moment);
    v(FieldInfo{"relax.deviator_node_force", G::nodes, E}, l.deviator_node_force);
    v(FieldInfo{"pressure.block_force", G::blocks, E}, l.pressure_block_force);
    v(FieldInfo{"pressure.block_moment", G::blocks, E}, l.pressure_block_moment);
    v(FieldInfo{"pressure.node_force", G::nodes, E}, l.pressure_node_force);
    v(FieldInfo{"pressure.scale", G::other, E}, l.pressure_scale);
}
/// The prescribed velocities and applied forces: constant in a model file's
/// stages, moved by lab tests (the servo's platen speed, the confinement ramp).
template <part_of<Loads> P, class V>
void visit_fields(P& l, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"blocks.fixed_velocity", G::blocks, E | M}, l.block_velocity);
    v(FieldInfo{"blocks.fixed_omega", G::blocks, E}, l.block_omega);
    v(FieldInfo{"blocks.applied", G::blocks, E | M}, l.block_force);
    v(FieldInfo{"blocks.applied_moment", G::blocks, E}, l.block_moment);
    v(FieldInfo{"nodes.fixed_velocity", G::nodes, E}, l.node_velocity);
    v(FieldInfo{"nodes.applied", G::nodes, E | M}, l.node_force);
    v(FieldInfo{"blocks.fixed", G::blocks, M}, l.block_fixed);
    v(FieldInfo{"nodes.fixed", G::nodes, M}, l.node_fixed);
    v(FieldInfo{"loads.tractions", G::other, R}, l.tractions);
}

/// The model's named boundaries: which blocks and nodes each holds or loads,
/// the force its blocks took in the last step, and where a `touching` velocity
/// boundary holds a block (the mean midpoint of its edges in the box, body frame:
/// block stresses count the support's reaction there).
struct Boundaries {
    struct HeldPoint {
        int block;
        Vec2 offset;
    };
    std::vector<std::string> names;
    /// Boundary k's blocks block_list[block_first[k] .. block_first[k + 1]) (CSR), and its nodes likewise.
    std::vector<int> block_first{0}, block_list, node_first{0}, node_list;
    std::vector<Vec2> force; ///< per boundary, last step (N/m)
    std::vector<HeldPoint> held;
};
template <part_of<Boundaries> P, class V>
void visit_fields(P& b, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned M = field_use::model, R = field_use::rebuilt;
    v(FieldInfo{"boundaries.force", G::other, field_use::evolving}, b.force);
    v(FieldInfo{"boundaries.block_first", G::other, M}, b.block_first);
    v(FieldInfo{"boundaries.block_list", G::other, M}, b.block_list);
    v(FieldInfo{"boundaries.node_first", G::other, M}, b.node_first);
    v(FieldInfo{"boundaries.node_list", G::other, M}, b.node_list);
    v(FieldInfo{"boundaries.held", G::other, R}, b.held);
}

/// Time and the step's measures.
struct Clock {
    double dt = 1.0, time = 0.0;
    long steps = 0;
    double first_dt = 0.0; ///< the step the model started with (a collapsing step: a sliver, a runaway stiffness)
    double ratio = 0.0;    ///< unbalanced-force ratio of the last step
    double work = 0.0;     ///< of the loads and the prescribed velocities, J/m
    /// Taken by damping so far — local, and Rayleigh's mass and stiffness parts —,
    /// J/m (the energy account's, core/measures.hpp: saved, not hashed).
    double damped = 0.0;
    /// The energy account's origin: stored + spent − supplied when the current
    /// stage started (its error is the change since; saved, not hashed).
    double energy_origin = 0.0;
    /// Kinetic energy at the last step's time, Σ ½ m v⁻·v⁺ of the velocities half
    /// a step before and after it (central differences' own, in step with the
    /// strain energy of the forces it used; saved, not hashed).
    double kinetic = 0.0;
};
template <part_of<Clock> P, class V>
void visit_fields(P& c, V&& v) {
    constexpr unsigned E = field_use::evolving;
    v(FieldInfo{"solver.timestep", MemoryGroup::other, E}, c.dt);
    v(FieldInfo{"solver.time", MemoryGroup::other, E}, c.time);
    v(FieldInfo{"solver.ratio", MemoryGroup::other, E}, c.ratio);
    v(FieldInfo{"solver.work", MemoryGroup::other, E}, c.work);
    v(FieldInfo{"solver.steps", MemoryGroup::other, E}, c.steps);
}
/// The step the model started with (in format A's order, after detection's fields).
template <part_of<Clock> P, class V>
void visit_start_fields(P& c, V&& v) {
    v(FieldInfo{"solver.first_timestep", MemoryGroup::other, field_use::evolving}, c.first_dt);
}

/// Contact detection: its tolerance, where each body was at its last pass, which
/// bodies moved since, and the broad phase's grid (not saved: contact::Detector).
struct Detection {
    double tolerance = 0.0;
    double corner_radius = 0.0; ///< of the rounded corners unbonded contacts see past an edge's end
    std::vector<double> radius; ///< per block, its largest vertex distance from the centroid
    std::vector<Vec2> detected_at;
    std::vector<double> detected_theta;
    std::vector<Vec2> detected_vertex; ///< deformable blocks: vertex positions at their last pass
    std::vector<std::uint8_t> active;  ///< per block: moved enough since its last pass
    std::uint8_t any_active = 0;       ///< this pass: some block has (shared by the team)
    std::vector<contact::Junction> junctions;
    contact::DetectionResult totals;   ///< contacts created, removed and transferred so far
    /// What the removed contacts' joints had dissipated, J/m (the energy account's:
    /// saved, not hashed).
    double dissipated_removed = 0.0;
    /// Created since the contacts were last sorted by block: it decides when they
    /// are renumbered next, so it is state (a checkpoint saves it).
    int unsorted_contacts = 0;
    contact::Detector detector;
};
template <part_of<Detection> P, class V>
void visit_fields(P& d, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    v(FieldInfo{"detection.detected_at", G::blocks, E}, d.detected_at);
    v(FieldInfo{"detection.detected_theta", G::blocks, E}, d.detected_theta);
    v(FieldInfo{"detection.detected_vertex", G::vertices, E}, d.detected_vertex);
    v(FieldInfo{"detection.active", G::blocks, E}, d.active);
    v(FieldInfo{"detection.totals", G::other, E}, d.totals);
    v(FieldInfo{"detection.dissipated_removed", G::other, field_use::saved}, d.dissipated_removed);
    v(FieldInfo{"detection.unsorted_contacts", G::other, E}, d.unsorted_contacts);
    v(FieldInfo{"detection.radius", G::blocks, R}, d.radius);
    v(FieldInfo{"detection.junctions", G::other, R}, d.junctions);
    // The broad phase's grid and the pass's scratch (contact::Detector): not saved,
    // a grid rebuilt offers a superset of the same pairs.
    auto& g = d.detector;
    v(FieldInfo{"detection.pieces", G::blocks, R}, g.pieces);
    v(FieldInfo{"detection.block_piece", G::blocks, R}, g.block_piece);
    v(FieldInfo{"detection.stored", G::blocks, R}, g.stored);
    v(FieldInfo{"detection.cell_first", G::other, R}, g.cell_first);
    v(FieldInfo{"detection.cell_piece", G::other, R}, g.cell_piece);
    v(FieldInfo{"detection.drop", G::contacts, R}, g.drop);
    v(FieldInfo{"detection.active_blocks", G::blocks, R}, g.active_blocks);
    v(FieldInfo{"detection.candidates", G::other, R}, g.candidates);
    v(FieldInfo{"detection.order", G::other, R}, g.order);
    v(FieldInfo{"detection.accepted", G::other, R}, g.accepted);
}

/// The supports' ties to the rock, numbered through the support types in
/// registry order: what each puts on its rock this step (a force and its moment
/// about a rigid host's centroid), and per block and per node its ties (CSR), in
/// tie order, which is the gather's order.
struct Ties {
    std::vector<int> first;            ///< per support type + 1: its first tie
    std::vector<Vec2> reaction;
    std::vector<double> moment;
    std::vector<int> block_first, block_tie;
    std::vector<int> node_first;
    std::vector<std::pair<int, double>> node_tie; ///< (tie, weight)
};
template <part_of<Ties> P, class V>
void visit_fields(P& t, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned R = field_use::rebuilt;
    v(FieldInfo{"supports.tie_first", G::other, R}, t.first);
    v(FieldInfo{"supports.tie_reaction", G::other, R}, t.reaction);
    v(FieldInfo{"supports.tie_moment", G::other, R}, t.moment);
    v(FieldInfo{"supports.block_first", G::other, R}, t.block_first);
    v(FieldInfo{"supports.block_tie", G::other, R}, t.block_tie);
    v(FieldInfo{"supports.node_first", G::other, R}, t.node_first);
    v(FieldInfo{"supports.node_tie", G::other, R}, t.node_tie);
}

/// The team's scratch: how the step's work is shared between threads (costs of
/// contiguous runs, the contact pass's measured times) and per-chunk partial
/// sums. Decides who computes what, never a result.
struct Team {
    static constexpr int sum_chunk = 512; ///< bodies per partial sum of the work and the unbalanced force
    static constexpr int chunks_of(int bodies) { return (bodies + sum_chunk - 1) / sum_chunk; }
    static constexpr int balance_every = 64; ///< steps between rebalances of the contact pass
    /// Per block the cost of the blocks before it (one more entry: the total), for
    /// the gather and for placing the blocks; per chunk, for integration.
    std::vector<double> gather_cost_before, place_cost_before, chunk_cost_before;
    struct ChunkSums {
        double work, unbalanced, damped, kinetic;
    };
    std::vector<ChunkSums> chunk_sums;
    /// Per thread, the seconds its share of the contact and zone passes took since
    /// the last rebalance (one cache line each: written every step by its thread).
    struct alignas(64) PassTime {
        double contacts = 0.0, zones = 0.0;
    };
    std::vector<PassTime> pass_time;
    std::vector<double> balance_scratch; ///< the rebalance's rates and targets
    /// Translational and rotational stiffness per block, and per node (update_timestep).
    std::vector<double> block_stiffness, rotation_stiffness, node_stiffness;
};
template <part_of<Team> P, class V>
void visit_fields(P& t, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned R = field_use::rebuilt;
    v(FieldInfo{"step.chunk_sums", G::other, R}, t.chunk_sums);
    v(FieldInfo{"step.block_stiffness", G::blocks, R}, t.block_stiffness);
    v(FieldInfo{"step.rotation_stiffness", G::blocks, R}, t.rotation_stiffness);
    v(FieldInfo{"step.node_stiffness", G::nodes, R}, t.node_stiffness);
    v(FieldInfo{"step.block_cost_before", G::blocks, R}, t.gather_cost_before);
    v(FieldInfo{"step.place_cost_before", G::blocks, R}, t.place_cost_before);
    v(FieldInfo{"step.chunk_cost_before", G::other, R}, t.chunk_cost_before);
    v(FieldInfo{"step.pass_time", G::other, R}, t.pass_time);
    v(FieldInfo{"step.balance_scratch", G::other, R}, t.balance_scratch);
}

struct World {
    SolverSpec settings;
    std::vector<std::string> region_names;
    Bodies bodies;
    Blocks blocks;
    Vertices vertices;
    Nodes nodes;
    fem::Zones zones;
    contact::Contacts contacts;
    /// Contact normals are a cache of the geometry the last step used: the loop
    /// does not store them (a write of every contact every step); contacts(w)
    /// (core/measures.hpp) brings them up to date for readers outside the step.
    mutable bool normals_stale = true;
    Properties properties;
    Loads loads;
    Boundaries boundaries;
    Clock clock;
    Detection detection;
    std::optional<JointFlow> flow; ///< water in the joints; none in a dry model
    std::optional<Creep> creep;     ///< real time: present where a law corrodes (core/creep.hpp)
    SupportStates supports;         ///< one state per registered support type (core/supports/registry.hpp)
    Ties ties;
    ViscousBoundaries viscous;      ///< the dynamic mode's absorbing edges and incident waves (core/viscous.hpp)
    std::optional<Events> events;   ///< seismic events from breaking bonds, where asked for (core/events.hpp)
    std::optional<PeakVelocities> peak; ///< each body's peak speed: the dynamic mode's (core/ejecta.hpp)
    StageMonitor monitor;           ///< what the current stage did, for its verdict
    Team team;
    /// Taken when the world is built (model_fingerprint, core/state.hpp):
    /// a checkpoint carries it and refuses another model.
    std::uint64_t fingerprint = 0;
};

/// The world's field list: its parts' lists joined. The order of the saved
/// fields is the checkpoint's format and that of the hashed ones the state hash
/// (format A's, kept since: recorded states stay the same bits), which is why
/// two parts come in two pieces each.
template <class W, class V>
void for_each_field(W& w, V&& v) {
    visit_fields(w.bodies, v);
    visit_fields(w.blocks, v);
    visit_fields(w.vertices, v);
    visit_fields(w.nodes, v);
    visit_fields(w.zones, v);
    visit_fields(w.contacts, v);
    // Water in the joints (core/joint_flow.hpp): empty in a dry model.
    v(FieldInfo{"contacts.flow_link", MemoryGroup::contacts, field_use::evolving}, w.contacts.flow_link);
    v(FieldInfo{"contacts.fluid_pressure", MemoryGroup::contacts, field_use::rebuilt}, w.contacts.fluid_pressure);
    if (w.flow) visit_fields(*w.flow, v);
    // Stress corrosion (core/creep.hpp): empty where no law corrodes.
    v(FieldInfo{"contacts.bond_section", MemoryGroup::contacts, field_use::evolving}, w.contacts.bond_section);
    if (w.creep) visit_fields(*w.creep, v);
    visit_index_fields(w.contacts, v);
    visit_excavation_fields(w.loads, v);
    visit_fields(w.clock, v);
    visit_fields(w.boundaries, v);
    visit_fields(w.detection, v);
    visit_start_fields(w.clock, v);
    visit_fields(w.loads, v);
    visit_fields(w.properties, v);
    for_each_support(w.supports, [&](auto type, auto& state) { decltype(type)::type::visit_fields(state, v); });
    visit_fields(w.ties, v);
    visit_fields(w.viscous, v);
    // Seismic events (core/events.hpp): saved, not hashed (a record, not state).
    if (w.events) visit_fields(*w.events, v);
    // Peak velocities (core/ejecta.hpp): saved, not hashed (a record, as the events).
    if (w.peak) visit_fields(*w.peak, v);
    visit_fields(w.team, v);
    // The energy taken by damping (a measure: saved, not in the state hash).
    v(FieldInfo{"solver.damped", MemoryGroup::other, field_use::saved}, w.clock.damped);
    v(FieldInfo{"solver.energy_origin", MemoryGroup::other, field_use::saved}, w.clock.energy_origin);
    v(FieldInfo{"solver.kinetic", MemoryGroup::other, field_use::saved}, w.clock.kinetic);
    // What the stage did so far, for its verdict (not physics: not in the state hash).
    v(FieldInfo{"monitor.samples", MemoryGroup::other, field_use::saved}, w.monitor.samples);
}

/// What the contact kernels read of the world's blocks (contact::BlockView).
contact::BlockView block_view(const World& w);

} // namespace bbm
