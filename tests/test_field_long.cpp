// Issue 48's field checks at reduced scale (CTest label `long`): the depth of
// failure against stress round the Mine-by tunnel, one seed per stress level,
// set against the field trend of Martin, Kaiser & McCreath (1999), and the block
// size: each shipped size's bonds give the same laboratory rock. The studies at
// full scale (3-6 seeds, four sizes): docs/field.md.
#include "core/solver.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"
#include "studies/lab/labtest.hpp"
#include "studies/lab/labtest_values.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "studies/model/opening.hpp"
#include "tests/model_text.hpp"
#include "tests/validation_record.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace bbm;

namespace {

std::string file_text(const std::string& path) {
    std::ifstream in(path);
    REQUIRE(in);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// The model file with every in-situ stress component (the lines `sxx = ...`,
/// `syy = ...`, `sxy = ...`: the boundaries' and the initial state's) times f,
/// as examples/field/depth_study.py scales it.
std::string scaled_stress(const std::string& text, double f) {
    std::istringstream in(text);
    std::string out, line;
    int scaled = 0;
    while (std::getline(in, line)) {
        if (line.size() > 6 && line[0] == 's' && (line[1] == 'x' || line[1] == 'y') &&
            (line[2] == 'x' || line[2] == 'y') && line.compare(3, 3, " = ") == 0) {
            std::ostringstream v;
            v.precision(17);
            v << std::stod(line.substr(6)) * f;
            line = line.substr(0, 6) + v.str();
            ++scaled;
        }
        out += line + '\n';
    }
    CHECK(scaled == 15); // four boundaries and the initial state, three components each
    return out;
}

/// The failed zone's depth within +/-15 degrees of a direction (the notch's
/// depth as the depth study reads it), m.
double depth_near(const FailedZone& zone, double direction_deg) {
    const double sector = 360.0 / double(zone.depth.size());
    double best = 0.0;
    for (std::size_t i = 0; i < zone.depth.size(); ++i) {
        const double centre = (double(i) + 0.5) * sector;
        if (std::abs(std::remainder(centre - direction_deg, 360.0)) <= 15.0) best = std::max(best, zone.depth[i]);
    }
    return best;
}

} // namespace

TEST_CASE("field: depth of failure against stress, the Mine-by model from 0.24 to 1.1 x UCS: no failure below the field's onset, then a notch deepening with the stress") {
    // examples/field/mineby_in_situ.toml (bonds calibrated on crack initiation, the
    // laboratory only), its in-situ stress scaled by 0.3, 0.6, 1.0 and 1.4: the
    // largest elastic hoop stress sigma_max = 3 sigma1 - sigma3 is 0.24, 0.48,
    // 0.79 and 1.11 of the record's UCS, 213 MPa. The field (Martin, Kaiser &
    // McCreath 1999, Can. Geotech. J. 36, 136-151): no failure below about
    // 0.4 x UCS, then rf/a = 1.25 sigma_max / UCS + 0.51. Seed as shipped; the
    // 3-seed study with the levels above 1.1 (where the zone reaches the bonded
    // region's edge) is docs/field.md, "Depth of failure against stress".
    const std::string path = std::string(BBM_SOURCE_DIR) + "/examples/field/mineby_in_situ.toml";
    const std::string text = file_text(path);
    constexpr double a = 1.75, ucs = 213e6, sigma1 = 60e6, sigma3 = 11e6;
    struct Level {
        double factor, ratio, rf_a, trend;
        int cracks;
        bool at_edge;
        Verdict::Kind verdict;
    };
    std::vector<Level> levels;
    for (double factor : {0.3, 0.6, 1.0, 1.4}) {
        auto model = test::build_model(scaled_stress(text, factor), path);
        model.file.analysis.solver.threads = 2;
        Solver s(model.blocks, model.file.analysis);
        struct Quiet : StageObserver {} q;
        const auto reports = run_stages(s, model.file.analysis.stages, q);
        const auto& rep = model.file.analysis.report;
        const auto zone = measure_failed_zone(s.world(), rep.center, rep.springline, rep.crown);
        const double roof = depth_near(zone, 104.0), floor = depth_near(zone, 284.0);
        const double ratio = factor * (3 * sigma1 - sigma3) / ucs;
        Level l{factor, ratio, (a + std::max(roof, floor)) / a, ratio < 0.4 ? 1.0 : 1.25 * ratio + 0.51,
                cracks(s.world(), contact::JointState::broken_tension) + cracks(s.world(), contact::JointState::broken_shear),
                zone.reaches_region_edge, reports.back().verdict.kind};
        MESSAGE("stress x " << factor << ": sigma_max/UCS " << ratio << ", cracks " << l.cracks << ", roof " << roof
                            << " m, floor " << floor << " m, rf/a " << l.rf_a << " (trend " << l.trend << "), edge "
                            << l.at_edge << ", verdict " << std::string(to_string(l.verdict)));
        levels.push_back(l);
    }
    // Below the field's onset: not a bond broken, rf/a 1.
    CHECK(levels[0].cracks == 0);
    CHECK(levels[0].rf_a == 1.0);
    // Near the onset (0.48): the first cracks, at most a skin (within 0.2 of the
    // trend's 1.11: at most 0.35 m, three block rows).
    CHECK(levels[1].cracks > 0);
    CHECK(levels[1].rf_a <= levels[1].trend + 0.2);
    // Then a notch that deepens with the stress, inside the bonded region.
    CHECK(levels[2].rf_a > levels[1].rf_a);
    CHECK(levels[3].rf_a > levels[2].rf_a);
    CHECK(levels[2].rf_a >= 1.0 + 2 * 0.12 / a); // at least two block rows at the Mine-by's stress
    for (std::size_t k = 0; k + 1 < levels.size(); ++k) CHECK_FALSE(levels[k].at_edge);
    for (const auto& l : levels) CHECK(l.verdict != Verdict::Kind::collapsing);
    for (std::size_t k = 0; k < levels.size(); ++k) {
        const auto& l = levels[k];
        const std::string asserted = k == 0   ? "no crack, rf/a 1"
                                     : k == 1 ? "cracks; rf/a within +0.2 of the trend"
                                     : k == 2 ? "deeper than at 0.48, >= 2 block rows"
                                              : "deeper than at 0.79";
        const bool held = k == 0   ? l.cracks == 0 && l.rf_a == 1.0
                          : k == 1 ? l.cracks > 0 && l.rf_a <= l.trend + 0.2
                          : k == 2 ? l.rf_a > levels[1].rf_a && l.rf_a >= 1.0 + 2 * 0.12 / a
                                   : l.rf_a > levels[2].rf_a;
        test::record_check(
            test::Against::field, "rf/a at sigma_max/UCS = " + test::figure(l.ratio, 2) + " (stress x " + test::figure(l.factor, 2) + ")",
            std::string("Martin, Kaiser & McCreath 1999: ") +
                (l.ratio < 0.4 ? "no failure below about 0.4 x UCS" : "rf/a = 1.25 sigma_max/UCS + 0.51 = " + test::figure(l.trend)) +
                " (issue 48 asks within 0.2; docs/field.md)",
            asserted,
            "rf/a " + test::figure(l.rf_a) +
                (l.ratio < 0.4 ? std::string()
                               : " (" + std::string(l.rf_a - l.trend >= 0 ? "+" : "") + test::figure(l.rf_a - l.trend, 2) + ")") +
                ", " + std::to_string(l.cracks) + " cracks, " + to_string(l.verdict) +
                (l.at_edge ? ", zone at the region's edge" : "") + " (seed as shipped)",
            held);
    }
}

TEST_CASE("block size: the Mine-by models at 0.12, 0.06 and 0.045 m hold the same laboratory rock, each calibrated at its size (one fresh seed)") {
    // Issue 48, item 4: a block-size study compares notches of one rock, so each
    // shipped size's bonds (examples/field/mineby_in_situ*.toml, calibrated at its
    // size on the in-situ record, the finest with the fracture energies held)
    // must give the record's E 69 GPa, nu 0.26, strength (crack initiation) 74.6
    // MPa and direct tension 9.3 MPa in the calibration's 2.4 x 4.8 m specimen.
    // One fresh seed (2001) per size: the tolerances are the calibration's 3-seed
    // misses (within 6%, docs/field.md "Block size") widened for one seed's
    // scatter (the strength's std over seeds is 5%): 10% on E, nu, strength and
    // tension. The notches at four sizes over 6 seeds: docs/field.md.
    struct Size {
        const char* file;
        double size;
        LabTestResult ucs, tension;
    };
    std::vector<Size> sizes{{"mineby_in_situ.toml", 0.12, {}, {}},
                            {"mineby_in_situ_fine.toml", 0.06, {}, {}},
                            {"mineby_in_situ_finest.toml", 0.045, {}, {}}};
    std::vector<std::function<void()>> jobs;
    for (auto& sz : sizes) {
        const std::string path = std::string(BBM_SOURCE_DIR) + "/examples/field/" + sz.file;
        const auto model = io::read_model(path);
        auto specimen = [&](LabTestOptions::Kind kind) {
            studies::LabTestValues c = studies::labtest_defaults(kind);
            c.o.rock = io::rock_of_model(model, path, c.o.rock);
            c.o.width = 2.4, c.o.height = 4.8, c.o.rock.pattern.seed = 2001;
            if (kind == LabTestOptions::Kind::tension) c.o.platen_friction = -1.0;
            studies::prepare_labtest(c, kind);
            CHECK(c.o.rock.pattern.size == sz.size);
            return c.o;
        };
        jobs.emplace_back([o = specimen(LabTestOptions::Kind::ucs), &sz] { sz.ucs = run_labtest(o); });
        jobs.emplace_back([o = specimen(LabTestOptions::Kind::tension), &sz] { sz.tension = run_labtest(o); });
    }
    // Two at a time, one thread each, longest (the finest) first.
    std::atomic<int> next{int(jobs.size()) - 1};
    auto worker = [&] {
        for (int j = next--; j >= 0; j = next--) jobs[j]();
    };
    std::thread other(worker);
    worker();
    other.join();
    for (const auto& sz : sizes) {
        const double E = sz.ucs.E / 69e9 - 1, nu = sz.ucs.nu / 0.26 - 1, peak = sz.ucs.peak_stress / 74.6e6 - 1,
                     T = sz.tension.peak_stress / 9.3e6 - 1;
        MESSAGE(sz.size << " m: E " << sz.ucs.E / 1e9 << " GPa (" << 100 * E << "%), nu " << sz.ucs.nu << " (" << 100 * nu
                        << "%), strength " << sz.ucs.peak_stress / 1e6 << " MPa (" << 100 * peak << "%), tension "
                        << sz.tension.peak_stress / 1e6 << " MPa (" << 100 * T << "%); " << sz.ucs.steps << " + "
                        << sz.tension.steps << " steps");
        CHECK(std::abs(E) <= 0.10);
        CHECK(std::abs(nu) <= 0.10);
        CHECK(std::abs(peak) <= 0.10);
        CHECK(std::abs(T) <= 0.10);
        CHECK_FALSE(sz.ucs.still_loading);
        auto pct = [](double x) { return std::string(x >= 0 ? "+" : "") + test::figure(100 * x, 2) + "%"; };
        test::record_check(test::Against::laboratory,
                           "E, nu, strength and tension of the Mine-by model's bonds at " + test::figure(sz.size) + " m blocks",
                           "Lac du Bonnet's in-situ record: E 69 GPa, nu 0.26, sigma_ci 74.6 MPa, T 9.3 MPa (docs/field.md)",
                           "each within 10% (one fresh seed)",
                           test::figure(sz.ucs.E / 1e9) + " GPa (" + pct(E) + "), " + test::figure(sz.ucs.nu) + " (" + pct(nu) +
                               "), " + test::figure(sz.ucs.peak_stress / 1e6) + " MPa (" + pct(peak) + "), " +
                               test::figure(sz.tension.peak_stress / 1e6) + " MPa (" + pct(T) + ")",
                           std::abs(E) <= 0.10 && std::abs(nu) <= 0.10 && std::abs(peak) <= 0.10 && std::abs(T) <= 0.10);
    }
}
