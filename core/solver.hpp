// bbm core: the explicit solver for rigid blocks (SPEC §5).
//
// One step is the list of stages of SPEC §5:
//   1. (when due) contact detection update          — detect_if_due()
//   2. contact forces from displacement increments   — face_slip_stage(), contact_and_zone_stage()
//   3. zone stresses of deformable blocks            —   the zone pass (fem/cst.hpp) in the latter
//   4. gravity, boundary tractions, applied loads    — support_stage() (core/support.hpp), gather_stage()
//   5. damping and integration, prescribed velocities — integrate()
//   6. convergence measure                           — the unbalanced-force ratio
//
// Threads: a step is one OpenMP parallel region; each stage is a work-sharing
// loop of the team over flat arrays (the serial bookkeeping in `single`s), so the
// thread count is a scheduling decision, not a different code path. Every sum —
// a block's force over its contacts, a node's over its zones and contacts, the
// work of the loads, the force scale — runs in an order fixed by the numbering of
// contacts, zones and bodies, never by the partition of the work: a model gives
// the same bits on 1 or 64 threads (tests/test_determinism.cpp).
//
// State is flat arrays indexed by block id (structure of arrays); vertices are
// stored once in body coordinates (relative to the centroid, at zero rotation)
// and their world positions recomputed at the start of each step. Nothing is
// allocated inside step() once the scratch arrays have their sizes.
//
// Time step and masses: for one degree of freedom of mass m on springs of total
// stiffness K, central differences are stable for Δt < 2√(m/K). K of a block sums
// (kn + ks)·L over its contacts (translation) and the same times the squared
// lever arm (rotation). Dynamic mode: real masses, Δt = safety × the smallest
// limit. Quasi-static mode: Δt = 1 (or as given) and each block's mass and inertia
// are set to K (Δt / (2 safety))², so every block converges at the same rate;
// gravity still acts on the real mass. Local non-viscous damping (Cundall):
// each force component is reduced by α|F| against the velocity.
//
// Deformable blocks (SPEC §6): a block of a meshed region keeps its entry in the
// block arrays (region, removal, polygon) but moves through its FE nodes: its
// polygon vertices are its boundary nodes, so contacts treat it like any block
// (contacts.hpp interpolates velocities and splits forces along its edges). Nodes
// have their own flat arrays and are damped, scaled and integrated like blocks
// (two degrees of freedom each). A node's stiffness for mass scaling and the
// stable step is the Gershgorin row sum of its zone stiffness (halved, to match
// the diagonal estimate used for blocks) plus its share of contact stiffness.
#pragma once

#include "contact/contacts.hpp"
#include "contact/detection.hpp"
#include "core/model_spec.hpp"
#include "core/support.hpp"
#include "core/state_fields.hpp"
#include "core/verdict.hpp"
#include "fem/cst.hpp"
#include "meshing/blocks.hpp"

#include <array>
#include <cstdint>
#include <exception>
#include <iosfwd>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bbm {

namespace fem {
struct SparseTriplets;
}

/// Wall time per stage of the step (`bbm run --profile`): measured on the team's
/// first thread between stage boundaries, so a stage's time includes its wait at
/// the barrier that ends it (the slowest thread's share). Off: one branch a stage.
struct StepProfile {
    enum Stage { vertices, detection, flow, face_slip, supports, contacts_and_zones, gather, integrate, bookkeeping, count };
    static constexpr std::array<const char*, count> names{"vertices",           "detection", "flow",
                                                          "face slip",          "supports",  "contacts and zones",
                                                          "gather",             "integrate", "bookkeeping"};
    bool enabled = false;
    long steps = 0;
    std::array<double, count> seconds{};
    double last = 0.0;
    void start();
    void lap(Stage stage);
};

/// An excavation's support along a path (StageSpec::support_path): rows [t,
/// k_mean, k_deviator] over the relaxation's steps, and the in-situ stress whose
/// deviator splits each support force into its mean and deviatoric parts.
struct SupportPath {
    std::vector<std::array<double, 3>> rows;
    StressFieldSpec in_situ;
};

