// `bbm compare --envelope` (studies/model/compare_envelopes.hpp).
#include "studies/model/compare_envelopes.hpp"

#include "io/model_input.hpp"

#include "io/vtk_output.hpp"
#include "studies/lab/envelope.hpp"
#include "studies/cluster/ranks.hpp"
#include "studies/model/run_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace bbm::studies {

namespace {

namespace fs = std::filesystem;

/// Every model's rock, as a lab test of the comparison's specimens takes it.
std::vector<LabTestValues> rocks_of_models(const std::vector<std::string>& models, const fs::path& out, int threads,
                                           const CompareEnvelopeOptions& options) {
    std::vector<LabTestValues> rocks;
    for (const auto& file : models) {
        LabTestValues base;
        base.o.width = options.width, base.o.height = options.height;
        base.realizations = options.realizations;
        base.threads = threads;
        base.out = (out / fs::path(file).stem() / "envelope").string();
        base.o.rock = io::rock_of_model(io::read_model(file), file, base.o.rock);
        rocks.push_back(base);
    }
    return rocks;
}

/// The table's introduction and header in comparison.md.
std::string markdown_header(const CompareEnvelopeOptions& options) {
    char text[1024];
    std::snprintf(text, sizeof text,
                  "\nThe rock of each model (`bbm envelope`, %g m x %g m specimens, %d seed%s from the model's own, "
                  "the model's pattern, joints and blocks):\n\n",
                  options.width, options.height, options.realizations, options.realizations > 1 ? "s" : "");
    return std::string(text) +
           "| model | blocks | UCS MPa | T/UCS | Hoek-Brown sigma_ci MPa, mi (RMS MPa) | Mohr-Coulomb c MPa, phi (RMS MPa) | "
           "sigma1 at the highest sigma3, MPa | sigma_ci / peak, sigma_cd / peak (unconfined) | jammed after failure |\n"
           "|---|---|---|---|---|---|---|---|---|\n";
}

double mpa(const nlohmann::json& v) { return v.get<double>() / 1e6; }

/// An envelope's compression runs (UCS and biaxial), and those jammed after failure.
struct JammedRuns {
    int jammed = 0, runs = 0;
};

JammedRuns jammed_runs(const nlohmann::json& j) {
    JammedRuns n;
    for (const auto& r : j["runs"]) {
        if (r["test"] != "ucs" && r["test"] != "biaxial") continue;
        ++n.runs;
        n.jammed += r["post_peak_locking"].get<bool>() ? 1 : 0;
    }
    return n;
}

/// The model's row of the table in comparison.md.
std::string markdown_row(const std::string& name, const nlohmann::json& j, JammedRuns n) {
    const auto& sp = j["specimen"];
    const auto& hb = j["hoek_brown"];
    const auto& mc = j["mohr_coulomb"];
    const auto& unconfined = j["levels"].front();
    const auto& top = j["levels"].back();
    const double f = sp["deformable_fraction"].get<double>();
    const std::string pattern = sp["pattern"].get<std::string>();
    char blocks[128];
    if (f > 0) std::snprintf(blocks, sizeof blocks, "%s %g m, deformable f = %g", pattern.c_str(), sp["size"].get<double>(), f);
    else std::snprintf(blocks, sizeof blocks, "%s %g m, rigid", pattern.c_str(), sp["size"].get<double>());
    char hb_cell[96] = "-", mc_cell[96] = "-";
    if (hb["valid"].get<bool>())
        std::snprintf(hb_cell, sizeof hb_cell, "%.1f, %.1f (%.2f)", mpa(hb["sigma_ci"]), hb["mi"].get<double>(), mpa(hb["rms"]));
    if (mc["valid"].get<bool>())
        std::snprintf(mc_cell, sizeof mc_cell, "%.2f, %.1f deg (%.2f)", mpa(mc["cohesion"]), mc["friction_deg"].get<double>(),
                      mpa(mc["rms"]));
    char text[1024];
    std::snprintf(text, sizeof text, "| %s | %s | %.2f +- %.2f | %.3f | %s | %s | %.1f +- %.1f at %.1f | %.2f, %.2f | %d of %d |\n",
                  name.c_str(), blocks, mpa(j["ucs"]["mean"]), mpa(j["ucs"]["std"]), j["tension"]["over_ucs"].get<double>(),
                  hb_cell, mc_cell, mpa(top["peak"]["mean"]), mpa(top["peak"]["std"]), mpa(top["sigma3"]),
                  unconfined["sigma_ci_over_peak"]["mean"].get<double>(),
                  unconfined["sigma_cd_over_peak"]["mean"].get<double>(), n.jammed, n.runs);
    return text;
}

const char* const csv_header =
    "model,pattern,size_m,deformable_fraction,specimen_width_m,specimen_height_m,realizations,ucs_MPa,ucs_sd_MPa,"
    "tension_MPa,t_over_ucs,hoek_brown_sigma_ci_MPa,hoek_brown_mi,hoek_brown_rms_MPa,mohr_coulomb_c_MPa,"
    "mohr_coulomb_phi_deg,mohr_coulomb_rms_MPa,top_sigma3_MPa,top_sigma1_MPa,top_sigma1_sd_MPa,"
    "sigma_ci_over_peak_unconfined,sigma_cd_over_peak_unconfined,runs,runs_jammed_after_failure\n";

/// The model's row of envelopes.csv.
std::string csv_row(const std::string& name, const nlohmann::json& j, JammedRuns n) {
    const auto& sp = j["specimen"];
    const auto& hb = j["hoek_brown"];
    const auto& mc = j["mohr_coulomb"];
    const auto& unconfined = j["levels"].front();
    const auto& top = j["levels"].back();
    const bool hb_ok = hb["valid"].get<bool>(), mc_ok = mc["valid"].get<bool>();
    char text[1024];
    std::snprintf(text, sizeof text,
                  "%s,%s,%g,%g,%g,%g,%d,%.4f,%.4f,%.4f,%.5f,%.4f,%.4f,%.4f,%.4f,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d,%d\n",
                  name.c_str(), sp["pattern"].get<std::string>().c_str(), sp["size"].get<double>(),
                  sp["deformable_fraction"].get<double>(), sp["width"].get<double>(),
                  sp["height"].get<double>(), sp["realizations"].get<int>(), mpa(j["ucs"]["mean"]), mpa(j["ucs"]["std"]),
                  mpa(j["tension"]["strength"]["mean"]), j["tension"]["over_ucs"].get<double>(),
                  hb_ok ? mpa(hb["sigma_ci"]) : 0.0, hb_ok ? hb["mi"].get<double>() : 0.0, hb_ok ? mpa(hb["rms"]) : 0.0,
                  mc_ok ? mpa(mc["cohesion"]) : 0.0, mc_ok ? mc["friction_deg"].get<double>() : 0.0,
                  mc_ok ? mpa(mc["rms"]) : 0.0, mpa(top["sigma3"]), mpa(top["peak"]["mean"]), mpa(top["peak"]["std"]),
                  unconfined["sigma_ci_over_peak"]["mean"].get<double>(),
                  unconfined["sigma_cd_over_peak"]["mean"].get<double>(), n.runs, n.jammed);
    return text;
}

} // namespace

