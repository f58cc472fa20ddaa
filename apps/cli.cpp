// bbm: the command-line program, a thin front end on the library (studies/):
// bbm_cli_main is main() of the program (apps/main.cpp) and of the fuzzer of
// --config files (tests/fuzz/fuzz_config.cpp), compiled once for both.
// Subcommands:
//   bbm mesh MODEL.toml --out DIR   generate the block model, write VTK and a summary
//   bbm run MODEL.toml --out DIR    generate it and run the model file's stages
//   bbm compare A.toml B.toml ...   run several models, tabulate and plot them
//   bbm ucs | tension | biaxial | brazilian [flags]   numerical lab tests (SPEC §8)
//   bbm envelope [flags]            the strength envelope: UCS, tension, biaxial; Hoek-Brown and Mohr-Coulomb fits
//   bbm shear [flags]               direct shear of a joint or a non-persistent joint (CNL / CNS)
//   bbm calibrate [flags]           micro-properties from macro targets
//   bbm sweep MODEL --set KEY=V1,V2 --seeds S   runs over key values and seeds
// Under mpirun the independent runs (realizations, calibration runs, compared
// models, sweep runs) are spread over the ranks; rank 0 writes the summaries.
// Exit status: 0 success, 2 bad input (the message names file, line and key),
// 3 stopped by a numerical health check, 4 calibration not converged, 130
// interrupted (SIGINT, SIGTERM or SIGUSR1; `bbm run` writes a checkpoint), 1 any
// other failure. Earlier output in DIR is only replaced by
// complete files.
#include "bbm_version.hpp" // generated: cmake/write_version.cmake
#include "base/error.hpp"
#include "io/model_input.hpp"
#include "apps/checks.hpp"
#include "studies/model/mesh_command.hpp"
#include "apps/flags.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/model/compare_envelopes.hpp"
#include "studies/cluster/ranks.hpp"
#include "studies/model/run_model.hpp"
#include "studies/lab/shear.hpp"
#include "studies/model/sweep.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace bbm;

namespace {

/// The options of the program itself, before any command: --version, --config,
/// --quiet and --check.
void add_program_options(CLI::App& app, bool& quiet, bool& check_only) {
    app.require_subcommand(1);
    app.set_version_flag("--version", "bbm " BBM_VERSION_TEXT, "Print bbm's version and the commit it was built from");
    // Any command's options can come from a TOML file: a table per command, keys
    // the long option names, e.g. [ucs] size = 0.3, pattern = "trigon" (docs/calibration.md).
    app.set_config("--config", "", "Read options from a TOML file ([ucs], [tension], [calibrate], ... tables; keys "
                                   "are the long option names)");
    app.allow_config_extras(CLI::config_extras_mode::error);
    app.add_flag("-q,--quiet", quiet, "Print nothing but errors");
    app.add_flag("--check", check_only,
                 "Check the options and model files (read, and for mesh and run, generate the blocks) and stop: "
                 "exit status 0 if they are valid, 2 with the mistake otherwise; nothing is written");
}

/// `bbm mesh`: its options and its run.
struct MeshCommandLine {
    CLI::App* cmd = nullptr;
    studies::MeshCommand values;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "mesh", "Generate the blocks of a model file and write DIR/blocks.vtu (polygons: block id, "
                    "region, area, pattern), DIR/joints.vtu (lines: joint tag, the two blocks) and "
                    "DIR/blocks.png (a picture of blocks and joints) and DIR/summary.json (counts, areas, "
                    "mean block size).");
        cmd->add_option("model", values.model, "Model file (TOML; keys in docs/input.md)")
            ->required()
            ->check(CLI::ExistingFile);
        cmd->add_option("-o,--out", values.out, "Output directory (created if missing)")->capture_default_str();
        cmd->add_flag("-q,--quiet", quiet, "Print nothing but errors");
        cmd->add_option("--max-elements", values.max_elements, cli::max_elements_help)->check(cli::positive());
        cmd->add_option("--window", values.window, "Part of the model drawn in blocks.png: XMIN YMIN XMAX YMAX (m)")
            ->expected(4);
    }
    int run(bool quiet, bool check_only) const { return studies::run_mesh(values, quiet, check_only); }
};

