// The rock of a model file, and a joint property's table text (io/model_input.hpp).
#include "base/error.hpp"
#include "base/bounds.hpp"
#include "contact/joint_keys.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"

#include <algorithm>
#include <string>
#include <utility>

namespace bbm::io {

namespace {

using meshing::JointTag;
using meshing::PatternSpec;

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

/// What a specimen's pattern does not carry (labtest_geometry): refused, not
/// dropped. `r` is the rock's region.
void check_specimen_pattern(const ModelFile& model, const std::string& file, int r) {
    const auto& src = model.source;
    const auto& pattern = model.geometry.regions[std::size_t(r)].pattern;
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
}

/// The one joint property of the rock's joints: a trigon region has two kinds,
/// the lattice and random patterns one.
const JointPropertySpec& rock_bonds(const ModelFile& model, const std::string& file, const meshing::RegionSpec& rock) {
    const auto& src = model.source;
    const auto& an = model.analysis;
    const std::vector<JointTag> tags = rock.pattern.kind == PatternSpec::Kind::trigon
                                           ? std::vector<JointTag>{JointTag::radial, JointTag::peripheral}
                                           : std::vector<JointTag>{JointTag::inner};
    int property = -1, property_rule = -1;
    for (JointTag tag : tags) {
        const auto [p, rule] = assigned_property(an, rock.name, tag);
        if (p < 0)
            throw InputError(file, src.line_of("joint_assignment"), "joint_assignment",
                             std::string("no joint property is assigned to the ") + meshing::to_string(tag) +
                                 " joints of region '" + rock.name + "'");
        if (property >= 0 && p != property) {
            // Name the later of the two rules: the one that set a kind of joint apart.
            const std::string key = "joint_assignment[" + std::to_string(std::max(rule, property_rule)) + "]";
            throw InputError(file, src.line_of(key), key,
                             "the radial and peripheral joints of region '" + rock.name + "' get different properties ('" +
                                 an.joint_properties[std::size_t(property)].name + "', '" +
                                 an.joint_properties[std::size_t(p)].name + "'): a lab specimen has one bond");
        }
        property = p, property_rule = rule;
    }
    return an.joint_properties[std::size_t(property)];
}

/// The rock's material (region `r`): density; meshed blocks take a fraction f of the deformation.
void set_rock_material(const ModelFile& model, const std::string& file, int r, RockSpec& rock_spec) {
    const auto& src = model.source;
    const auto& an = model.analysis;
    const auto& rock = model.geometry.regions[std::size_t(r)];
    const MaterialSpec* material = nullptr;
    for (const auto& [region_name, material_name] : an.region_material)
        if (region_name == rock.name)
            for (const auto& m : an.materials)
                if (m.name == material_name) material = &m;
    if (!material && an.region_material.empty() && !an.materials.empty()) material = &an.materials.front();
    if (material) rock_spec.material.density = material->density;
    rock_spec.material.deformable_fraction = 0.0;
    if (rock.mesh.enabled) {
        if (!material || !(material->deformable_fraction > 0.0))
            throw InputError(file, src.line_of(r, "material"), "region[" + std::to_string(r) + "].material",
                             "meshed blocks without a deformable_fraction: a lab specimen's deformable blocks take "
                             "a fraction f of the deformation (give the material deformable_fraction)");
        rock_spec.material.deformable_fraction = material->deformable_fraction;
        rock_spec.material.young = material->young;
        rock_spec.material.poisson = material->poisson;
        rock_spec.mesh_size = rock.mesh.size;
    }
}

} // namespace

RockSpec rock_of_model(const ModelFile& model, const std::string& file, RockSpec rock_spec) {
    const auto& regions = model.geometry.regions;
    const auto rock = std::find_if(regions.begin(), regions.end(),
                                   [](const meshing::RegionSpec& r) { return r.pattern.kind != PatternSpec::Kind::single; });
    if (rock == regions.end())
        throw InputError(file, 0, "region", "no region with a block pattern: the model has no bonded rock to test");
    const int r = int(rock - regions.begin());
    check_specimen_pattern(model, file, r);
    rock_spec.pattern = rock->pattern;
    rock_spec.bonds = rock_bonds(model, file, *rock);
    set_rock_material(model, file, r, rock_spec);
    return rock_spec;
}

std::string joint_property_toml(const JointPropertySpec& j) {
    const JointPropertySpec defaults;
    std::string toml = "[[joint_property]]\nname = \"" + j.name + "\"\nlaw = \"" + j.law + "\"\n";
    auto points = [](const std::vector<std::pair<double, double>>& v) {
        std::string s = "[";
        for (std::size_t i = 0; i < v.size(); ++i)
            s += (i ? ", [" : "[") + shortest_text(v[i].first) + ", " + shortest_text(v[i].second) + "]";
        return s + "]";
    };
    for (const contact::JointKey* k : contact::law_keys(j.law)) {
        if (k->kind == KeyKind::boolean) {
            if (k->get(j) != k->get(defaults)) toml += std::string(k->key) + " = " + (k->get(j) != 0 ? "true" : "false") + "\n";
        } else if (k->get) {
            // Required keys always; the others where they differ from the default.
            if (k->required || k->get(j) != k->get(defaults))
                toml += std::string(k->key) + " = " + shortest_text(k->get(j)) + "\n";
        } else if (k->get_curve && !k->get_curve(j).empty()) {
            toml += std::string(k->key) + " = " + points(k->get_curve(j)) + "\n";
        }
    }
    return toml;
}

} // namespace bbm::io
