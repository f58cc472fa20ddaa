// The solver's state as one list (core/state_fields.hpp), and what walks it:
// checkpoints, the state hash, the model fingerprint, the memory report and the
// generic views.
//
// A checkpoint saves everything a step reads that the model file does not
// determine: block and node kinematics and (scaled) masses, contacts in their
// order with their full histories (detection adds and removes them), the count of
// contacts created since the last renumbering (it decides when the next one
// happens, and the numbering fixes the order of every sum), zone stresses,
// relaxation and detection bookkeeping, loads and support velocities that a study
// may have changed (a lab test's servo, a confinement ramp), time and counters,
// installed supports, and the stage monitor's samples (core/verdict.hpp) that the
// verdict is taken from. Geometry, property sets and the initial boundary
// conditions are rebuilt from the model file, which generates the same assembly
// every time; a checkpoint carries its format version, the fingerprint of the
// model it belongs to, the number of blocks, nodes and zones and the state hash
// at save time, and refuses to load into a solver built from another model or
// into another format. Not saved, on purpose: the broad-phase grid of detection
// (a conservative superset of the pairs within the tolerance, rebuilt on load:
// which pairs it offers never changes which contacts form) and the fields marked
// `rebuilt` (indices and per-step scratch).
#include "core/solver.hpp"
#include "core/state_fields.hpp"

#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <type_traits>
#include <variant>

namespace bbm {

namespace {
// "bbm-chp" and the format version as the last byte: 2 lacked the renumbering
// count (a resumed run renumbered its contacts at another step: issue 27); 3 the
// stage monitor's samples (a resumed run's verdict); 4 the installed bolts and liners; 5 a
// constant support pressure (excavate's `pressure`); 6 the same fields with a
// hash of the bolts' and liners' kinematics; 7 the state hash over every saved
// field (the state-field list); 8 the dowels' fields (core/dowels.hpp); 9 the
// opening's pressure scale (a pressurise stage); A an excavation's support path.
constexpr std::uint64_t magic_base = 0x62626d2d63687000ull; // "bbm-chp\0"
constexpr std::uint64_t format = 'A';
constexpr std::uint64_t magic = magic_base | format;

template <class T>
void put(std::ostream& o, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    o.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
void put(std::ostream& o, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(o, std::uint64_t(v.size()));
    o.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}
template <class T>
void get(std::istream& i, T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    i.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!i) throw std::runtime_error("checkpoint is truncated");
}
template <class T>
void get(std::istream& i, std::vector<T>& v) {
    std::uint64_t n = 0;
    get(i, n);
    if (n > (std::uint64_t(1) << 40) / sizeof(T)) throw std::runtime_error("checkpoint is corrupt (array size)");
    v.resize(n);
    i.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)));
    if (!i) throw std::runtime_error("checkpoint is truncated");
}


/// A field's bytes, for the hash and the fingerprint (a scalar, or a vector's elements).
template <class T>
std::span<const std::byte> bytes_of(const T& x) {
    return std::as_bytes(std::span(&x, 1));
}
template <class T>
std::span<const std::byte> bytes_of(const std::vector<T>& v) {
    return std::as_bytes(std::span(v.data(), v.size()));
}
template <class T>
struct Element {
    using type = T;
};
template <class T>
struct Element<std::vector<T>> {
    using type = T;
};
/// The element type of a field (a scalar field is its own element).
template <class Field>
using element_t = typename Element<std::remove_cvref_t<Field>>::type;

/// FNV-1a, 64 bits.
struct Fnv {
    std::uint64_t h = 1469598103934665603ull;
    void mix(std::span<const std::byte> bytes) {
        for (std::byte c : bytes) h = (h ^ std::uint64_t(c)) * 1099511628211ull;
    }
    template <class T>
    void mix_value(const T& v) {
        mix(std::as_bytes(std::span(&v, 1)));
    }
};
} // namespace

// Records saved and hashed as raw bytes: each fills its size exactly.
template <>
struct ElementTraits<contact::JointHistory> : PackedRecordTraits<contact::JointHistory> {};
static_assert(sizeof(contact::JointHistory) == 7 * 8 + 4 + 4);
template <>
struct ElementTraits<BoltHost> : PackedRecordTraits<BoltHost> {};
static_assert(sizeof(BoltHost) == 2 * sizeof(int) + sizeof(Vec2) + 3 * sizeof(double));
template <>
struct ElementTraits<contact::DetectionResult> : PackedRecordTraits<contact::DetectionResult> {};
static_assert(sizeof(contact::DetectionResult) == 5 * sizeof(int));
template <>
struct ElementTraits<fem::Elasticity> : PackedRecordTraits<fem::Elasticity> {};
static_assert(sizeof(fem::Elasticity) == 2 * sizeof(double));
template <>
struct ElementTraits<MonitorSample> : PackedRecordTraits<MonitorSample> {};

