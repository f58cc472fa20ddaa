// Flow in the joints (core/flow.hpp) against closed forms: the cubic law along a
// fracture through Voronoi blocks, hydrostatic pressure carrying no flow, and a
// pressure step diffusing along one fracture as erfc.
#include "core/flow.hpp"
#include "meshing/blocks.hpp"
#include "meshing/spec.hpp"

#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <vector>

using namespace bbm;

namespace {

/// A region of Voronoi blocks of size d: a rectangle, with a circular hole of
/// radius r about `hole` when r > 0, and the real joints `joints`.
meshing::BlockAssembly voronoi_region(Vec2 lo, Vec2 hi, double size, std::uint64_t seed,
                                      std::vector<meshing::SegmentSpec> joints = {}, Vec2 hole = {},
                                      double radius = 0.0) {
    meshing::ModelGeometrySpec g;
    g.max_segment = 0.1;
    meshing::RegionSpec r;
    r.name = "rock";
    r.outline.min = lo;
    r.outline.max = hi;
    if (radius > 0.0) {
        meshing::OutlineSpec h;
        h.kind = meshing::OutlineSpec::Kind::circle;
        h.center = hole;
        h.radius = radius;
        r.holes.push_back(h);
    }
    r.pattern.kind = meshing::PatternSpec::Kind::voronoi;
    r.pattern.size = size;
    r.pattern.seed = seed;
    r.joints = std::move(joints);
    g.regions.push_back(r);
    return meshing::generate_blocks(g);
}

/// A W × H region of Voronoi blocks of size d with one straight fracture along
/// y = H / 2 from side to side (a real joint: its joints are tagged so).
meshing::BlockAssembly fractured_region(double width, double height, double size, std::uint64_t seed = 1) {
    return voronoi_region({0.0, 0.0}, {width, height}, size, seed, {{{0.0, 0.5 * height}, {width, 0.5 * height}}});
}

/// Aperture a on the fracture's pipes, 0 (closed) on every other joint.
flow::State fracture_open(const flow::Network& n, const meshing::BlockAssembly& a, double aperture) {
    flow::State s(n);
    for (int k = 0; k < n.pipes(); ++k)
        s.aperture[k] = a.joints[n.pipe_joint[k]].tag == meshing::JointTag::real_joint ? aperture : 0.0;
    return s;
}

} // namespace

TEST_CASE("flow: the joint network's domains are the joints' ends, each junction once") {
    const auto a = fractured_region(2.0, 1.0, 0.2);
    const auto n = flow::Network::of_joints(a);
    CHECK(n.pipes() == int(a.joints.size()));
    // Euler on the planar graph of joints: inner junctions of a Voronoi tiling
    // join three joints, so domains are far fewer than joint ends.
    CHECK(n.domains() < n.pipes());
    std::vector<int> degree(n.domains(), 0);
    for (int k = 0; k < n.pipes(); ++k) ++degree[n.pipe_from[k]], ++degree[n.pipe_to[k]];
    int lonely = 0;
    for (int i = 0; i < n.domains(); ++i) lonely += degree[i] == 1;
    // Only the domains on the region's outline end one joint.
    for (int i = 0; i < n.domains(); ++i) {
        if (degree[i] != 1) continue;
        const Vec2 p = n.domain_position[i];
        const double to_edge = std::min({p.x, 2.0 - p.x, p.y, 1.0 - p.y});
        CHECK(to_edge < 1e-9);
    }
    CHECK(lonely > 0);
}