class Solver {
public:
    /// Builds the model (core/build_model.cpp): blocks, FE nodes and zones,
    /// property sets and the contacts of the initial assembly, boundaries and
    /// support types. Throws InputError (file "" with the key) if a joint has no
    /// property set or a name does not resolve.
    Solver(const meshing::BlockAssembly& blocks, const AnalysisSpec& analysis);

    // --- stages -------------------------------------------------------------
    /// Joint stresses from a stress field, with the matching elastic displacements.
    void initialize_stress(const StressFieldSpec& field);
    /// Removes the blocks of these regions; the forces they exerted on the rest are
    /// relaxed linearly over relax_steps steps to the fraction `keep` of them, which
    /// stays (a support pressure: the convergence–confinement method's 1 − λ).
    /// `pressure` (Pa) pushes on the new boundary, normal to it, from now on and for
    /// good (a support pressure in Pa); a later excavate replaces both. A support
    /// path instead relaxes the support's mean and deviatoric parts each along its
    /// own curve (a tunnel face going by; theory.md §6.5).
    void excavate(const std::vector<std::string>& regions, long relax_steps, double keep = 0.0,
                  double pressure = 0.0, const SupportPath& path = {});
    /// The latest opening's pressure is now `pressure` (Pa): the push on its wall
    /// scaled from the excavation's `excavation_pressure`, which must be > 0 (it
    /// gave the push its direction and extent), and, with water in the joints,
    /// the wall's junctions held at it (`solve_now`: a steady solve at the next
    /// step). What a `pressurise` stage does, step by step along its ramp.
    void set_opening_pressure(double pressure, double excavation_pressure, bool solve_now);
    void step();
    /// Installs the named support sets, of any registered type (core/support.hpp:
    /// [[bolt]] sets, [[liner]]s, …): what an `install` stage does. Each node is
    /// tied to the rock it lies in now. Throws InputError (key "stage.supports")
    /// for an unknown or already installed set.
    void install_supports(const std::vector<std::string>& names);
    /// The registered support types, in tie order (core/support.cpp).
    const std::vector<std::unique_ptr<Support>>& supports() const { return supports_; }
    /// The support of a registered type.
    template <class T>
    T& support() const {
        for (const auto& s : supports_)
            if (auto* t = dynamic_cast<T*>(s.get())) return *t;
        throw std::logic_error("support type not registered");
    }
    const BoltState& bolts() const { return support<BoltSupport>().state(); }
    BoltState& bolts() { return support<BoltSupport>().state(); } ///< a study may load a node (BoltState::applied)
    const LinerState& liners() const { return support<LinerSupport>().state(); }
    /// Water in the joints (core/joint_flow.hpp); null in a dry model.
    const JointFlow* flow() const { return flow_.get(); }
    /// Recomputes time step and (quasi-static) masses from the current contacts.
    void update_timestep();
    /// Implicit elastic stage (SPEC §5): assembles the linear stiffness of blocks
    /// (3 DOF), nodes (2 DOF), contacts (kn, ks) and zones at the current state,
    /// solves K Δu = unbalanced force with CHOLMOD (prescribed components held),
    /// and applies Δu through the contact laws and zones. Velocities are zero
    /// after it. Throws std::runtime_error naming the cause if the system is
    /// singular (a floating block or a model without supports).
    struct ElasticSolveReport {
        int equations = 0, iterations = 0;
        long nonzeros = 0;
        std::string method;
        double relative_residual = 0, seconds = 0, ratio_before = 0, ratio_after = 0;
    };
    ElasticSolveReport solve_elastic();
    /// Moves the prescribed velocity components by fixed velocity × `time` through
    /// the contact laws and zones, every free component held (one kinematic step,
    /// no dynamics); velocities are zero after it. Followed by solve_elastic(): the
    /// static state at that support displacement (a lab test's elastic preload).
    void move_supports(double time);
    /// Moves every block and node by the given displacement and rotation increments
    /// (per block, per node) through the contact laws and zones, as one kinematic
    /// step; velocities are zero after it. Scaling a linear-elastic solution: add
    /// (λ − 1) times its displacements to reach λ times its state.
    void move_bodies(const std::vector<Vec2>& block_displacement, const std::vector<double>& block_rotation,
                     const std::vector<Vec2>& node_displacement);

