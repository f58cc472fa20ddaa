#include "studies/lab/envelope.hpp"

#include "studies/lab/labtest_command.hpp"
#include "base/error.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "meshing/blocks.hpp"
#include "io/vtk_output.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "studies/cluster/ranks.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <numeric>
#include <numbers>
#include <set>
#include <sstream>
#include <thread>

namespace bbm::studies {

namespace fs = std::filesystem;

// --- fits ----------------------------------------------------------------------

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
    LineFit f;
    const std::size_t n = std::min(x.size(), y.size());
    if (n < 2) return f;
    double mx = 0.0, my = 0.0;
    for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
    mx /= double(n), my /= double(n);
    double sxx = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
    if (!(sxx > 0.0)) return f; // one abscissa: no line
    f.slope = sxy / sxx;
    f.intercept = my - f.slope * mx;
    double ss = 0.0;
    for (std::size_t i = 0; i < n; ++i) ss += std::pow(f.intercept + f.slope * x[i] - y[i], 2);
    f.rms = std::sqrt(ss / double(n));
    f.valid = true;
    return f;
}

double HoekBrownFit::sigma1(double s3) const {
    const double inner = mi * s3 / sigma_ci + 1.0;
    return s3 + sigma_ci * std::sqrt(std::max(0.0, inner));
}

double HoekBrownFit::tensile_strength() const { return 0.5 * sigma_ci * (std::sqrt(mi * mi + 4.0) - mi); }

namespace {

/// A start of the Hoek-Brown fit (A, B) when the linearised one fails: an
/// envelope that rises faster than the criterion's square root at low
/// confinement (a lattice that interlocks) puts the linearised intercept below
/// zero: start instead from the points at the lowest σ3 and the chord to the
/// highest (y = (σ1 − σ3)²). False when that fails too.
bool chord_start(const std::vector<double>& s3, const std::vector<double>& y, std::size_t n, double& A, double& B) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < n; ++i) lo = std::min(lo, s3[i]), hi = std::max(hi, s3[i]);
    double y_lo = 0.0, y_hi = 0.0;
    int n_lo = 0, n_hi = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (s3[i] == lo) y_lo += y[i], ++n_lo;
        if (s3[i] == hi) y_hi += y[i], ++n_hi;
    }
    y_lo /= n_lo, y_hi /= n_hi;
    B = std::max((y_hi - y_lo) / (hi - lo), 1e-12 * y_lo / std::max(hi, 1.0));
    A = std::max(y_lo - B * lo, 1e-6 * y_lo);
    return A > 0.0;
}

/// The sum of squared σ1 residuals of σ1 = σ3 + √(a + b σ3) (inf where the root is not real).
double hoek_brown_cost(const std::vector<double>& s3, const std::vector<double>& s1, std::size_t n, double a, double b) {
    double ss = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double q = a + b * s3[i];
        if (!(q > 0.0)) return double(INFINITY);
        ss += std::pow(s3[i] + std::sqrt(q) - s1[i], 2);
    }
    return ss;
}

/// Gauss–Newton on the σ1 residuals from (A, B), each step halved until it lowers
/// the cost; the cost at the end.
double gauss_newton_hoek_brown(const std::vector<double>& s3, const std::vector<double>& s1, std::size_t n, double& A,
                               double& B) {
    double current = hoek_brown_cost(s3, s1, n, A, B);
    for (int iteration = 0; iteration < 100 && std::isfinite(current); ++iteration) {
        // Normal equations of the 2 × 2 Gauss–Newton step.
        double jaa = 0.0, jab = 0.0, jbb = 0.0, ga = 0.0, gb = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double root = std::sqrt(A + B * s3[i]);
            const double r = s3[i] + root - s1[i], da = 0.5 / root, db = 0.5 * s3[i] / root;
            jaa += da * da, jab += da * db, jbb += db * db, ga += da * r, gb += db * r;
        }
        const double det = jaa * jbb - jab * jab;
        if (!(std::abs(det) > 0.0)) break;
        const double stepA = -(jbb * ga - jab * gb) / det, stepB = -(jaa * gb - jab * ga) / det;
        double t = 1.0, next = hoek_brown_cost(s3, s1, n, A + stepA, B + stepB);
        while (!(next <= current) && t > 1e-6) t *= 0.5, next = hoek_brown_cost(s3, s1, n, A + t * stepA, B + t * stepB);
        if (!(next <= current)) break;
        A += t * stepA, B += t * stepB;
        const bool done = current - next <= 1e-15 * current;
        current = next;
        if (done) break;
    }
    return current;
}

} // namespace

