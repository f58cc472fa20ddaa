// bbm core: the analysis part of a model file — materials, joint properties,
// boundary conditions, the solver settings, histories and the stages to run.
//
// Like meshing/spec.hpp these are plain data filled by the input layer (io/)
// and checked there for types and ranges; build_world (core/build_world.hpp)
// turns them into the world's flat arrays once. SI units throughout (SPEC §2): stresses in Pa with
// tension positive for continuum stress tensors (a 15 MPa overburden is
// syy = -15e6), joint stiffness in Pa/m, angles in degrees.
#pragma once

#include "base/vec2.hpp"
#include "core/joint_flow.hpp"
#include "core/supports/registry.hpp"
#include "contact/joint_property.hpp"
#include "meshing/blocks.hpp"

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bbm {

struct MaterialSpec {
    std::string name;
    double density = 2700.0; ///< kg/m³
    /// Elasticity of deformable blocks (SPEC §6; plane strain, isotropic). young = 0:
    /// none given (the material's regions must then be rigid).
    double young = 0;        ///< Young's modulus E of the rock, Pa
    double poisson = 0.2;    ///< Poisson's ratio ν, 0 <= ν < 0.5
    /// Fraction f of the deformation taken by the blocks (paper §3.2, SPEC §6). With
    /// 0 < f < 1 the blocks get E / f and the joints of the material's regions have
    /// their stiffness scaled by 1 / (1 − f); 0 = not split (blocks get E, joints
    /// keep their stiffness).
    double deformable_fraction = 0;
};

/// Which property set the joints of given tags (and regions) get. Rules are applied
/// in order; a later matching rule overrides an earlier one.
struct JointAssignmentSpec {
    std::string property;
    std::vector<meshing::JointTag> tags;  ///< empty = every tag
    std::vector<std::string> regions;     ///< joint between blocks of these regions; empty = any
};

/// Blocks (or block edges) selected by region and/or box. Empty = everything.
struct SelectionSpec {
    std::vector<std::string> regions;
    std::optional<Box2> box; ///< block centroid (or edge midpoint) inside the box
    /// Velocity boundaries: select rigid blocks with an edge inside the box (both
    /// ends) instead of by centroid, e.g. the blocks along a symmetry plane.
    /// Nodes of deformable blocks are always selected by position.
    bool touching = false;
};

/// A stress field σ(y) = σ0 + (y − y_ref)·dσ/dy, tension positive.
struct StressFieldSpec {
    double sxx = 0, syy = 0, sxy = 0;
    double y_ref = 0;
    double dsxx_dy = 0, dsyy_dy = 0, dsxy_dy = 0;
};

/// A plane wave sent in through a viscous boundary: its particle velocity v(t) at
/// the boundary, of a named pulse (core/viscous.hpp has their formulas).
struct IncidentWaveSpec {
    enum class Pulse { none, ricker, half_sine, harmonic, file };
    enum class Wave { p, s }; ///< p: particle motion along the inward normal; s: along the edge
    Pulse pulse = Pulse::none;
    Wave wave = Wave::p;
    double velocity = 0.0;  ///< peak particle velocity of the incoming wave, m/s
    double frequency = 0.0; ///< Hz (Ricker: its peak frequency)
    double cycles = 1.0;    ///< harmonic: the train's length in periods
    double start = 0.0;     ///< s: when the pulse starts at the boundary
    /// file: the record's (time since start, s; particle velocity, m/s) rows,
    /// times increasing; linear between rows, 0 outside them. Times `velocity`.
    std::vector<std::pair<double, double>> record;
    std::string record_file; ///< where it was read from (messages)
};

struct BoundarySpec {
    enum class Kind { velocity, stress, viscous };
    std::string name;
    Kind kind = Kind::velocity;
    SelectionSpec select;
    /// velocity: the components given are prescribed (fixed if 0), others free.
    std::optional<double> vx, vy, omega;
    /// stress: traction σ·n on the exposed (unjointed) block edges selected.
    StressFieldSpec stress;
    /// viscous: dashpots ρ c_p and ρ c_s per unit length on the exposed edges
    /// selected, and the wave sent in through them (none: they only absorb).
    IncidentWaveSpec incident;
};

struct SolverSpec {
    enum class Mode { quasi_static, dynamic };
    Mode mode = Mode::quasi_static;
    double damping = 0.8;   ///< local non-viscous damping coefficient (quasi-static default 0.8)
    double safety = 0.5;    ///< time step / critical time step
    double timestep = 0.0;  ///< s; 0 = automatic (dynamic) or 1 (quasi-static, scaled masses)
    Vec2 gravity{0.0, 0.0}; ///< m/s²
    /// Contact detection tolerance (m) for new contacts; 0 = 0.02 × mean block size.
    double detection_tolerance = 0.0;
    std::string new_contact_property; ///< property set of contacts formed during the run
    /// Radius (m) of the rounded corners unbonded contacts see past an edge's end;
    /// 0 = 0.05 × the mean joint length.
    double corner_radius = 0.0;
    /// Length given to a contact formed during the run: `edge`, half of the vertex's
    /// adjacent edge that lies most along the other block's edge; `overlap`, half of
    /// that edge's overlap with the other block's edge (at least the corner radius),
    /// as UDEC shares a face between its two end contacts.
    enum class NewContactLength { edge, overlap };
    NewContactLength new_contact_length = NewContactLength::edge;
    /// A contact formed already overlapped (a vertex that passed into the other
    /// block between detection passes): `push`, its overlap loads it at once
    /// (σn = −kn un, energy no work paid for, which local damping takes out); `rest`,
    /// its overlap is its rest position and only further approach loads it
    /// (docs/theory.md §19.4). By mode: rest in the dynamic mode, push in the
    /// quasi-static one (the mode the shipped calibrations were made in).
    enum class NewContactOverlap { push, rest, by_mode };
    NewContactOverlap new_contact_overlap = NewContactOverlap::by_mode;
    bool overlap_at_rest() const {
        return new_contact_overlap == NewContactOverlap::rest ||
               (new_contact_overlap == NewContactOverlap::by_mode && mode == Mode::dynamic);
    }
    /// Rayleigh damping (dynamic mode): the critical ratio ξ at the centre
    /// frequency f (Hz), half from the mass and half from the stiffness:
    /// C = α M + β K, α = ξ ω, β = ξ / ω, ω = 2π f (docs/theory.md §19).
    double rayleigh_ratio = 0.0;
    double rayleigh_frequency = 0.0;
    double rayleigh_alpha() const { return rayleigh_ratio * 2.0 * 3.141592653589793 * rayleigh_frequency; }
    double rayleigh_beta() const {
        return rayleigh_frequency > 0.0 ? rayleigh_ratio / (2.0 * 3.141592653589793 * rayleigh_frequency) : 0.0;
    }
    /// Keep the energy account's damping and kinetic terms (core/measures.hpp):
    /// on in the dynamic mode and where a history asks for them; a quasi-static
    /// run asks with this key (integration costs more with it).
    bool energy_account = false;
    int output_every = 0;             ///< steps between VTK outputs; 0 = at stage ends only
    int history_every = 10;           ///< steps between history rows
    int threads = 1;                  ///< threads of the contact loop (from the command line)
};

struct HistorySpec {
    enum class Quantity {
        unbalanced_ratio, displacement_x, displacement_y, velocity_x, velocity_y, rotation,
        boundary_force_x, boundary_force_y, cracks_tensile, cracks_shear, kinetic_energy,
        strain_energy, dissipated_energy, work,
        inflow, ///< into the drained openings, m²/s per unit depth ([flow])
        absorbed_energy, ///< taken by the viscous boundaries' dashpots so far, J/m
        wave_energy,     ///< the work of their incident waves so far, J/m
        creep_time,      ///< stress corrosion's creep time so far, s (core/creep.hpp)
        damping_energy,  ///< taken by damping so far (local and Rayleigh), J/m
        energy_error,    ///< the energy account's error since the stage started, J/m (core/measures.hpp)
        ejected_mass,    ///< rock detached from the rock mass: ejected, kg/m (core/ejecta.hpp)
        ejection_speed   ///< its mass-weighted mean speed, m/s
    };
    std::string name;
    Quantity quantity = Quantity::unbalanced_ratio;
    std::optional<Vec2> point;   ///< block containing (or nearest to) this point
    std::string boundary;        ///< for boundary forces
};

struct StageSpec {
    /// elastic: elastic equilibrium in one implicit sparse solve (SPEC §5), no keys.
    /// install: puts the named support sets in place, tied to the rock
    /// as it is at that moment (after a partial relaxation: convergence–confinement).
    /// pressurise: the latest opening's pressure (excavated with one) ramped to
    /// `pressure` over `steps` steps (0: at once): a borehole's pressurisation
    /// cycles, as a hydraulic fracturing test runs them.
    /// creep: real time (stress corrosion, core/creep.hpp): mechanical equilibrium
    /// and creep steps in turn for `duration` seconds of creep time.
    enum class Kind { initialize, solve, excavate, cycle, elastic, install, pressurise, creep };
    std::string name;
    Kind kind = Kind::solve;
    StressFieldSpec stress;            ///< initialize
    double ratio = 1e-5;               ///< solve: target unbalanced-force ratio
    long max_steps = 200000;           ///< solve: step limit
    /// solve: where the stage ends (core/verdict.hpp).
    ///   ratio        the model's unbalanced-force ratio at `ratio` (the default);
    ///   rest         that, or the rock mass at rest: no crack in the last
    ///                quiet_steps and its ratio, fragments left out, at `ratio`;
    ///   equilibrium  only the verdict "equilibrium" (with or without fragments):
    ///                no crack over the verdict's window and the ratio at `ratio`.
    ///                A brittle rock can reach the ratio while it still cracks,
    ///                a few cracks per thousand steps; this waits for it to stop.
    enum class Until { ratio, rest, equilibrium };
    Until until = Until::ratio;
    long quiet_steps = 2000;
    long steps = 0;                    ///< cycle; excavate: steps run in the stage (<= relax_steps); pressurise: ramp
    double time = 0.0;                 ///< cycle, dynamic mode: the model time it runs instead (s)
    std::vector<std::string> regions;  ///< excavate
    long relax_steps = 0;              ///< excavate: support relaxed to zero over these steps
    double keep = 0.0;                 ///< excavate: fraction of the support kept for good (a support pressure)
    double pressure = 0.0;             ///< excavate: Pa on the new boundary, normal to it, for good; pressurise: target
    /// excavate: the support's path instead of a linear relaxation, rows [t, k_mean,
    /// k_deviator] from t = 0 to t = 1 over relax_steps: the fractions of the
    /// in-situ support's mean and deviatoric parts left at t (the last row's for
    /// good). A tunnel face's three-dimensional stress path in a plane section
    /// (examples/field/face_path.py; docs/theory.md §6.5).
    std::vector<std::array<double, 3>> support_path;
    std::vector<std::string> supports; ///< install: names of support sets (of any registered type)
    double duration = 0.0;             ///< creep: the creep time it runs, s
    double loss = 0.02;                ///< creep: the largest fraction of a bond's section one creep step takes
    /// creep: mechanical steps after a creep step that find no rest: the rock is
    /// failing under its held load (a pillar whose strata follow it down moves too
    /// slowly for the collapse test), and the stage ends with its time to failure.
    long settle_steps = 200000;
};

/// [report]: what `bbm run` measures and draws around an opening (optional;
/// studies/model/opening.hpp).
struct ReportSpec {
    bool opening = false;           ///< measure the opening (center, springline, crown given)
    Vec2 center{}, springline{}, crown{};
    std::optional<Box2> window;     ///< part drawn in failure.png; empty = 2 radii around the opening
    double ejection_speed = 1.0;    ///< m/s: detached rock moving into the opening faster is ejected (core/ejecta.hpp)
};

/// [events]: the seismic events recorded from breaking bonds (optional;
/// core/events.hpp). Present: the catalogue is kept.
struct EventSpec {
    bool on = false;
    double join_distance = 0.0; ///< m; 0: twice the mean rigid block size
    long window = 0;            ///< steps; 0: 50
    double thickness = 0.0;     ///< m; 0: each event's own length
};

struct AnalysisSpec {
    std::vector<MaterialSpec> materials;
    /// Material of each region by name (region name -> material name).
    std::vector<std::pair<std::string, std::string>> region_material;
    std::vector<JointPropertySpec> joint_properties;
    std::vector<JointAssignmentSpec> joint_assignments;
    std::vector<BoundarySpec> boundaries;
    SolverSpec solver;
    std::vector<HistorySpec> histories;
    std::vector<StageSpec> stages;
    /// The support sets of each registered type (core/supports/registry.hpp), in
    /// file order, installed by install stages.
    SupportSpecs supports;
    FlowSpec flow; ///< [flow], [[flow_boundary]], [[flow_source]]: water in the joints
    ReportSpec report;
    EventSpec events;
};

} // namespace bbm