std::string compare_envelopes(const std::vector<std::string>& models, const std::filesystem::path& out, int threads,
                              bool quiet, const CompareEnvelopeOptions& options) {
    // Every model's rock first, so that a model a specimen cannot carry stops the
    // comparison's envelopes before any runs.
    const std::vector<LabTestValues> rocks = rocks_of_models(models, out, threads, options);
    std::ostringstream md, csv;
    csv << csv_header;
    md << markdown_header(options);
    for (std::size_t m = 0; m < models.size(); ++m) {
        if (stop_signal_received()) break;
        const std::string name = fs::path(models[m]).stem().string();
        if (!quiet && Ranks::root()) std::fprintf(stderr, "== %s: the rock's envelope\n", name.c_str());
        EnvelopeOptions e; // as `bbm envelope --model` (the rock read above)
        e.lab = rocks[m];
        e.confinements = options.confinements;
        EnvelopeStudy study;
        run_envelope(e, quiet, false, &study);
        const auto j = nlohmann::json::parse(study.summary_json);
        const JammedRuns n = jammed_runs(j);
        md << markdown_row(name, j, n);
        csv << csv_row(name, j, n);
    }
    if (Ranks::root()) io::write_text_atomically(out / "envelopes.csv", csv.str());
    return md.str();
}

} // namespace bbm::studies