/// The one list of the solver's state (core/state_fields.hpp): every array and
/// scalar it holds, with what it is indexed by and what it is used for. Saved
/// fields are written in this order (the checkpoint format: change the order or
/// the saved set and raise `format` above).
/// The list's first part: blocks, FE nodes and zones.
template <class Self, class Visit>
void Solver::for_each_body_field(Self& s, Visit& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model, R = field_use::rebuilt;
    auto& b = s.b_;
    auto& n = s.n_;
    auto& z = s.z_;
    // Blocks: kinematics and (scaled) masses, then what the model file fixes.
    v({"blocks.centroid", G::blocks, E}, b.centroid), v({"blocks.velocity", G::blocks, E}, b.velocity);
    v({"blocks.theta", G::blocks, E}, b.theta), v({"blocks.omega", G::blocks, E}, b.omega);
    v({"blocks.mass", G::blocks, E}, b.mass), v({"blocks.inertia", G::blocks, E}, b.inertia);
    v({"blocks.removed", G::blocks, E}, b.removed);
    // Recomputed from the vertices at the start of every step (deformable blocks)
    // and by load_state: a value saved after a step's integration is stale.
    v({"blocks.inv_edge_length", G::vertices, R}, b.inv_edge_length);
    v({"blocks.local", G::vertices, M}, b.local), v({"blocks.centroid0", G::blocks, M}, b.centroid0);
    v({"blocks.real_mass", G::blocks, M}, b.real_mass), v({"blocks.fixed", G::blocks, M}, b.fixed);
    v({"blocks.real_inertia", G::blocks, R}, b.real_inertia), v({"blocks.area", G::blocks, R}, b.area);
    v({"blocks.deformable", G::blocks, R}, b.deformable), v({"blocks.region", G::blocks, R}, b.region);
    v({"blocks.material", G::blocks, R}, b.material), v({"blocks.first", G::blocks, R}, b.first);
    v({"blocks.vertex", G::vertices, R}, b.vertex), v({"blocks.vertex_node", G::vertices, R}, b.vertex_node);
    v({"blocks.corner", G::vertices, R}, b.corner);
    v({"blocks.force", G::blocks, R}, b.force), v({"blocks.moment", G::blocks, R}, b.moment);
    // FE nodes and zones.
    v({"nodes.position", G::nodes, E}, n.position), v({"nodes.velocity", G::nodes, E}, n.velocity);
    v({"nodes.mass", G::nodes, E}, n.mass);
    v({"nodes.position0", G::nodes, M}, n.position0), v({"nodes.real_mass", G::nodes, M}, n.real_mass);
    v({"nodes.fixed", G::nodes, M}, n.fixed);
    v({"nodes.block", G::nodes, R}, n.block), v({"nodes.force", G::nodes, R}, n.force);
    v({"zones.stress", G::zones, E}, z.stress), v({"zones.strain", G::zones, E}, z.strain);
    v({"zones.elasticity", G::zones, M}, z.elasticity);
    v({"zones.node", G::zones, R}, z.node), v({"zones.block", G::zones, R}, z.block);
    v({"zones.density", G::zones, R}, z.density), v({"zones.node_first", G::nodes, R}, z.node_first);
    v({"zones.node_entry", G::zones, R}, z.node_entry), v({"zones.nodal_force", G::zones, R}, z.nodal_force);
    v({"zones.partial_sum", G::zones, R}, z.partial_sum);
}