HoekBrownFit fit_hoek_brown(const std::vector<double>& s3, const std::vector<double>& s1) {
    // In A = σci², B = mi σci the criterion is σ1 = σ3 + √(A + B σ3): Hoek's
    // linearisation (σ1 − σ3)² = A + B σ3 starts, Gauss–Newton on the σ1
    // residuals finishes (the linearised fit weighs the high-confinement points
    // by (σ1 − σ3)², not as a laboratory's least squares on σ1 would).
    HoekBrownFit f;
    const std::size_t n = std::min(s3.size(), s1.size());
    std::vector<double> y(n);
    for (std::size_t i = 0; i < n; ++i) y[i] = (s1[i] - s3[i]) * (s1[i] - s3[i]);
    const LineFit start = fit_line(s3, y);
    if (!start.valid) return f; // fewer than two confinements
    double A = start.intercept, B = start.slope;
    if (!(A > 0.0) || !(B > 0.0))
        if (!chord_start(s3, y, n, A, B)) return f;
    const double current = gauss_newton_hoek_brown(s3, s1, n, A, B);
    f.sigma_ci = std::sqrt(A);
    f.mi = B / f.sigma_ci;
    f.rms = std::sqrt(current / double(n));
    f.valid = std::isfinite(f.rms);
    return f;
}

MohrCoulombFit fit_mohr_coulomb(const std::vector<double>& s3, const std::vector<double>& s1) {
    MohrCoulombFit f;
    const LineFit line = fit_line(s3, s1);
    if (!line.valid || !(line.slope >= 1.0)) return f;
    f.sigma_c = line.intercept, f.slope = line.slope, f.rms = line.rms;
    const double sin_phi = (line.slope - 1.0) / (line.slope + 1.0);
    const double phi = std::asin(sin_phi);
    f.friction_deg = phi * 180.0 / std::numbers::pi;
    f.cohesion = line.intercept * (1.0 - sin_phi) / (2.0 * std::cos(phi));
    f.valid = true;
    return f;
}

std::vector<std::pair<double, double>> read_strength_record(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file, 0, "", "cannot open the strength record");
    std::vector<std::pair<double, double>> out;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream fields(line);
        double s3 = 0.0, s1 = 0.0;
        if (!(fields >> s3 >> s1)) {
            if (out.empty() && number == 1) continue; // a header
            throw InputError(file, number, "", "expected two numbers, sigma3 and sigma1 in MPa");
        }
        if (!std::isfinite(s3) || !std::isfinite(s1) || s1 < s3)
            throw InputError(file, number, "", "sigma1 must be finite and at least sigma3 (MPa)");
        out.push_back({s3 * 1e6, s1 * 1e6});
    }
    if (out.empty()) throw InputError(file, 0, "", "no sigma3, sigma1 pairs in the record");
    return out;
}

// --- the study -----------------------------------------------------------------