/// `bbm run`: its options and its run.
struct RunCommandLine {
    CLI::App* cmd = nullptr;
    studies::RunOptions options;
    std::string out = "out";
    std::string checkpoint_every;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "run", "Generate the blocks of a model file and run its stages (initialize, elastic, solve, excavate, "
                   "cycle). Writes DIR/result.pvd (ParaView series of blocks, zones and contacts), DIR/history.csv, "
                   "history.png, failure.png/.svg and DIR/summary.json. Ctrl-C stops after the current step, writes a "
                   "checkpoint and the output; `bbm run --resume --out DIR` continues.");
        cmd->add_option("model", options.model, "Model file (TOML; keys in docs/input.md)")->check(CLI::ExistingFile);
        cmd->add_option("-o,--out", out, "Output directory (created if missing)")->capture_default_str();
        cmd->add_flag("-q,--quiet", quiet, "No progress, only errors");
        cmd->add_option("--threads", options.threads,
                        "Threads of the loop (the result is the same, bit for bit, on any number)")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_option("--checkpoint-every", checkpoint_every,
                        "Write DIR/checkpoint.bin every N steps (5000) or every stretch of wall time (30min, 2h, 90s), "
                        "as well as when interrupted (SIGINT, SIGTERM, SIGUSR1)");
        cmd->add_option("--stop-at-step", options.stop_at_step,
                        "Stop after this step as if interrupted: checkpoint, output, exit status 130 (an exact "
                        "interruption, for tests and scripted runs)")
            ->check(cli::positive());
        cmd->add_flag("--resume", options.resume,
                      "Continue the run whose checkpoint is in --out (the model file is the checkpoint's; exit 0 if the "
                      "run had already finished)");
        cmd->add_option("--max-elements", options.max_elements, cli::max_elements_help)->check(cli::positive());
        cmd->add_flag("--profile", options.profile,
                      "Time each stage of the step (detection, contacts and zones, gather, integration...): a table on "
                      "stderr at the end, and \"profile\" in summary.json");
        cmd->add_option_function<std::string>(
               "--shade", [this](const std::string& v) { options.shade_pressure = v == "pressure"; },
               "What failure.png's blocks are shaded by: displacement (the default) or pressure (the water in their "
               "joints, a model with [flow])")
            ->check(CLI::IsMember({"displacement", "pressure"}));
    }
    int run(bool quiet, bool check_only) {
        if (options.model.empty() && !options.resume)
            throw InputError("bbm run", 0, "", "give a model file, or --resume with the --out of a run to continue");
        options.out = out;
        if (!checkpoint_every.empty()) options.checkpoint_every = studies::parse_checkpoint_interval(checkpoint_every);
        options.quiet = quiet;
        options.check_only = check_only;
        return studies::run_model(options);
    }
};

/// `bbm sweep`: its options and its run.
struct SweepCommandLine {
    CLI::App* cmd = nullptr;
    studies::SweepOptions options;
    std::vector<std::string> sets;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "sweep", "Run a model file over the cross product of key overrides and seeds (under mpirun: spread over the "
                     "ranks). Each run gets DIR/run_NNN (the edited model.toml and the output of bbm run); DIR/sweep.csv "
                     "and sweep.json tabulate them (values, status, error, steps, cracks, the --plot value) and "
                     "sweep.png plots --plot against the first --set key. A failed run is reported and the others go "
                     "on (exit status 1 if any failed).");
        cmd->add_option("model", options.model, "Model file (TOML; keys in docs/input.md)")
            ->required()
            ->check(CLI::ExistingFile);
        cmd->add_option("--set", sets,
                        "KEY=V1,V2,...: a model-file key as error messages name it and its values, e.g. "
                        "joint_property[0].tensile=2e6,3e6 or region[1].pattern.size=0.2,0.3 (repeatable); keys joined by '+' take the same values together")
            ->take_all();
        cmd->add_option("--seeds", options.seeds,
                        "Seeds per combination: the random patterns' seeds plus 0, 1, ... seeds-1")
            ->check(cli::whole_at_least(1))
            ->capture_default_str();
        cmd->add_option("-o,--out", options.out, "Output directory")->capture_default_str();
        cmd->add_option("--threads", options.threads, "Threads of each run's loop")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_option("--jobs", options.jobs, "Runs at once (per rank under mpirun)")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_flag("--resume", options.resume,
                      "Keep the runs already finished in --out (complete summary, same model)");
        cmd->add_option("--plot", options.plot,
                        "The summary.json value drawn in sweep.png, dotted (cracks.shear, steps, "
                        "opening.failed_depth_springline, ...)")
            ->capture_default_str();
        cmd->add_flag("-q,--quiet", quiet, "No progress, only errors");
    }
    int run(bool quiet, bool check_only) {
        for (const auto& text : sets) options.set.push_back(studies::parse_set(text));
        options.quiet = quiet;
        options.check_only = check_only;
        return studies::run_sweep(options);
    }
};