    // --- checkpoints (core/state.cpp) -----------------------------------
    /// Writes the evolving state (binary). A solver built from the same model
    /// file and given this state continues exactly as the saved one would.
    void save_state(std::ostream& out) const;
    /// Throws std::runtime_error if the data is truncated, corrupt or of another model.
    void load_state(std::istream& in);
    /// Hash of what the model file determines (initial geometry, masses, supports,
    /// loads, property sets): a checkpoint records it and refuses another model.
    std::uint64_t model_fingerprint() const { return fingerprint_; }

    // --- measures -------------------------------------------------------------
    double unbalanced_ratio() const { return ratio_; }
    double time() const { return time_; }
    long steps() const { return steps_; }
    double timestep() const { return dt_; }
    /// The time step the model started with (the health checks compare: a step
    /// that collapses means a sliver block or a runaway contact stiffness).
    double initial_timestep() const { return first_dt_; }
    double kinetic_energy() const;
    /// The scale of the unbalanced-force ratio: the RMS contact (and zone nodal) force.
    double force_scale() const;
    /// What the rock did in the current stage, for its verdict (core/verdict.hpp);
    /// sampled by run_stages, saved with the state.
    StageMonitor& monitor() { return monitor_; }
    const StageMonitor& monitor() const { return monitor_; }
    double strain_energy() const;
    double dissipated_energy() const;
    double external_work() const { return work_; }
    /// Cracks (broken bonds) so far, by mode; cumulative.
    int cracks(contact::JointState mode) const;
    /// Total contact force on a boundary's blocks in the last step, N/m (for a
    /// prescribed-velocity boundary: minus the reaction its supports provide).
    Vec2 boundary_force(const std::string& boundary) const;
    /// Block-averaged stress of every block (SPEC §7): σ = (1/A) Σ x ⊗ f over its
    /// contacts and boundary tractions, symmetrised; tension positive. {sxx, syy, sxy}.
    std::vector<std::array<double, 3>> block_stresses() const;
    /// Total strain energy of the zones (½ σ·D⁻¹σ A), J/m.
    double zone_strain_energy() const;
    int block_at(Vec2 p) const;

