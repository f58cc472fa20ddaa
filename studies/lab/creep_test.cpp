#include "studies/lab/creep_test.hpp"

#include "base/error.hpp"
#include "base/progress.hpp"
#include "core/measures.hpp"
#include "contact/laws/stress_corrosion.hpp"
#include "core/stages.hpp"
#include "io/model_input.hpp"
#include "io/picture.hpp"
#include "io/vtk_output.hpp"
#include "meshing/blocks.hpp"
#include "studies/lab/labtest_values.hpp"
#include "studies/model/model.hpp"
#include "studies/model/run_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

namespace bbm {

namespace {

using studies::fmt_number;

std::string pattern_text(const meshing::PatternSpec& p) {
    const bool random = p.kind == meshing::PatternSpec::Kind::voronoi || p.kind == meshing::PatternSpec::Kind::trigon ||
                        p.kind == meshing::PatternSpec::Kind::delaunay;
    std::string t = "pattern = { type = \"" + std::string(meshing::to_string(p.kind)) + "\", size = " + shortest_text(p.size);
    if (random)
        t += ", size_measure = \"" +
             std::string(p.size_measure == meshing::PatternSpec::SizeMeasure::area ? "area" : "feret") +
             "\", lloyd = " + std::to_string(p.lloyd_iterations) + ", seed = " + std::to_string(p.seed);
    return t + " }\n";
}

/// The bonds as the run takes them: corroding, or (the short-term trial) the same
/// bond with its law's softening and no corrosion.
JointPropertySpec run_bonds(const JointPropertySpec& bonds, bool creep) {
    JointPropertySpec j = bonds;
    j.name = "bond";
    if (!creep) {
        j.law = "softening";
        std::erase_if(j.values, [](const auto& kv) { return kv.first.starts_with("corrosion_"); });
    }
    return j;
}

// The history rows every run records; the top's displacement is the last.
constexpr int top_history = 3;

} // namespace

std::string creep_model_text(const CreepTestOptions& o, std::uint64_t seed, double load, bool creep) {
    const RockSpec& rock = o.rock;
    meshing::PatternSpec pattern = rock.pattern;
    pattern.seed = seed;
    const double w = o.width, h = o.height, margin = 0.01 * std::min(w, h), d = pattern.size;
    const std::string W = shortest_text(w), H = shortest_text(h);
    const std::string box_x = "min = [" + shortest_text(-margin) + ", ", box_x1 = "max = [" + shortest_text(w + margin) + ", ";
    std::string t = "# bbm creep: " + std::string(creep ? "held under " : "short-term trial under ") + fmt_number(load) +
                    " Pa" + (creep ? " while its bonds corrode" : " (no corrosion), solved to equilibrium") + "\n";
    t += "[solver]\nmode = \"quasi_static\"\n\n";
    const MaterialSpec& m = rock.material;
    t += "[[material]]\nname = \"rock\"\ndensity = " + shortest_text(m.density) + "\nyoung = " + shortest_text(m.young) +
         "\npoisson = " + shortest_text(m.poisson) + "\n";
    if (m.deformable_fraction > 0.0) t += "deformable_fraction = " + shortest_text(m.deformable_fraction) + "\n";
    t += "\n[[region]]\nname = \"specimen\"\nmaterial = \"rock\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [" +
         W + ", " + H + "] }\n" + pattern_text(pattern);
    if (m.deformable_fraction > 0.0)
        t += "mesh = { size = " + shortest_text(rock.mesh_size > 0.0 ? rock.mesh_size : 0.5 * d) + " }\n";
    t += "\n" + io::joint_property_toml(run_bonds(rock.bonds, creep));
    t += "\n[[joint_assignment]]\nproperty = \"bond\"\n";
    t += "\n[[boundary]]\nname = \"base\"\ntype = \"velocity\"\nbox = { " + box_x + shortest_text(-margin) + "], " + box_x1 +
         shortest_text(margin) + "] }\ntouching = true\nvx = 0.0\nvy = 0.0\nomega = 0.0\n";
    t += "\n[[boundary]]\nname = \"top\"\ntype = \"stress\"\nbox = { " + box_x + shortest_text(h - margin) + "], " + box_x1 +
         shortest_text(h + margin) + "] }\nsyy = " + shortest_text(-load) + "\n";
    t += "\n[[history]]\nname = \"creep time\"\nquantity = \"creep_time\"\n";
    t += "\n[[history]]\nname = \"tensile cracks\"\nquantity = \"cracks_tensile\"\n";
    t += "\n[[history]]\nname = \"shear cracks\"\nquantity = \"cracks_shear\"\n";
    t += "\n[[history]]\nname = \"top\"\nquantity = \"displacement_y\"\npoint = [" + shortest_text(0.5 * w) + ", " +
         shortest_text(h - 0.5 * d) + "]\n";
    t += "\n# The load put on at once, by one elastic solve (no dynamic overshoot).\n[[stage]]\nname = \"load\"\ntype = "
         "\"elastic\"\n";
    if (creep)
        t += "\n[[stage]]\nname = \"hold\"\ntype = \"creep\"\nduration = " + shortest_text(o.max_time) +
             "\nloss = " + shortest_text(o.loss) + "\nmax_steps = " + std::to_string(o.max_steps) + "\n";
    else
        t += "\n[[stage]]\nname = \"hold\"\ntype = \"solve\"\nuntil = \"equilibrium\"\nmax_steps = " +
             std::to_string(o.strength_max_steps) + "\n";
    return t;
}

void check_creep_options(const CreepTestOptions& o) {
    if (o.rock.bonds.law != "stress_corrosion")
        throw InputError("--law", 0, "",
                         "bbm creep holds a load while the bonds corrode: give law = stress_corrosion with its "
                         "corrosion_rate and corrosion_exponent (the rock's law is " + o.rock.bonds.law + ")");
    studies::check_joint_flags(o.rock.bonds);
    if (o.ratios.empty()) throw InputError("--ratios", 0, "", "give at least one stress ratio");
    for (double r : o.ratios)
        if (!(r > 0.0 && r < 1.0))
            throw InputError("--ratios", 0, "",
                             fmt_number(r) + " is not a stress ratio below the short-term strength: each in (0, 1)");
    if (!(o.max_time > 0.0 && o.max_time <= 3.2e10))
        throw InputError("--max-time", 0, "", fmt_number(o.max_time) + " s: give (0, 3.2e10] s (at most a millennium)");
    studies::LabTestValues lab;
    lab.o.rock = o.rock;
    lab.o.width = o.width, lab.o.height = o.height, lab.o.max_elements = o.max_elements;
    studies::check_specimen_size(lab);
}

namespace {

/// One run's model, built from its text (named for messages as its file would be).
studies::Model build_run(const CreepTestOptions& o, std::uint64_t seed, double load, bool creep) {
    const std::string name = "creep seed " + std::to_string(seed) + " at " + fmt_number(load) + " Pa";
    return studies::Model::from_text(creep_model_text(o, seed, load, creep), name, o.threads, o.max_elements);
}

studies::ModelProgress interruptible() {
    return {[](const studies::Model&) { return !studies::stop_signal_received(); }, 1000};
}

void stop_if_interrupted() {
    if (studies::stop_signal_received()) throw Interrupted("interrupted during a creep test");
}

/// Whether the specimen carries `load` at rest without corrosion.
bool holds(const CreepTestOptions& o, std::uint64_t seed, double load, ShortTermStrength& s) {
    studies::Model m = build_run(o, seed, load, false);
    ++s.trials;
    s.blocks = m.solver().world().bodies.count();
    s.contacts = int(m.solver().world().contacts.size());
    try {
        m.run(interruptible());
    } catch (const NumericalError&) {
        return false; // a specimen collapsing under the load outruns its contacts: it does not hold
    }
    stop_if_interrupted();
    const StageReport& r = m.reports().back();
    return r.converged && (r.verdict.kind == Verdict::Kind::equilibrium ||
                           r.verdict.kind == Verdict::Kind::equilibrium_with_fragments);
}

/// The largest dead load the seed's specimen carries at rest: bracketed from the
/// bonds' own strength (σt + c, within a factor 1.5 a step), then bisected.
ShortTermStrength short_term_strength(const CreepTestOptions& o, std::uint64_t seed,
                                      const std::function<void(const std::string&)>& say) {
    ShortTermStrength s;
    s.seed = seed;
    double guess = o.rock.bonds.tensile + o.rock.bonds.cohesion;
    if (!(guess > 0.0)) guess = 1e6;
    if (holds(o, seed, guess, s)) {
        s.holds = guess;
        for (s.fails = 1.5 * guess; holds(o, seed, s.fails, s) && s.trials < 40; s.fails *= 1.5) s.holds = s.fails;
    } else {
        s.fails = guess;
        for (s.holds = guess / 1.5; !holds(o, seed, s.holds, s) && s.trials < 40; s.holds /= 1.5) s.fails = s.holds;
    }
    while (s.fails - s.holds > o.strength_tolerance * s.holds && s.trials < 60) {
        const double mid = 0.5 * (s.holds + s.fails);
        (holds(o, seed, mid, s) ? s.holds : s.fails) = mid;
    }
    if (say)
        say("seed " + std::to_string(seed) + ": short-term strength " + fmt_number(s.holds / 1e6) + " MPa (fails at " +
            fmt_number(s.fails / 1e6) + ", " + std::to_string(s.trials) + " trials, " + std::to_string(s.blocks) +
            " blocks)");
    return s;
}

CreepRun hold(const CreepTestOptions& o, std::uint64_t seed, double strength, double ratio, bool show_progress) {
    const auto start = std::chrono::steady_clock::now();
    CreepRun run;
    run.seed = seed, run.ratio = ratio, run.load = ratio * strength;
    studies::Model m = build_run(o, seed, run.load, true);
    m.run_stage("load", interruptible());
    stop_if_interrupted();
    const World& w = m.solver().world();
    const HistoryRecorder gauges(w, m.file().analysis.histories);
    const double top0 = gauges.sample(w)[top_history];
    run.cracks_at_load = cracks(w, contact::JointState::broken_tension) + cracks(w, contact::JointState::broken_shear);
    run.highest_ratio_at_load = highest_stress_ratio(w);
    auto sample = [&] {
        const double time = w.creep ? w.creep->time : 0.0;
        if (!run.curve.empty() && run.curve.back().time == time) return;
        run.curve.push_back({time, -(gauges.sample(w)[top_history] - top0) / o.height,
                             cracks(w, contact::JointState::broken_tension), cracks(w, contact::JointState::broken_shear)});
    };
    sample();
    Progress progress;
    m.run_stage("hold", {[&](const studies::Model&) {
                             sample();
                             if (show_progress && progress.due())
                                 progress.line("  seed %llu at %g: creep %.4g of %.4g years, %d cracks, %ld steps",
                                               static_cast<unsigned long long>(seed), ratio,
                                               run.curve.back().time / seconds_per_year, o.max_time / seconds_per_year,
                                               run.curve.back().cracks_tensile + run.curve.back().cracks_shear,
                                               w.clock.steps);
                             return !studies::stop_signal_received();
                         },
                         100});
    stop_if_interrupted();
    sample();
    const StageReport& r = m.reports().back();
    run.failed = r.failed;
    run.time_to_failure = r.creep_time;
    run.step_limit = !r.failed && r.creep_time < o.max_time * (1.0 - 1e-12);
    run.creep_steps = r.creep_steps, run.steps = r.steps;
    run.cracks_tensile = run.curve.back().cracks_tensile, run.cracks_shear = run.curve.back().cracks_shear;
    run.creep_strain = run.curve.back().strain;
    run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return run;
}

std::vector<FatiguePoint> failed_points(const CreepTestResult& res) {
    std::vector<FatiguePoint> p;
    for (const CreepRun& run : res.runs)
        if (run.failed && run.time_to_failure > 0.0) p.push_back({run.ratio, run.time_to_failure});
    return p;
}

} // namespace

FatigueLine fit_fatigue_line(const std::vector<FatiguePoint>& points) {
    FatigueLine line;
    if (points.size() < 2) return line;
    double mr = 0, mt = 0;
    for (const FatiguePoint& p : points) mr += p.ratio / points.size(), mt += std::log10(p.time) / points.size();
    double sxy = 0, sxx = 0;
    for (const FatiguePoint& p : points)
        sxy += (p.ratio - mr) * (std::log10(p.time) - mt), sxx += (p.ratio - mr) * (p.ratio - mr);
    if (!(sxx > 1e-12)) return line;
    line.b = sxy / sxx;
    line.a = mt - line.b * mr;
    return line;
}

std::vector<FatiguePoint> read_fatigue_record(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file, 0, "", "cannot open the static-fatigue record");
    std::vector<FatiguePoint> out;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        const auto first = line.find_first_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') continue;
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream fields(line);
        double ratio = 0.0, time = 0.0;
        if (!(fields >> ratio >> time)) {
            if (out.empty()) continue; // a header
            throw InputError(file, number, "", "expected two numbers: the stress ratio and the time to failure (s)");
        }
        if (!(ratio > 0.0 && ratio < 1.0))
            throw InputError(file, number, "", "stress ratio " + fmt_number(ratio) + ": a held load below the short-term "
                                               "strength is a ratio in (0, 1)");
        if (!(time > 0.0 && std::isfinite(time)))
            throw InputError(file, number, "", "time to failure " + fmt_number(time) + " s: must be positive");
        out.push_back({ratio, time});
    }
    const FatigueLine fitted = fit_fatigue_line(out);
    if (out.size() < 2 || fitted.b == 0.0)
        throw InputError(file, 0, "", "a static-fatigue line needs tests at two stress ratios at least");
    if (fitted.b > 0.0)
        throw InputError(file, 0, "", "the record's times fall as the load falls (its line rises " +
                                          fmt_number(fitted.b) + " decades per unit ratio): not static fatigue");
    return out;
}

