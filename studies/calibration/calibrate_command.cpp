// `bbm calibrate` as a command: its checks, its report and its files (the
// iteration itself is studies/calibration/calibrate.cpp).
#include "base/error.hpp"
#include "io/vtk_output.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"
#include "studies/calibration/calibrate_command.hpp"
#include "studies/lab/labtest_command.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/cluster/ranks.hpp"
#include "studies/lab/residual_friction.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace bbm::studies {

namespace fs = std::filesystem;

namespace {

/// The confined targets of `bbm calibrate` (one biaxial test, a CSV record or a
/// Hoek–Brown mi: one of them) as targets.envelope, checked.
void confined_targets(CalibrateValues& v) {
    auto& t = v.targets;
    if ((v.biaxial > 0.0) != (v.confinement > 0.0))
        throw InputError(v.biaxial > 0.0 ? "--target-biaxial" : "--target-confinement", 0, "",
                         "--target-biaxial and --target-confinement go together (the strength and the lateral stress "
                         "of one biaxial test)");
    const int given = int(v.biaxial > 0.0) + int(!v.record.empty()) + int(v.mi > 0.0);
    if (given > 1)
        throw InputError("--target-record", 0, "",
                         "give one confined target: --target-biaxial, --target-record or --target-mi");
    if (!v.mi_confinements.empty() && !(v.mi > 0.0))
        throw InputError("--target-mi-confinements", 0, "", "goes with --target-mi");
    t.envelope.clear();
    if (v.biaxial > 0.0) t.envelope.push_back({v.confinement, v.biaxial});
    if (!v.record.empty()) {
        for (const auto& p : read_strength_record(v.record))
            if (p.first > 0.0) t.envelope.push_back(p); // σ3 = 0 is the UCS target's
        if (t.envelope.empty()) throw InputError(v.record, 0, "", "no confined test (sigma3 > 0) in the record");
    }
    if (v.mi > 0.0) {
        const auto s3 = v.mi_confinements.empty() ? std::vector<double>{t.ucs / 6.0, t.ucs / 3.0} : v.mi_confinements;
        t.envelope = hoek_brown_targets(t.ucs, v.mi, s3);
    }
    for (const auto& [s3, s1] : t.envelope)
        if (s1 <= t.ucs)
            throw InputError(!v.record.empty() ? v.record : "--target-biaxial", 0, "",
                             "a confined strength must exceed the UCS target (" + fmt_number(t.ucs) + " Pa); got " +
                                 fmt_number(s1) + " Pa at sigma3 " + fmt_number(s3) + " Pa");
}

/// The calibration's options from the command's values, checked.
CalibrationOptions calibration_options(CalibrateValues& values) {
    LabTestValues& c = values.lab;
    confined_targets(values);
    CalibrationOptions o;
    o.base = c.o;
    // Joint values given on the command line (or in --config) are the starting point.
    o.start_kn = values.given_kn;
    o.start_ks = values.given_ks;
    o.start_tensile = values.given_tensile;
    o.start_cohesion = values.given_cohesion;
    check_joint_flags(o.base.rock.bonds);
    o.realizations = c.realizations;
    o.threads = c.threads > 0 ? c.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    o.max_iterations = values.iterations;
    o.fit_ci = values.fit_ci;
    o.fit_confined_friction = values.fit_confined_friction;
    if (o.fit_confined_friction && values.targets.envelope.empty())
        throw InputError("--fit-confined-friction", 0, "",
                         "needs a confined target (--target-biaxial, --target-record or --target-mi) for phi2");
    o.fit_curvature = values.fit_curvature;
    if (o.fit_curvature && values.targets.envelope.size() < 2)
        throw InputError("--fit-curvature", 0, "",
                         "needs two confined targets or more (--target-record or --target-mi) for phi and phi2");
    if (o.fit_curvature && o.fit_confined_friction)
        throw InputError("--fit-curvature", 0, "", "fits phi2 itself: leave out --fit-confined-friction");
    if (values.residual_confinement > 0.0 && !(values.residual_target > 0.0))
        throw InputError("--residual-confinement", 0, "", "goes with --target-residual-friction");
    if (values.residual_target > 0.0 && !(values.residual_confinement > 0.0))
        values.residual_confinement = 0.1 * values.targets.ucs;
    if (o.fit_ci && !(values.targets.ci_ratio > 0))
        throw InputError("--fit-ci", 0, "", "needs the record's sigma_ci / UCS (--target-ci-ratio)");
    check_specimen_size(c);
    return o;
}

/// SPEC §8's first estimates, kn = E/d and ks = G/d, for reference; the iteration
/// starts from the lattice inversion on the generated blocks (calibrate.hpp).
struct FirstEstimates {
    double kn, ks;
};

void print_calibration_header(const CalibrateValues& values, const CalibrationOptions& o, const FirstEstimates& first,
                              const JointPropertySpec& start) {
    const CalibrationTargets& targets = values.targets;
    std::fprintf(stderr,
                 "bbm calibrate: %s blocks of %.3g m, %g m x %g m, %d realizations of UCS and direct tension per "
                 "iteration\ntargets: E %.4g GPa, nu %.3g, UCS %.4g MPa, tensile %.4g MPa\n",
                 meshing::to_string(o.base.rock.pattern.kind), o.base.rock.pattern.size, o.base.width, o.base.height, o.realizations, targets.E / 1e9,
                 targets.nu, targets.ucs / 1e6, targets.tensile / 1e6);
    if (!targets.envelope.empty()) {
        std::fprintf(stderr, "and the confined strengths sigma1 at sigma3 (MPa):");
        for (const auto& [s3, s1] : targets.envelope) std::fprintf(stderr, " %.4g at %.4g,", s1 / 1e6, s3 / 1e6);
        std::fprintf(stderr, o.fit_confined_friction
                                 ? " the confined friction phi2 calibrated (phi and sigma* held; sigma*, phi2 and the "
                                   "sigma1 at the end of each row)\n"
                             : o.fit_curvature
                                 ? " the cap in two pieces calibrated, phi below sigma* and phi2 above it (sigma* held; "
                                   "sigma*, phi2, phi and the sigma1 at the end of each row)\n"
                                 : " the friction angle calibrated too (phi and the sigma1 at the end of each row)\n");
    }
    if (targets.ci_ratio > 0 && o.fit_ci)
        std::fprintf(stderr, "and sigma_ci/UCS %.3g (within %.2g), by the bonds' strength heterogeneity (Weibull "
                             "modulus m, at the end of each row)\n",
                     targets.ci_ratio, o.tolerance_ci);
    else if (targets.ci_ratio > 0)
        std::fprintf(stderr, "the record's sigma_ci/UCS %.3g is reported beside the model's, not calibrated "
                             "(--fit-ci calibrates it)\n",
                     targets.ci_ratio);
    std::fprintf(stderr, "first estimates kn = E/d %.2f, ks = G/d %.2f GPa/m; start kn %.2f, ks %.2f GPa/m (%s)\n",
                 first.kn / 1e9, first.ks / 1e9, start.kn / 1e9, start.ks / 1e9,
                 o.start_kn || o.start_ks ? "as given" : "lattice inversion on the generated blocks");
}

/// The iteration table's column heads.
void print_iteration_columns() {
    std::fprintf(stderr, "%4s %10s %10s %9s %9s | %9s %9s %7s %10s %10s %8s\n", "iter", "kn GPa/m", "ks GPa/m",
                 "st MPa", "c MPa", "E GPa", "E(curve)", "nu", "UCS MPa", "T MPa", "s");
}

/// One row of the iteration table on the console.
void print_iteration(int k, const CalibrationIteration& it, const CalibrationOptions& o, bool with_phi) {
    std::fprintf(stderr, "%4d %10.2f %10.2f %9.3f %9.3f | %9.2f %9.2f %7.3f %10.2f %10.3f %8.0f", k,
                 it.joint.kn / 1e9, it.joint.ks / 1e9, it.joint.tensile / 1e6, it.joint.cohesion / 1e6, it.E / 1e9,
                 it.E_test / 1e9, it.nu, it.ucs / 1e6, it.tensile / 1e6, it.seconds);
    std::fprintf(stderr, " ci/UCS %.2f", it.ci_ratio);
    if (o.fit_ci)
        std::fprintf(stderr, " (m %s)",
                     it.joint.weibull_modulus > 0 ? fmt_number(it.joint.weibull_modulus).c_str() : "uniform");
    if (with_phi) {
        if (o.fit_confined_friction || o.fit_curvature)
            std::fprintf(stderr, "   sigma* %.4g MPa phi2 %5.2f", it.joint.confined_friction_from / 1e6,
                         it.joint.confined_friction);
        std::fprintf(stderr, "   phi %5.2f  sigma1", it.joint.friction);
        for (double s1 : it.confined) std::fprintf(stderr, " %7.2f", s1 / 1e6);
    }
    std::fprintf(stderr, "  misfit %.3f%s\n", it.misfit, it.converged ? "  converged" : "");
    if (it.still_loading > 0)
        std::fprintf(stderr, "     %d test%s still loading at the strain cap %g: lower bounds, not strengths "
                             "(blocks jammed)\n",
                     it.still_loading, it.still_loading == 1 ? "" : "s", std::max(o.base.stop.max_strain, o.base.stop.strain_cap));
}

/// One row of calibration.json's iteration table.
nlohmann::json iteration_json(const CalibrationIteration& it) {
    return {{"kn", it.joint.kn}, {"ks", it.joint.ks}, {"tensile", it.joint.tensile},
            {"cohesion", it.joint.cohesion}, {"E", it.E}, {"E_std", it.E_std}, {"E_ucs_curve", it.E_test}, {"nu", it.nu},
            {"nu_std", it.nu_std}, {"ucs", it.ucs}, {"ucs_std", it.ucs_std}, {"tensile_strength", it.tensile},
            {"tensile_strength_std", it.tensile_std}, {"friction", it.joint.friction},
            {"confined_friction", it.joint.confined_friction},
            {"confined_friction_from", it.joint.confined_friction_from},
            {"confined_strength", nlohmann::json(it.confined)},
            {"confined_strength_std", nlohmann::json(it.confined_std)}, {"ci_ratio", it.ci_ratio},
            {"ci_ratio_std", it.ci_ratio_std}, {"weibull_modulus", it.joint.weibull_modulus},
            {"misfit", it.misfit}, {"seconds", it.seconds},
            {"converged", it.converged}, {"still_loading", it.still_loading}};
}

/// The calibrated set measured on seeds the calibration has not seen, on the console.
void print_fresh_seeds(const CalibrationIteration& fresh, const CalibrationOptions& o, const CalibrationTargets& targets,
                       const std::vector<double>& sigma3, const CalibrationIteration& last, int last_number) {
    std::fprintf(stderr, "fresh seeds %llu..: E %.2f GPa (curve %.2f), nu %.3f, UCS %.2f MPa (std %.2f), T %.3f MPa "
                         "(std %.3f)",
                 static_cast<unsigned long long>(o.base.rock.pattern.seed + 1000), fresh.E / 1e9, fresh.E_test / 1e9, fresh.nu,
                 fresh.ucs / 1e6, fresh.ucs_std / 1e6, fresh.tensile / 1e6, fresh.tensile_std / 1e6);
    for (std::size_t i = 0; i < sigma3.size(); ++i)
        std::fprintf(stderr, ", sigma1 %.2f MPa (std %.2f; target %.2f) at %.3g", fresh.confined[i] / 1e6,
                     fresh.confined_std[i] / 1e6, targets.envelope[i].second / 1e6, sigma3[i] / 1e6);
    std::fprintf(stderr, ", ci/UCS %.2f (std %.2f%s), misfit %.3f\n", fresh.ci_ratio, fresh.ci_ratio_std,
                 targets.ci_ratio > 0 ? ("; record " + fmt_number(targets.ci_ratio)).c_str() : "", fresh.misfit);
    if (!last.converged)
        std::fprintf(stderr, "not converged: the best set is iteration %d (misfit %.3f)\n", last_number, last.misfit);
    if (o.fit_ci && !(last.joint.weibull_modulus > 0.0) && last.ci_ratio < targets.ci_ratio - o.tolerance_ci)
        std::fprintf(stderr, "sigma_ci/UCS is below the record's with uniform bonds: heterogeneous bonds only lower "
                             "it (docs/calibration.md, \"Calibrating sigma_ci/UCS\")\n");
}

/// joint_property.toml: the calibrated set with a header naming the pattern it
/// holds for, the targets and what the set measured; every number exact.
std::string calibrated_set_toml(const CalibrateValues& values, const CalibrationOptions& o,
                                const CalibrationIteration& last, int last_number) {
    const CalibrationTargets& targets = values.targets;
    const meshing::PatternSpec& pattern = o.base.rock.pattern;
    const std::string kind = meshing::to_string(pattern.kind);
    const bool area = pattern.size_measure == meshing::PatternSpec::SizeMeasure::area;
    // The set holds for this pattern only: say which, as a model file writes it.
    const std::string pattern_line = "pattern = { type = \"" + kind + "\", size = " + fmt_number(pattern.size) +
                                     ", size_measure = \"" + (area ? "area" : "feret") + "\", lloyd = " +
                                     std::to_string(pattern.lloyd_iterations) + " }";
    std::string toml = "# bbm calibrate: " + kind + " blocks of " + fmt_number(pattern.size) + " m (" +
                       (area ? "equal-area diameter" : "mean Feret diameter") + "), Lloyd " +
                       std::to_string(o.base.rock.pattern.lloyd_iterations) + ", in a " + fmt_number(o.base.width) + " m x " +
                       fmt_number(o.base.height) + " m specimen; for regions with\n#   " + pattern_line +
                       "\n# Targets E " + fmt_number(targets.E) + " Pa, nu " + fmt_number(targets.nu) + ", UCS " +
                       fmt_number(targets.ucs) + " Pa, tensile " + fmt_number(targets.tensile) + " Pa" +
                       (!targets.envelope.empty()
                            ? ", " + std::to_string(targets.envelope.size()) + " confined strengths"
                            : std::string()) +
                       ".\n# Calibrated set, iteration " + std::to_string(last_number) + " (mean of " +
                       std::to_string(o.realizations) + "): E " + fmt_number(last.E) + " Pa, nu " + fmt_number(last.nu) +
                       ", UCS " + fmt_number(last.ucs) + " Pa, tensile " + fmt_number(last.tensile) + " Pa" +
                       ", largest misfit " + fmt_number(last.misfit) +
                       (last.converged ? "" : " (NOT converged: the best set; see calibration.json)") + ".\n";
    // Every key of its law that differs from the default, heterogeneity and fracture
    // energies included: without them the file would describe a rock the
    // calibration never measured.
    JointPropertySpec j = last.joint;
    j.name = "calibrated";
    toml += io::joint_property_toml(j);
    // Bonds calibrated with deformable blocks hold only with them: kn and ks are the
    // rock's, split by the blocks' share f (SPEC §6). The material travels with them.
    const MaterialSpec& m = o.base.rock.material;
    if (m.deformable_fraction > 0.0)
        toml += "\n# The blocks the bonds were calibrated with (a region with a mesh of " +
                fmt_number(o.base.rock.mesh_size > 0.0 ? o.base.rock.mesh_size : 0.5 * o.base.rock.pattern.size) +
                " m triangles):\n[[material]]\nname = \"calibrated\"\ndensity = " + shortest_text(m.density) +
                "\nyoung = " + shortest_text(m.young) + "\npoisson = " + shortest_text(m.poisson) +
                "\ndeformable_fraction = " + shortest_text(m.deformable_fraction) + "\n";
    return toml;
}

/// One iteration of the broken joints' friction on the console (0: the fresh-seed check).
void print_residual_step(int k, const ResidualFrictionStep& s) {
    if (k > 0) std::fprintf(stderr, "  r%d ", k);
    std::fprintf(stderr, "broken joints %5.2f deg: rubble %5.2f deg (std %.2f), residual %.4g MPa, peak %.4g MPa, %.0f s%s",
                 s.residual_friction, s.rubble_friction, s.rubble_std, s.residual_stress / 1e6, s.peak_stress / 1e6,
                 s.seconds, s.converged ? "  converged" : "");
    if (s.unmeasured > 0) std::fprintf(stderr, "  (%d run%s ended too soon after the peak)", s.unmeasured, s.unmeasured == 1 ? "" : "s");
    std::fprintf(stderr, "\n");
}

/// calibration.json's "residual_friction": the target, the iterations and the fresh-seed check.
nlohmann::json residual_record(const ResidualFrictionTarget& t, const std::vector<ResidualFrictionStep>& steps,
                               const ResidualFrictionStep& fresh, bool converged) {
    auto row = [](const ResidualFrictionStep& s) {
        return nlohmann::json{{"residual_friction", s.residual_friction}, {"rubble_friction", s.rubble_friction},
                              {"rubble_friction_std", s.rubble_std}, {"residual_stress", s.residual_stress},
                              {"peak_stress", s.peak_stress}, {"unmeasured", s.unmeasured}, {"seconds", s.seconds},
                              {"converged", s.converged}};
    };
    nlohmann::json iterations = nlohmann::json::array();
    for (const auto& s : steps) iterations.push_back(row(s));
    return {{"target", t.friction}, {"confinement", t.confinement}, {"tolerance", t.tolerance},
            {"max_strain", t.max_strain}, {"calibrated", best_residual_step(steps, t.friction).residual_friction},
            {"iterations", iterations}, {"fresh_seeds", row(fresh)}, {"converged", converged}};
}

/// calibration.json: the targets, the start, the iterations, the set on fresh
/// seeds and the set's model-file text.
nlohmann::json calibration_record(const CalibrateValues& values, const CalibrationOptions& o, const FirstEstimates& first,
                                  const JointPropertySpec& start, const CalibrationIteration& last, int last_number,
                                  const CalibrationIteration& fresh, nlohmann::json table, const std::string& toml) {
    const CalibrationTargets& targets = values.targets;
    return {{"targets", {{"E", targets.E}, {"nu", targets.nu}, {"ucs", targets.ucs},
                         {"tensile", targets.tensile}, {"envelope", targets.envelope},
                         {"ci_ratio", targets.ci_ratio}, {"fit_ci", o.fit_ci},
                         {"fit_confined_friction", o.fit_confined_friction},
                         {"fit_curvature", o.fit_curvature}}},
            {"pattern", meshing::to_string(o.base.rock.pattern.kind)},
            {"size", o.base.rock.pattern.size},
            {"size_measure", o.base.rock.pattern.size_measure == meshing::PatternSpec::SizeMeasure::area ? "area" : "feret"},
            {"lloyd", o.base.rock.pattern.lloyd_iterations},
            {"realizations", o.realizations},
            {"converged", last.converged},
            {"calibrated_iteration", last_number},
            {"first_estimate", {{"kn", first.kn}, {"ks", first.ks}}},
            {"start", {{"kn", start.kn}, {"ks", start.ks}, {"tensile", start.tensile}, {"cohesion", start.cohesion}}},
            {"fresh_seeds", {{"first_seed", o.base.rock.pattern.seed + 1000}, {"E", fresh.E},
                             {"E_ucs_curve", fresh.E_test}, {"nu", fresh.nu},
                             {"ucs", fresh.ucs}, {"ucs_std", fresh.ucs_std},
                             {"tensile_strength", fresh.tensile},
                             {"tensile_strength_std", fresh.tensile_std},
                             {"confined_strength", nlohmann::json(fresh.confined)},
                             {"confined_strength_std", nlohmann::json(fresh.confined_std)},
                             {"ci_ratio", fresh.ci_ratio},
                             {"ci_ratio_std", fresh.ci_ratio_std},
                             {"misfit", fresh.misfit}}},
            {"iterations", std::move(table)},
            {"joint_property_toml", toml}};
}

/// The broken joints' friction first, on the rubble's: the bonds' confined
/// strengths depend on it, it hardly on them (residual_friction.hpp). Sets the
/// bonds' residual friction in `o`; the steps taken (none without a target).
std::vector<ResidualFrictionStep> calibrate_residual_first(const JointPropertySpec& start,
                                                          const ResidualFrictionTarget& residual, CalibrationOptions& o,
                                                          bool quiet) {
    std::vector<ResidualFrictionStep> residual_steps;
    if (!(residual.friction > 0.0)) return residual_steps;
    if (!quiet)
        std::fprintf(stderr, "the broken joints' friction first: the rubble's friction %.3g deg (within %.2g) on "
                             "biaxial tests at sigma3 %.4g MPa to %.2g%% strain, with the start's bonds\n",
                     residual.friction, residual.tolerance, residual.confinement / 1e6, 100 * residual.max_strain);
    int r = 0;
    residual_steps = calibrate_residual_friction(start, residual, o, [&](const ResidualFrictionStep& step) {
        if (!quiet) print_residual_step(++r, step);
    });
    o.base.rock.bonds.residual_friction = best_residual_step(residual_steps, residual.friction).residual_friction;
    if (!quiet)
        std::fprintf(stderr, "broken joints' friction %.4g deg; now the bonds\n", o.base.rock.bonds.residual_friction);
    return residual_steps;
}

/// The calibrated set's rubble on the fresh seeds: the friction it will slide at,
/// recorded in `calibration`; whether it is within the target's tolerance.
bool check_fresh_rubble(const CalibrationIteration& last, const ResidualFrictionTarget& residual,
                        const std::vector<ResidualFrictionStep>& residual_steps, const CalibrationOptions& o, bool quiet,
                        nlohmann::json& calibration) {
    const auto fresh_rubble = measure_rubble_friction(last.joint, residual, o, o.base.rock.pattern.seed + 1000);
    const bool residual_converged = std::abs(fresh_rubble.rubble_friction - residual.friction) <= residual.tolerance &&
                                    fresh_rubble.unmeasured < o.realizations;
    if (!quiet) {
        std::fprintf(stderr, "fresh seeds, the rubble: ");
        print_residual_step(0, fresh_rubble);
    }
    calibration["residual_friction"] = residual_record(residual, residual_steps, fresh_rubble, residual_converged);
    return residual_converged;
}

/// joint_property.toml and calibration.json in the output directory.
void write_calibration_files(const fs::path& out, const std::string& toml, const nlohmann::json& calibration,
                             bool converged, bool quiet) {
    io::write_text_atomically(out / "joint_property.toml", toml);
    io::write_text_atomically(out / "calibration.json", calibration.dump(2) + "\n");
    if (!quiet)
        std::fprintf(stderr, "wrote %s/joint_property.toml and calibration.json%s\n", out.string().c_str(),
                     converged ? "" : " (not converged within the iteration limit)");
}

} // namespace

