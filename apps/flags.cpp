// The flags made from key declarations, the rock's flags and a lab test's options
// (apps/flags.hpp).
#include "apps/flags.hpp"

#include "apps/checks.hpp"
#include "base/error.hpp"
#include "contact/joint_keys.hpp"
#include "core/material_keys.hpp"
#include "io/model_input.hpp"
#include "meshing/region_keys.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

namespace bbm::cli {

const char* const max_elements_help =
    "Largest number of blocks plus triangles the model may ask for (estimated before generating; default: what "
    "fits in half of this machine's memory)";

namespace {

/// The flag of a declared key: `--<prefix><key>`, or its own name.
template <class Spec>
std::string flag_of(const Key<Spec>& k, std::string_view prefix) {
    return key_flag(k.flag_name.empty() ? k.key : k.flag_name, prefix);
}

/// A key's meaning in the flags' words: the other keys it names, by their flags.
template <class Spec>
std::string meaning_in_flags(const Key<Spec>& k, std::span<const Key<Spec>* const> keys, std::string_view prefix) {
    auto declared = [keys](std::string_view word) {
        return std::ranges::any_of(keys, [word](const Key<Spec>* d) { return d->key == word; });
    };
    std::string meaning;
    for (std::size_t at = 0; at < k.meaning.size();) {
        std::size_t end = at;
        while (end < k.meaning.size() &&
               (std::islower(static_cast<unsigned char>(k.meaning[end])) || k.meaning[end] == '_'))
            ++end;
        const std::string_view word = k.meaning.substr(at, std::max(end, at + 1) - at);
        meaning += word.find('_') != std::string_view::npos && declared(word) ? key_flag(word, prefix) : std::string(word);
        at += word.size();
    }
    return meaning;
}

std::string curve_text(const std::vector<std::pair<double, double>>& points) {
    std::string s = "[";
    for (std::size_t i = 0; i < points.size(); ++i)
        s += std::string(i ? ", " : "") + "[" + shortest_text(points[i].first) + ", " + shortest_text(points[i].second) + "]";
    return s + "]";
}

/// A curve flag's value: the model file's points "[[1.7, 0.5], [4, 0]]", or the
/// former three numbers b1,a1,a2 (the points (a1, b1), (a2, 0)), read with a
/// deprecation message. Checked by the reader's rules.
std::vector<std::pair<double, double>> curve_of_flag(const std::string& text, const std::string& flag) {
    if (!text.empty() && text.front() == '[') return io::parse_curve(text, flag);
    std::vector<double> numbers;
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        double x = 0.0;
        if (!detail::parse_finite(text.substr(at, comma - at), x))
            throw InputError(flag, 0, "", "expected the curve's points as a model file writes them, e.g. "
                                          "'[[1.7, 0.5], [4.0, 0]]', got '" + text + "'");
        numbers.push_back(x);
        at = comma + 1;
    }
    if (numbers.size() != 3)
        throw InputError(flag, 0, "", "expected the curve's points, e.g. '[[1.7, 0.5], [4.0, 0]]', got '" + text + "'");
    const std::string points = "[[" + shortest_text(numbers[1]) + ", " + shortest_text(numbers[0]) + "], [" +
                               shortest_text(numbers[2]) + ", 0]]";
    std::fprintf(stderr, "bbm: %s b1,a1,a2 is deprecated; write the curve's points as a model file does: %s '%s'\n",
                 flag.c_str(), flag.c_str(), points.c_str());
    return io::parse_curve(points, flag);
}

/// The flag of one declared key bound to spec's field.
template <class Spec>
CLI::Option* add_key_flag(CLI::App* cmd, Spec& spec, const Key<Spec>& k, const std::string& names,
                          const std::string& help) {
    if (k.kind == KeyKind::choice) {
        const std::vector<std::string_view> words = key_words(k.words);
        auto set = k.set;
        CLI::Option* opt = cmd->add_option_function<std::string>(
            names, [&spec, set, words](const std::string& w) { set(spec, double(std::ranges::find(words, w) - words.begin())); },
            help);
        opt->check(CLI::IsMember(std::vector<std::string>(words.begin(), words.end())));
        opt->default_str(std::string(words.at(std::size_t(k.get(spec)))));
        return opt;
    }
    if (k.kind == KeyKind::curve) {
        auto set = k.set_curve;
        const std::string flag = names.substr(0, names.find(','));
        // One string (a vector option would split "[[...]]" at its commas).
        CLI::Option* opt = cmd->add_option_function<std::string>(
            names, [&spec, set, flag](const std::string& v) { set(spec, curve_of_flag(v, flag)); }, help);
        opt->type_name("POINTS");
        if (!k.get_curve(spec).empty()) opt->default_str(curve_text(k.get_curve(spec)));
        return opt;
    }
    auto set = k.set;
    CLI::Option* opt = cmd->add_option_function<double>(names, [&spec, set](double v) { set(spec, v); }, help);
    const bool whole = k.kind == KeyKind::integer;
    opt->check(whole ? whole_within(k.bounds) : within(k.bounds));
    // A whole number travels as a double: above 2^53 it would not be the one given.
    if (whole) opt->check(whole_within(between(-9007199254740992.0, 9007199254740992.0, "")));
    opt->type_name(whole ? "INT" : "FLOAT");
    if (k.bounds.contains(k.get(spec))) opt->default_str(shortest_text(k.get(spec)));
    return opt;
}

} // namespace