CreepTestResult run_creep_test(const CreepTestOptions& o, const std::function<void(const std::string&)>& say,
                               const std::function<void(const CreepRun&, const std::string&)>& on_run,
                               const std::vector<ShortTermStrength>* strengths) {
    check_creep_options(o);
    CreepTestResult res;
    for (int k = 0; k < o.realizations; ++k) {
        const std::uint64_t seed = o.rock.pattern.seed + std::uint64_t(k);
        res.strengths.push_back(strengths && std::size_t(k) < strengths->size() ? (*strengths)[k]
                                                                                : short_term_strength(o, seed, say));
        for (double ratio : o.ratios) {
            CreepRun run = hold(o, seed, res.strengths.back().holds, ratio, bool(say));
            if (say)
                say("seed " + std::to_string(seed) + " at " + fmt_number(ratio) + " (" + fmt_number(run.load / 1e6) +
                    " MPa): " +
                    (run.failed      ? "failed after " + fmt_number(run.time_to_failure) + " s (" +
                                          fmt_number(run.time_to_failure / 86400.0) + " days)"
                     : run.step_limit ? "NOT failed at the step limit after " +
                                            fmt_number(run.time_to_failure / seconds_per_year) +
                                            " years (a lower bound: raise --max-steps)"
                                      : "held for " + fmt_number(run.time_to_failure / seconds_per_year) + " years") +
                    ", creep strain " + fmt_number(run.creep_strain) + ", " +
                    std::to_string(run.cracks_tensile + run.cracks_shear) + " cracks, " +
                    std::to_string(run.creep_steps) + " creep steps");
            if (on_run) on_run(run, creep_model_text(o, seed, run.load, true));
            res.runs.push_back(std::move(run));
        }
    }
    for (double ratio : o.ratios) {
        double log_sum = 0;
        int n = 0;
        for (const CreepRun& run : res.runs)
            if (run.ratio == ratio && run.failed) log_sum += std::log(run.time_to_failure), ++n;
        res.mean_time.push_back(n > 0 ? std::exp(log_sum / n) : 0.0);
        res.failed.push_back(n);
    }
    const FatigueLine line = fit_fatigue_line(failed_points(res));
    res.decades_per_ratio = line.b, res.line_intercept = line.a;
    return res;
}

