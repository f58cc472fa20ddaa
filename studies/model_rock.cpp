// The rock of a model file as a laboratory specimen (model_rock.hpp).
#include "studies/model_rock.hpp"

#include "io/vtk_output.hpp"
#include "studies/envelope.hpp"
#include "studies/ranks.hpp"
#include "studies/run_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace bbm::studies {

namespace {

using meshing::JointTag;
using meshing::PatternSpec;

const char* pattern_name(PatternSpec::Kind k) { return meshing::to_string(k); }

/// The property the assignment rules give a joint of `tag` between two blocks of
/// `region` (index into the model's joint properties; -1 if none), and the rule's index.
std::pair<int, int> assigned_property(const AnalysisSpec& an, const std::string& region, JointTag tag) {
    int property = -1, rule_index = -1;
    for (std::size_t k = 0; k < an.joint_assignments.size(); ++k) {
        const auto& rule = an.joint_assignments[k];
        const bool tag_ok = rule.tags.empty() || std::find(rule.tags.begin(), rule.tags.end(), tag) != rule.tags.end();
        const bool region_ok =
            rule.regions.empty() || std::find(rule.regions.begin(), rule.regions.end(), region) != rule.regions.end();
        if (!tag_ok || !region_ok) continue;
        const auto it = std::find_if(an.joint_properties.begin(), an.joint_properties.end(),
                                     [&](const JointPropertySpec& p) { return p.name == rule.property; });
        if (it != an.joint_properties.end()) property = int(it - an.joint_properties.begin()), rule_index = int(k);
    }
    return {property, rule_index};
}

} // namespace

LabTestCli labtest_of_model(const io::ModelFile& model, const std::string& file, LabTestCli c) {
    const auto& regions = model.geometry.regions;
    const auto rock = std::find_if(regions.begin(), regions.end(),
                                   [](const meshing::RegionSpec& r) { return r.pattern.kind != PatternSpec::Kind::single; });
    if (rock == regions.end())
        throw InputError(file, 0, "region", "no region with a block pattern: the model has no bonded rock to test");
    const int r = int(rock - regions.begin());
    const auto& src = model.source;
    const auto& pattern = rock->pattern;
    // What a specimen's pattern does not carry (labtest_geometry): refused, not dropped.
    auto refuse = [&](const std::string& key, const std::string& why) {
        throw InputError(file, src.line_of(r, "pattern." + key), "region[" + std::to_string(r) + "].pattern." + key,
                         why + ": a lab specimen cannot test this rock");
    };
    const bool lattice = pattern.kind == PatternSpec::Kind::brick || pattern.kind == PatternSpec::Kind::hexagonal;
    if (lattice && pattern.angle != 0.0) refuse("angle", "a rotated lattice (specimens are generated unrotated)");
    if (pattern.kind == PatternSpec::Kind::brick && pattern.aspect != PatternSpec{}.aspect)
        refuse("aspect", "bricks of another aspect than the specimens' 2");
    if (pattern.kind == PatternSpec::Kind::brick && !pattern.running_bond)
        refuse("bond", "stack-bonded bricks (specimens are running bond)");
    if (pattern.min_edge >= 0.0) refuse("min_edge", "a given shortest edge (specimens use the default, 0.1 x size)");
    c.pattern = pattern_name(pattern.kind);
    c.size_measure = pattern.size_measure == PatternSpec::SizeMeasure::area ? "area" : "feret";
    c.o.size = pattern.size;
    c.o.lloyd = pattern.lloyd_iterations;
    c.o.seed = pattern.seed;

    // Its joints: a trigon region has two kinds, the lattice and random patterns one.
    const auto& an = model.analysis;
    const std::vector<JointTag> tags = pattern.kind == PatternSpec::Kind::trigon
                                           ? std::vector<JointTag>{JointTag::radial, JointTag::peripheral}
                                           : std::vector<JointTag>{JointTag::inner};
    int property = -1, property_rule = -1;
    for (JointTag tag : tags) {
        const auto [p, rule] = assigned_property(an, rock->name, tag);
        if (p < 0)
            throw InputError(file, src.line_of("joint_assignment"), "joint_assignment",
                             std::string("no joint property is assigned to the ") + meshing::to_string(tag) +
                                 " joints of region '" + rock->name + "'");
        if (property >= 0 && p != property) {
            // Name the later of the two rules: the one that set a kind of joint apart.
            const std::string key = "joint_assignment[" + std::to_string(std::max(rule, property_rule)) + "]";
            throw InputError(file, src.line_of(key), key,
                             "the radial and peripheral joints of region '" + rock->name + "' get different properties ('" +
                                 an.joint_properties[std::size_t(property)].name + "', '" +
                                 an.joint_properties[std::size_t(p)].name + "'): a lab specimen has one bond");
        }
        property = p, property_rule = rule;
    }
    c.o.joint = an.joint_properties[std::size_t(property)];
    // The model's curves as they are (any number of points; not the flags' b1, a1, a2).
    c.tension_softening.clear();
    c.shear_softening.clear();

    // Its material: density; meshed blocks take a fraction f of the deformation.
    const MaterialSpec* material = nullptr;
    for (const auto& [region_name, material_name] : an.region_material)
        if (region_name == rock->name)
            for (const auto& m : an.materials)
                if (m.name == material_name) material = &m;
    if (!material && an.region_material.empty() && !an.materials.empty()) material = &an.materials.front();
    if (material) c.o.material.density = material->density;
    c.o.material.deformable_fraction = 0.0;
    if (rock->mesh.enabled) {
        if (!material || !(material->deformable_fraction > 0.0))
            throw InputError(file, src.line_of(r, "material"), "region[" + std::to_string(r) + "].material",
                             "meshed blocks without a deformable_fraction: a lab specimen's deformable blocks take "
                             "a fraction f of the deformation (give the material deformable_fraction)");
        c.o.material.deformable_fraction = material->deformable_fraction;
        c.o.material.young = material->young;
        c.o.material.poisson = material->poisson;
        c.o.mesh_size = rock->mesh.size;
    }
    return c;
}