template <class Spec>
void add_key_flags(CLI::App* cmd, Spec& spec, std::span<const Key<Spec>* const> keys, std::string_view prefix,
                   std::string_view help_prefix) {
    for (const Key<Spec>* k : keys) {
        const bool number = k->kind == KeyKind::number || k->kind == KeyKind::integer;
        const bool choice = k->kind == KeyKind::choice && k->set, curve = k->kind == KeyKind::curve && k->set_curve;
        if (!(number && k->set) && !choice && !curve) continue;
        std::string help = std::string(help_prefix) + meaning_in_flags(*k, keys, prefix);
        if (number && !k->bounds.unit.empty()) help += " (" + std::string(k->bounds.unit.substr(1)) + ")";
        if (number && !k->bounds.contains(k->get(spec)) && !k->absent.empty())
            help += "; if not given: " + std::string(k->absent);
        std::string names = flag_of(*k, prefix);
        if (k->key == "weibull_modulus" && prefix.empty()) names += ",--weibull-m"; // its name before the keys were shared
        add_key_flag(cmd, spec, *k, names, help);
    }
}
template void add_key_flags(CLI::App*, JointPropertySpec&, std::span<const contact::JointKey* const>, std::string_view,
                            std::string_view);
template void add_key_flags(CLI::App*, MaterialSpec&, std::span<const MaterialKey* const>, std::string_view,
                            std::string_view);
template void add_key_flags(CLI::App*, meshing::PatternSpec&, std::span<const meshing::PatternKey* const>,
                            std::string_view, std::string_view);

namespace {

/// The joint keys a lab test's rock takes as flags.
std::vector<const contact::JointKey*> bond_flag_keys() {
    std::vector<const contact::JointKey*> keys;
    for (const contact::JointKey* k : contact::joint_keys())
        if (k->flag) keys.push_back(k);
    return keys;
}

bool given(const CLI::App& cmd, const std::string& flag) {
    const CLI::Option* opt = cmd.get_option_no_throw(flag);
    return opt && opt->count() > 0;
}

/// The values of the flags given on `cmd` from `from` to `to`, key by key.
template <class Spec>
void keep_given(const CLI::App& cmd, std::span<const Key<Spec>* const> keys, Spec& to, const Spec& from) {
    for (const Key<Spec>* k : keys) {
        if (!given(cmd, flag_of(*k, ""))) continue;
        if (k->set) k->set(to, k->get(from));
        if (k->set_curve) k->set_curve(to, k->get_curve(from));
    }
}

} // namespace