namespace {

struct Job {
    LabTestOptions::Kind kind;
    double confinement;
    int realization;
};

const char* test_name(LabTestOptions::Kind k) {
    switch (k) {
    case LabTestOptions::Kind::ucs: return "ucs";
    case LabTestOptions::Kind::tension: return "tension";
    case LabTestOptions::Kind::biaxial: return "biaxial";
    case LabTestOptions::Kind::brazilian: return "brazilian";
    }
    return "?";
}

nlohmann::json stats(const std::vector<double>& v) {
    double m = 0.0, s = 0.0;
    for (double x : v) m += x;
    m /= std::max<std::size_t>(1, v.size());
    for (double x : v) s += (x - m) * (x - m);
    return {{"mean", m}, {"std", v.size() > 1 ? std::sqrt(s / double(v.size() - 1)) : 0.0}, {"n", v.size()}};
}


/// The fits of an envelope from its runs (every compression peak, σ3 ≥ 0), into
/// the summary: hoek_brown, mohr_coulomb, the σci and σcd lines, and each level's
/// fitted σ1.
void add_fits(nlohmann::json& e) {
    std::vector<double> s3, s1, ci_x, ci_y, cd_x, cd_y;
    for (const auto& r : e["runs"]) {
        const std::string test = r["test"];
        if (test != "ucs" && test != "biaxial") continue;
        const double x = r["sigma3"];
        s3.push_back(x), s1.push_back(r["peak"].get<double>());
        if (r["sigma_ci"].get<double>() > 0.0) ci_x.push_back(x), ci_y.push_back(r["sigma_ci"].get<double>());
        if (r["sigma_cd"].get<double>() > 0.0) cd_x.push_back(x), cd_y.push_back(r["sigma_cd"].get<double>());
    }
    const HoekBrownFit hb = fit_hoek_brown(s3, s1);
    const MohrCoulombFit mc = fit_mohr_coulomb(s3, s1);
    const LineFit ci = fit_line(ci_x, ci_y), cd = fit_line(cd_x, cd_y);
    e["hoek_brown"] = {{"valid", hb.valid}, {"sigma_ci", hb.sigma_ci}, {"mi", hb.mi}, {"a", 0.5}, {"rms", hb.rms},
                       {"tensile_strength", hb.valid ? hb.tensile_strength() : 0.0}};
    e["mohr_coulomb"] = {{"valid", mc.valid}, {"cohesion", mc.cohesion}, {"friction_deg", mc.friction_deg},
                         {"sigma_c", mc.sigma_c}, {"slope", mc.slope}, {"rms", mc.rms}};
    auto line = [](const LineFit& f) {
        return nlohmann::json{{"valid", f.valid}, {"intercept", f.intercept}, {"slope", f.slope}, {"rms", f.rms}};
    };
    e["crack_initiation_line"] = line(ci);
    e["crack_damage_line"] = line(cd);
    for (auto& level : e["levels"]) {
        const double x = level["sigma3"];
        level["hoek_brown_sigma1"] = hb.valid ? hb.sigma1(x) : 0.0;
        level["mohr_coulomb_sigma1"] = mc.valid ? mc.sigma_c + mc.slope * x : 0.0;
    }
}

void print_fits(const nlohmann::json& e) {
    const auto& hb = e["hoek_brown"];
    const auto& mc = e["mohr_coulomb"];
    if (hb["valid"].get<bool>())
        std::fprintf(stderr, "Hoek-Brown: sigma_ci %.2f MPa, mi %.2f (rms %.2f MPa)\n", hb["sigma_ci"].get<double>() / 1e6,
                     hb["mi"].get<double>(), hb["rms"].get<double>() / 1e6);
    if (mc["valid"].get<bool>())
        std::fprintf(stderr, "Mohr-Coulomb: c %.2f MPa, phi %.1f deg (rms %.2f MPa)\n", mc["cohesion"].get<double>() / 1e6,
                     mc["friction_deg"].get<double>(), mc["rms"].get<double>() / 1e6);
}

/// envelope.png from envelope.json's content: σ1 against σ3 (MPa) — σci and σcd
/// of every compression test, every realization's peak drawn over them (the
/// tension tests at σ3 = −T, σ1 = 0), the fitted curves and the target record.
/// Every run's points: the peaks (tension at −T), σci and σcd; in that order.
std::vector<io::Series> measured_points(const nlohmann::json& e) {
    using Style = io::Series::Style;
    io::Series peaks{"peaks (each realization)", {}, {}, Style::points};
    io::Series cis{"sigma_ci", {}, {}, Style::points}, cds{"sigma_cd", {}, {}, Style::points};
    const bool brazilian = e["tension"]["test"] == "brazilian";
    for (const auto& r : e["runs"]) {
        const std::string test = r["test"];
        const double s3 = r["sigma3"].get<double>() / 1e6;
        if (test == "ucs" || test == "biaxial") {
            peaks.x.push_back(s3), peaks.y.push_back(r["peak"].get<double>() / 1e6);
            if (r["sigma_ci"].get<double>() > 0) cis.x.push_back(s3), cis.y.push_back(r["sigma_ci"].get<double>() / 1e6);
            if (r["sigma_cd"].get<double>() > 0) cds.x.push_back(s3), cds.y.push_back(r["sigma_cd"].get<double>() / 1e6);
        } else {
            const double t = (brazilian ? r["tensile_strength"] : r["peak"]).get<double>();
            peaks.x.push_back(-t / 1e6), peaks.y.push_back(0.0);
        }
    }
    return {cis, cds, peaks};
}

/// A criterion σ1(σ3) drawn from σ3 = 0 to `top`.
template <class Sigma1>
io::Series criterion_curve(const std::string& label, double top, Sigma1 sigma1) {
    io::Series c{label, {}, {}};
    for (int k = 0; k <= 60; ++k) {
        const double x = top * k / 60.0;
        c.x.push_back(x / 1e6), c.y.push_back(sigma1(x) / 1e6);
    }
    return c;
}

/// The fitted criteria up to the highest confinement (tested, or of the
/// laboratory record), the record's points and the target criterion.
void add_criteria(std::vector<io::Series>& series, const nlohmann::json& e) {
    double top = 0.0;
    for (double s3 : e["confinements"]) top = std::max(top, s3);
    if (e.contains("target_record"))
        for (const auto& pair : e["target_record"]["pairs"]) top = std::max(top, pair[0].get<double>());
    char label[256];
    if (e["hoek_brown"]["valid"].get<bool>()) {
        const HoekBrownFit hb{e["hoek_brown"]["sigma_ci"], e["hoek_brown"]["mi"], 0.0, true};
        std::snprintf(label, sizeof label, "Hoek-Brown: sigma_ci %.1f MPa, mi %.1f", hb.sigma_ci / 1e6, hb.mi);
        series.push_back(criterion_curve(label, top, [&](double x) { return hb.sigma1(x); }));
    }
    if (e["mohr_coulomb"]["valid"].get<bool>()) {
        const double sc = e["mohr_coulomb"]["sigma_c"], k = e["mohr_coulomb"]["slope"];
        std::snprintf(label, sizeof label, "Mohr-Coulomb: c %.2f MPa, phi %.1f deg",
                      e["mohr_coulomb"]["cohesion"].get<double>() / 1e6, e["mohr_coulomb"]["friction_deg"].get<double>());
        series.push_back(criterion_curve(label, top, [&](double x) { return sc + k * x; }));
    }
    if (e.contains("target_record")) {
        io::Series r{"laboratory record", {}, {}, io::Series::Style::points};
        for (const auto& pair : e["target_record"]["pairs"])
            r.x.push_back(pair[0].get<double>() / 1e6), r.y.push_back(pair[1].get<double>() / 1e6);
        series.push_back(r);
    }
    if (e.contains("target_hoek_brown")) {
        const HoekBrownFit target{e["target_hoek_brown"]["sigma_ci"], e["target_hoek_brown"]["mi"], 0.0, true};
        std::snprintf(label, sizeof label, "target Hoek-Brown: sigma_ci %.1f MPa, mi %.1f", target.sigma_ci / 1e6, target.mi);
        series.push_back(criterion_curve(label, top, [&](double x) { return target.sigma1(x); }));
    }
}

/// The picture's title: the rock drawn.
std::string envelope_title(const nlohmann::json& e) {
    const auto& sp = e["specimen"];
    // Heterogeneous bonds are part of the rock drawn (older envelope.json files have no modulus).
    const double weibull = sp.value("weibull_modulus", 0.0);
    char bonds[48] = "";
    if (weibull > 0) std::snprintf(bonds, sizeof bonds, ", bond strengths Weibull m = %.3g", weibull);
    char label[256];
    std::snprintf(label, sizeof label, "strength envelope, %s blocks of %.2g m%s%s, %d realization%s",
                  sp["pattern"].get<std::string>().c_str(), sp["size"].get<double>(),
                  sp["deformable_fraction"].get<double>() > 0
                      ? (", deformable f = " + std::to_string(sp["deformable_fraction"].get<double>()).substr(0, 4)).c_str()
                      : "",
                  bonds, sp["realizations"].get<int>(), sp["realizations"].get<int>() > 1 ? "s" : "");
    return label;
}

void draw_envelope(const nlohmann::json& e, const fs::path& file) {
    std::vector<io::Series> series = measured_points(e);
    add_criteria(series, e);
    io::draw_curves(series, "sigma3 (MPa; tension at -T)", "sigma1 (MPa)", file, envelope_title(e), false, true);
}

} // namespace

