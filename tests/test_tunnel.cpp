// The paper's tunnel end to end (issue 6): the elastic reference against Kirsch,
// the side-wall failure of the trigon model and of Voronoi blocks with joints
// calibrated in bbm, and exact restart from a checkpoint.
#include "io/model_input.hpp"
#include "core/stages.hpp"
#include "studies/model/opening.hpp"
#include "core/solver.hpp"
#include "tests/restart.hpp"

#include <doctest/doctest.h>
#include "tests/validation.hpp"
#include "tests/validation_record.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

using namespace bbm;

namespace {

io::ModelFile read_example(const std::string& name) {
    return io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/" + name);
}

struct Quiet : StageObserver {};

/// Runs an example tunnel model to the end of its stages (the last one limited to
/// `max_steps` if > 0) on one thread (CTest runs tests side by side: a second
/// thread per test would oversubscribe the cores); returns the opening measures
/// and the cracks.
struct TunnelRun {
    OpeningMeasures opening;
    int tensile = 0, shear = 0;
    Verdict verdict; ///< of the last stage
    long steps = 0;
};
TunnelRun run_tunnel(const std::string& name, long max_steps = 0) {
    auto file = read_example(name);
    if (max_steps > 0) file.analysis.stages.back().max_steps = max_steps;
    file.analysis.solver.threads = 1;
    const auto blocks = meshing::generate_blocks(file.geometry);
    Solver s(blocks, file.analysis);
    Quiet q;
    const auto reports = run_stages(s, file.analysis.stages, q);
    return {measure_opening(s.world(), {0, 0}, {4, 0}, {0, 4}), cracks(s.world(), contact::JointState::broken_tension),
            cracks(s.world(), contact::JointState::broken_shear), reports.back().verdict, s.world().clock.steps};
}

// Kirsch, plane strain, infinite plate, vertical p = 15 MPa and horizontal 7.5 MPa
// (SPEC §8): hoop stress (compression positive, MPa) on the springline and crown lines.
double kirsch_hoop(double r, bool springline) {
    const double a = 4.0, pv = 15.0, ph = 7.5, q = (a * a) / (r * r);
    // θ from the horizontal: σθ = ½(pv+ph)(1 + q) − ½(ph − pv)(1 + 3q²) cos 2θ.
    const double c2 = springline ? 1.0 : -1.0;
    return 0.5 * (pv + ph) * (1 + q) - 0.5 * (ph - pv) * (1 + 3 * q * q) * c2;
}

} // namespace

TEST_CASE("tunnel: Kirsch reference values of SPEC §8") {
    CHECK(kirsch_hoop(4.0, true) == doctest::Approx(37.5));
    CHECK(kirsch_hoop(6.0, true) == doctest::Approx(22.2).epsilon(0.005));
    CHECK(kirsch_hoop(4.0, false) == doctest::Approx(7.5));
    CHECK(kirsch_hoop(6.0, false) == doctest::Approx(10.3).epsilon(0.005));
}