void add_rock_flags(CLI::App* cmd, RockSpec& rock) {
    const auto pattern = flag_keys(meshing::pattern_keys);
    const auto material = flag_keys(material_keys);
    const auto bonds = bond_flag_keys();
    add_key_flags<meshing::PatternSpec>(cmd, rock.pattern, pattern, "", "The rock's blocks: ");
    add_key_flags<JointPropertySpec>(cmd, rock.bonds, bonds, "", "The rock's bonds: ");
    add_key_flags<MaterialSpec>(cmd, rock.material, material, "", "The rock's blocks: ");
    cmd->add_option("--mesh-size", rock.mesh_size, "With --deformable-fraction: triangle size (m; default size / 2)")
        ->check(non_negative());
}

void apply_rock_file(const CLI::App& cmd, const std::string& file, RockSpec& rock) {
    if (file.empty()) return;
    const RockSpec flags = rock;
    rock = io::read_rock(file, rock);
    // The flags given beside the file (a command may lack some).
    keep_given<meshing::PatternSpec>(cmd, flag_keys(meshing::pattern_keys), rock.pattern, flags.pattern);
    keep_given<JointPropertySpec>(cmd, bond_flag_keys(), rock.bonds, flags.bonds);
    keep_given<MaterialSpec>(cmd, flag_keys(material_keys), rock.material, flags.material);
    if (given(cmd, "--mesh-size")) rock.mesh_size = flags.mesh_size;
}

namespace {

/// The keys of a joint with a law of its own: every number and curve any law
/// declares (the law's name is its own flag).
std::vector<const contact::JointKey*> joint_law_keys() {
    std::vector<const contact::JointKey*> keys;
    for (const contact::JointKey* k : contact::joint_keys())
        if (k->kind == KeyKind::number || k->kind == KeyKind::integer || k->kind == KeyKind::curve) keys.push_back(k);
    return keys;
}

} // namespace

void add_joint_law_flags(CLI::App* cmd, JointPropertySpec& joint, std::string_view prefix, std::string_view help_prefix) {
    std::vector<std::string> laws(contact::law_names.begin(), contact::law_names.end());
    std::string law_help = std::string(help_prefix) + "its law (";
    for (std::size_t l = 0; l < laws.size(); ++l) law_help += (l ? ", " : "") + laws[l];
    law_help += "; the flags of the keys it reads: docs/reference/joint_property.md)";
    cmd->add_option(key_flag("law", prefix), joint.law, law_help)->check(CLI::IsMember(laws))->capture_default_str();
    const auto keys = joint_law_keys();
    add_key_flags<JointPropertySpec>(cmd, joint, keys, prefix, help_prefix);
    for (const char* stiffness : {"kn", "ks"})
        if (CLI::Option* opt = cmd->get_option_no_throw(key_flag(stiffness, prefix)))
            opt->description(opt->get_description() + "; if not given: the rock's bonds'");
}

void check_joint_law_flags(const CLI::App& cmd, const JointPropertySpec& joint, std::string_view prefix) {
    const auto read = contact::law_key_names(joint.law);
    std::string flags;
    for (const contact::JointKey* k : joint_law_keys())
        if (std::ranges::find(read, k->key) != read.end()) flags += (flags.empty() ? "" : ", ") + key_flag(k->key, prefix);
    for (const contact::JointKey* k : joint_law_keys()) {
        if (!given(cmd, key_flag(k->key, prefix)) || std::ranges::find(read, k->key) != read.end()) continue;
        std::string laws; // the laws that do read it
        for (const std::string_view law : contact::law_names) {
            const auto keys = contact::law_key_names(law);
            if (std::ranges::find(keys, k->key) != keys.end()) laws += (laws.empty() ? "" : " or ") + std::string(law);
        }
        throw InputError(key_flag(k->key, prefix), 0, "",
                         "does not apply to a " + joint.law + " joint (" + key_flag("law", prefix) + " " + joint.law +
                             "), it is a key of " + laws + "; the " + joint.law + " joint's flags are: " + flags);
    }
}