namespace {

/// `--replot`: envelope.png again from envelope.json (another record to compare, a
/// new style), no test run.
int replot_envelope(const EnvelopeOptions& e, bool quiet, bool check_only) {
    const LabTestValues& c = e.lab;
    const fs::path file = fs::path(c.out) / "envelope.json";
    std::ifstream in(file);
    if (!in) throw InputError(file.string(), 0, "", "no envelope.json to draw from (run bbm envelope first)");
    auto summary = nlohmann::json::parse(in, nullptr, false);
    if (summary.is_discarded() || !summary.contains("runs"))
        throw InputError(file.string(), 0, "", "not an envelope.json written by bbm envelope");
    if (!e.target_record.empty()) {
        nlohmann::json pairs = nlohmann::json::array();
        for (const auto& [a, b] : read_strength_record(e.target_record)) pairs.push_back({a, b});
        summary["target_record"] = {{"file", e.target_record}, {"pairs", pairs}};
    }
    if (e.target_sigma_ci > 0.0 && e.target_mi > 0.0)
        summary["target_hoek_brown"] = {{"sigma_ci", e.target_sigma_ci}, {"mi", e.target_mi}};
    if (check_only) return 0;
    add_fits(summary); // this bbm's fits of the same runs
    io::write_text_atomically(file, summary.dump(2) + "\n");
    draw_envelope(summary, fs::path(c.out) / "envelope.png");
    if (!quiet) print_fits(summary);
    if (!quiet) std::fprintf(stderr, "wrote %s and envelope.png\n", file.string().c_str());
    return 0;
}

/// The tests of a list, side by side over the threads (deformable specimens one at
/// a time, with the threads in their loop, as `bbm ucs`); each result printed as
/// it ends, appended to `runs` in list order.
struct EnvelopeRunner {
    const LabTestValues& c;
    const LabTestValues& compression;
    const LabTestValues& tension;
    LabTestOptions::Kind tension_kind;
    int available;
    bool one_at_a_time, quiet;
    std::vector<EnvelopeRun>& runs;
    std::mutex print{};

