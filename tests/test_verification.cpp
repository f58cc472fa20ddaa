// Verification problems of the rigid-block engine (issue 3): the model files in
// examples/verification/ run through the solver and compared with analytic answers.
#include "io/model_input.hpp"
#include "core/stages.hpp"
#include "studies/lab/labtest.hpp"
#include "core/solver.hpp"

#include "tests/softening_reference.hpp"

#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <numbers>

using namespace bbm;

namespace {

struct Loaded {
    io::ModelFile file;
    meshing::BlockAssembly blocks;
};

Loaded load(const std::string& name) {
    Loaded l;
    l.file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/verification/" + name);
    l.blocks = meshing::generate_blocks(l.file.geometry);
    return l;
}

double tan_deg(double d) { return std::tan(d * std::numbers::pi / 180.0); }


struct Silent : StageObserver {};

/// The rock and the frictional property of contacts formed during a run, shared by
/// the two-block models written inline below.
const std::string two_block_materials = R"(
[[material]]
name = "rock"
density = 2700.0
[[joint_property]]
name = "slide"
law = "coulomb"
kn = 10.0e9
ks = 4.0e9
friction = 30.0
)";

/// Reads a model from text (with the materials above), builds it and runs its stages.
std::unique_ptr<Solver> run_text(const std::string& text, const std::string& name) {
    const auto file = io::parse_model(text + two_block_materials, name);
    const auto blocks = meshing::generate_blocks(file.geometry);
    auto s = std::make_unique<Solver>(blocks, file.analysis);
    Silent quiet;
    run_stages(*s, file.analysis.stages, quiet);
    return s;
}

} // namespace

TEST_CASE("verification 1: a bonded joint opened monotonically follows the tension curve, work = G_I") {
    auto m = load("joint_opening.toml");
    Solver s(m.blocks, m.file.analysis);
    REQUIRE(contacts(s.world()).size() == 2);
    const double kn = 96.6e9, st = 3e6, u0 = st / kn;
    double work = 0.0, max_err = 0.0, prev_u = 0.0;
    for (int k = 0; k < 500; ++k) {
        s.step();
        // The joint's tension is the pull the joint exerts back on the block, over 1 m.
        const double stress = -boundary_force(s.world(), "pull").x;
        const double u = s.world().bodies.state[1].centroid.x - s.world().blocks.centroid0[1].x;
        // Stresses at step k come from the displacement reached at its start.
        max_err = std::max(max_err, std::abs(stress / st - softening_reference(prev_u / u0, 1.7, 0.5, 4.0)));
        work += stress * (u - prev_u);
        prev_u = u;
    }
    CHECK(max_err < 1e-6);
    CHECK(cracks(s.world(), contact::JointState::broken_tension) == 2);
    CHECK(dissipated_energy(s.world()) == doctest::Approx(149.07).epsilon(0.01));
    CHECK(work == doctest::Approx(1.6 * st * st / kn).epsilon(0.01));
    const double g_i = 1.6 * st * st / kn;
    test::record_check(test::Against::closed_form, "work of opening a bonded joint to failure (SPEC's bilinear law)",
                       "G_I = area under the tension curve = " + test::figure(g_i, 4) + " J/m²",
                       "within 1%; the curve's points within 1e-6 of σt",
                       test::figure(work, 4) + " J/m² (" + test::percent(work, g_i) + "); points within " +
                           test::figure(max_err, 1),
                       std::abs(work / g_i - 1.0) <= 0.01 && max_err < 1e-6);
}