/// `bbm calibrate`: iterates the micro-properties and writes the joint property
/// set as a TOML fragment, with the iteration table as JSON.
int run_calibrate(CalibrateValues& values, bool quiet, bool check_only, std::string* calibration_json) {
    quiet = quiet || !Ranks::root(); // under mpirun, rank 0 reports and writes
    CalibrationOptions o = calibration_options(values);
    if (check_only) return 0;
    const CalibrationTargets& targets = values.targets;
    const FirstEstimates first{targets.E / o.base.rock.pattern.size, targets.E / (2.0 * (1.0 + targets.nu)) / o.base.rock.pattern.size};
    const JointPropertySpec start = calibration_start(targets, o);
    const fs::path out = values.lab.out;
    if (values.lab.write_files) io::make_output_directory(out);
    const bool with_phi = !targets.envelope.empty();
    std::vector<double> sigma3;
    for (const auto& p : targets.envelope) sigma3.push_back(p.first);
    if (!quiet) print_calibration_header(values, o, first, start);
    const ResidualFrictionTarget residual{values.residual_target, values.residual_confinement};
    const std::vector<ResidualFrictionStep> residual_steps = calibrate_residual_first(start, residual, o, quiet);
    if (!quiet) print_iteration_columns();
    nlohmann::json table = nlohmann::json::array();
    int k = 0;
    const auto iterations_done = calibrate(targets, o, [&](const CalibrationIteration& it) {
        if (!quiet) print_iteration(++k, it, o, with_phi);
        table.push_back(iteration_json(it));
    });
    // The converged set, or else the best one (the smallest misfit).
    const auto& last = best_iteration(iterations_done);
    const int last_number = int(&last - iterations_done.data()) + 1;
    // The calibrated set on seeds it has not seen: what a new model will get.
    auto fresh = measure_macro_properties(last.joint, o, o.base.rock.pattern.seed + 1000, sigma3);
    fresh.misfit = calibration_misfit(fresh, targets, o.fit_ci);
    if (!quiet) print_fresh_seeds(fresh, o, targets, sigma3, last, last_number);
    const std::string toml = calibrated_set_toml(values, o, last, last_number);
    nlohmann::json calibration =
        calibration_record(values, o, first, start, last, last_number, fresh, std::move(table), toml);
    const bool residual_converged =
        residual_steps.empty() || check_fresh_rubble(last, residual, residual_steps, o, quiet, calibration);
    const bool converged = last.converged && residual_converged;
    if (calibration_json) *calibration_json = calibration.dump();
    if (values.lab.write_files && Ranks::root()) write_calibration_files(out, toml, calibration, converged, quiet);
    return converged ? 0 : 4;
}

} // namespace bbm::studies