TEST_CASE("flow: a fracture between two held pressures carries the cubic law's rate, a^3 / (12 mu) dp / L") {
    const double width = 4.0, a0 = 1e-4, dp = 1e5;
    const auto a = fractured_region(width, 2.0, 0.2);
    const auto n = flow::Network::of_joints(a);
    flow::FluidSpec f;
    auto s = fracture_open(n, a, a0);
    std::vector<std::uint8_t> left(n.domains(), 0), right(n.domains(), 0);
    for (int i = 0; i < n.domains(); ++i) {
        if (n.domain_position[i].x < 1e-9) s.hold(i, dp), left[i] = 1;
        if (n.domain_position[i].x > width - 1e-9) s.hold(i, 0.0), right[i] = 1;
    }
    const auto report = flow::solve_steady(n, f, s);
    CHECK(report.free_domains > 0);
    const double exact = a0 * a0 * a0 / (12.0 * f.viscosity) * dp / width;
    const double out_right = flow::outflow_at_held(n, f, s, right), out_left = flow::outflow_at_held(n, f, s, left);
    INFO("cubic law " << exact << " m2/s, bbm " << out_right);
    CHECK(out_right == doctest::Approx(exact).epsilon(1e-6));
    CHECK(out_left == doctest::Approx(-exact).epsilon(1e-6)); // what goes in at the left comes out at the right
    test::record_check(test::Against::closed_form, "flow along a fracture through 0.2 m Voronoi blocks, a 0.1 mm",
                       "cubic law q = a³ Δp / (12 μ L) = " + test::figure(exact) + " m²/s", "1e-6 relative",
                       test::figure(out_right, 7) + " m²/s (" + test::percent(out_right, exact, 1) + ")",
                       std::abs(out_right / exact - 1.0) <= 1e-6);
    // The pressure falls linearly along the fracture.
    int on_fracture = 0;
    for (int i = 0; i < n.domains(); ++i) {
        if (std::abs(n.domain_position[i].y - 1.0) > 1e-9 || left[i] || right[i]) continue;
        CHECK(s.pressure[i] == doctest::Approx(dp * (1.0 - n.domain_position[i].x / width)).epsilon(1e-6));
        ++on_fracture;
    }
    CHECK(on_fracture >= 10);
}

TEST_CASE("flow: hydrostatic pressure carries no flow, and the steady state of a network held so is hydrostatic") {
    const double height = 2.0, rho = 1000.0, g = 9.81;
    const auto a = fractured_region(3.0, height, 0.25, 4);
    const auto n = flow::Network::of_joints(a);
    flow::FluidSpec f;
    f.gravity = {0.0, -g};
    flow::State s(n, 5e-5); // every joint open
    for (int i = 0; i < n.domains(); ++i) {
        const double y = n.domain_position[i].y;
        if (y > height - 1e-9) s.hold(i, 0.0);                 // the water table at the top
        if (y < 1e-9) s.hold(i, rho * g * height);             // its pressure at the bottom
    }
    const auto report = flow::solve_steady(n, f, s);
    CHECK(report.isolated_domains == 0);
    double worst = 0.0;
    for (int i = 0; i < n.domains(); ++i)
        worst = std::max(worst, std::abs(s.pressure[i] - rho * g * (height - n.domain_position[i].y)));
    CHECK(worst < 1e-6 * rho * g * height);
    double largest_flow = 0.0;
    for (double q : flow::pipe_flows(n, f, s)) largest_flow = std::max(largest_flow, std::abs(q));
    // Against the flow one pascal per metre would drive through these apertures.
    CHECK(largest_flow < 1e-6 * (5e-5 * 5e-5 * 5e-5 / (12.0 * f.viscosity)) * rho * g);
}