TEST_CASE("verification 2: a bonded joint in shear at sn = 0 and sn = 5 MPa") {
    const double ks = 40.3e9, c = 9.5e6, u0 = c / ks;
    for (double sn : {0.0, 5e6}) {
        INFO("sigma_n = " << sn);
        auto m = load("joint_shear.toml");
        m.file.analysis.stages[0].stress.sxx = -sn;
        Solver s(m.blocks, m.file.analysis);
        Silent quiet;
        run_stages(s, {m.file.analysis.stages[0]}, quiet);
        double work = 0.0, prev_u = 0.0, peak = 0.0, max_err = 0.0;
        for (int k = 0; k < 3000; ++k) {
            s.step();
            const double tau = -boundary_force(s.world(), "shear").y, u = s.world().bodies.state[1].centroid.y - s.world().blocks.centroid0[1].y;
            peak = std::max(peak, tau);
            if (sn == 0.0) max_err = std::max(max_err, std::abs(tau / c - softening_reference(prev_u / u0, 1.3, 0.5, 2.1)));
            work += tau * (u - prev_u);
            prev_u = u;
        }
        const double residual = sn * tan_deg(25.0);
        CHECK(peak <= (c + residual) * (1 + 1e-12));
        CHECK(peak >= c + residual - ks * u0 / 1000);
        CHECK(-boundary_force(s.world(), "shear").y == doctest::Approx(residual).epsilon(1e-9));
        CHECK(cracks(s.world(), contact::JointState::broken_shear) == 2);
        if (sn == 0.0) {
            CHECK(max_err < 1e-6);
            CHECK(work == doctest::Approx(0.925 * c * c / ks).epsilon(0.01)); // 2071.5 J/m²
        }
    }
}

TEST_CASE("verification 3: a block on an inclined plane sticks below phi and slides above it") {
    const double g = 9.81, phi = 20.0;
    for (double theta : {15.0, 30.0, 45.0}) {
        INFO("theta = " << theta);
        auto m = load("sliding_block.toml");
        const double t = theta * std::numbers::pi / 180.0;
        m.file.analysis.solver.gravity = {g * std::sin(t), -g * std::cos(t)};
        m.file.analysis.stages[0].stress.syy = -2000.0 * g * std::cos(t);
        Solver s(m.blocks, m.file.analysis);
        Silent quiet;
        run_stages(s, {m.file.analysis.stages[0]}, quiet);
        // Let the shear spring take up the load, then measure over a long window.
        for (int k = 0; k < 200; ++k) s.step();
        const double t0 = s.world().clock.time, v0 = s.world().bodies.state[1].velocity.x;
        for (int k = 0; k < 2000; ++k) s.step();
        const double a = (s.world().bodies.state[1].velocity.x - v0) / (s.world().clock.time - t0);
        if (theta < phi) {
            CHECK(std::abs(s.world().bodies.state[1].centroid.x - s.world().blocks.centroid0[1].x) < 1e-4);
            CHECK(std::abs(a) < 1e-3);
        } else {
            const double expected = g * (std::sin(t) - std::cos(t) * tan_deg(phi));
            CHECK(a == doctest::Approx(expected).epsilon(0.01));
        }
    }
}