/// Its second: contacts (with their water links) and the water in the joints.
template <class Self, class Visit>
void Solver::for_each_contact_field(Self& s, Visit& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, R = field_use::rebuilt;
    auto& c = s.c_;
    // Contacts in their order, with their histories; then their index and scratch.
    v({"contacts.vertex_block", G::contacts, E}, c.vertex_block), v({"contacts.vertex_id", G::contacts, E}, c.vertex_id);
    v({"contacts.edge_block", G::contacts, E}, c.edge_block), v({"contacts.edge_id", G::contacts, E}, c.edge_id);
    v({"contacts.edge_end", G::contacts, E}, c.edge_end), v({"contacts.length", G::contacts, E}, c.length);
    v({"contacts.property", G::contacts, E}, c.property), v({"contacts.history", G::contacts, E}, c.history);
    v({"contacts.normal", G::contacts, R}, c.normal), v({"contacts.force", G::contacts, R}, c.force);
    // Water in the joints (core/joint_flow.hpp): empty in a dry model.
    v({"contacts.flow_link", G::contacts, E}, c.flow_link);
    v({"contacts.fluid_pressure", G::contacts, R}, c.fluid_pressure);
    if (s.flow_) s.flow_->visit_fields(v, E, R);
    v({"contacts.block_first", G::blocks, R}, c.block_first), v({"contacts.block_entry", G::contacts, R}, c.block_entry);
    v({"contacts.node_first", G::nodes, R}, c.node_first), v({"contacts.node_entry", G::contacts, R}, c.node_entry);
    v({"contacts.fill", G::contacts, R}, c.fill_), v({"contacts.partial_sum", G::contacts, R}, c.partial_sum);
    v({"contacts.work", G::contacts, R}, c.work), v({"contacts.work_cost_before", G::contacts, R}, c.work_cost_before);
    v({"contacts.team_split", G::other, R}, c.team_split);
    v({"contacts.face_group", G::contacts, R}, c.face_group), v({"contacts.face_first", G::contacts, R}, c.face_first);
    v({"contacts.face_entry", G::contacts, R}, c.face_entry), v({"contacts.face_du_s", G::contacts, R}, c.face_du_s);
    v({"contacts.face_scratch", G::contacts, R}, c.face_scratch);
}

/// Its third: the run's loads, time and counters, detection, supports and the step's scratch.
template <class Self, class Visit>
void Solver::for_each_run_field(Self& s, Visit& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving, M = field_use::model, R = field_use::rebuilt;
    auto& b = s.b_;
    auto& n = s.n_;
    // Excavation: support forces being relaxed, and a constant support pressure.
    v({"relax.block_force", G::blocks, E}, s.relax_block_force_);
    v({"relax.block_moment", G::blocks, E}, s.relax_block_moment_);
    v({"relax.node_force", G::nodes, E}, s.relax_node_force_);
    v({"relax.total_steps", G::other, E}, s.relax_total_), v({"relax.steps_left", G::other, E}, s.relax_left_);
    v({"relax.keep", G::other, E}, s.relax_keep_);
    v({"relax.path", G::other, E}, s.relax_path_);
    v({"relax.deviator_block_force", G::blocks, E}, s.relax_deviator_block_force_);
    v({"relax.deviator_block_moment", G::blocks, E}, s.relax_deviator_block_moment_);
    v({"relax.deviator_node_force", G::nodes, E}, s.relax_deviator_node_force_);
    v({"pressure.block_force", G::blocks, E}, s.pressure_block_force_);
    v({"pressure.block_moment", G::blocks, E}, s.pressure_block_moment_);
    v({"pressure.node_force", G::nodes, E}, s.pressure_node_force_);
    v({"pressure.scale", G::other, E}, s.pressure_scale_);
    // Time and counters.
    v({"solver.timestep", G::other, E}, s.dt_), v({"solver.time", G::other, E}, s.time_);
    v({"solver.ratio", G::other, E}, s.ratio_), v({"solver.work", G::other, E}, s.work_);
    v({"solver.steps", G::other, E}, s.steps_);
    v({"boundaries.force", G::other, E}, s.boundary_force_);
    // Detection: where each body was at its last pass, which bodies moved since.
    v({"detection.detected_at", G::blocks, E}, s.detected_at_);
    v({"detection.detected_theta", G::blocks, E}, s.detected_theta_);
    v({"detection.detected_vertex", G::vertices, E}, s.detected_vertex_);
    v({"detection.active", G::blocks, E}, s.active_);
    v({"detection.totals", G::other, E}, s.detection_totals_);
    v({"detection.unsorted_contacts", G::other, E}, s.unsorted_contacts_);
    v({"solver.first_timestep", G::other, E}, s.first_dt_);
    v({"detection.radius", G::blocks, R}, s.radius_), v({"detection.junctions", G::other, R}, s.junctions_);
    // Loads and support velocities: constant in a model file's stages, moved by
    // lab tests (the servo's platen speed, the confinement ramp).
    v({"blocks.fixed_velocity", G::blocks, E | M}, b.fixed_velocity);
    v({"blocks.fixed_omega", G::blocks, E}, b.fixed_omega);
    v({"blocks.applied", G::blocks, E | M}, b.applied), v({"blocks.applied_moment", G::blocks, E}, b.applied_moment);
    v({"nodes.fixed_velocity", G::nodes, E}, n.fixed_velocity), v({"nodes.applied", G::nodes, E | M}, n.applied);
    v({"properties.face_shear", G::other, M}, s.face_shear_);
    // The support types' arrays (core/support.hpp), in registry order.
    for (const auto& support : s.supports_)
        for (const SupportField& f : support->fields()) std::visit([&](auto* x) { v(f.info, *x); }, f.field);
    // Their ties to the rock (index_support_ties) and this step's reactions.
    v({"supports.tie_first", G::other, R}, s.support_tie_first_);
    v({"supports.tie_reaction", G::other, R}, s.tie_reaction_), v({"supports.tie_moment", G::other, R}, s.tie_moment_);
    v({"supports.block_first", G::other, R}, s.tie_block_first_), v({"supports.block_tie", G::other, R}, s.tie_block_tie_);
    v({"supports.node_first", G::other, R}, s.tie_node_first_), v({"supports.node_tie", G::other, R}, s.tie_node_tie_);
    // The step's scratch: packed body state, stiffness, partial sums, thread balance.
    v({"step.body", G::blocks, R}, s.body_), v({"step.chunk_sums", G::other, R}, s.chunk_sums_);
    v({"step.block_stiffness", G::blocks, R}, s.stiffness_scratch_.block);
    v({"step.rotation_stiffness", G::blocks, R}, s.stiffness_scratch_.rotation);
    v({"step.node_stiffness", G::nodes, R}, s.stiffness_scratch_.node);
    v({"step.block_cost_before", G::blocks, R}, s.block_cost_before_);
    v({"step.place_cost_before", G::blocks, R}, s.place_cost_before_);
    v({"step.chunk_cost_before", G::other, R}, s.chunk_cost_before_);
    v({"step.pass_time", G::other, R}, s.pass_time_), v({"step.balance_scratch", G::other, R}, s.balance_scratch_);
    // What the stage did so far, for its verdict (not physics: not in the state hash).
    v({"monitor.samples", G::other, field_use::saved}, s.monitor_.samples_);
}

