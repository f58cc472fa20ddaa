// bbm meshing: discrete fracture networks — the rock mass's own discontinuities
// (issue 26), generated or read, before the bonded pattern fills the rock.
//
// A fracture set ([[region.dfn]], spec.hpp DfnSetSpec) is a marked point process:
//   centres   Poisson (uniform, given count) or clustered (Thomas: cluster centres
//             uniform, fractures offset from theirs by a Gaussian of σ = radius);
//   angle     von Mises, density ∝ exp(κ cos(θ − mean)) folded into mean ± 90°
//             (a trace at θ + 180° is the same trace), uniform on [0°, 180°), or
//             picked from a list with weights;
//   length    fixed, power law (∝ l^−a on [min, max]), lognormal or exponential
//             (given by their mean, truncated to [min, max]);
//   intensity P21 (trace length per unit area) or a count of centres in the region.
// For a stationary process the trace length per unit area is λ E[L] wherever
// every fracture that can reach a point is generated (Campbell's theorem), so
// centres are drawn over the region's box grown by half the longest fracture, at
// λ = P21 / E[L] (E[L] of the truncated law, in closed form). A later set may end
// at the fractures of earlier ones: walking out from its centre, at each crossing
// it stops with a given probability. Traces are clipped to the region; the
// statistics of what was built (P10 on scanlines, P20, P21, orientation and length
// per set) are reported beside what was asked.
#pragma once

#include "meshing/cgal_ops.hpp"
#include "meshing/spec.hpp"

#include <span>
#include <string>
#include <vector>

namespace bbm::meshing {

/// What a set asked for and what was built, in the region it was cut into.
struct FractureSetStats {
    std::string name;
    std::string source;      ///< "generated", or the trace file (and, for DXF, what it held)
    int fractures = 0;       ///< generated fractures whose centre lies in the region
    int traces = 0;          ///< pieces of trace inside the region
    double area = 0.0;       ///< of the region, m²
    double p20 = 0.0;        ///< fracture centres per m² (given traces: their midpoints)
    double p21 = 0.0, p21_target = 0.0; ///< trace length per m² in the region; asked (count: λ E[L]); 0 = traces given
    double p10_x = 0.0, p10_y = 0.0;    ///< crossings per metre of horizontal / vertical scanline
    double mean_angle = 0.0;            ///< degrees in [0, 180): axial mean of the fractures' angles
    double concentration = 0.0;         ///< von Mises κ fitted to them (A1⁻¹ of the mean resultant)
    double mean_length = 0.0, std_length = 0.0; ///< of the fractures (whole, before clipping), m
    double mean_length_target = 0.0;    ///< E[L] of the asked law (0 for given traces)
    double mean_trace = 0.0;            ///< of the pieces inside the region (censored by it), m
};

/// One fracture: its whole trace (after termination, before clipping) and set.
/// An end where it stops at an earlier fracture is rounded; `a_at` (`b_at`) names
/// that fracture, so that the cutting can put the end exactly on it (where the line
/// through line_a and line_b, the fracture as drawn, crosses that fracture's line).
struct Fracture {
    Vec2 a{}, b{};
    int set = 0;
    Vec2 line_a{}, line_b{};
    int a_at = -1, b_at = -1; ///< index in FractureNetwork::fractures, or −1: a free end
};

struct FractureNetwork {
    std::vector<Fracture> fractures;
    std::vector<SegmentSpec> traces; ///< clipped to the region
    std::vector<int> trace_set;      ///< per trace: index of its set in the region's list
    std::vector<int> trace_fracture; ///< per trace: the fracture it is a piece of
    std::vector<FractureSetStats> stats;
};

/// The fracture sets of one region, generated in order (a set can end only at
/// earlier ones) and clipped to `domain`. Throws std::invalid_argument naming the
/// set for a length law that cannot be sampled (its truncation keeps < 0.1%).
FractureNetwork generate_fracture_network(std::span<const DfnSetSpec> sets, const cgal::Domain& domain);

namespace dfn {
/// E[L] of the (truncated) length law; `diagonal` stands for an unset max.
double mean_length(const FractureLengthSpec& s, double diagonal);
/// P(L ≤ x) of the (truncated) length law.
double length_cdf(const FractureLengthSpec& s, double diagonal, double x);
/// P(θ ≤ x) of the angle law, x in degrees within [mean − 90, mean + 90) (von
/// Mises) or [0, 180) (uniform, list).
double angle_cdf(const FractureOrientationSpec& s, double x);
/// Before generating: the fractures a set will draw (centres over the region's box
/// grown by half the longest fracture) and the trace length per m² it will leave in
/// the region (0 for given traces: their count is known).
struct SetSize {
    double fractures = 0.0, p21 = 0.0;
};
SetSize expected_size(const DfnSetSpec& s, const cgal::Domain& domain);
/// Pieces of segment ab inside the domain.
std::vector<SegmentSpec> clip_to_domain(Vec2 a, Vec2 b, const cgal::Domain& domain);
} // namespace dfn

} // namespace bbm::meshing