TEST_CASE("tunnel: elastic Voronoi model — hoop stress within 15% of Kirsch at 5, 6 and 8 m" * validation) {
    const auto file = read_example("tunnel_elastic.toml");
    const auto blocks = meshing::generate_blocks(file.geometry);
    Solver s(blocks, file.analysis);
    Quiet q;
    const auto reports = run_stages(s, file.analysis.stages, q);
    REQUIRE(reports.back().converged);
    CHECK(cracks(s.world(), contact::JointState::broken_tension) + cracks(s.world(), contact::JointState::broken_shear) == 0);
    // The model's vertical stress at the tunnel axis is 15 MPa plus the weight of
    // 20 m of rock: Kirsch scaled by that ratio.
    const double scale = (15e6 + 2700 * 9.81 * 20) / 15e6;
    const auto stress = block_stresses(s.world());
    const Vec2 c{0, 0};
    // The records' figures at 5, 6 and 8 m.
    std::string spring_ref, spring_got, spring_off, crown_ref, crown_got, crown_off;
    bool spring_held = true, crown_held = true;
    for (double r : {5.0, 6.0, 8.0}) {
        const double spring = -hoop_stress_at(s.world(), stress, c, {4, 0}, r, 0.5) / 1e6;
        const double crown = -hoop_stress_at(s.world(), stress, c, {0, 4}, r, 0.5) / 1e6;
        const double ks = scale * kirsch_hoop(r, true), kc = scale * kirsch_hoop(r, false);
        MESSAGE("r = " << r << " m: springline " << spring << " MPa (Kirsch " << ks << ", " << (spring / ks - 1) * 100
                       << "%), crown " << crown << " MPa (Kirsch " << kc << ", " << (crown / kc - 1) * 100 << "%)");
        CHECK(spring == doctest::Approx(ks).epsilon(0.15));
        CHECK(crown == doctest::Approx(kc).epsilon(0.15));
        const std::string sep = spring_ref.empty() ? "" : " / ";
        spring_held = spring_held && (spring == doctest::Approx(ks).epsilon(0.15));
        crown_held = crown_held && (crown == doctest::Approx(kc).epsilon(0.15));
        spring_ref += sep + test::figure(ks), spring_got += sep + test::figure(spring);
        spring_off += sep + test::percent(spring, ks);
        crown_ref += sep + test::figure(kc), crown_got += sep + test::figure(crown);
        crown_off += sep + test::percent(crown, kc);
    }
    const std::string kirsch =
        "Kirsch, pv 15, ph 7.5 MPa (SPEC §8) x " + test::figure(scale) + " for 20 m of rock's weight: ";
    test::record_check(test::Against::closed_form, "hoop stress beyond the springline at r = 5 / 6 / 8 m",
                       kirsch + spring_ref + " MPa", "each within 15%", spring_got + " MPa (" + spring_off + ")",
                       spring_held);
    test::record_check(test::Against::closed_form, "hoop stress beyond the crown at r = 5 / 6 / 8 m",
                       kirsch + crown_ref + " MPa", "each within 15%", crown_got + " MPa (" + crown_off + ")",
                       crown_held);
}

TEST_CASE("tunnel: a run resumed from a checkpoint ends in the same state as an uninterrupted one") {
    // The Voronoi tunnel through excavation into the failure stage (detection,
    // cracking, deformable far field), stopped mid-stage and resumed in a new
    // solver (more models and stops: test_restart.cpp).
    auto file = read_example("tunnel_voronoi.toml");
    file.analysis.stages.back().max_steps = 1500;
    file.analysis.stages.back().ratio = 1e-9;
    const auto blocks = meshing::generate_blocks(file.geometry);
    test::check_exact_restart({blocks, file.analysis}, {3700}, {1}); // excavation relaxes over 3000 steps

    // A checkpoint of another model is refused with a reason.
    Solver first(blocks, file.analysis);
    std::stringstream checkpoint;
    save_state(first.world(), checkpoint);
    auto other = read_example("verification/stack.toml");
    Solver wrong(meshing::generate_blocks(other.geometry), other.analysis);
    CHECK_THROWS_WITH_AS(load_state(wrong.world(), checkpoint), doctest::Contains("different model"), std::runtime_error);
}

TEST_CASE("tunnel: the trigon model fails at the side walls, not at the crown" * validation) {
    const auto r = run_tunnel("tunnel_trigon.toml", 8000); // the failure is well developed by then
    const auto& m = r.opening;
    MESSAGE("cracks " << r.tensile << " tensile, " << r.shear << " shear; springline sector " << m.cracks_springline_sector
                      << ", crown sector " << m.cracks_crown_sector << "; failed depth " << m.failed_depth_springline
                      << " m (springline), " << m.failed_depth_crown << " m (crown)");
    CHECK(m.cracks_springline_sector >= 20);
    CHECK(m.cracks_springline_sector >= 3 * m.cracks_crown_sector);
    test::record_check(test::Against::paper, "cracks in the springline and crown ±30° sectors at 8,000 steps",
                       "the paper's tunnel (§4.3): side-wall spalling, not the crown (docs/calibration.md)",
                       ">= 20 at the springline and >= 3x the crown's",
                       std::to_string(m.cracks_springline_sector) + " at the springline, " +
                           std::to_string(m.cracks_crown_sector) + " at the crown",
                       m.cracks_springline_sector >= 20 && m.cracks_springline_sector >= 3 * m.cracks_crown_sector);
    CHECK(r.shear > 0); // trigon: sliding along the triangle edges takes part
    // Cut at 8,000 steps, it is still breaking (issue 24: the verdict says so).
    MESSAGE(describe(r.verdict));
    CHECK(r.verdict.kind == Verdict::Kind::failing);
    CHECK(r.verdict.crack_rate > 0.0);
}