namespace {

/// The specimen: the rock file and the specimen's size.
void add_specimen_options(CLI::App* sub, studies::LabTestValues& c) {
    auto& o = c.o;
    sub->add_option("--rock", c.rock,
                    "The rock from a file: one [[joint_property]] and at most one [[material]] as a model file has "
                    "them (what bbm calibrate writes: joint_property.toml), or a whole model file (its bonded "
                    "region's pattern, bonds and material); the rock's flags given beside it override it")
        ->check(CLI::ExistingFile);
    sub->add_option("--width", o.width, "Specimen width (m); brazilian: disc diameter")->check(positive())->capture_default_str();
    sub->add_option("--height", o.height, "Specimen height (m)")->check(positive())->capture_default_str();
}

/// How the platens load: the rate, the servo, the implicit preload, the platens.
void add_loading_options(CLI::App* sub, LabTestOptions& o) {
    sub->add_option("--strain-rate", o.strain_per_step,
                    "Platen velocity over specimen height, per step (with the servo: the unit of its rates)")
        ->check(positive())->capture_default_str();
    sub->add_option("--servo", o.servo.on,
                    "Servo-controlled platens: slower while cracks form, faster after failure (docs/calibration.md)")
        ->capture_default_str();
    sub->add_option("--servo-cracks", o.servo.cracks, "Servo: new cracks per record (20 steps) per 5,000 contacts it aims at")
        ->check(positive())->capture_default_str();
    sub->add_option("--servo-balance", o.servo.balance,
                    "Servo, once cracking has started: largest difference between the top and bottom platen forces, "
                    "as a fraction of the load (0: off)")
        ->check(non_negative())->capture_default_str();
    sub->add_option("--servo-min", o.servo.min_factor, "Servo: slowest platen speed, times --strain-rate")
        ->check(positive())->capture_default_str();
    sub->add_option("--servo-max", o.servo.max_factor, "Servo: fastest platen speed before failure, times --strain-rate")
        ->check(positive())->capture_default_str();
    sub->add_option("--servo-post-peak", o.servo.post_peak_factor, "Servo: platen speed after failure, times --strain-rate")
        ->check(positive())->capture_default_str();
    sub->add_flag("--events", o.events,
                  "Record seismic events from breaking bonds (acoustic emission): the events column of "
                  "stress_strain.csv, summary.json's events (count, b-value, sigma_ci from events); slower");
    sub->add_option("--preload", o.elastic_preload,
                    "The linear part by one implicit solve, up to just below the first joint's yield")
        ->capture_default_str();
    sub->add_option_function<std::string>(
           "--platens", [&o](const std::string& v) { o.rough_platens = v == "rough"; },
           "rough: the face blocks are held horizontally; smooth: free to slide")
        ->check(CLI::IsMember({"rough", "smooth"}))->default_str("rough");
    sub->add_option("--platen-friction", o.platen_friction,
                    "Rigid platen blocks pressing on the faces through contacts of this friction angle (degrees), "
                    "instead of prescribed face blocks (--platens); ucs and biaxial")
        ->check(within(below(0, 90, degrees)));
}

/// When a test stops and how its peak is read.
void add_stop_options(CLI::App* sub, LabTestOptions& o) {
    sub->add_option("--stop-fraction", o.stop.fraction, "Stop after the peak once the stress is below this fraction of it")
        ->check(in_range(0.0, 1.0))->capture_default_str();
    sub->add_option("--failure-drop", o.stop.failure_drop,
                    "A drop by this fraction from the peak marks failure; the run stops if the stress then climbs "
                    "back above the peak")
        ->check(in_range(0.0, 1.0))->capture_default_str();
    sub->add_option("--frame-every", o.frame_every,
                    "Steps between frames of the failure series in result.pvd (0: the final state only)")
        ->check(non_negative())->capture_default_str();
    sub->add_option("--max-strain", o.stop.max_strain,
                    "Stop at this axial strain; a specimen not failed by then loads on up to --strain-cap")
        ->check(positive())->capture_default_str();
    sub->add_option("--strain-cap", o.stop.strain_cap,
                    "Hard limit for a specimen still loading at --max-strain (at most --max-strain: stop there); "
                    "reached unfailed, the peak is a lower bound (still_loading)")
        ->check(non_negative())->capture_default_str();
    sub->add_option_function<std::string>(
           "--confined-peak", [&o](const std::string& v) { o.stop.peak_at_first_stall = v == "first-stall"; },
           "Confined tests: lab = the laboratory's peak, the largest stress before a lasting drop by --failure-drop "
           "(a specimen that only hardens loads on to --strain-cap); first-stall = the rule until 2026-11-27, the "
           "first stall of the stress after cracking (docs/calibration.md, The confined peak)")
        ->check(CLI::IsMember({"lab", "first-stall"}))->default_str("lab");
    sub->add_option("--post-peak-strain", o.stop.post_peak_strain,
                    "Confined tests: stop this much axial strain past the failure (the peak's drop; first-stall: past "
                    "the peak) once the specimen has failed (0: go on to --max-strain or --stop-fraction; bbm "
                    "envelope and calibrate use 2e-4)")
        ->check(non_negative());
}

/// A persistent joint set across the specimen.
void add_joint_set_options(CLI::App* sub, LabTestOptions& o) {
    sub->add_option_function<double>(
           "--joint-set-angle", [&o](const double& a) { o.joint_set.on = true, o.joint_set.angle = a; },
           "A persistent joint set across the specimen at this angle from horizontal (degrees; a single plane "
           "of weakness through the centre unless --joint-set-spacing), a Coulomb joint unless --joint-set-law "
           "(--joint-set-friction, --joint-set-cohesion, --joint-set-tensile: a brittle weak bond when > 0)")
        ->check(in_range(0.0, 180.0));
    sub->add_option("--joint-set-spacing", o.joint_set.spacing, "Joint set: spacing along the normal (m; 0 = one joint)")
        ->check(non_negative())->capture_default_str();
    add_joint_law_flags(sub, o.joint_set.joint, "joint-set-", "Joint set: ");
}

} // namespace