template <class Self, class Visit>
void Solver::for_each_field(Self& s, Visit&& v) {
    for_each_body_field(s, v);
    for_each_contact_field(s, v);
    for_each_run_field(s, v);
}

std::uint64_t Solver::compute_model_fingerprint() const {
    // What the model file fixes: initial geometry, masses (materials), supports,
    // loads and property sets. Taken when the solver is built, before a study
    // changes loads or support velocities.
    Fnv h;
    for_each_field(*this, [&](const FieldInfo& f, const auto& x) {
        if constexpr (ElementTraits<element_t<decltype(x)>>::padding_free) {
            if (f.uses & field_use::model) h.mix(bytes_of(x));
        } else {
            if (f.uses & field_use::model) throw std::logic_error(std::string("unhashable field ") + f.name);
        }
    });
    std::vector<double> parameters;
    for (const auto& support : supports_) {
        parameters.clear();
        support->model_parameters(parameters);
        h.mix(std::as_bytes(std::span(parameters)));
    }
    for (const auto& law : laws_) {
        const double k[2] = {contact::normal_stiffness(law), contact::shear_stiffness(law)};
        h.mix_value(k);
    }
    return h.h;
}

std::uint64_t Solver::state_hash() const {
    // Every non-empty hashed field, its name, its length and then its bytes (no
    // padding in any: the static_assert below), in list order. An empty field adds
    // nothing, so a capability a model does not use (a support type it has no
    // table of) leaves that model's hash as it was.
    Fnv h;
    for_each_field(*this, [&](const FieldInfo& f, const auto& x) {
        using T = element_t<decltype(x)>;
        if constexpr (ElementTraits<T>::padding_free) {
            if ((f.uses & field_use::hashed) && !bytes_of(x).empty()) {
                h.mix(std::as_bytes(std::span(f.name, std::strlen(f.name))));
                h.mix_value(std::uint64_t(bytes_of(x).size()));
                h.mix(bytes_of(x));
            }
        } else {
            // A field whose elements have padding bytes cannot be hashed (their
            // value is not defined): only rebuilt and unhashed fields may be such.
            if (f.uses & field_use::hashed) throw std::logic_error(std::string("unhashable field ") + f.name);
        }
    });
    return h.h;
}

Solver::Memory Solver::memory() const {
    Memory m;
    auto group = [&](MemoryGroup g) -> std::size_t& {
        switch (g) {
        case MemoryGroup::blocks: return m.blocks;
        case MemoryGroup::vertices: return m.vertices;
        case MemoryGroup::nodes: return m.nodes;
        case MemoryGroup::zones: return m.zones;
        case MemoryGroup::contacts: return m.contacts;
        case MemoryGroup::other: break;
        }
        return m.other;
    };
    for_each_field(*this, [&](const FieldInfo& f, const auto& x) {
        if constexpr (requires { x.capacity(); }) group(f.group) += x.capacity() * sizeof(x[0]);
    });
    for (const auto& batch : c_.batches) m.contacts += batch.capacity() * sizeof(int);
    return m;
}