TEST_CASE("tunnel: Voronoi blocks with joints calibrated in bbm (macro friction 25°) fail at the side walls" * validation) {
    // The joint set bbm calibrate found for the paper's rock including its
    // confined strength (examples/tunnel_voronoi_calibrated.toml); with the
    // paper's UDEC values the Voronoi wall barely breaks (docs/calibration.md).
    const auto r = run_tunnel("tunnel_voronoi_calibrated.toml");
    const auto& m = r.opening;
    MESSAGE("cracks " << r.tensile << " tensile, " << r.shear << " shear; springline sector " << m.cracks_springline_sector
                      << ", crown sector " << m.cracks_crown_sector << "; failed depth " << m.failed_depth_springline
                      << " m (springline)");
    CHECK(m.cracks_springline_sector >= 20);
    CHECK(m.cracks_springline_sector >= 3 * m.cracks_crown_sector);
    CHECK(m.failed_depth_springline > 0.5);
    // With the far field straining along the rigid faces (face_shear, docs/theory.md
    // §11.1) the wall keeps spalling in bursts to its 30,000-step limit (501 cracks
    // there; 726 and still moving at 120,000): the verdict says it is still failing,
    // from cracks made over the run's last part — not equilibrium.
    MESSAGE(describe(r.verdict) << "; " << r.steps << " steps");
    CHECK(r.verdict.kind == Verdict::Kind::failing);
    CHECK(r.verdict.crack_rate > 0.0);
    CHECK(m.cracks_springline_sector >= 100);
}

TEST_CASE("failed zone lobes: each run of sectors with a depth, its depth-weighted direction, width and area") {
    // 36 sectors of 10 degrees round a 2 m opening: a notch over 80-120 degrees
    // (depths 0.2, 0.4, 0.4, 0.2: symmetric about 100), a lobe across 0 degrees
    // (350-10: 0.3, 0.3) and a one-sector lobe at 200-210 (0.1).
    FailedZone z;
    z.radius = 2.0;
    z.depth.assign(36, 0.0);
    z.wall_offset.assign(36, 0.0);
    z.depth[8] = 0.2, z.depth[9] = 0.4, z.depth[10] = 0.4, z.depth[11] = 0.2;
    z.depth[35] = 0.3, z.depth[0] = 0.3;
    z.depth[20] = 0.1;
    const auto lobes = z.lobes();
    REQUIRE(lobes.size() == 3);
    const double sector = std::numbers::pi / 18;
    auto ring = [&](double d) { return 0.5 * sector * ((2 + d) * (2 + d) - 4); };
    CHECK(lobes[0].centre_deg == doctest::Approx(100.0));
    CHECK(lobes[0].depth == doctest::Approx(0.4));
    CHECK(lobes[0].width_deg == doctest::Approx(40.0));
    CHECK(lobes[0].area == doctest::Approx(2 * ring(0.2) + 2 * ring(0.4)));
    // Across 0 degrees: one lobe, centred on 0 (reported in [0, 360)).
    CHECK(lobes[1].width_deg == doctest::Approx(20.0));
    CHECK(std::min(lobes[1].centre_deg, 360.0 - lobes[1].centre_deg) == doctest::Approx(0.0).epsilon(1e-9));
    CHECK(lobes[2].centre_deg == doctest::Approx(205.0));
    CHECK(lobes[2].area == doctest::Approx(ring(0.1)));
    // A zone all round is one lobe; no zone, none.
    z.depth.assign(36, 0.5);
    CHECK(z.lobes().size() == 1);
    z.depth.assign(36, 0.0);
    CHECK(z.lobes().empty());
}

