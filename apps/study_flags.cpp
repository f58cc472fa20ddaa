// The options of the studies built on lab tests — the envelope, the direct shear
// test and the calibration — and their runs from option strings (apps/flags.hpp).
#include "apps/checks.hpp"
#include "apps/flags.hpp"

#include "contact/laws/stress_corrosion.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace bbm::cli {

void add_envelope_options(CLI::App* cmd, studies::EnvelopeOptions& e, bool& quiet) {
    add_labtest_options(cmd, e.lab, quiet);
    cmd->add_option("--confinements", e.confinements,
                    "Lateral stresses of the biaxial tests, Pa, comma-separated (default: 0.1, 0.2, 0.3, 0.4 and 0.5 "
                    "times the measured UCS)")
        ->delimiter(',');
    cmd->add_option("--tension-test", e.tension_test, "The tension test: direct, or brazilian (a disc)")
        ->check(CLI::IsMember({"direct", "brazilian"}))
        ->capture_default_str();
    cmd->add_option("--brazilian-diameter", e.brazilian_diameter, "Disc diameter of the Brazilian test (m)")
        ->check(positive())
        ->capture_default_str();
    cmd->add_option("--target-record", e.target_record,
                    "A laboratory record to draw beside the envelope: CSV of sigma3, sigma1 in MPa")
        ->check(CLI::ExistingFile);
    cmd->add_option("--target-sigma-ci", e.target_sigma_ci, "A Hoek-Brown record to draw: sigma_ci (Pa)")
        ->check(positive());
    cmd->add_option("--target-mi", e.target_mi, "A Hoek-Brown record to draw: mi")->check(positive());
    cmd->add_option("--model", e.model,
                    "Test the rock of this model file: its first region with a block pattern (pattern, size, seed, the "
                    "joint property of its inner joints, deformable fraction and mesh of its blocks) replaces those "
                    "flags; the specimen's size, loading and the envelope's flags still apply")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--replot", e.replot,
                  "Draw envelope.png again from --out's envelope.json (with --target-record or --target-sigma-ci/"
                  "--target-mi to compare), running no test");
}

studies::EnvelopeStudy run_envelope_args(const std::vector<std::string>& args, bool quiet) {
    CLI::App app{"envelope", "envelope"};
    studies::EnvelopeOptions e;
    e.lab.write_files = false;
    bool q = quiet;
    add_envelope_options(&app, e, q);
    e.lab.write_files = parse_args(app, "envelope", args);
    studies::EnvelopeStudy study;
    studies::run_envelope(e, q, false, &study);
    return study;
}

void add_shear_options(CLI::App* sub, studies::ShearValues& v, bool& quiet) {
    auto& c = v.lab;
    auto& o = v.o;
    sub->add_option("--rock", c.rock,
                    "The rock's bonds, material and block pattern from a file, as the lab tests' --rock (what bbm "
                    "calibrate writes); the rock's flags given beside it override it")
        ->check(CLI::ExistingFile);
    sub->add_option("--width", o.width, "Specimen width = length of the shear plane (m)")->check(positive())->capture_default_str();
    sub->add_option("--height", o.height, "Specimen height (m); the plane is at mid-height")->check(positive())->capture_default_str();
    // The rock as the lab tests take it; its pattern may be `single` (each half one
    // rigid block; persistent joints only).
    add_rock_flags(sub, o.rock);
    add_joint_law_flags(sub, o.plane, "joint-", "The plane's joint: ");
    sub->add_option("--persistence", o.persistence,
                    "Joint length over the plane's length, k; the rest is rock bridges (bonded blocks)")
        ->check(in_range(0.0, 1.0))->capture_default_str();
    sub->add_option("--bridges", o.bridges, "Number of rock bridges along the plane (k < 1), each centred in an equal cell")
        ->check(whole_at_least(1))->capture_default_str();
    sub->add_option("--normal-stress", v.normal_stresses, "Normal stress(es) sigma_n (Pa, compression positive): one test per value")
        ->delimiter(',')->check(positive())->capture_default_str();
    sub->add_option("--normal-stiffness", o.normal_stiffness,
                    "Constant normal stiffness K (Pa/m): sigma_n = sigma_n0 + K x dilation; 0 = constant normal load")
        ->check(non_negative())->capture_default_str();
    sub->add_option("--shear-rate", o.shear_rate, "Shear displacement per step (m; quasi-static steps)")->check(positive())->capture_default_str();
    sub->add_option("--max-displacement", o.max_displacement, "Shear displacement at which the test ends (m)")
        ->check(positive())->capture_default_str();
    sub->add_option("--servo-gain", o.servo_gain, "Normal-force servo: fraction of the force error corrected per step")
        ->check(in_range(1e-4, 1.0))->capture_default_str();
    sub->add_option("--frame-every", o.frame_every, "Steps between frames in result.pvd (0: the final state only)")
        ->check(non_negative())->capture_default_str();
    sub->add_option("--realizations", c.realizations, "Random realizations per normal stress (seeds seed, seed+1, ...)")
        ->check(positive())->capture_default_str();
    sub->add_option("--threads", c.threads, "Threads (0 = all cores): runs side by side; a single run uses them in its contact loop")
        ->check(non_negative());
    sub->add_option("--max-elements", o.max_elements, max_elements_help)->check(positive());
    sub->add_option("-o,--out", c.out, "Output directory")->capture_default_str();
    sub->add_flag("-q,--quiet", quiet, "No progress, only errors");
    sub->final_callback([sub, &v] { // after --config: see add_labtest_options
        apply_rock_file(*sub, v.lab.rock, v.o.rock);
        check_joint_law_flags(*sub, v.o.plane, "joint-");
    });
}