/// `bbm compare`: its options and its run.
struct CompareCommandLine {
    CLI::App* cmd = nullptr;
    std::vector<std::string> models;
    std::string out = "out/compare";
    int threads = 1;
    studies::CompareEnvelopeOptions envelope;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "compare", "Run several model files (e.g. rigid and deformable blocks, examples/compare_rigid_deformable/) "
                       "into DIR/<name>/ and write DIR/comparison.csv, comparison.md (wall displacements, cracks by "
                       "mode, failed-zone depth, run time) and comparison.png (cracks against step).");
        cmd->add_option("models", models, "Model files")->required()->check(CLI::ExistingFile);
        cmd->add_option("-o,--out", out, "Output directory")->capture_default_str();
        cmd->add_option("--threads", threads, "Threads of each run's contact loop")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_flag("--envelope", envelope.enabled,
                      "Also measure each model's rock as a laboratory does (bbm envelope on specimens of the model's "
                      "block pattern, joints and blocks): DIR/<name>/envelope/, DIR/envelopes.csv and a table in "
                      "comparison.md (UCS, T/UCS, Hoek-Brown mi, Mohr-Coulomb c and phi, sigma_ci / peak)");
        cmd->add_option("--envelope-width", envelope.width, "--envelope: specimen width (m)")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_option("--envelope-height", envelope.height, "--envelope: specimen height (m)")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_option("--envelope-realizations", envelope.realizations,
                        "--envelope: seeds of each test (from the model's pattern seed)")
            ->check(cli::positive())
            ->capture_default_str();
        cmd->add_option("--envelope-confinements", envelope.confinements,
                        "--envelope: lateral stresses of the biaxial tests, Pa, comma-separated (default: 0.1 to 0.5 "
                        "times each rock's UCS)")
            ->delimiter(',')
            ->check(cli::positive());
        cmd->add_flag("-q,--quiet", quiet, "No progress, only errors");
    }
    int run(bool quiet, bool check_only) {
        if (check_only) {
            for (const auto& m : models) {
                const auto model = io::read_model(m);
                if (envelope.enabled) (void)io::rock_of_model(model, m);
            }
            return 0;
        }
        return studies::compare_models(models, out, threads, quiet, &envelope);
    }
};

/// `bbm calibrate`: its options (apps/study_flags.cpp) and its run.
struct CalibrateCommandLine {
    CLI::App* cmd = nullptr;
    studies::CalibrateValues values;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "calibrate", "Find kn, ks, tensile strength and cohesion that give target E, nu, UCS and direct tensile "
                         "strength (means over --realizations seeds of UCS and tension tests), and the friction angle "
                         "too given a biaxial strength (--target-biaxial, --target-confinement). Prints the iterations, "
                         "writes DIR/joint_property.toml (a [[joint_property]] for a model file) and calibration.json. "
                         "Exit status 4 if not converged.");
        cli::add_calibrate_options(cmd, values, quiet);
    }
    int run(bool quiet, bool check_only) {
        cli::note_given_joint_values(*cmd, values);
        return studies::run_calibrate(values, quiet, check_only);
    }
};

/// `bbm envelope`: its options (apps/study_flags.cpp) and its run.
struct EnvelopeCommandLine {
    CLI::App* cmd = nullptr;
    studies::EnvelopeOptions values;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "envelope", "The strength envelope of a block model as a laboratory measures it: uniaxial compression, a "
                        "tension test and biaxial tests at several confinements (--confinements), --realizations seeds "
                        "each; fits Hoek-Brown (sigma_ci, mi) and Mohr-Coulomb (c, phi) to the peaks, and reports "
                        "sigma_ci and sigma_cd at each confinement. Writes envelope.json, envelope.csv and envelope.png "
                        "in --out.");
        cli::add_envelope_options(cmd, values, quiet);
    }
    int run(bool quiet, bool check_only) { return studies::run_envelope(values, quiet, check_only); }
};