TEST_CASE("failed zone: the damaged rock connected to the wall, its depth and extent, and a deep crack cluster apart is not in it") {
    // Issue 24: cracks written into the joints of the Voronoi tunnel at known
    // places: every joint within 1.2 m of the wall and 20 degrees of the
    // springline, and a cluster 3 to 3.6 m from the wall at the crown that the
    // wall's intact rock separates from it.
    const auto file = read_example("tunnel_voronoi.toml");
    const auto blocks = meshing::generate_blocks(file.geometry);
    Solver s(blocks, file.analysis);
    auto& c = contacts(s.world());
    const double a = 4.0, pi = 3.141592653589793;
    for (int i = 0; i < c.size(); ++i) {
        const Vec2 x = s.world().blocks.centroid0[c.vertex_block[i]] + s.world().vertices.local[c.vertex_id[i]];
        const double r = norm(x), angle = std::atan2(x.y, x.x) * 180 / pi;
        const bool wall = r - a < 1.2 && std::abs(angle) < 20.0;
        const bool deep = r - a > 3.0 && r - a < 3.6 && std::abs(angle - 90.0) < 20.0;
        if (wall || deep) c.history[i].broken = contact::JointState::broken_tension, c.history[i].bonded = false;
    }
    const auto z = measure_failed_zone(s.world(), {0, 0}, {4, 0}, {0, 4});
    MESSAGE("cell " << z.cell << " m; depth springline " << z.depth_springline << " m, crown " << z.depth_crown
                    << " m; extent " << z.extent_springline_deg << " deg; area " << z.area << " m2");
    // Depth: the outermost broken contact point, so 1.2 m or less by the spacing
    // of contact points (issue 48: a measure finer than a block; its step at the
    // Mine-by's blocks is asserted in the long suite); the cells' coarse measure,
    // the outer edge of the deepest damaged cell, 1.2 m to one cell more.
    MESSAGE("resolution " << z.resolution << " m");
    CHECK(z.resolution > 0.0);
    CHECK(z.resolution < 0.25 * z.cell);
    CHECK(z.depth_springline <= 1.2 + 1e-9);
    CHECK(z.depth_springline >= 1.2 - 2 * z.resolution);
    double cells_springline = 0;
    for (int k : {0, 1, 34, 35}) cells_springline = std::max(cells_springline, z.depth_cells[std::size_t(k)]);
    CHECK(cells_springline >= 1.2 - 1e-9);
    CHECK(cells_springline <= 1.2 + z.cell + 1e-9);
    // The crown cluster is not connected to the wall: no failed zone there.
    CHECK(z.depth_crown == 0.0);
    // +/-20 degrees: the four 10-degree sectors whose centres lie within it (and a
    // sector cut by its edge where its cells still pass the threshold).
    CHECK(z.extent_springline_deg >= 40.0);
    CHECK(z.extent_springline_deg <= 60.0);
    // The zone's area against the annular sector it covers.
    const double sector_area = pi * (std::pow(a + 1.2, 2) - a * a) * 40.0 / 360.0;
    CHECK(z.area >= 0.8 * sector_area);
    CHECK(z.area <= 2.0 * sector_area);
    // The deepest single crack (OpeningMeasures) sees the crown cluster.
    const auto m = measure_opening(s.world(), {0, 0}, {4, 0}, {0, 4});
    CHECK(m.failed_depth_crown > 3.0);
    // Neither reaches the bonded region's edge at x = 8 m (its interface with the
    // elastic far field).
    CHECK_FALSE(z.reaches_region_edge);
    CHECK(z.edge_cells > 20);
    CHECK(z.edge_cells_damaged == 0);

    // A column of cracks along that edge, apart from the wall (x 7.3 to 8 m, y 2
    // to 6 m): not the zone, but damage along the edge.
    auto crack = [&](auto where) {
        for (int i = 0; i < c.size(); ++i) {
            const Vec2 x = s.world().blocks.centroid0[c.vertex_block[i]] + s.world().vertices.local[c.vertex_id[i]];
            if (where(x) && c.history[i].bonded && s.world().blocks.region[c.vertex_block[i]] == s.world().blocks.region[c.edge_block[i]])
                c.history[i].broken = contact::JointState::broken_tension, c.history[i].bonded = false;
        }
    };
    crack([](Vec2 x) { return x.x > 7.3 && x.x < 8.0 && x.y > 2.0 && x.y < 6.0; });
    const auto column = measure_failed_zone(s.world(), {0, 0}, {4, 0}, {0, 4});
    MESSAGE("column along the edge: " << column.edge_cells_damaged << " of " << column.edge_cells << " edge cells damaged");
    CHECK_FALSE(column.reaches_region_edge);
    CHECK(column.edge_cells_damaged >= 3);
    CHECK(column.depth_springline == z.depth_springline);
    // The wall's zone carried on to the edge along the springline: it reaches it,
    // at x about 8 m (and, joined to the column there, takes the column in).
    crack([](Vec2 x) { return x.x > 4.0 && x.x < 8.0 && std::abs(x.y) < 0.8; });
    const auto through = measure_failed_zone(s.world(), {0, 0}, {4, 0}, {0, 4});
    MESSAGE("zone to the edge: depth " << through.depth_springline << " m, edge point (" << through.region_edge_point.x
                                       << ", " << through.region_edge_point.y << ")");
    CHECK(through.reaches_region_edge);
    CHECK(through.region_edge_point.x > 8.0 - 2 * through.cell);
    CHECK(std::abs(through.region_edge_point.y) < 6.0 + through.cell);
}