namespace {

FatigueFitIteration measure_fit(const CreepTestResult& res, const std::vector<FatiguePoint>& record, double exponent,
                                double rate) {
    FatigueFitIteration it;
    it.exponent = exponent, it.rate = rate;
    const auto points = failed_points(res);
    it.line = fit_fatigue_line(points);
    it.failed = int(points.size()), it.runs = int(res.runs.size());
    if (it.line.b != 0.0) {
        double sum = 0.0;
        for (const FatiguePoint& p : record) sum += std::pow(it.line.at(p.ratio) - std::log10(p.time), 2);
        it.misfit = std::sqrt(sum / record.size());
    }
    return it;
}

/// How far (decades) the model's times lie above the record's line, over the model's failed runs.
double mean_offset(const std::vector<FatiguePoint>& model, const FatigueLine& record) {
    double sum = 0.0;
    for (const FatiguePoint& p : model) sum += std::log10(p.time) - record.at(p.ratio);
    return model.empty() ? 0.0 : sum / model.size();
}

/// The next β toward the record's slope from the iterations so far (the last
/// one's slope off): the slope is about linear in β but not through 0 (the
/// assembly redistributes load), so a secant through the last two sets with
/// slopes, the proportional step before there are two; at most a factor 2 a step,
/// never below a tenth of a unit. None when a steeper β no longer steepened the
/// specimen's line (or a gentler one no longer flattened it): its slope is then
/// held by how the assembly sheds load, not by the bonds' law.
std::optional<double> next_exponent(const std::vector<FatigueFitIteration>& iterations, double record_slope) {
    const FatigueFitIteration& it = iterations.back();
    const FatigueFitIteration* before = nullptr;
    for (std::size_t i = iterations.size() - 1; i-- > 0 && !before;)
        if (iterations[i].line.b < 0.0 && iterations[i].exponent != it.exponent) before = &iterations[i];
    const double secant = before ? (it.line.b - before->line.b) / (it.exponent - before->exponent) : 0.0;
    if (before && secant >= 0.0) return std::nullopt;
    const double next = before ? it.exponent + (record_slope - it.line.b) / secant : it.exponent * record_slope / it.line.b;
    return std::clamp(next, std::max(0.1, 0.5 * it.exponent), 2.0 * it.exponent);
}

/// A fit that did not converge keeps the set that came nearest (its misfit),
/// one that did its last.
void keep_nearest(FatigueFit& fit) {
    std::size_t best = fit.iterations.size() - 1;
    if (!fit.converged) {
        best = 0;
        for (std::size_t k = 1; k < fit.iterations.size(); ++k)
            if (fit.iterations[k].line.b < 0.0 &&
                (fit.iterations[best].line.b >= 0.0 || fit.iterations[k].misfit < fit.iterations[best].misfit))
                best = k;
    }
    fit.best = int(best);
    set_law_value(fit.bonds, "corrosion_exponent", fit.iterations[best].exponent);
    set_law_value(fit.bonds, "corrosion_rate", fit.iterations[best].rate);
    fit.final_test = fit.tests[best];
}

} // namespace