void add_creep_options(CLI::App* sub, studies::CreepValues& v, bool& quiet) {
    CreepTestOptions& o = v.o;
    sub->add_option("--rock", v.rock,
                    "The rock's bonds, material and block pattern from a file, as the lab tests' --rock (what bbm "
                    "calibrate writes); a softening bond becomes a corroding one with --corrosion-rate, and the rock's "
                    "flags given beside the file override it")
        ->check(CLI::ExistingFile);
    sub->add_option("--width", o.width, "Specimen width (m)")->check(positive())->capture_default_str();
    sub->add_option("--height", o.height, "Specimen height (m)")->check(positive())->capture_default_str();
    add_rock_flags(sub, o.rock);
    static constexpr const contact::JointKey* corrosion[] = {&contact::key_corrosion_rate, &contact::key_corrosion_exponent,
                                                             &contact::key_corrosion_threshold};
    add_key_flags<JointPropertySpec>(sub, o.rock.bonds, corrosion, "", "The bonds' corrosion: ");
    sub->add_option("--ratios", o.ratios, "Held stresses over each seed's short-term strength, comma-separated, each in (0, 1)")
        ->delimiter(',')->capture_default_str();
    sub->add_option("--realizations", o.realizations, "Seeds per ratio (seed, seed+1, ...), each with its own short-term strength")
        ->check(positive())->capture_default_str();
    sub->add_option("--max-time", o.max_time, "Creep time after which a specimen that has not failed holds (s; default 100 years)")
        ->check(positive())->capture_default_str();
    sub->add_option("--loss", o.loss, "Largest fraction of a bond's section lost in one creep step")
        ->check(in_range(1e-6, 0.5))->capture_default_str();
    sub->add_option("--strength-tolerance", o.strength_tolerance,
                    "The short-term strength's bisection stops when its bracket is this fraction of it")
        ->check(in_range(1e-4, 0.5))->capture_default_str();
    sub->add_option("--max-steps", o.max_steps, "Mechanical steps of a held specimen at most")
        ->check(whole_at_least(1))->capture_default_str();
    sub->add_option("--fit-record", v.fit_record,
                    "Fit the corrosion law's exponent and rate to this static-fatigue record (CSV of stress ratio and "
                    "time to failure in s, one row per test) on the bonds as given; writes joint_property.toml (the "
                    "fitted set) and fit.json, and runs the test at the record's ratios")
        ->check(CLI::ExistingFile);
    sub->add_option("--threads", o.threads, "Threads of each run's contact loop")->check(positive())->capture_default_str();
    sub->add_option("--max-elements", o.max_elements, max_elements_help)->check(positive());
    sub->add_option("-o,--out", v.out, "Output directory")->capture_default_str();
    sub->add_flag("-q,--quiet", quiet, "No progress, only errors");
    sub->final_callback([sub, &v] { // after --config: see add_labtest_options
        apply_rock_file(*sub, v.rock, v.o.rock);
        // A calibrated rock file holds a softening bond: the corrosion makes it corroding.
        if (v.o.rock.bonds.law == "softening" && sub->get_option("--corrosion-rate")->count() > 0)
            v.o.rock.bonds.law = "stress_corrosion";
    });
}

studies::CreepStudy run_creep_args(const std::vector<std::string>& args, bool quiet) {
    CLI::App app{"creep", "creep"};
    studies::CreepValues v;
    bool q = quiet;
    add_creep_options(&app, v, q);
    v.write_files = parse_args(app, "creep", args);
    studies::CreepStudy study;
    studies::run_creep(v, q, false, &study);
    return study;
}

studies::ShearStudy run_shear_args(const std::vector<std::string>& args, bool quiet) {
    CLI::App app{"shear", "shear"};
    studies::ShearValues v;
    v.lab.write_files = false;
    bool q = quiet;
    add_shear_options(&app, v, q);
    v.lab.write_files = parse_args(app, "shear", args);
    studies::ShearStudy study;
    studies::run_shear(v, q, false, &study);
    return study;
}