TEST_CASE("flow: a pressure step diffuses along one fracture as p0 erfc(x / (2 sqrt(D t))), D = K_w a^2 / (12 mu)") {
    const double length = 10.0, a0 = 2e-5, p0 = 1e6;
    const auto a = fractured_region(length, 1.0, 0.1, 2);
    const auto n = flow::Network::of_joints(a);
    flow::FluidSpec f;
    auto s = fracture_open(n, a, a0);
    for (int i = 0; i < n.domains(); ++i)
        if (n.domain_position[i].x < 1e-9) s.hold(i, p0);
    const double diffusivity = f.bulk_modulus * a0 * a0 / (12.0 * f.viscosity);
    const double spread = 1.5; // sqrt(D t), m
    const double t = spread * spread / diffusivity;
    const int substeps = flow::advance(n, f, s, t);
    CHECK(s.time == doctest::Approx(t));
    MESSAGE("erfc test: D = " << diffusivity << " m2/s, t = " << t << " s in " << substeps << " sub-steps");
    double worst = 0.0;
    int compared = 0;
    for (int i = 0; i < n.domains(); ++i) {
        const Vec2 x = n.domain_position[i];
        if (std::abs(x.y - 0.5) > 1e-9 || x.x < 1e-9) continue;
        const double exact = p0 * std::erfc(x.x / (2.0 * spread));
        worst = std::max(worst, std::abs(s.pressure[i] - exact));
        ++compared;
    }
    MESSAGE("largest difference from erfc: " << worst / p0 * 100.0 << "% of p0 over " << compared << " domains");
    CHECK(compared > 60);
    CHECK(worst < 1e-3 * p0); // 0.003% measured: the fracture's pipes are short against sqrt(D t)
    test::record_check(test::Against::closed_form, "pressure step diffusing along a fracture, √(Dt) 1.5 m",
                       "p0 erfc(x / 2√(Dt)), D = K_w a² / (12 μ)", "largest difference < 0.1% of p0",
                       test::figure(100.0 * worst / p0, 2) + "% of p0 at " + std::to_string(compared) + " domains",
                       worst < 1e-3 * p0);
}

namespace {

/// The network's equivalent conductivity κ (Darcy: u = −κ ∇p, m²/(Pa·s) per unit
/// depth) across an L × L sample: pressure P held on one side, 0 on the other,
/// the two sides between sealed; the mean of the x and y directions.
double equivalent_conductivity(double side, double size, double aperture, std::uint64_t seed) {
    const auto a = voronoi_region({0.0, 0.0}, {side, side}, size, seed);
    const auto n = flow::Network::of_joints(a);
    const flow::FluidSpec f;
    double sum = 0.0;
    for (int axis = 0; axis < 2; ++axis) {
        flow::State s(n, aperture);
        std::vector<std::uint8_t> outlet(n.domains(), 0);
        for (int i = 0; i < n.domains(); ++i) {
            const double x = axis == 0 ? n.domain_position[i].x : n.domain_position[i].y;
            if (x < 1e-9) s.hold(i, 1e5);
            if (x > side - 1e-9) s.hold(i, 0.0), outlet[i] = 1;
        }
        flow::solve_steady(n, f, s);
        sum += flow::outflow_at_held(n, f, s, outlet) / (1e5 / side) / side;
    }
    return 0.5 * sum;
}

} // namespace