void add_labtest_options(CLI::App* sub, studies::LabTestValues& c, bool& quiet) {
    add_specimen_options(sub, c);
    add_rock_flags(sub, c.o.rock);
    add_loading_options(sub, c.o);
    add_stop_options(sub, c.o);
    add_joint_set_options(sub, c.o);
    sub->add_option("--realizations", c.realizations, "Number of random realizations (seeds seed, seed+1, ...)")
        ->check(positive())->capture_default_str();
    sub->add_option("--threads", c.threads,
                    "Threads (0 = all cores): realizations run in parallel; a single one uses them in its contact loop")
        ->check(non_negative());
    sub->add_option("--max-elements", c.o.max_elements, max_elements_help)->check(positive());
    sub->add_option("-o,--out", c.out, "Output directory")->capture_default_str();
    sub->add_flag("-q,--quiet", quiet, "No progress, only errors");
    // After the command's flags are parsed, those of --config too: the file, then
    // the flags given beside it. A final callback, not a parse-complete callback: with
    // one, CLI11 (2.1) reads a --config file after it and never sets the
    // command's flags from the file (fit-curvature = true was silently false).
    sub->final_callback([sub, &c] {
        apply_rock_file(*sub, c.rock, c.o.rock);
        check_joint_law_flags(*sub, c.o.joint_set.joint, "joint-set-");
    });
}

studies::LabTestStudy run_labtest_args(const std::string& command, const std::vector<std::string>& args, bool quiet,
                                       const std::function<void(const Solver&, const StressStrainPoint&, int)>& on_frame) {
    const auto kind = studies::labtest_kind(command);
    studies::LabTestValues values = studies::labtest_defaults(kind);
    CLI::App app{command, command};
    bool quiet_flag = quiet;
    add_labtest_options(&app, values, quiet_flag);
    if (kind == LabTestOptions::Kind::biaxial)
        app.add_option("--confinement", values.o.confinement, "Lateral stress (Pa, compression positive)")
            ->required()
            ->check(non_negative());
    values.write_files = parse_args(app, command, args);
    values.on_frame = on_frame;
    studies::LabTestStudy study;
    studies::run_labtest_command(values, kind, quiet_flag, false, &study);
    return study;
}

} // namespace bbm::cli