    // --- state (read by output and tests) ------------------------------------
    struct Blocks {
        std::vector<Vec2> centroid, centroid0, velocity, force, applied;
        std::vector<double> theta, omega, moment, applied_moment;
        std::vector<double> mass, inertia, real_mass, real_inertia, area;
        std::vector<std::uint8_t> fixed; ///< bit 0 vx, bit 1 vy, bit 2 ω prescribed
        std::vector<Vec2> fixed_velocity;
        std::vector<double> fixed_omega;
        std::vector<std::uint8_t> removed;
        std::vector<std::uint8_t> deformable; ///< moves through FE nodes (see above)
        std::vector<int> region, material;
        std::vector<Vec2> local, vertex; ///< body and world vertex positions (CSR by first)
        std::vector<double> inv_edge_length; ///< per vertex: 1 / length of the edge it starts
        std::vector<std::uint32_t> first;
        std::vector<int> vertex_node; ///< per vertex: its FE node, −1 on rigid blocks
        /// Per vertex: 1 at a corner of its block (every vertex of a rigid block),
        /// 0 at a node along a deformable block's face (contact::BlockView::corner).
        std::vector<std::uint8_t> corner;
        int count() const { return static_cast<int>(centroid.size()); }
    };
    /// FE nodes of deformable blocks.
    struct Nodes {
        std::vector<Vec2> position, position0, velocity, force, applied;
        std::vector<double> mass, real_mass;
        std::vector<std::uint8_t> fixed; ///< bit 0 vx, bit 1 vy prescribed
        std::vector<Vec2> fixed_velocity;
        std::vector<int> block;
        int count() const { return static_cast<int>(position.size()); }
    };
    const Nodes& nodes() const { return n_; }
    Nodes& nodes() { return n_; }
    const fem::Zones& zones() const { return z_; }
    const Blocks& blocks() const { return b_; }
    Blocks& blocks() { return b_; }
    /// The contacts, their normals brought up to date (refresh_normals()).
    const contact::Contacts& contacts() const {
        refresh_normals();
        return c_;
    }
    contact::Contacts& contacts() {
        refresh_normals();
        return c_;
    }
    const std::vector<contact::JointLaw>& laws() const { return laws_; }
    const std::vector<std::string>& property_names() const { return property_names_; }
    const std::vector<std::string>& region_names() const { return region_names_; }
    /// Block lists by boundary name.
    const std::vector<std::pair<std::string, std::vector<int>>>& boundary_blocks() const { return boundary_blocks_; }
    /// Hash of every field of the state list marked hashed (core/state_fields.hpp):
    /// equal hashes, the same evolving state bit for bit.
    std::uint64_t state_hash() const;
    /// Every field of the state list, by name, over its bytes in place (Python's
    /// Model.state, the tests). Writing through it changes the solver's state.
    std::vector<StateField> state_fields();
    /// Bytes the solver holds (capacity of its arrays), by what they are indexed by.
    struct Memory {
        std::size_t blocks = 0, vertices = 0, nodes = 0, zones = 0, contacts = 0, other = 0;
        std::size_t total() const { return blocks + vertices + nodes + zones + contacts + other; }
    };
    Memory memory() const;
    /// For the benchmarks: wall seconds of `passes` contact passes alone (the
    /// contact loop: kinematics, laws, forces) on `threads` threads, over a copy of
    /// the contacts in their present state; the model is not changed.
    double time_contact_passes(long passes, int threads) const;
    /// Contacts created, removed and transferred by detection so far.
    const contact::DetectionResult& detection_totals() const { return detection_totals_; }
    double detection_tolerance() const { return tolerance_; }
    /// Time per stage of step() (`bbm run --profile`); enable it before stepping.
    StepProfile& profile() { return profile_; }
    const StepProfile& profile() const { return profile_; }

private:
    // Building the model (core/build_model.cpp), in the constructor's order.
    void build_bodies(const meshing::BlockAssembly& a, const AnalysisSpec& an); ///< blocks, FE nodes, zones
    /// Property sets (with their derived strength classes and deformable splits)
    /// and the contacts of the assembly's joints; the set of new contacts.
    void build_contacts(const meshing::BlockAssembly& a, const AnalysisSpec& an);
    /// A joint's two point contacts (one per end, half its length each; collinear
    /// edges share one).
    /// The contacts at the joint's two ends (new, or an existing one's share grown).
    std::array<int, 2> add_joint_contacts(const meshing::BlockAssembly& a, const meshing::JointRecord& j, int property,
                                          std::map<std::pair<int, int>, int>& existing);
    void prepare_detection(const meshing::BlockAssembly& a); ///< tolerance, reach, junctions
    void prepare_team();                                     ///< the step's per-thread scratch
    // The elastic stage's pieces (core/implicit.cpp).
    struct ElasticDofs {
        std::vector<std::array<int, 3>> block; ///< per block: x, y, rotation (−1: held or not in the model)
        std::vector<std::array<int, 2>> node;  ///< per FE node: x, y
        int count = 0;
    };
    ElasticDofs number_elastic_dofs() const;
    /// Forces at the current state; the largest free force over the force scale.
    double elastic_residual_ratio(const ElasticDofs& d);
    std::vector<double> elastic_residual(const ElasticDofs& d) const;
    /// The linear stiffness of zones and contacts (not open cracks) at the current state.
    void assemble_elastic_stiffness(const ElasticDofs& d, fem::SparseTriplets& K, std::vector<double>& diagonal) const;
    /// Throws naming a floating body, or loads no stiffness could carry.
    void check_elastic_system(const ElasticDofs& d, const std::vector<double>& diagonal,
                              const std::vector<double>& r) const;
    /// Δu applied through the laws and zones as one kinematic step.
    void apply_elastic_increment(const ElasticDofs& d, const std::vector<double>& du);
    contact::BlockView view() const;
    void detect_if_due();
    void detection_pass();
    void update_vertices();
    void place_rigid_block(int i);      ///< world vertices and packed state from centroid and θ
    void place_deformable_block(int i); ///< vertices from the block's boundary nodes
    void rebuild_contact_index();
    /// The force stages below in order (the implicit stage's evaluations).
    void compute_forces();
    // The force stages of a step (core/solver.cpp), in order.
    void flow_stage();             ///< water in the joints: apertures, pressures, contact pressures
    void face_slip_stage();        ///< mean slip of rigid faces on deformable blocks
    void support_stage();          ///< the supports' force passes, one thread, no barrier
    void contact_and_zone_stage(); ///< the contact and zone passes, then a barrier
    void gather_stage();           ///< each block's and node's forces, in a fixed order
    /// The contact loop does not store normals (a write of every contact every
    /// step, for readers outside the loop): they are computed on demand from the
    /// vertex positions the last step used, which gives the same values.
    void refresh_normals() const;
    /// Boundary reactions (boundary_force) from the forces of the last evaluation.
    void sum_boundary_forces();
    void release_relaxation();
    /// The support's factors now: on the whole in-situ support, and on its
    /// deviatoric part besides (k_mean and k_deviator − k_mean along a path).
    std::pair<double, double> relaxation_factors() const;
    /// The one list of the state (core/state.cpp): visit(FieldInfo, field&) per field.
    template <class Self, class Visit>
    static void for_each_field(Self& self, Visit&& visit);
    template <class Self, class Visit>
    static void for_each_body_field(Self& self, Visit& visit);
    template <class Self, class Visit>
    static void for_each_contact_field(Self& self, Visit& visit);
    template <class Self, class Visit>
    static void for_each_run_field(Self& self, Visit& visit);
    std::uint64_t compute_model_fingerprint() const; ///< core/state.cpp
    /// Per hashed field, its name and the hash of its bytes (load_state's check).
    std::vector<std::pair<std::string, std::uint64_t>> field_hashes() const;
    void integrate();
    /// Where a point lies in the rock (a rigid block or a zone), else the nearest
    /// within `reach` (core/solver_supports.cpp): a support's install.
    BoltHost find_host(Vec2 p, double reach) const;
    /// The rock as the supports see it this step.
    SupportRock support_rock() const;
    /// The per-block and per-node lists of support ties, numbered through the
    /// support types in registry order (after an install, a load).
    void index_support_ties();
    void apply_boundaries(const AnalysisSpec& a, const meshing::BlockAssembly& blocks);
    std::vector<int> select_blocks(const SelectionSpec& s) const;