TEST_CASE("flow: steady inflow into a circular tunnel below the water table, against Goodman's Q = 2 pi k H / ln(2H/r)") {
    // A tunnel of radius r, its centre H below the water table (the ground
    // surface, held at the pressure P = ρ_w g H over the tunnel's drained wall: no
    // gravity term, the same potential problem), in a uniformly jointed block mass
    // whose conductivity κ is measured on a sample of the same pattern.
    const double size = 0.3, aperture = 5e-5, r = 1.0, depth = 5.0, pressure = 1e5;
    const double half_width = 20.0, bottom = -20.0;
    std::string differences;
    bool all_within = true;
    for (std::uint64_t seed : {11, 12, 13}) { // the sample and the tunnel on other seeds
        const double kappa = equivalent_conductivity(8.0, size, aperture, seed);
        const auto a = voronoi_region({-half_width, bottom}, {half_width, 0.0}, size, seed + 100, {}, {0.0, -depth}, r);
        const auto n = flow::Network::of_joints(a);
        const flow::FluidSpec f;
        flow::State s(n, aperture);
        std::vector<std::uint8_t> wall(n.domains(), 0);
        for (int i = 0; i < n.domains(); ++i) {
            const Vec2 p = n.domain_position[i];
            if (p.y > -1e-9) s.hold(i, pressure);
            if (norm(p - Vec2{0.0, -depth}) < r + 1e-6) s.hold(i, 0.0), wall[i] = 1;
        }
        const auto report = flow::solve_steady(n, f, s);
        const double inflow = flow::outflow_at_held(n, f, s, wall);
        const double goodman = 2.0 * M_PI * kappa * pressure / std::log(2.0 * depth / r);
        // The image solution for a circle (Goodman's formula is its limit for H >> r).
        const double circle = 2.0 * M_PI * kappa * pressure / std::acosh(depth / r);
        MESSAGE("seed " << seed << ": kappa " << kappa << " m2/(Pa s); " << n.domains() << " domains ("
                        << report.free_domains << " free); inflow " << inflow << " m2/s against Goodman " << goodman
                        << " (" << (inflow / goodman - 1.0) * 100.0 << "%) and the circle's image solution " << circle
                        << " (" << (inflow / circle - 1.0) * 100.0 << "%)");
        CHECK(inflow == doctest::Approx(goodman).epsilon(0.10));
        differences += (differences.empty() ? "" : ", ") + test::percent(inflow, goodman);
        all_within = all_within && std::abs(inflow / goodman - 1.0) <= 0.10;
    }
    test::record_check(test::Against::closed_form, "inflow into a tunnel 5 m below the water table, 0.3 m blocks",
                       "Goodman Q = 2π k H / ln(2H/r), k measured on the same pattern", "within 10%, each of 3 seeds",
                       differences, all_within);
}

TEST_CASE("flow: a chain of joints over 16 decades of conductance (intact bonds beside parted blocks) solves to its "
          "series closed form, uphill too") {
    // Domains 0..40 along a line rising at 30 degrees, 0 held at p0 and 40 at 0;
    // pipes alternately a bond of 0.05 um and a 1 cm gap. Each pair joined by a
    // gap floats between two bonds: a mode the plain factorisation cannot resolve
    // (its pivot is the bonds' conductance less rounding of the gap's: unmerged,
    // the solve's residual passed with pressures half the true ones). The flux
    // is q = (p0 − ρ g Δy) / Σ(1/c) (heads add in series), and the pressure falls
    // by q / c_i + ρ g dy across pipe i.
    const int pipes = 40;
    flow::Network n;
    const Vec2 step{0.1 * std::cos(3.141592653589793 / 6), 0.1 * std::sin(3.141592653589793 / 6)};
    for (int i = 0; i <= pipes; ++i) n.domain_position.push_back(double(i) * step);
    for (int i = 0; i < pipes; ++i)
        n.pipe_from.push_back(i), n.pipe_to.push_back(i + 1), n.pipe_length.push_back(0.1), n.pipe_joint.push_back(i);
    flow::FluidSpec f;
    f.gravity = {0.0, -9.81};
    flow::State s(n);
    for (int i = 0; i < pipes; ++i) s.aperture[i] = i % 2 ? 1e-2 : 5e-8;
    const double p0 = 4e6, rho_g_dy = 1000.0 * 9.81 * step.y;
    s.hold(0, p0), s.hold(pipes, 0.0);
    double resistance = 0.0;
    for (int i = 0; i < pipes; ++i) resistance += 1.0 / flow::conductance(n, f, s, i);
    const double q = (p0 - pipes * rho_g_dy) / resistance;
    const auto report = flow::solve_steady(n, f, s);
    CHECK(report.merged_pipes == pipes / 2);
    double expected = p0;
    for (int i = 1; i < pipes; ++i) {
        expected -= q / flow::conductance(n, f, s, i - 1) + rho_g_dy;
        CHECK(s.pressure[i] == doctest::Approx(expected).epsilon(1e-7).scale(p0));
    }
    // The flux through every pipe is q: nothing is lost in the merged gaps.
    const auto flows = flow::pipe_flows(n, f, s);
    CHECK(flows[0] == doctest::Approx(q).epsilon(1e-6));
    CHECK(flows[pipes - 1] == doctest::Approx(q).epsilon(1e-6));
}