/// `bbm shear`: its options (apps/study_flags.cpp) and its run.
struct ShearCommandLine {
    CLI::App* cmd = nullptr;
    studies::ShearValues values;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "shear", "Direct shear test of a joint across a bonded-block specimen, persistent or with rock bridges "
                     "(--persistence, --bridges), under constant normal load or constant normal stiffness "
                     "(--normal-stiffness), at one or more normal stresses (--normal-stress 2e6,5e6,10e6). Writes "
                     "summary.json (peak and residual strength, dilation, Coulomb fits), shear.csv, shear_stress.png, "
                     "dilation.png and per run failure.png and result.pvd in --out.");
        cli::add_shear_options(cmd, values, quiet);
    }
    int run(bool quiet, bool check_only) { return studies::run_shear(values, quiet, check_only); }
};

/// `bbm creep`: its options (apps/study_flags.cpp) and its run.
struct CreepCommandLine {
    CLI::App* cmd = nullptr;
    studies::CreepValues values;

    void add(CLI::App& app, bool& quiet) {
        cmd = app.add_subcommand(
            "creep", "Static fatigue of a bonded-block specimen whose bonds corrode (law stress_corrosion): per seed its "
                     "short-term strength under a dead load (bisected), then the specimen held at each --ratios of it "
                     "until it fails or --max-time passes; the time to failure, creep strain and cracks against time. "
                     "Writes summary.json, creep.csv, creep_curves.csv, time_to_failure.png, creep_curves.png and "
                     "each run's model file in --out.");
        cli::add_creep_options(cmd, values, quiet);
    }
    int run(bool quiet, bool check_only) { return studies::run_creep(values, quiet, check_only); }
};

/// The lab tests: each its own options, defaults = the paper's calibration (SPEC §8).
struct LabTestCommandLines {
    std::vector<std::pair<CLI::App*, studies::LabTestValues>> commands;

    void add(CLI::App& app, bool& quiet) {
        const std::pair<const char*, const char*> labtests[] = {
            {"ucs", "Uniaxial compression test of a bonded-block specimen; with no flags, the paper's calibration run "
                    "(Voronoi 0.3 m, 8 m x 16 m, SPEC §8). Writes summary.json (E, nu, peak_stress, ...), "
                    "stress_strain.csv/.png, failure.png/.svg and result.pvd in --out."},
            {"tension", "Direct uniaxial tension test (same options as ucs; loaded ten times slower by default: its peak "
                        "comes at a tenth of the strain)."},
            {"biaxial", "Compression with a constant lateral stress (same options as ucs)."},
            {"brazilian", "Brazilian test: a disc of diameter --width loaded across a diameter; reports the indirect "
                          "tensile strength 2P/(pi D)."}};
        commands.reserve(4);
        for (const auto& [name, help] : labtests) {
            const auto kind = studies::labtest_kind(name);
            commands.emplace_back(app.add_subcommand(name, help), studies::labtest_defaults(kind));
            auto& [command, values] = commands.back();
            cli::add_labtest_options(command, values, quiet);
            if (kind == LabTestOptions::Kind::biaxial)
                command->add_option("--confinement", values.o.confinement, "Lateral stress (Pa, compression positive)")
                    ->required()
                    ->check(cli::non_negative());
        }
    }
    /// The lab test given, run; none if no lab test was given.
    std::optional<int> run(bool quiet, bool check_only) {
        for (auto& [command, values] : commands)
            if (*command) return studies::run_labtest_command(values, values.o.kind, quiet, check_only);
        return std::nullopt;
    }
};

/// Every command, added to the program in the order of its help.
struct Commands {
    MeshCommandLine mesh;
    RunCommandLine run;
    SweepCommandLine sweep;
    CompareCommandLine compare;
    CalibrateCommandLine calibrate;
    EnvelopeCommandLine envelope;
    ShearCommandLine shear;
    CreepCommandLine creep;
    LabTestCommandLines labtests;