TEST_CASE("field: the Mine-by model carries its inclined in-situ stress round the tunnel as Kirsch's solution" * validation) {
    // examples/field/mineby.toml (docs/field.md): 60 and 11 MPa, the largest
    // plunging 14 degrees, on all four sides and as the initial state, and a 3.5 m
    // tunnel excavated. Up to the excavation (its 3,000 relaxation steps), the
    // hoop stress behind the roof and floor — where the field's notches formed,
    // across the largest stress — follows Kirsch's solution for the inclined
    // field, and is largest there. (That the lab-calibrated rock then does not
    // notch is measured in docs/field.md, not asserted here.)
    auto file = read_example("field/mineby.toml");
    file.analysis.solver.threads = 1;
    file.analysis.stages.pop_back(); // the failure stage
    const auto blocks = meshing::generate_blocks(file.geometry);
    Solver s(blocks, file.analysis);
    Quiet q;
    (void)run_stages(s, file.analysis.stages, q);
    const auto stress = block_stresses(s.world());
    const double a = 1.75, p1 = 60.0, p3 = 11.0, plunge = 14.0 * std::numbers::pi / 180.0;
    auto kirsch = [&](double r, double theta) { // compression positive, theta from +x
        const double q2 = a * a / (r * r);
        return 0.5 * (p1 + p3) * (1 + q2) - 0.5 * (p1 - p3) * (1 + 3 * q2 * q2) * std::cos(2 * (theta - plunge));
    };
    auto hoop = [&](double r, double theta) {
        return -hoop_stress_at(s.world(), stress, {0, 0}, {std::cos(theta), std::sin(theta)}, r, 0.25) / 1e6;
    };
    for (double deg : {104.0, 284.0}) {
        std::string wanted, measured, off; // the record's figures at 2.5, 3 and 4 m
        bool held = true;
        for (double r : {2.5, 3.0, 4.0}) {
            const double theta = deg * std::numbers::pi / 180.0, got = hoop(r, theta), want = kirsch(r, theta);
            MESSAGE(deg << "°, r = " << r << " m: hoop " << got << " MPa, Kirsch " << want << " MPa ("
                        << (got / want - 1) * 100 << "%)");
            CHECK(got == doctest::Approx(want).epsilon(0.10));
            const std::string sep = wanted.empty() ? "" : " / ";
            held = held && (got == doctest::Approx(want).epsilon(0.10));
            wanted += sep + test::figure(want), measured += sep + test::figure(got);
            off += sep + test::percent(got, want);
        }
        test::record_check(test::Against::closed_form,
                           std::string(deg < 180 ? "hoop stress behind the roof (104°)"
                                                 : "hoop stress behind the floor (284°)") +
                               " at r = 2.5 / 3 / 4 m",
                           "Kirsch, 60 and 11 MPa, the largest plunging 14° (docs/field.md): " + wanted + " MPa",
                           "each within 10%", measured + " MPa (" + off + ")", held);
    }
    // Around the tunnel at 2.5 m, the hoop stress peaks across the largest stress:
    // its second harmonic (a least-squares fit of A + B cos 2θ + C sin 2θ over 72
    // directions, which averages the blocks' scatter) has its crest at 104°.
    double sc = 0, ss = 0;
    for (int k = 0; k < 72; ++k) {
        const double theta = k * std::numbers::pi / 36.0, h = hoop(2.5, theta);
        sc += h * std::cos(2 * theta), ss += h * std::sin(2 * theta);
    }
    double crest = 0.5 * std::atan2(ss, sc) * 180.0 / std::numbers::pi;
    if (crest < 0) crest += 180.0;
    MESSAGE("crest of the hoop stress at 2.5 m: " << crest << "° (Kirsch: 104°)");
    CHECK(crest == doctest::Approx(104.0).epsilon(0.03));
    test::record_check(test::Against::closed_form, "crest of the hoop stress round the tunnel at r = 2.5 m",
                       "104°, across the largest stress (Kirsch, 60 MPa plunging 14°)", "within 3%",
                       test::figure(crest) + "°", crest == doctest::Approx(104.0).epsilon(0.03));
}