TEST_CASE("verification 4: square lattice under uniaxial stress: E = kn d, nu = 0") {
    auto m = load("square_lattice.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    const auto reports = run_stages(s, m.file.analysis.stages, quiet);
    REQUIRE(reports[0].converged);
    const double kn = 10e9, d = 0.5, sigma = 1e4;
    double max_ux = 0.0;
    for (int i = 0; i < s.world().bodies.count(); ++i) {
        max_ux = std::max(max_ux, std::abs(s.world().bodies.state[i].centroid.x - s.world().blocks.centroid0[i].x));
        if (s.world().blocks.centroid0[i].y > 2.0) {
            // Four joint layers above the fixed row, over a gauge of 4 d.
            const double strain = -(s.world().bodies.state[i].centroid.y - s.world().blocks.centroid0[i].y) / (4 * d);
            CHECK(sigma / strain == doctest::Approx(kn * d).epsilon(1e-6));
        }
    }
    const double uy = 4 * sigma / kn;
    CHECK(max_ux < 1e-6 * uy); // ν = 0 (to second order in the strain, see the model file)
    double top_strain = 0.0;
    for (int i = 0; i < s.world().bodies.count(); ++i)
        if (s.world().blocks.centroid0[i].y > 2.0) top_strain = -(s.world().bodies.state[i].centroid.y - s.world().blocks.centroid0[i].y) / (4 * d);
    test::record_check(test::Against::closed_form, "modulus of a square lattice of blocks, uniaxial stress",
                       "E = kn d = " + test::figure(kn * d / 1e9) + " GPa, ν = 0", "1e-6 relative",
                       test::figure(sigma / top_strain / 1e9, 7) + " GPa, lateral displacement " +
                           test::figure(max_ux / uy, 1) + " of the axial",
                       std::abs(sigma / top_strain / (kn * d) - 1.0) <= 1e-6 && max_ux < 1e-6 * uy);
}

TEST_CASE("verification 5: undamped oscillation on a joint conserves energy over 1000 periods") {
    auto m = load("oscillator.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    run_stages(s, {m.file.analysis.stages[0]}, quiet);
    const double e0 = strain_energy(s.world());
    CHECK(e0 == doctest::Approx(500.0)); // σ²/(2 kn) × 1 m
    const double period = 2 * std::numbers::pi * std::sqrt(1000.0 / 1e9);
    const long per = std::lround(period / s.world().clock.dt);
    // Amplitude of the strain energy in the first and the thousandth period.
    auto peak_over_period = [&] {
        double e = 0.0;
        for (long k = 0; k < per + 2; ++k) {
            s.step();
            e = std::max(e, strain_energy(s.world()));
        }
        return e;
    };
    const double first = peak_over_period();
    while (s.world().clock.time < 999 * period) s.step();
    const double last = peak_over_period();
    INFO("first " << first << ", last " << last << ", steps per period " << per);
    CHECK(first == doctest::Approx(e0).epsilon(0.005));
    CHECK(last == doctest::Approx(first).epsilon(0.005));
}

TEST_CASE("verification 7: uniform in-situ stress of a Voronoi assembly is in equilibrium") {
    auto m = load("insitu_voronoi.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    run_stages(s, m.file.analysis.stages, quiet);
    CHECK(s.world().clock.ratio < 1e-6);
    double max_u = 0.0;
    for (int i = 0; i < s.world().bodies.count(); ++i)
        max_u = std::max(max_u, norm(s.world().bodies.state[i].centroid - s.world().blocks.centroid0[i]));
    CHECK(max_u < 1e-12);
    // Block-averaged stress equals the field in every block (SPEC §7).
    for (const auto& st : block_stresses(s.world())) {
        CHECK(st[0] == doctest::Approx(-10e6).epsilon(1e-9));
        CHECK(st[1] == doctest::Approx(-20e6).epsilon(1e-9));
        CHECK(st[2] == doctest::Approx(-3e6).epsilon(1e-9));
    }
}

TEST_CASE("verification 6: a block dropped on a bonded base forms contacts and comes to rest") {
    auto m = load("dropped_block.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    run_stages(s, m.file.analysis.stages, quiet);
    const int block = s.world().bodies.count() - 1; // the last region's single block
    CHECK(s.world().detection.totals.created > 0);
    CHECK(s.world().bodies.state[block].centroid.y - s.world().blocks.centroid0[block].y == doctest::Approx(-0.5).epsilon(1e-3));
    CHECK(s.world().clock.ratio < 1e-6);
    CHECK(kinetic_energy(s.world()) < 1e-6);
    // No overlap beyond the tolerance, measured geometrically: no vertex of the block
    // inside a base block, nor a base vertex inside the block, deeper than it.
    auto depth_inside = [&](Vec2 x, int blk) {
        const std::span<const Vec2> poly(s.world().vertices.position.data() + s.world().blocks.first[blk], s.world().vertices.position.data() + s.world().blocks.first[blk + 1]);
        if (!point_in_polygon(x, poly)) return 0.0;
        double d = INFINITY;
        for (std::size_t i = 0; i < poly.size(); ++i) d = std::min(d, distance_to_segment(x, poly[i], poly[(i + 1) % poly.size()]));
        return d;
    };
    double deepest = 0.0;
    for (int o = 0; o < block; ++o) {
        for (auto v = s.world().blocks.first[block]; v < s.world().blocks.first[block + 1]; ++v) deepest = std::max(deepest, depth_inside(s.world().vertices.position[v], o));
        for (auto v = s.world().blocks.first[o]; v < s.world().blocks.first[o + 1]; ++v) deepest = std::max(deepest, depth_inside(s.world().vertices.position[v], block));
    }
    INFO("deepest penetration " << deepest << " m, tolerance " << s.world().detection.tolerance);
    CHECK(deepest < 0.01 * s.world().detection.tolerance);
    // The weight is carried: vertical contact force on the block = m g.
    double fy = 0.0;
    const auto& c = contacts(s.world());
    for (int i = 0; i < c.size(); ++i) {
        if (c.vertex_block[i] == block) fy += contact::contact_force(c, i).y;
        if (c.edge_block[i] == block) fy -= contact::contact_force(c, i).y;
    }
    CHECK(fy == doctest::Approx(2700.0 * 9.81).epsilon(1e-6));
}

TEST_CASE("new contact lengths: half the edge, or the faces' overlap shared by its two end contacts") {
    // A 1 m square set 5 mm (within the tolerance) above a 2 m wide block,
    // overhanging its right edge by 0.2 m: the faces overlap over 0.8 m. Contacts:
    // the square's left corner on the base's top face, the base's right corner on
    // the square's bottom face.
    const std::string text = R"(
[solver]
mode = "dynamic"
damping = 0.3
gravity = [0.0, -9.81]
new_contact_property = "slide"
detection_tolerance = 0.01
NEW_CONTACT_LENGTH
[[region]]
name = "base"
outline = { type = "rectangle", min = [0.0, 0.0], max = [2.0, 1.0] }
pattern = { type = "single" }
[[region]]
name = "block"
outline = { type = "rectangle", min = [1.2, 1.005], max = [2.2, 2.005] }
pattern = { type = "single" }
[[boundary]]
name = "bottom"
type = "velocity"
box = { min = [-1.0, -1.0], max = [3.0, 0.6] }
vx = 0.0
vy = 0.0
omega = 0.0
[[stage]]
name = "drop"
type = "cycle"
steps = 6000
)";
    auto lengths = [&](const std::string& rule) {
        std::string t = text;
        t.replace(t.find("NEW_CONTACT_LENGTH"), 18, rule);
        const auto s = run_text(t, "drop.toml");
        const auto& c = contacts(s->world());
        double total = 0.0;
        int n = 0;
        for (int i = 0; i < c.size(); ++i) total += c.length[i], ++n;
        CHECK(n == 2);
        CHECK(kinetic_energy(s->world()) < 1e-6); // at rest on the base, not tipped
        return total;
    };
    CHECK(lengths("") == doctest::Approx(0.5 * 1.0 + 0.5 * 2.0).epsilon(1e-9));
    CHECK(lengths("new_contact_length = \"overlap\"") == doctest::Approx(0.8).epsilon(1e-3));
}

TEST_CASE("a vertex beside an acute corner, outside the block, is not born in overlap") {
    // Block B is a sliver with an 11.4° tip at the origin. A's corner moves in at
    // 0.3 mm a step (quasi-static, Δt = 1) and is detected about 2 mm beyond the
    // tip, 1 mm below the line of B's upper edge — the nearest — and 1.2 mm
    // outside the line of its lower one: outside B. Taken against the upper edge
    // it was inside the rounded corner (r = 5 mm, a circle tangent to that edge
    // at the tip, which reaches past so sharp a corner) and was born 0.3 mm in
    // overlap, pushing with kn × 0.3 mm = 3 MPa on nothing, while its approach
    // across the lower edge went unseen. It faces the lower edge: the contact is
    // that edge's and starts open (issue 12, docs/calibration.md, "After the
    // peak", fix 4).
    const std::string text = R"(
[solver]
new_contact_property = "slide"
detection_tolerance = 0.01
corner_radius = 0.005
[[region]]
name = "a"
outline = { type = "polygon", points = [[-0.0056, -0.001], [-0.5, 0.2], [-0.5, -0.3]] }
pattern = { type = "single" }
[[region]]
name = "b"
outline = { type = "polygon", points = [[0.0, 0.0], [1.0, -0.1], [1.0, 0.1]] }
pattern = { type = "single" }
[[boundary]]
name = "push"
type = "velocity"
box = { min = [-1.0, -1.0], max = [-0.1, 1.0] }
vx = 0.0003
vy = 0.0
omega = 0.0
[[boundary]]
name = "hold"
type = "velocity"
box = { min = [0.3, -1.0], max = [2.0, 1.0] }
vx = 0.0
vy = 0.0
omega = 0.0
[[stage]]
name = "approach"
type = "cycle"
steps = 13
)";
    const auto s = run_text(text, "corner.toml");
    const auto& c = contacts(s->world());
    REQUIRE(c.size() >= 1);
    const Vec2 corner = s->world().vertices.position[c.vertex_id[0]];
    INFO("corner at (" << corner.x << ", " << corner.y << "), un " << c.history[0].un << " m, sn " << c.history[0].sn
                       << " Pa");
    CHECK(c.vertex_block[0] == 0); // A's corner against B's edge
    CHECK(corner.x < 0.0);         // still beside the tip, outside B
    // The lower edge, (0, 0) to (1, -0.1): its outward normal points down, and the
    // gap is to its rounded corner at the tip, centre r inside: 6.48 mm - r.
    CHECK(s->world().vertices.position[c.edge_id[0]].x == doctest::Approx(0.0));
    CHECK(s->world().vertices.position[c.edge_end[0]].y == doctest::Approx(-0.1));
    CHECK(c.history[0].un == doctest::Approx(1.476e-3).epsilon(0.01));
    CHECK(c.history[0].sn == 0.0);
}

TEST_CASE("verification 8: determinism — the state hash after a cracking run is pinned") {
    auto m = load("determinism.toml");
    Solver a(m.blocks, m.file.analysis), b(m.blocks, m.file.analysis);
    Silent quiet;
    run_stages(a, m.file.analysis.stages, quiet);
    run_stages(b, m.file.analysis.stages, quiet);
    CHECK(state_hash(a.world()) == state_hash(b.world()));
    CHECK(cracks(a.world(), contact::JointState::broken_tension) > 0);
    // Pinned for this compiler and flags (g++ 12, Release, x86-64); see the model file.
    // Re-pinned when detection stopped creating contacts on tessellation junctions,
    // when the Voronoi size became the blocks' mean Feret diameter, and when forces
    // came to be summed per block in contact order (the same on any thread count),
    // blocks numbered along a Hilbert curve and rotations taken from rotation();
    // and when the hash came to cover every saved field of the state list (the
    // same run: tests/recorded_states.json's steps and cracks unchanged), and when
    // each non-empty field came to be hashed with its name and an empty one not at all.
    CHECK(state_hash(a.world()) == 5282646459962396154ull);
}

TEST_CASE("excavation stage: support relaxed gradually, walls move in, hoop stress concentrates") {
    auto m = load("excavation.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    const auto reports = run_stages(s, m.file.analysis.stages, quiet);
    REQUIRE(reports.size() == 3);
    CHECK(reports[1].steps == 500);
    CHECK(reports[2].converged);
    const auto stress = block_stresses(s.world());
    const double p = 10e6, a = 1.5;
    int wall = 0, inward = 0;
    std::vector<double> hoop(4, 0.0);
    std::vector<int> count(4, 0);
    for (int i = 0; i < s.world().bodies.count(); ++i) {
        if (s.world().bodies.removed[i]) continue;
        const Vec2 c = s.world().blocks.centroid0[i];
        const double r = norm(c);
        if (r < a + 0.3) {
            ++wall;
            inward += dot(s.world().bodies.state[i].centroid - c, c) < 0;
        }
        const Vec2 et = perp(c / r);
        const double s_hoop = -(stress[i][0] * et.x * et.x + stress[i][1] * et.y * et.y + 2 * stress[i][2] * et.x * et.y);
        for (int k = 0; k < 4; ++k)
            if (std::abs(r - (1.75 + 0.5 * k)) < 0.125) hoop[k] += s_hoop, ++count[k];
    }
    CHECK(wall > 40);
    CHECK(inward == wall);
    for (int k = 0; k < 4; ++k) hoop[k] /= count[k];
    INFO("hoop at r = 1.75, 2.25, 2.75, 3.25 m: " << hoop[0] << " " << hoop[1] << " " << hoop[2] << " " << hoop[3]);
    // Kirsch gives 1.73 p at 1.75 m in an infinite plate; this 8 m plate carries the
    // load across a ligament of 2.5 m, so its stresses lie higher (mean hoop stress
    // across the ligament 1.6 p by equilibrium, Kirsch's mean there 1.375 p).
    CHECK(hoop[0] > 1.5 * p);
    CHECK(hoop[0] > hoop[1]);
    CHECK(hoop[1] > hoop[2]);
    CHECK(hoop[3] > p);
    CHECK(hoop[0] < 2.0 * p * (1 + a * a / (1.75 * 1.75)));
}

TEST_CASE("hexagonal lattice of rigid blocks: E and nu match the closed form") {
    auto m = load("hexagonal_lattice.toml");
    Solver s(m.blocks, m.file.analysis);
    Silent quiet;
    const auto reports = run_stages(s, m.file.analysis.stages, quiet);
    REQUIRE(reports[0].converged);
    // Least-squares strains from interior blocks (1 m away from every edge).
    std::vector<double> x, ux, y, uy;
    for (int i = 0; i < s.world().bodies.count(); ++i) {
        const Vec2 c = s.world().blocks.centroid0[i];
        if (c.x < 1 || c.x > 5 || c.y < 1 || c.y > 7) continue;
        x.push_back(c.x), ux.push_back(s.world().bodies.state[i].centroid.x - c.x);
        y.push_back(c.y), uy.push_back(s.world().bodies.state[i].centroid.y - c.y);
    }
    REQUIRE(x.size() > 200);
    const double exx = fit_slope(x, ux), eyy = fit_slope(y, uy);
    const double kn = 96.6e9, ks = 40.3e9, a = 0.3;
    const double E = 2 * a * kn * (kn + ks) / (3 * kn + ks), nu = (kn - ks) / (3 * kn + ks);
    INFO("E " << 1e6 / -eyy << " (closed form " << E << "), nu " << -exx / eyy << " (" << nu << ")");
    CHECK(1e6 / -eyy == doctest::Approx(E).epsilon(0.01));
    CHECK(-exx / eyy == doctest::Approx(nu).epsilon(0.02));
    test::record_check(test::Against::closed_form, "E and ν of a hexagonal lattice of rigid blocks",
                       "E = 2a kn (kn + ks) / (3kn + ks) = " + test::figure(E / 1e9) + " GPa, ν = (kn − ks) / (3kn + ks) = " +
                           test::figure(nu),
                       "E within 1%, ν within 2%",
                       "E " + test::figure(1e6 / -eyy / 1e9) + " GPa (" + test::percent(1e6 / -eyy, E) + "), ν " +
                           test::figure(-exx / eyy) + " (" + test::percent(-exx / eyy, nu) + ")",
                       std::abs(1e6 / -eyy / E - 1.0) <= 0.01 && std::abs(-exx / eyy / nu - 1.0) <= 0.02);
}
