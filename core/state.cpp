// Checkpoints: the solver's evolving state as a flat binary dump.
//
// What is saved is everything a step reads that the model file does not
// determine: block and node kinematics and (scaled) masses, contacts in their
// order with their full histories (detection adds and removes them), the count of
// contacts created since the last renumbering (it decides when the next one
// happens, and the numbering fixes the order of every sum), zone stresses,
// relaxation and detection bookkeeping, loads and support velocities that a study
// may have changed (a lab test's servo, a confinement ramp), time and counters,
// and the stage monitor's samples (core/verdict.hpp) that the verdict is taken from.
// Geometry, property sets and the initial boundary conditions are rebuilt from
// the model file, which generates the same assembly every time; a checkpoint
// carries its format version, the fingerprint of the model it belongs to, the
// number of blocks, nodes and zones and the state hash at save time, and refuses
// to load into a solver built from another model or into another format.
// Not saved, on purpose: the broad-phase grid of detection (a conservative
// superset of the pairs within the tolerance, rebuilt on load: which pairs it
// offers never changes which contacts form) and per-step scratch.
#include "core/solver.hpp"

#include <istream>
#include <ostream>
#include <stdexcept>
#include <type_traits>

namespace bbm {

namespace {
// "bbm-chp" and the format version as the last byte: 2 lacked the renumbering
// count (a resumed run renumbered its contacts at another step: issue 27); 3 the
// stage monitor's samples (a resumed run's verdict); 4 the installed bolts and liners; 5 a
// constant support pressure (excavate's `pressure`).
constexpr std::uint64_t magic_base = 0x62626d2d63687000ull; // "bbm-chp\0"
constexpr std::uint64_t format = '6';
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
} // namespace

std::uint64_t Solver::compute_model_fingerprint() const {
    // What the model file fixes: initial geometry, masses (materials), supports,
    // loads and property sets. Taken when the solver is built, before a study
    // changes loads or support velocities.
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](const void* p, std::size_t n) {
        const auto* c = static_cast<const unsigned char*>(p);
        for (std::size_t k = 0; k < n; ++k) h = (h ^ c[k]) * 1099511628211ull;
    };
    auto vec = [&](const auto& v) { mix(v.data(), v.size() * sizeof(v[0])); };
    vec(b_.local), vec(b_.centroid0), vec(b_.real_mass), vec(b_.fixed), vec(b_.fixed_velocity), vec(b_.applied);
    vec(n_.position0), vec(n_.real_mass), vec(n_.fixed), vec(n_.applied), vec(z_.elasticity), vec(face_shear_);
    for (const auto& set : bolts_.sets) {
        const double p[9] = {set.ea, set.yield_force, set.rupture_strain, set.bond_stiffness, set.bond_strength,
                             set.normal_stiffness, set.line_mass, set.spacing, double(set.cable)};
        mix(p, sizeof p);
    }
    for (const auto& set : liners_.sets) {
        const double p[13] = {set.ea, set.ei, set.line_mass, set.line_inertia, set.kn, set.ks, set.tensile,
                              set.cohesion, set.tan_friction, set.thrust_capacity, set.tension_capacity,
                              set.moment_capacity, double(set.symmetric_ends)};
        mix(p, sizeof p);
    }
    for (const auto& law : laws_) {
        const double k[2] = {contact::normal_stiffness(law), contact::shear_stiffness(law)};
        mix(k, sizeof k);
    }
    return h;
}

/// Every evolving array and scalar, in checkpoint order: save and load walk the
/// same list, so they cannot drift apart.
template <class Self, class Visit>
void Solver::visit_state(Self& s, Visit&& v) {
    v(s.b_.centroid), v(s.b_.velocity), v(s.b_.theta), v(s.b_.omega);
    v(s.b_.mass), v(s.b_.inertia), v(s.b_.removed), v(s.b_.inv_edge_length);
    v(s.n_.position), v(s.n_.velocity), v(s.n_.mass);
    v(s.z_.stress), v(s.z_.strain);
    v(s.c_.vertex_block), v(s.c_.vertex_id), v(s.c_.edge_block), v(s.c_.edge_id), v(s.c_.edge_end);
    v(s.c_.length), v(s.c_.property), v(s.c_.history);
    v(s.relax_block_force_), v(s.relax_block_moment_), v(s.relax_node_force_), v(s.relax_total_), v(s.relax_left_), v(s.relax_keep_);
    v(s.pressure_block_force_), v(s.pressure_block_moment_), v(s.pressure_node_force_);
    v(s.dt_), v(s.time_), v(s.ratio_), v(s.work_), v(s.steps_);
    v(s.boundary_force_);
    v(s.detected_at_), v(s.detected_theta_), v(s.detected_vertex_), v(s.active_);
    v(s.detection_totals_), v(s.unsorted_contacts_), v(s.first_dt_);
    // Loads and support velocities: constant in a model file's stages, moved by
    // lab tests (the servo's platen speed, the confinement ramp).
    v(s.b_.fixed_velocity), v(s.b_.fixed_omega), v(s.b_.applied), v(s.b_.applied_moment);
    v(s.n_.fixed_velocity), v(s.n_.applied);
    // Installed bolts (core/bolts.hpp): nodes, their ties to the rock, segments.
    auto& B = s.bolts_;
    v(B.installed), v(B.position), v(B.velocity), v(B.applied), v(B.mass), v(B.length), v(B.slip), v(B.bond), v(B.host);
    v(B.tied), v(B.node_set), v(B.segment_node), v(B.rest), v(B.plastic), v(B.axial), v(B.state);
    v(B.first), v(B.bolt_set);
    auto& L = s.liners_;
    v(L.installed), v(L.position), v(L.velocity), v(L.theta), v(L.omega), v(L.mass), v(L.inertia), v(L.length);
    v(L.shear_slip), v(L.host), v(L.separated), v(L.normal_stress), v(L.node_set), v(L.held);
    v(L.element_node), v(L.rest), v(L.chord0), v(L.thrust), v(L.moment_a), v(L.moment_b);
    v(L.plastic_strain), v(L.plastic_rotation_a), v(L.plastic_rotation_b), v(L.yielded);
    v(L.first), v(L.liner_set), v(L.closed);
    // What the stage did so far, for its verdict (not physics: not in the state hash).
    v(s.monitor_.samples_);
}

void Solver::save_state(std::ostream& o) const {
    put(o, magic);
    put(o, std::int64_t(b_.count())), put(o, std::int64_t(n_.count())), put(o, std::int64_t(z_.size()));
    put(o, fingerprint_);
    visit_state(*this, [&](const auto& x) { put(o, x); });
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
    visit_state(*this, [&](auto& x) { get(i, x); });
    std::uint64_t hash = 0;
    get(i, hash);
    c_.normal.resize(c_.size());
    bolts_.force.assign(bolts_.position.size(), {});
    liners_.force.assign(liners_.position.size(), {});
    liners_.moment.assign(liners_.position.size(), 0.0);
    liners_.reaction.assign(liners_.position.size(), {});
    liners_.reaction_moment.assign(liners_.position.size(), 0.0);
    index_bolt_hosts();
    normals_stale_ = true;
    update_vertices(); // the faces of assign_face_groups are read off the current geometry
    rebuild_contact_index();
    detector_.invalidate();
    if (hash != state_hash()) throw std::runtime_error("checkpoint is corrupt (state hash differs)");
}

} // namespace bbm