FatigueFit fit_static_fatigue(const CreepTestOptions& o, const std::vector<FatiguePoint>& record, double slope_tolerance,
                              int max_iterations, const std::function<void(const std::string&)>& say) {
    // The model's mean time within 0.1 decade (a factor 1.26) of the record's line.
    constexpr double offset_tolerance = 0.1;
    FatigueFit fit;
    fit.record = fit_fatigue_line(record);
    CreepTestOptions t = o;
    t.ratios.clear();
    for (const FatiguePoint& p : record)
        if (std::find(t.ratios.begin(), t.ratios.end(), p.ratio) == t.ratios.end()) t.ratios.push_back(p.ratio);
    std::sort(t.ratios.rbegin(), t.ratios.rend());
    double exponent = contact::key_corrosion_exponent.get(o.rock.bonds), rate = contact::key_corrosion_rate.get(o.rock.bonds);
    std::vector<ShortTermStrength> strengths;
    for (int k = 0; k < max_iterations + 1; ++k) {
        set_law_value(t.rock.bonds, "corrosion_exponent", exponent);
        set_law_value(t.rock.bonds, "corrosion_rate", rate);
        CreepTestResult res = run_creep_test(t, say, {}, strengths.empty() ? nullptr : &strengths);
        strengths = res.strengths;
        FatigueFitIteration it = measure_fit(res, record, exponent, rate);
        fit.iterations.push_back(it);
        fit.tests.push_back(res);
        fit.bonds = t.rock.bonds, fit.final_test = std::move(res);
        if (say)
            say("fit " + std::to_string(k + 1) + ": beta " + fmt_number(exponent) + ", rate " + fmt_number(rate) +
                " /s: " + std::to_string(it.failed) + " of " + std::to_string(it.runs) + " failed, slope " +
                fmt_number(it.line.b) + " decades per unit ratio (record " + fmt_number(fit.record.b) + "), rms misfit " +
                fmt_number(it.misfit) + " decades");
        const double offset = mean_offset(failed_points(fit.final_test), fit.record);
        if (it.line.b >= 0.0) {
            // Fewer than two ratios failed within max_time: the corrosion is too slow
            // for the record (every time scales as 1/rate): speed it up.
            rate *= it.failed == 0 ? 1e3 : std::pow(10.0, std::max(1.0, offset));
            continue;
        }
        const bool slope_matched = std::abs(fit.record.b / it.line.b - 1.0) <= slope_tolerance;
        if (slope_matched && std::abs(offset) <= offset_tolerance) {
            fit.converged = true;
            break;
        }
        if (!slope_matched) {
            const auto next = next_exponent(fit.iterations, fit.record.b);
            if (!next) {
                fit.unreachable = true;
                break;
            }
            exponent = *next;
        }
        rate *= std::pow(10.0, offset);
    }
    keep_nearest(fit);
    return fit;
}