std::string compare_envelopes(const std::vector<std::string>& models, const std::filesystem::path& out, int threads,
                              bool quiet, const CompareEnvelopeOptions& options) {
    namespace fs = std::filesystem;
    // Every model's rock first, so that a model a specimen cannot carry stops the
    // comparison's envelopes before any runs.
    std::vector<LabTestCli> rocks;
    for (const auto& file : models) {
        LabTestCli base;
        base.o.width = options.width, base.o.height = options.height;
        base.realizations = options.realizations;
        base.threads = threads;
        base.out = (out / fs::path(file).stem() / "envelope").string();
        rocks.push_back(labtest_of_model(io::read_model(file), file, base));
    }
    std::ostringstream md, csv;
    csv << "model,pattern,size_m,deformable_fraction,specimen_width_m,specimen_height_m,realizations,ucs_MPa,ucs_sd_MPa,"
           "tension_MPa,t_over_ucs,hoek_brown_sigma_ci_MPa,hoek_brown_mi,hoek_brown_rms_MPa,mohr_coulomb_c_MPa,"
           "mohr_coulomb_phi_deg,mohr_coulomb_rms_MPa,top_sigma3_MPa,top_sigma1_MPa,top_sigma1_sd_MPa,"
           "sigma_ci_over_peak_unconfined,sigma_cd_over_peak_unconfined,runs,runs_jammed_after_failure\n";
    char text[1024];
    std::snprintf(text, sizeof text,
                  "\nThe rock of each model (`bbm envelope`, %g m x %g m specimens, %d seed%s from the model's own, "
                  "the model's pattern, joints and blocks):\n\n",
                  options.width, options.height, options.realizations, options.realizations > 1 ? "s" : "");
    md << text
       << "| model | blocks | UCS MPa | T/UCS | Hoek-Brown sigma_ci MPa, mi (RMS MPa) | Mohr-Coulomb c MPa, phi (RMS MPa) | "
          "sigma1 at the highest sigma3, MPa | sigma_ci / peak, sigma_cd / peak (unconfined) | jammed after failure |\n"
       << "|---|---|---|---|---|---|---|---|---|\n";
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
        const auto& sp = j["specimen"];
        const auto& hb = j["hoek_brown"];
        const auto& mc = j["mohr_coulomb"];
        const auto& unconfined = j["levels"].front();
        const auto& top = j["levels"].back();
        int jammed = 0, runs = 0;
        for (const auto& r : j["runs"]) {
            if (r["test"] != "ucs" && r["test"] != "biaxial") continue;
            ++runs;
            jammed += r["post_peak_locking"].get<bool>() ? 1 : 0;
        }
        const double f = sp["deformable_fraction"].get<double>();
        const std::string pattern = sp["pattern"].get<std::string>();
        char blocks[128];
        if (f > 0) std::snprintf(blocks, sizeof blocks, "%s %g m, deformable f = %g", pattern.c_str(), sp["size"].get<double>(), f);
        else std::snprintf(blocks, sizeof blocks, "%s %g m, rigid", pattern.c_str(), sp["size"].get<double>());
        auto mpa = [](const nlohmann::json& v) { return v.get<double>() / 1e6; };
        const bool hb_ok = hb["valid"].get<bool>(), mc_ok = mc["valid"].get<bool>();
        char hb_cell[96] = "-", mc_cell[96] = "-";
        if (hb_ok) std::snprintf(hb_cell, sizeof hb_cell, "%.1f, %.1f (%.2f)", mpa(hb["sigma_ci"]), hb["mi"].get<double>(), mpa(hb["rms"]));
        if (mc_ok)
            std::snprintf(mc_cell, sizeof mc_cell, "%.2f, %.1f deg (%.2f)", mpa(mc["cohesion"]), mc["friction_deg"].get<double>(),
                          mpa(mc["rms"]));
        std::snprintf(text, sizeof text, "| %s | %s | %.2f +- %.2f | %.3f | %s | %s | %.1f +- %.1f at %.1f | %.2f, %.2f | %d of %d |\n",
                      name.c_str(), blocks, mpa(j["ucs"]["mean"]), mpa(j["ucs"]["std"]), j["tension"]["over_ucs"].get<double>(),
                      hb_cell, mc_cell, mpa(top["peak"]["mean"]), mpa(top["peak"]["std"]), mpa(top["sigma3"]),
                      unconfined["sigma_ci_over_peak"]["mean"].get<double>(),
                      unconfined["sigma_cd_over_peak"]["mean"].get<double>(), jammed, runs);
        md << text;
        std::snprintf(text, sizeof text,
                      "%s,%s,%g,%g,%g,%g,%d,%.4f,%.4f,%.4f,%.5f,%.4f,%.4f,%.4f,%.4f,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d,%d\n",
                      name.c_str(), pattern.c_str(), sp["size"].get<double>(), f, sp["width"].get<double>(),
                      sp["height"].get<double>(), sp["realizations"].get<int>(), mpa(j["ucs"]["mean"]), mpa(j["ucs"]["std"]),
                      mpa(j["tension"]["strength"]["mean"]), j["tension"]["over_ucs"].get<double>(),
                      hb_ok ? mpa(hb["sigma_ci"]) : 0.0, hb_ok ? hb["mi"].get<double>() : 0.0, hb_ok ? mpa(hb["rms"]) : 0.0,
                      mc_ok ? mpa(mc["cohesion"]) : 0.0, mc_ok ? mc["friction_deg"].get<double>() : 0.0,
                      mc_ok ? mpa(mc["rms"]) : 0.0, mpa(top["sigma3"]), mpa(top["peak"]["mean"]), mpa(top["peak"]["std"]),
                      unconfined["sigma_ci_over_peak"]["mean"].get<double>(),
                      unconfined["sigma_cd_over_peak"]["mean"].get<double>(), runs, jammed);
        csv << text;
    }
    if (Ranks::root()) io::write_text_atomically(out / "envelopes.csv", csv.str());
    return md.str();
}

} // namespace bbm::studies
