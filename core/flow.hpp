// bbm core: fluid flow in the joints between blocks (docs/theory.md §16).
//
// The joints of a block assembly are the pipes of a network whose nodes are the
// domains where joints meet — UDEC's domains, the voids at the junctions of the
// joint network, where the fluid pressure lives. Per unit depth (plane strain),
// with a pipe's hydraulic aperture a, length L, the fluid's viscosity μ, bulk
// modulus K_w and density ρ_w, and gravity g (a vector):
//
//   flow from domain i to j (cubic law)  q_ij = c_ij [(p_i − p_j) − ρ_w g·(x_i − x_j)],
//                                        c_ij = a³ / (12 μ L)
//   storage of domain i                  dp_i/dt = K_w / V_i (Σ_j q_ji + Q_i − dV_i/dt)
//   volume of domain i                   V_i = Σ over its pipes of a L / 2
//
// The gravity term makes a hydrostatic pressure (p = ρ_w |g| depth below a water
// table) carry no flow. Q_i is a rate injected at the domain (m²/s per unit depth;
// negative: extracted). A domain may have its pressure held (a boundary or an
// opening's wall): its net outflow is then what the network gives up there — the
// inflow into a drained opening.
//
// Transient flow is explicit (forward Euler). For dp/dt = −D L p, D = diag(K_w /
// V_i) and L the network's conductance Laplacian, Gershgorin's discs on D L bound
// every eigenvalue by max_i 2 K_w Σ_j c_ij / V_i, so Δt_f = min_i V_i / (K_w Σ_j c_ij)
// is stable; a larger step is taken as sub-steps of Δt_f. Steady flow (drained
// conditions) is one sparse solve of Σ_j q_ij = Q_i in the free domains (the
// conductance matrix is symmetric positive definite in every connected part of
// the network with a held pressure; a part with none keeps its pressure).
//
// Every sum runs in pipe order, so a result is the same bits on any thread count.
#pragma once

#include "base/vec2.hpp"
#include "meshing/blocks.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm::flow {

/// The fluid and the joints' hydraulic apertures.
struct FluidSpec {
    double viscosity = 1.0e-3;     ///< μ, Pa·s (water at 20 °C)
    double bulk_modulus = 2.0e9;   ///< K_w, Pa
    double density = 1000.0;       ///< ρ_w, kg/m³
    Vec2 gravity{0.0, 0.0};        ///< m/s² (e.g. {0, −9.81})
    double residual_aperture = 0.0; ///< a_res: the smallest hydraulic aperture, m
    double max_aperture = 1.0e-2;   ///< a_max: the largest, m
};

/// The network: domains (joint junctions) and pipes (joints between two of them).
struct Network {
    std::vector<Vec2> domain_position;
    std::vector<int> pipe_from, pipe_to; ///< domains at the pipe's ends
    std::vector<double> pipe_length;     ///< m
    std::vector<int> pipe_joint;         ///< index into BlockAssembly::joints

    int domains() const { return int(domain_position.size()); }
    int pipes() const { return int(pipe_from.size()); }

    /// The joints of `a` as pipes; joint ends closer than `tolerance` (m; 0: 1e-9
    /// of the assembly's extent) are one domain. A joint shorter than that is no pipe,
    /// nor one with `joint_in[j] == 0` (when given).
    static Network of_joints(const meshing::BlockAssembly& a, double tolerance = 0.0,
                             const std::vector<std::uint8_t>* joint_in = nullptr);
    /// The domain within the merge tolerance of `p`, or −1.
    int domain_at(Vec2 p) const;
    double merge_tolerance = 0.0;
};

/// The flow state: a pressure per domain, an aperture per pipe, and what holds
/// or feeds each domain.
struct State {
    std::vector<double> pressure;  ///< per domain, Pa (gauge: 0 is atmospheric)
    std::vector<double> aperture;  ///< per pipe, m (hydraulic)
    std::vector<std::uint8_t> held; ///< per domain: 1 = pressure prescribed
    std::vector<double> source;    ///< per domain: injected rate Q, m²/s per unit depth
    double time = 0.0;             ///< s
    /// advance()'s work arrays, kept between calls (no allocation per step).
    struct Scratch {
        std::vector<double> conductance_sum, volume, c, rate, net;
        std::vector<int> open, wet;
    } scratch;

    explicit State(const Network& n, double initial_aperture = 0.0)
        : pressure(n.domains(), 0.0), aperture(n.pipes(), initial_aperture), held(n.domains(), 0),
          source(n.domains(), 0.0) {}
    void hold(int domain, double p) { held[domain] = 1, pressure[domain] = p; }
};

/// a³ / (12 μ L) of pipe k, its aperture bounded to [a_res, a_max]; an aperture of
/// exactly 0 seals the pipe (an intact bond without an aperture of its own, a
/// joint of excavated rock): it neither conducts nor stores.
double conductance(const Network& n, const FluidSpec& f, const State& s, int pipe);
/// a clamped to [a_res, a_max], or 0 if a is 0 (sealed).
double hydraulic_aperture(const FluidSpec& f, double a);

/// Flow along each pipe, from pipe_from to pipe_to, m²/s per unit depth.
std::vector<double> pipe_flows(const Network& n, const FluidSpec& f, const State& s);

/// The explicit flow stage's stable time step: min over domains of V / (K_w Σ c).
/// Infinite when no pipe conducts.
double stable_timestep(const Network& n, const FluidSpec& f, const State& s);

/// Advances the pressures by `dt` (s), in sub-steps no longer than `safety` ×
/// stable_timestep; returns the number of sub-steps. Apertures are held fixed
/// over the step (dV/dt = 0: the mechanical coupling supplies it).
int advance(const Network& n, const FluidSpec& f, State& s, double dt, double safety = 0.9);

struct SteadyReport {
    int free_domains = 0;     ///< solved for
    int isolated_domains = 0; ///< in a part without a held pressure: left as they were
    double relative_residual = 0.0;
    /// pipes whose ends were merged at one head: 10^10 times the others at an
    /// end, in a network whose conductances span more than 10 decades (flow.cpp)
    int merged_pipes = 0;
};

/// The steady state: pressures with Σ_j q_ij = Q_i in every free domain connected
/// (by conducting pipes) to a held one. Throws InputError if a part of the network
/// with an injection has no held pressure (no steady state exists). A pipe 10^10
/// times stronger than the others at one of its ends has its ends merged at one
/// head (beyond double precision otherwise); a solve that fails throws NumericalError.
SteadyReport solve_steady(const Network& n, const FluidSpec& f, State& s);

/// The net flow out of the network at each held domain, summed: what a drained
/// boundary or opening takes in (m²/s per unit depth; positive = out of the rock).
double outflow_at_held(const Network& n, const FluidSpec& f, const State& s, const std::vector<std::uint8_t>& which);

} // namespace bbm::flow