namespace studies {

namespace {

nlohmann::json creep_summary(const CreepTestOptions& o, const CreepTestResult& res) {
    nlohmann::json strengths = nlohmann::json::array(), runs = nlohmann::json::array(), ratios = nlohmann::json::array();
    for (const ShortTermStrength& s : res.strengths)
        strengths.push_back({{"seed", s.seed}, {"strength", s.holds}, {"fails_at", s.fails}, {"trials", s.trials},
                             {"blocks", s.blocks}, {"contacts", s.contacts}});
    for (const CreepRun& r : res.runs)
        runs.push_back({{"seed", r.seed}, {"ratio", r.ratio}, {"load", r.load}, {"failed", r.failed},
                        {r.failed ? "time_to_failure" : r.step_limit ? "lower_bound" : "held_for", r.time_to_failure},
                        {"step_limit", r.step_limit},
                        {"cracks_tensile", r.cracks_tensile}, {"cracks_shear", r.cracks_shear},
                        {"cracks_at_load", r.cracks_at_load},
                        {"highest_ratio_at_load", r.highest_ratio_at_load}, {"creep_strain", r.creep_strain},
                        {"creep_steps", r.creep_steps}, {"steps", r.steps}, {"wall_seconds", r.wall_seconds}});
    for (std::size_t k = 0; k < o.ratios.size(); ++k)
        ratios.push_back({{"ratio", o.ratios[k]}, {"failed", res.failed[k]}, {"of", o.realizations},
                          {"geometric_mean_time", res.mean_time[k]}});
    nlohmann::json j{{"test", "static fatigue"}, {"width", o.width}, {"height", o.height}, {"max_time", o.max_time},
                     {"loss", o.loss}, {"short_term", strengths}, {"ratios", ratios}, {"runs", runs}};
    if (res.decades_per_ratio != 0.0)
        j["line"] = {{"log10_time", "a + b ratio"}, {"a", res.line_intercept}, {"b", res.decades_per_ratio},
                     {"ratio_per_decade", -1.0 / res.decades_per_ratio}};
    return j;
}

std::string creep_csv(const CreepTestResult& res) {
    std::string t = "seed,ratio,load_Pa,failed,step_limit,time_s,cracks_tensile,cracks_shear,creep_strain,creep_steps\n";
    for (const CreepRun& r : res.runs)
        t += std::to_string(r.seed) + "," + shortest_text(r.ratio) + "," + shortest_text(r.load) + "," +
             (r.failed ? "1" : "0") + "," + (r.step_limit ? "1" : "0") + "," + shortest_text(r.time_to_failure) + "," + std::to_string(r.cracks_tensile) + "," +
             std::to_string(r.cracks_shear) + "," + shortest_text(r.creep_strain) + "," + std::to_string(r.creep_steps) + "\n";
    return t;
}

std::string curves_csv(const CreepTestResult& res) {
    std::string t = "seed,ratio,creep_time_s,creep_strain,cracks_tensile,cracks_shear\n";
    for (const CreepRun& r : res.runs)
        for (const CreepPoint& p : r.curve)
            t += std::to_string(r.seed) + "," + shortest_text(r.ratio) + "," + shortest_text(p.time) + "," +
                 shortest_text(p.strain) + "," + std::to_string(p.cracks_tensile) + "," + std::to_string(p.cracks_shear) + "\n";
    return t;
}

/// time_to_failure.png: each run's time against its ratio (held runs at max_time
/// as their own series), the geometric means and the fitted line; creep_curves.png:
/// creep strain against creep time over the time to failure, the three stages of
/// creep a laboratory sees.
void draw_creep(const CreepTestOptions& o, const CreepTestResult& res, const std::vector<FatiguePoint>& record,
                const std::filesystem::path& out) {
    io::Series failed{"runs (failed)", {}, {}, io::Series::Style::points};
    io::Series held{"not failed: held to max-time or at the step limit", {}, {}, io::Series::Style::points};
    io::Series mean{"geometric mean", {}, {}, io::Series::Style::line};
    for (const CreepRun& r : res.runs) {
        io::Series& s = r.failed ? failed : held;
        s.x.push_back(r.ratio), s.y.push_back(std::log10(r.time_to_failure));
    }
    for (std::size_t k = 0; k < o.ratios.size(); ++k)
        if (res.failed[k] > 0) mean.x.push_back(o.ratios[k]), mean.y.push_back(std::log10(res.mean_time[k]));
    io::Series measured{"record", {}, {}, io::Series::Style::points};
    for (const FatiguePoint& p : record) measured.x.push_back(p.ratio), measured.y.push_back(std::log10(p.time));
    std::vector<io::Series> series;
    for (io::Series* s : {&failed, &held, &mean, &measured})
        if (!s->x.empty()) series.push_back(*s);
    if (!series.empty())
        io::draw_curves(series, "held stress / short-term strength",
                        "log10 time to failure (s): 5 = 1.2 days, 7 = 116 days, 9.5 = 100 years",
                        out / "time_to_failure.png", "static fatigue", false, false, false);
    std::vector<io::Series> curves;
    for (const CreepRun& r : res.runs) {
        if (!r.failed || r.time_to_failure <= 0.0) continue;
        io::Series s{"seed " + std::to_string(r.seed) + " at " + fmt_number(r.ratio), {}, {}, io::Series::Style::line};
        for (const CreepPoint& p : r.curve) s.x.push_back(p.time / r.time_to_failure), s.y.push_back(1e3 * p.strain);
        curves.push_back(std::move(s));
    }
    if (!curves.empty())
        io::draw_curves(curves, "creep time / time to failure", "creep strain (1e-3)", out / "creep_curves.png",
                        "creep under a held load", false, true);
}

nlohmann::json fit_json(const FatigueFit& fit, const std::vector<FatiguePoint>& record) {
    nlohmann::json iterations = nlohmann::json::array(), points = nlohmann::json::array();
    for (const FatigueFitIteration& it : fit.iterations)
        iterations.push_back({{"corrosion_exponent", it.exponent}, {"corrosion_rate", it.rate}, {"a", it.line.a},
                              {"b", it.line.b}, {"failed", it.failed}, {"runs", it.runs}, {"rms_misfit_decades", it.misfit}});
    for (const FatiguePoint& p : record) points.push_back({p.ratio, p.time});
    return {{"record", points}, {"record_line", {{"a", fit.record.a}, {"b", fit.record.b}}},
            {"converged", fit.converged}, {"unreachable", fit.unreachable}, {"best_iteration", fit.best + 1},
            {"iterations", iterations},
            {"corrosion_exponent", contact::key_corrosion_exponent.get(fit.bonds)},
            {"corrosion_rate", contact::key_corrosion_rate.get(fit.bonds)},
            {"corrosion_threshold", contact::key_corrosion_threshold.get(fit.bonds)},
            {"joint_property_toml", io::joint_property_toml(fit.bonds)}};
}

/// The fitted set as a model file's [[joint_property]], with what it was fitted to.
std::string fitted_set_toml(const FatigueFit& fit, const std::string& record_file) {
    const FatigueFitIteration& last = fit.iterations[fit.best];
    JointPropertySpec j = fit.bonds;
    j.name = "fitted";
    return "# bbm creep --fit-record " + record_file + ": the corrosion law fitted to its static-fatigue line,\n" +
           "# log10 t = " + fmt_number(fit.record.a) + " " + fmt_number(fit.record.b) + " ratio; the fitted set gives " +
           fmt_number(last.line.a) + " " + fmt_number(last.line.b) + " ratio, rms " + fmt_number(last.misfit) +
           " decades" + (fit.converged ? "" : " (NOT converged: the nearest set tried; see fit.json)") + ".\n" +
           io::joint_property_toml(j);
}

} // namespace

int run_creep(CreepValues& v, bool quiet, bool check_only, CreepStudy* study) {
    check_creep_options(v.o);
    const std::vector<FatiguePoint> record = v.fit_record.empty() ? std::vector<FatiguePoint>{}
                                                                  : read_fatigue_record(v.fit_record);
    if (check_only) return 0;
    const std::filesystem::path out = v.out;
    if (v.write_files) std::filesystem::create_directories(out / "runs");
    const auto say = [quiet](const std::string& line) {
        if (!quiet) std::printf("%s\n", line.c_str()), std::fflush(stdout);
    };
    const auto keep = [&](const CreepRun& r, const std::string& text) {
        if (v.write_files)
            io::write_text_atomically(out / "runs" / ("seed" + std::to_string(r.seed) + "_" + fmt_number(r.ratio) + ".toml"),
                                      text);
    };
    CreepTestResult res;
    nlohmann::json fit_summary;
    if (!record.empty()) {
        const FatigueFit fit = fit_static_fatigue(v.o, record, 0.1, 6, say);
        fit_summary = fit_json(fit, record);
        if (v.write_files) {
            io::write_text_atomically(out / "fit.json", fit_summary.dump(2) + "\n");
            io::write_text_atomically(out / "joint_property.toml", fitted_set_toml(fit, v.fit_record));
        }
        v.o.rock.bonds = fit.bonds;
        res = fit.final_test;
        for (const CreepRun& r : res.runs) keep(r, creep_model_text(v.o, r.seed, r.load, true));
        if (fit.unreachable)
            std::fprintf(stderr, "bbm creep: the record's line (%g decades per unit ratio) is out of the specimen's reach: "
                                 "a steeper corrosion exponent no longer steepens its line (its steepness is held by how "
                                 "the assembly sheds load); the nearest set tried is written. Try more realizations or "
                                 "another block size\n", fit.record.b);
        else if (!fit.converged)
            std::fprintf(stderr, "bbm creep: the fit did not converge: the nearest set tried is written\n");
    } else {
        res = run_creep_test(v.o, say, keep);
    }
    nlohmann::json summary = creep_summary(v.o, res);
    if (!record.empty()) summary["fit"] = fit_summary;
    if (v.write_files) {
        io::write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
        io::write_text_atomically(out / "creep.csv", creep_csv(res));
        io::write_text_atomically(out / "creep_curves.csv", curves_csv(res));
        draw_creep(v.o, res, record, out);
    }
    if (res.decades_per_ratio != 0.0)
        say("static-fatigue line: log10 t = " + fmt_number(res.line_intercept) + " " + fmt_number(res.decades_per_ratio) +
            " ratio (a decade of time per " + fmt_number(-1.0 / res.decades_per_ratio) + " of stress ratio)");
    if (study) study->result = std::move(res), study->summary_json = summary.dump();
    return 0;
}

} // namespace studies
} // namespace bbm