    void add(CLI::App& app, bool& quiet) {
        mesh.add(app, quiet);
        run.add(app, quiet);
        sweep.add(app, quiet);
        compare.add(app, quiet);
        calibrate.add(app, quiet);
        envelope.add(app, quiet);
        shear.add(app, quiet);
        creep.add(app, quiet);
        labtests.add(app, quiet);
    }

    /// The command given, run; its exit status.
    int run_given(bool quiet, bool check_only) {
        if (*run.cmd) return run.run(quiet, check_only);
        if (*envelope.cmd) return envelope.run(quiet, check_only);
        if (*shear.cmd) return shear.run(quiet, check_only);
        if (*creep.cmd) return creep.run(quiet, check_only);
        if (*calibrate.cmd) return calibrate.run(quiet, check_only);
        if (*sweep.cmd) return sweep.run(quiet, check_only);
        if (*compare.cmd) return compare.run(quiet, check_only);
        if (const auto status = labtests.run(quiet, check_only)) return *status;
        if (*mesh.cmd) return mesh.run(quiet, check_only);
        return 0;
    }
};

/// Parses the command line; the exit status if the program stops here (help,
/// the version, or a mistake in the options, said on stderr), none to go on.
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::ConfigError& e) {
        const auto* config = app.get_config_ptr();
        if (studies::Ranks::root())
        std::fprintf(stderr, "bbm: error: %s: %s (keys are the long option names of the command, without '--'; "
                             "see bbm COMMAND --help)\n",
                     config && config->count() ? config->as<std::string>().c_str() : "--config", e.what());
        return 2;
    } catch (const CLI::ParseError& e) {
        // Under mpirun every rank parses the same line: rank 0 says what is wrong.
        std::ostringstream discard;
        const int code = studies::Ranks::root() ? app.exit(e) : app.exit(e, discard, discard);
        return code == 0 ? 0 : 2;
    } catch (const InputError& e) {
        // A file read while parsing (a lab test's --rock, in its command's final
        // callback) names its own file, line and key.
        if (studies::Ranks::root()) std::fprintf(stderr, "bbm: error: %s\n", e.what());
        return 2;
    }
    return std::nullopt;
}

/// Runs the command given; its exit status, a failure's said on stderr.
int run_command(Commands& commands, bool quiet, bool check_only) {
    try {
        return commands.run_given(quiet, check_only);
    } catch (const InputError& e) {
        // Under mpirun every rank meets the same error: one says it.
        if (studies::Ranks::root()) std::fprintf(stderr, "bbm: error: %s\n", e.what());
        return 2;
    } catch (const NumericalError& e) {
        if (studies::Ranks::root()) std::fprintf(stderr, "bbm: stopped: %s\n", e.what());
        return 3;
    } catch (const Interrupted& e) {
        // A lab test, calibration, envelope or shear test stopped by SIGINT/SIGTERM
        // (`bbm run` writes a checkpoint and returns 130 itself).
        std::fprintf(stderr, "bbm: interrupted: stopped without writing output (%s)\n", e.what());
        return 130;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bbm: error%s: %s\n",
                     studies::Ranks::size() > 1 ? (" on rank " + std::to_string(studies::Ranks::rank())).c_str() : "",
                     e.what());
        return 1;
    }
}

int run_cli(int argc, char** argv) {
    CLI::App app{"bbm — bonded-block models of rock failure (2D, plane strain).\n"
                 "Rigid or deformable blocks bonded by softening joints, one explicit loop.",
                 "bbm"};
    bool quiet = false, check_only = false;
    add_program_options(app, quiet, check_only);
    Commands commands;
    commands.add(app, quiet);
    if (const auto status = parse_command_line(app, argc, argv)) return *status;
    return run_command(commands, quiet, check_only);
}

} // namespace

int bbm_cli_main(int argc, char** argv) {
    // First thing: a scheduler's SIGUSR1 or SIGTERM while bbm starts must ask for
    // a checkpoint, not kill it (again after MPI, which may install its own).
    studies::catch_stop_signals();
    // Under mpirun (or srun) the independent runs of a study are spread over the
    // ranks (studies/cluster/ranks.hpp); otherwise nothing changes.
    studies::Ranks::start(&argc, &argv);
    studies::catch_stop_signals();
    const int status = run_cli(argc, argv);
    studies::Ranks::stop();
    return status;
}