std::vector<StateField> Solver::state_fields() {
    std::vector<StateField> fields;
    for_each_field(*this, [&](const FieldInfo& f, auto& x) {
        using T = element_t<decltype(x)>;
        StateField out;
        out.name = f.name, out.group = f.group, out.uses = f.uses;
        out.type = ElementTraits<T>::type, out.components = ElementTraits<T>::components;
        out.element_size = sizeof(T);
        if constexpr (requires { x.capacity(); }) {
            out.bytes = std::as_writable_bytes(std::span(x.data(), x.size()));
            out.capacity_bytes = x.capacity() * sizeof(T);
        } else {
            out.bytes = std::as_writable_bytes(std::span(&x, 1));
        }
        fields.push_back(std::move(out));
    });
    return fields;
}

void Solver::save_state(std::ostream& o) const {
    put(o, magic);
    put(o, std::int64_t(b_.count())), put(o, std::int64_t(n_.count())), put(o, std::int64_t(z_.size()));
    put(o, fingerprint_);
    for_each_field(*this, [&](const FieldInfo& f, const auto& x) {
        if constexpr (std::is_trivially_copyable_v<element_t<decltype(x)>>) {
            if (f.uses & field_use::saved) put(o, x);
        } else {
            if (f.uses & field_use::saved) throw std::logic_error(std::string("unsavable field ") + f.name);
        }
    });
    put(o, state_hash());
    if (!o) throw std::runtime_error("cannot write the checkpoint");
}

void Solver::load_state(std::istream& i) {
    std::uint64_t m = 0;
    get(i, m);
    if ((m & ~std::uint64_t(0xff)) != magic_base) throw std::runtime_error("not a bbm checkpoint");
    if (m != magic)
        throw std::runtime_error("the solver state is of checkpoint format " + std::string(1, char(m & 0xff)) +
                                 "; this bbm reads format " + std::string(1, char(format)) +
                                 " only (start the run again)");
    std::int64_t nb = 0, nn = 0, nz = 0;
    get(i, nb), get(i, nn), get(i, nz);
    if (nb != b_.count() || nn != n_.count() || nz != z_.size())
        throw std::runtime_error("checkpoint is of a different model (" + std::to_string(nb) + " blocks, " +
                                 std::to_string(nn) + " nodes, " + std::to_string(nz) + " zones; this model has " +
                                 std::to_string(b_.count()) + ", " + std::to_string(n_.count()) + ", " +
                                 std::to_string(z_.size()) + ")");
    std::uint64_t fingerprint = 0;
    get(i, fingerprint);
    if (fingerprint != fingerprint_)
        throw std::runtime_error("checkpoint is of a different model (same counts, but the geometry, materials, "
                                 "joint properties or boundaries differ: was the model file edited?)");
    for_each_field(*this, [&](const FieldInfo& f, auto& x) {
        if constexpr (std::is_trivially_copyable_v<element_t<decltype(x)>>) {
            if (f.uses & field_use::saved) get(i, x);
        }
    });
    std::uint64_t hash = 0;
    get(i, hash);
    if (hash != state_hash()) throw std::runtime_error("checkpoint is corrupt (state hash differs)");
    const auto loaded = field_hashes();
    c_.normal.resize(c_.size());
    if (flow_) flow_->write_contact_pressures(c_);
    for (auto& support : supports_) support->after_load();
    index_support_ties();
    normals_stale_ = true;
    update_vertices(); // the faces of assign_face_groups are read off the current geometry
    rebuild_contact_index();
    detector_.invalidate();
    // What was loaded must not be recomputed: a field that is (an index, a value
    // derived from the vertices) belongs in the list as `rebuilt`.
    const auto now = field_hashes();
    for (std::size_t k = 0; k < now.size(); ++k)
        if (now[k].second != loaded[k].second)
            throw std::logic_error("the state list marks " + now[k].first +
                                   " as saved and hashed, but loading a checkpoint recomputes it");
}

std::vector<std::pair<std::string, std::uint64_t>> Solver::field_hashes() const {
    std::vector<std::pair<std::string, std::uint64_t>> out;
    for_each_field(*this, [&](const FieldInfo& f, const auto& x) {
        if constexpr (ElementTraits<element_t<decltype(x)>>::padding_free) {
            if (f.uses & field_use::hashed) {
                Fnv h;
                h.mix(bytes_of(x));
                out.emplace_back(f.name, h.h);
            }
        }
    });
    return out;
}

} // namespace bbm