    void operator()(const std::vector<Job>& jobs) {
        const int side_by_side = one_at_a_time ? 1 : std::max(1, std::min(int(jobs.size()), available));
        // Handed out longest first, so that no thread is left with a long test while
        // the other idles: confined tests take more steps the higher their
        // confinement, a tension test a fraction of a compression test's. Results
        // come back in list order whatever order they ran in.
        std::vector<int> order(jobs.size());
        std::iota(order.begin(), order.end(), 0);
        auto expected_cost = [&](const Job& job) {
            return job.kind == LabTestOptions::Kind::biaxial ? 2.0 + job.confinement
                   : job.kind == LabTestOptions::Kind::ucs   ? 1.0
                                                             : 0.0;
        };
        std::stable_sort(order.begin(), order.end(),
                         [&](int a, int b) { return expected_cost(jobs[a]) > expected_cost(jobs[b]); });
        const auto texts_by_turn = run_spread(int(jobs.size()), side_by_side, [&](int turn) {
            const Job& job = jobs[order[turn]];
            LabTestOptions o = job.kind == tension_kind ? tension.o : compression.o;
            o.kind = job.kind;
            o.confinement = job.confinement;
            o.rock.pattern.seed = c.o.rock.pattern.seed + std::uint64_t(job.realization);
            o.frame_every = 0;
            // The peak is what an envelope needs: a confined specimen that has failed
            // stops 0.02% strain later, not at --max-strain (rigid trigon blocks keep
            // most of their strength under confinement and would run to 1% strain).
            // Once failed, its peak is final (run_labtest): a longer tail only draws
            // more of the curve (1e-3 gave the same peaks, σci and σcd, 25% slower),
            // and that tail runs at the servo's fastest speed.
            if (job.kind == LabTestOptions::Kind::biaxial) as_envelope_confined_test(o);
            o.threads = side_by_side == 1 ? available : 1;
            LabTestResult result;
            try {
                result = run_labtest(o);
            } catch (const GeometryError& error) {
                throw InputError("--size", 0, "", error.what());
            }
            if (!quiet) {
                // As each run ends (a long envelope shows its progress).
                std::lock_guard lock(print);
                std::fprintf(stderr, "  %-9s sigma3 %6.2f MPa seed %3llu: peak %8.2f MPa at %5.2f%%  first stall %8.2f  "
                                     "sigma_ci %7.2f  sigma_cd %7.2f  %ld steps %6.1f s%s\n",
                             test_name(job.kind), job.confinement / 1e6, static_cast<unsigned long long>(o.rock.pattern.seed),
                             result.peak_stress / 1e6, 100.0 * result.strain_at_peak, result.first_stall_stress / 1e6,
                             result.crack_initiation_stress / 1e6, result.crack_damage_stress / 1e6, result.steps,
                             result.wall_seconds,
                             result.still_loading       ? "  (still loading at the strain cap: a lower bound)"
                             : result.post_peak_locking ? "  (fragments jammed after failure)"
                                                        : "");
            }
            return labtest_record_text(result);
        });
        std::vector<std::string> texts(jobs.size());
        for (std::size_t turn = 0; turn < jobs.size(); ++turn) texts[order[turn]] = texts_by_turn[turn];
        for (std::size_t k = 0; k < jobs.size(); ++k)
            runs.push_back({test_name(jobs[k].kind), jobs[k].confinement, c.o.rock.pattern.seed + std::uint64_t(jobs[k].realization),
                            labtest_from_record_text(texts[k])});
    }
};

/// Per level of confinement (0 = the UCS tests): peak, σci, σcd, their ratios, E,
/// ν, strain at the peak, first stall (mean and spread over the realizations).
nlohmann::json envelope_levels(const std::vector<EnvelopeRun>& runs, const std::vector<double>& confinements) {
    nlohmann::json levels = nlohmann::json::array();
    std::vector<double> levels_s3{0.0};
    levels_s3.insert(levels_s3.end(), confinements.begin(), confinements.end());
    for (double level : levels_s3) {
        std::vector<double> peak, ci, cd, ci_ratio, cd_ratio, E, nu, stall, strain_at_peak;
        int still_loading = 0;
        for (const auto& r : runs) {
            if ((r.test != "ucs" && r.test != "biaxial") || r.confinement != level) continue;
            const auto& x = r.result;
            peak.push_back(x.peak_stress), E.push_back(x.E), nu.push_back(x.nu);
            still_loading += x.still_loading;
            strain_at_peak.push_back(x.strain_at_peak);
            if (x.first_stall_stress > 0) stall.push_back(x.first_stall_stress);
            if (x.crack_initiation_stress > 0) ci.push_back(x.crack_initiation_stress), ci_ratio.push_back(x.crack_initiation_stress / x.peak_stress);
            if (x.crack_damage_stress > 0) cd.push_back(x.crack_damage_stress), cd_ratio.push_back(x.crack_damage_stress / x.peak_stress);
        }
        levels.push_back({{"sigma3", level}, {"peak", stats(peak)}, {"sigma_ci", stats(ci)}, {"sigma_cd", stats(cd)},
                          {"sigma_ci_over_peak", stats(ci_ratio)}, {"sigma_cd_over_peak", stats(cd_ratio)},
                          {"E", stats(E)}, {"nu", stats(nu)}, {"still_loading", still_loading},
                          {"strain_at_peak", stats(strain_at_peak)}, {"first_stall", stats(stall)}});
    }
    return levels;
}

/// Every run, as envelope.json's "runs" and as envelope.csv's text.
std::pair<nlohmann::json, std::string> envelope_runs_table(const std::vector<EnvelopeRun>& runs) {
    nlohmann::json per_run = nlohmann::json::array();
    std::ostringstream csv;
    csv << "test,sigma3_Pa,seed,peak_Pa,sigma_ci_Pa,sigma_cd_Pa,tensile_strength_Pa,E_Pa,nu,cracks_tensile,cracks_shear,"
           "steps,post_peak_locking,still_loading,strain_at_peak,first_stall_Pa,reloads\n";
    csv.precision(10);
    for (const auto& r : runs) {
        const auto& x = r.result;
        per_run.push_back({{"test", r.test}, {"sigma3", r.confinement}, {"seed", r.seed}, {"peak", x.peak_stress},
                           {"sigma_ci", x.crack_initiation_stress}, {"sigma_cd", x.crack_damage_stress},
                           {"tensile_strength", x.tensile_strength}, {"E", x.E}, {"nu", x.nu},
                           {"cracks", {{"tensile", x.cracks_tensile}, {"shear", x.cracks_shear}}},
                           {"steps", x.steps}, {"wall_seconds", x.wall_seconds},
                           {"post_peak_locking", x.post_peak_locking}, {"still_loading", x.still_loading},
                           {"strain_at_peak", x.strain_at_peak}, {"first_stall", x.first_stall_stress},
                           {"reloads", x.reloads}});
        csv << r.test << ',' << r.confinement << ',' << r.seed << ',' << x.peak_stress << ','
            << x.crack_initiation_stress << ',' << x.crack_damage_stress << ',' << x.tensile_strength << ',' << x.E
            << ',' << x.nu << ',' << x.cracks_tensile << ',' << x.cracks_shear << ',' << x.steps << ','
            << x.post_peak_locking << ',' << x.still_loading << ',' << x.strain_at_peak << ','
            << x.first_stall_stress << ',' << x.reloads << '\n';
    }
    return {per_run, csv.str()};
}

/// What an engineer must know of the runs: peaks that are lower bounds, confined
/// specimens that hardened past their yield.
void warn_about_envelope_runs(const std::vector<EnvelopeRun>& runs, const LabTestValues& c) {
    int still_loading = 0;
    for (const auto& r : runs) still_loading += r.result.still_loading;
    if (still_loading > 0)
        std::fprintf(stderr, "warning: %d test%s reached the strain cap %g still loading: %s peak is a lower bound "
                             "of the strength, and the fits with it (blocks jammed, or raise --strain-cap)\n",
                     still_loading, still_loading == 1 ? "" : "s", std::max(c.o.stop.max_strain, c.o.stop.strain_cap),
                     still_loading == 1 ? "its" : "their");
    // Interlocking: a confined peak far above its first stall (the yield).
    int hardened = 0, confined = 0;
    for (const auto& r : runs) {
        if (r.test != "biaxial") continue;
        ++confined;
        hardened += r.result.hardened_past_yield();
    }
    if (hardened > 0 && !c.o.stop.peak_at_first_stall)
        std::fprintf(stderr, "warning: %d of %d confined tests hardened past their first stall (the yield) by more "
                             "than 20%%: broken blocks interlocking, and the fits mix them with the specimens that "
                             "failed. A residual friction below the joints' lets broken joints slide "
                             "(--residual-friction); --confined-peak first-stall reads the yield "
                             "(docs/calibration.md, The confined peak)\n",
                     hardened, confined);
}

/// The confinements to test: as given, or 0.1 to 0.5 times the measured UCS
/// (rounded to 0.1 MPa); sorted, each once.
std::vector<double> confinements_to_test(const std::vector<double>& given, const std::vector<double>& ucs) {
    double ucs_mean = 0.0;
    for (double v : ucs) ucs_mean += v / double(ucs.size());
    std::vector<double> confinements = given;
    if (confinements.empty())
        for (double f : {0.1, 0.2, 0.3, 0.4, 0.5}) confinements.push_back(std::round(f * ucs_mean / 1e5) * 1e5);
    std::sort(confinements.begin(), confinements.end());
    confinements.erase(std::unique(confinements.begin(), confinements.end()), confinements.end());
    return confinements;
}

/// The biaxial tests at these confinements, `realizations` seeds each.
std::vector<Job> biaxial_jobs(const std::vector<double>& confinements, int realizations) {
    std::vector<Job> jobs;
    for (double s3 : confinements)
        for (int k = 0; k < realizations; ++k) jobs.push_back({LabTestOptions::Kind::biaxial, s3, k});
    return jobs;
}

/// Runs every test of the envelope into the runner's list, in list order: the UCS
/// and tension tests, then the biaxials. The default confinements follow the
/// measured UCS, so its tests come first; confinements given go in one list with
/// them, none waiting for the UCS. Returns the confinements tested.
std::vector<double> run_envelope_tests(const EnvelopeOptions& e, EnvelopeRunner& run_jobs,
                                       LabTestOptions::Kind tension_kind) {
    const int n = e.lab.realizations;
    std::vector<Job> first;
    for (int k = 0; k < n; ++k) first.push_back({LabTestOptions::Kind::ucs, 0.0, k});
    for (int k = 0; k < n; ++k) first.push_back({tension_kind, 0.0, k});
    const bool given = !e.confinements.empty();
    if (given) {
        const auto jobs = biaxial_jobs(confinements_to_test(e.confinements, {}), n);
        first.insert(first.end(), jobs.begin(), jobs.end());
    }
    run_jobs(first);
    std::vector<double> ucs;
    for (const auto& r : run_jobs.runs)
        if (r.test == "ucs") ucs.push_back(r.result.peak_stress);
    const std::vector<double> confinements = confinements_to_test(e.confinements, ucs);
    if (!given) run_jobs(biaxial_jobs(confinements, n));
    return confinements;
}

/// envelope.json: the specimen, the UCS and tension statistics, each level and
/// run, the fits and the records to draw beside them.
nlohmann::json envelope_summary(const EnvelopeOptions& e, const std::vector<EnvelopeRun>& runs,
                                const nlohmann::json& per_run, const std::vector<double>& confinements,
                                const std::vector<std::pair<double, double>>& record) {
    const LabTestValues& c = e.lab;
    const bool brazilian = e.tension_test == "brazilian";
    std::vector<double> ucs, strength_t;
    for (const auto& r : runs)
        if (r.test == "ucs") ucs.push_back(r.result.peak_stress);
        else if (r.test != "biaxial") strength_t.push_back(brazilian ? r.result.tensile_strength : r.result.peak_stress);
    const auto ucs_stats = stats(ucs), t_stats = stats(strength_t);
    const double t_over_c = ucs_stats["mean"].get<double>() > 0
                                ? t_stats["mean"].get<double>() / ucs_stats["mean"].get<double>() : 0.0;
    nlohmann::json summary{
        {"specimen", {{"pattern", meshing::to_string(c.o.rock.pattern.kind)}, {"size", c.o.rock.pattern.size}, {"width", c.o.width}, {"height", c.o.height},
                      {"deformable_fraction", c.o.rock.material.deformable_fraction}, {"weibull_modulus", c.o.rock.bonds.weibull_modulus},
                      {"seed", c.o.rock.pattern.seed}, {"realizations", c.realizations}}},
        {"ucs", ucs_stats},
        {"tension", {{"test", brazilian ? "brazilian" : "direct"}, {"strength", t_stats}, {"over_ucs", t_over_c}}},
        {"confinements", confinements},
        {"levels", envelope_levels(runs, confinements)},
        {"runs", per_run}};
    if (!e.model.empty()) summary["specimen"]["model"] = e.model;
    add_fits(summary);
    if (e.target_sigma_ci > 0.0) summary["target_hoek_brown"] = {{"sigma_ci", e.target_sigma_ci}, {"mi", e.target_mi}};
    if (!record.empty()) {
        nlohmann::json pairs = nlohmann::json::array();
        for (const auto& [a, b] : record) pairs.push_back({a, b});
        summary["target_record"] = {{"file", e.target_record}, {"pairs", pairs}};
    }
    return summary;
}

/// The envelope's inputs checked and read: the confinements, the model's rock
/// (--model), the laboratory record and the target criterion; the record's pairs.
std::vector<std::pair<double, double>> read_envelope_inputs(EnvelopeOptions& e) {
    LabTestValues& c = e.lab;
    for (double s3 : e.confinements)
        if (!(s3 > 0.0) || !std::isfinite(s3))
            throw InputError("--confinements", 0, "", "each confinement must be a positive stress in Pa");
    if (!e.model.empty()) c.o.rock = io::rock_of_model(io::read_model(e.model), e.model, c.o.rock);
    std::vector<std::pair<double, double>> record;
    if (!e.target_record.empty()) record = read_strength_record(e.target_record);
    if ((e.target_sigma_ci > 0.0) != (e.target_mi > 0.0))
        throw InputError(e.target_mi > 0.0 ? "--target-sigma-ci" : "--target-mi", 0, "",
                         "--target-sigma-ci and --target-mi go together (the Hoek-Brown record to draw)");
    return record;
}

/// The tests' options: compression as given; tension loaded like `bbm tension`
/// (ten times slower: it peaks at a tenth of the strain), Brazilian like `bbm brazilian`.
struct EnvelopeTests {
    LabTestValues compression, tension;
    LabTestOptions::Kind tension_kind;
};

EnvelopeTests envelope_tests(const EnvelopeOptions& e) {
    const LabTestValues& c = e.lab;
    const bool brazilian = e.tension_test == "brazilian";
    EnvelopeTests t{c, c, brazilian ? LabTestOptions::Kind::brazilian : LabTestOptions::Kind::tension};
    prepare_labtest(t.compression, LabTestOptions::Kind::ucs);
    if (brazilian) t.tension.o.width = e.brazilian_diameter;
    t.tension.o.strain_per_step = c.o.strain_per_step * (brazilian ? 0.2 : 0.1);
    t.tension.o.platen_friction = -1.0;
    prepare_labtest(t.tension, t.tension_kind);
    return t;
}

/// The envelope on the console: the UCS and tension, the fits, what to know of the runs.
void print_envelope_result(const nlohmann::json& summary, const std::vector<EnvelopeRun>& runs, const EnvelopeOptions& e) {
    const LabTestValues& c = e.lab;
    const auto& ucs = summary["ucs"];
    const auto& t = summary["tension"];
    std::fprintf(stderr, "UCS %.2f +- %.2f MPa; %s tension %.2f MPa (T/UCS %.3f)\n", ucs["mean"].get<double>() / 1e6,
                 ucs["std"].get<double>() / 1e6, e.tension_test == "brazilian" ? "Brazilian" : "direct",
                 t["strength"]["mean"].get<double>() / 1e6, t["over_ucs"].get<double>());
    print_fits(summary);
    warn_about_envelope_runs(runs, c);
    if (c.write_files) std::fprintf(stderr, "wrote %s/{envelope.json, envelope.csv, envelope.png}\n", fs::path(c.out).string().c_str());
}

} // namespace