void add_calibrate_options(CLI::App* cmd, studies::CalibrateValues& v, bool& quiet) {
    add_labtest_options(cmd, v.lab, quiet);
    auto& t = v.targets;
    cmd->add_option("--target-E", t.E, "Target Young's modulus (Pa)")->check(positive())->capture_default_str();
    cmd->add_option("--target-nu", t.nu, "Target Poisson's ratio")->check(in_range(0.01, 0.33))->capture_default_str();
    cmd->add_option("--target-ucs", t.ucs, "Target uniaxial compressive strength (Pa)")->check(positive())->capture_default_str();
    cmd->add_option("--target-tensile", t.tensile, "Target direct tensile strength (Pa)")->check(positive())->capture_default_str();
    cmd->add_option("--target-biaxial", v.biaxial,
                    "Optional: target strength sigma1 of a biaxial test at --target-confinement (Pa); calibrates the "
                    "friction angle too")
        ->check(positive());
    cmd->add_option("--target-confinement", v.confinement,
                    "Lateral stress of the --target-biaxial test (Pa, compression positive)")
        ->check(positive());
    cmd->add_option("--target-record", v.record,
                    "Optional: the record's triaxial strengths, a CSV of sigma3, sigma1 in MPa (a header line "
                    "allowed); calibrates the friction angle to their mean slope")
        ->check(CLI::ExistingFile);
    cmd->add_option("--target-mi", v.mi,
                    "Optional: the record's Hoek-Brown mi (sigma_ci = --target-ucs); its curve at "
                    "--target-mi-confinements is the confined target")
        ->check(positive());
    cmd->add_option("--target-mi-confinements", v.mi_confinements,
                    "sigma3 of the Hoek-Brown targets (Pa, comma-separated; default UCS/6 and UCS/3)")
        ->delimiter(',')
        ->check(positive());
    cmd->add_option("--target-ci-ratio", t.ci_ratio,
                    "Optional: the record's crack-initiation stress over its UCS (reported beside the model's; "
                    "calibrated with --fit-ci)")
        ->check(in_range(0.01, 1.0));
    cmd->add_flag("--fit-ci", v.fit_ci,
                  "Calibrate sigma_ci/UCS (--target-ci-ratio) too, within 0.05, by the heterogeneity of the bond "
                  "strengths (their Weibull modulus m; --weibull-m is the start)");
    cmd->add_flag("--fit-confined-friction", v.fit_confined_friction,
                  "Calibrate the bonds' confined friction phi2 (docs/input.md, confined_friction) on the confined "
                  "targets, the friction and sigma* held (--confined-friction-from; default --target-ucs) and the "
                  "cohesion steered by the UCS alone (--confined-friction is the start; default 55)");
    cmd->add_flag("--fit-curvature", v.fit_curvature,
                  "Calibrate the bonds' cap in two straight pieces: the cohesion and friction phi below the normal "
                  "stress sigma* (--confined-friction-from; default --target-ucs) and the confined friction phi2 "
                  "above it, together on the UCS and two confined targets or more, so that the envelope bends as "
                  "the record's (phi2 < phi: concave; --confined-friction is the start; default phi)");
    cmd->add_option("--target-residual-friction", v.residual_target,
                    "Optional: the friction angle of the rock's rubble in degrees, as the laboratory measures it "
                    "(the residual strength of a confined test: asin((sr - s3)/(sr + s3)); broken crystalline rock "
                    "slides at 40.4, Byerlee 1978); calibrates the broken joints' friction (--residual-friction is "
                    "the start) before the bonds, on biaxial tests run to 2% strain")
        ->check(in_range(1.0, 75.0));
    cmd->add_option("--residual-confinement", v.residual_confinement,
                    "sigma3 of the --target-residual-friction tests (Pa; default a tenth of --target-ucs)")
        ->check(positive());
    cmd->add_option("--iterations", v.iterations, "Iteration limit")->check(positive())->capture_default_str();
}

void note_given_joint_values(const CLI::App& cmd, studies::CalibrateValues& v) {
    // A --rock file gives them too: the calibration starts from its bonds.
    const bool rock = !v.lab.rock.empty();
    v.given_kn = rock || cmd.count("--kn") > 0;
    v.given_ks = rock || cmd.count("--ks") > 0;
    v.given_tensile = rock || cmd.count("--tensile") > 0;
    v.given_cohesion = rock || cmd.count("--cohesion") > 0;
}

std::string run_calibrate_args(const std::vector<std::string>& args, bool quiet) {
    studies::CalibrateValues values;
    CLI::App app{"calibrate", "calibrate"};
    bool quiet_flag = quiet;
    add_calibrate_options(&app, values, quiet_flag);
    parse_args(app, "calibrate", args);
    note_given_joint_values(app, values);
    values.lab.write_files = app.count("--out") > 0;
    std::string json;
    studies::run_calibrate(values, quiet_flag, false, &json);
    return json;
}

} // namespace bbm::cli