    Blocks b_;
    Nodes n_;
    fem::Zones z_;
    mutable contact::Contacts c_; ///< mutable: its normals are a cache (refresh_normals)
    mutable bool normals_stale_ = true;
    StageMonitor monitor_;
    /// The support types (core/support.hpp), and the first tie of each (of supports_.size() + 1).
    std::vector<std::unique_ptr<Support>> supports_;
    std::unique_ptr<JointFlow> flow_;
    std::exception_ptr stage_error_; ///< thrown inside the step's parallel region, thrown again after it
    std::vector<int> support_tie_first_;
    /// What each support tie puts on its rock this step (the force, and its moment
    /// about a rigid host's centroid): written by the support stage, gathered by the rock.
    std::vector<Vec2> tie_reaction_;
    std::vector<double> tie_moment_;
    /// Ties to each rigid block (CSR), and (tie, weight) to each FE node.
    std::vector<int> tie_block_first_, tie_block_tie_, tie_node_first_;
    std::vector<std::pair<int, double>> tie_node_tie_;
    std::vector<contact::JointLaw> laws_;
    std::vector<std::string> property_names_;
    std::vector<std::uint8_t> face_shear_; ///< per property set: JointPropertySpec::face_shear
    std::vector<std::string> region_names_;
    SolverSpec settings_;
    std::vector<std::pair<std::string, std::vector<int>>> boundary_blocks_;
    std::vector<Vec2> boundary_force_; ///< per boundary_blocks_ entry, last step
    std::vector<std::vector<int>> boundary_nodes_; ///< per boundary_blocks_ entry: its FE nodes
    struct Traction { int block; Vec2 offset; Vec2 force; }; ///< boundary point load, body frame
    std::vector<Traction> tractions_;
    /// Blocks held by a `touching` velocity boundary: where the support acts (the
    /// mean midpoint of their edges in the box, body frame), for block stresses.
    struct HeldPoint { int block; Vec2 offset; };
    std::vector<HeldPoint> held_points_;
    /// Work of the loads and largest unbalanced force of a step per fixed chunk of
    /// bodies (integrate()).
    static constexpr int sum_chunk = 512;
    static constexpr int chunks_of(int bodies) { return (bodies + sum_chunk - 1) / sum_chunk; }
    /// Per thread, the seconds its share of the contact and zone passes took since
    /// the last rebalance (one cache line each: written every step by its thread).
    struct alignas(64) PassTime { double contacts = 0.0, zones = 0.0; };
    std::vector<PassTime> pass_time_;
    std::vector<double> balance_scratch_; ///< balance_contact_pass()'s rates and targets
    static constexpr int balance_every = 64; ///< steps between rebalances of the contact pass
    void balance_contact_pass();
    /// Per block, the gather's estimated cost of the blocks before it (and the
    /// total): a team shares the blocks by it (rebuild_contact_index()).
    std::vector<double> block_cost_before_;
    /// Likewise for placing the blocks, and for integrate()'s chunks.
    std::vector<double> place_cost_before_, chunk_cost_before_;
    bool any_active_ = false; ///< detect_if_due(): some block has moved (shared by the team)
    struct ChunkSums { double work, unbalanced; };
    std::vector<ChunkSums> chunk_sums_;
    /// The blocks' position and velocity packed for the contact loop, refreshed by
    /// update_vertices() at the start of every step (contact/contacts.hpp).
    std::vector<contact::BodyState> body_;
    /// Translational and rotational stiffness per block, and per node (update_timestep()).
    struct { std::vector<double> block, rotation, node; } stiffness_scratch_;
    /// Support forces being relaxed after an excavation, per block and per node
    /// (empty when none).
    std::vector<Vec2> relax_block_force_, relax_node_force_;
    std::vector<double> relax_block_moment_;
    long relax_total_ = 0, relax_left_ = 0;
    double relax_keep_ = 0.0; ///< fraction of the excavated rock's support kept for good
    /// With a support path: its rows flattened (t, k_mean, k_deviator, ...), and the
    /// deviatoric part of the support forces above (empty without one).
    std::vector<double> relax_path_;
    std::vector<Vec2> relax_deviator_block_force_, relax_deviator_node_force_;
    std::vector<double> relax_deviator_block_moment_;
    /// A constant support pressure on the excavated boundary, as forces per block
    /// and per node (empty when none).
    std::vector<Vec2> pressure_block_force_, pressure_node_force_;
    std::vector<double> pressure_block_moment_;
    /// The opening's pressure over the excavation's: one value once a pressurise
    /// stage has changed it, else empty (1: as excavated; hashed only when set).
    std::vector<double> pressure_scale_;
    double first_dt_ = 0.0;
    double dt_ = 1.0, time_ = 0.0, ratio_ = 0.0, work_ = 0.0, corner_radius_ = 0.0;
    // Detection: tolerance, property of new contacts, motion since the last pass.
    double tolerance_ = 0.0;
    int new_contact_property_ = 0;
    std::vector<double> radius_; ///< largest vertex distance from the centroid
    std::vector<Vec2> detected_at_;
    std::vector<double> detected_theta_;
    std::vector<Vec2> detected_vertex_; ///< deformable blocks: vertex positions at their last pass
    std::vector<std::uint8_t> active_; ///< moved enough since its last detection pass
    std::vector<contact::Junction> junctions_; ///< vertices touching a block they have no joint with (detection.hpp)
    contact::DetectionResult detection_totals_;
    contact::Detector detector_;
    /// Created since the contacts were last sorted by block: it decides when they
    /// are renumbered next, so it is state (a checkpoint saves it).
    int unsorted_contacts_ = 0;
    std::uint64_t fingerprint_ = 0; ///< model_fingerprint(), taken at construction
    long steps_ = 0;
    StepProfile profile_;
};

} // namespace bbm