int run_envelope(EnvelopeOptions& e, bool quiet, bool check_only, EnvelopeStudy* study) {
    quiet = quiet || !Ranks::root();
    LabTestValues& c = e.lab;
    if (e.replot) return replot_envelope(e, quiet, check_only);
    const std::vector<std::pair<double, double>> record = read_envelope_inputs(e);
    const EnvelopeTests tests = envelope_tests(e);
    if (check_only) return 0;
    const fs::path out = c.out;
    if (c.write_files && Ranks::root()) io::make_output_directory(out);

    const int n = c.realizations;
    const int available = c.threads > 0 ? c.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    // Deformable specimens one at a time, with the threads in their loop (as `bbm ucs`).
    const bool one_at_a_time = c.o.rock.material.deformable_fraction > 0.0;
    std::vector<EnvelopeRun> runs;
    EnvelopeRunner run_jobs{c, tests.compression, tests.tension, tests.tension_kind, available, one_at_a_time, quiet, runs};
    if (!quiet)
        std::fprintf(stderr, "bbm envelope: %s blocks of %.3g m, %g m x %g m, %d realization%s of each test on %d thread%s\n",
                     meshing::to_string(c.o.rock.pattern.kind), c.o.rock.pattern.size, c.o.width, c.o.height, n, n > 1 ? "s" : "", available,
                     available > 1 ? "s" : "");
    const std::vector<double> confinements = run_envelope_tests(e, run_jobs, tests.tension_kind);
    const auto [per_run, csv] = envelope_runs_table(runs);
    const nlohmann::json summary = envelope_summary(e, runs, per_run, confinements, record);

    if (c.write_files && Ranks::root()) {
        io::write_text_atomically(out / "envelope.json", summary.dump(2) + "\n");
        io::write_text_atomically(out / "envelope.csv", csv);
        draw_envelope(summary, out / "envelope.png");
    }
    if (!quiet) print_envelope_result(summary, runs, e);
    if (study) {
        study->runs = std::move(runs);
        study->summary_json = summary.dump();
    }
    return 0;
}

} // namespace bbm::studies
