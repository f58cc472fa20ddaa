// bbm io: the model file — TOML text in, a checked model description out.
//
// read_model() turns a model file (format and every key: docs/input.md) into the
// plain-data ModelGeometrySpec that meshing/ consumes and the AnalysisSpec
// (materials, joint properties, boundaries, solver, histories, stages) that core/
// consumes. Everything a user can get wrong without drawing a picture is caught
// here, at once, as an InputError that names file, line and the full key
// ("tunnel.toml:14: region[1].pattern.size: must be > 0 m, got -0.3"): syntax,
// unknown keys (with a "did you mean"), types, missing keys, ranges, enum strings,
// names and the references between tables (a boundary's regions, a history's
// boundary, softening curves that snap back). Geometry proper (self-crossing
// outlines, holes outside, overlaps) is judged by meshing/, which knows nothing of
// files and reports a GeometryError by region index and key; ModelSource keeps the
// line of every key read so that to_input_error() can point the user back at the
// right line anyway.
//
// toml++ is included by model_input.cpp only: it is heavy to compile, and no other
// layer needs to see it.
#pragma once

#include "base/error.hpp"
#include "core/model_spec.hpp"
#include "core/rock.hpp"
#include "meshing/spec.hpp"

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bbm::io {

/// Where each region of a model came from, to report a GeometryError with a line.
struct ModelSource {
    std::string file;
    /// Line of each [[region]] table.
    std::vector<int> region_line;
    /// Per region: key inside the region ("outline", "holes[0]", "minus[1]",
    /// "pattern.size", "joint_set[0].spacing", ...) -> line.
    std::vector<std::map<std::string, int>> key_line;

    /// Best line for a key of a region: the key itself, else its nearest recorded
    /// parent ("holes[0].radius" -> "holes[0]" -> "holes"), else the region's line;
    /// 0 for a region index out of range.
    int line_of(int region, const std::string& key) const;

    /// Outside regions: full key ("solver.gravity", "boundary[0]", "boundary[0].box",
    /// "stage[2].regions[1]") -> line, for errors found later by the solver.
    std::map<std::string, int> analysis_line;
    /// Best line for such a key, as above (nearest recorded parent); 0 if none.
    int line_of(const std::string& key) const;
};

struct ModelFile {
    meshing::ModelGeometrySpec geometry;
    /// Materials, joint properties, boundaries, solver, histories, stages: each
    /// table optional; defaults as in core/model_spec.hpp.
    AnalysisSpec analysis;
    ModelSource source;
    std::string title;
};

/// Reads and checks a model file. Throws InputError.
ModelFile read_model(const std::string& path);
/// The same from text; `name` stands for the file name in messages (for tests).
ModelFile parse_model(std::string_view text, const std::string& name);

/// A rock (core/rock.hpp) as `--rock FILE` gives it to the lab tests, calibrate,
/// envelope and shear: a rock file — one [[joint_property]] (the bonds) and at
/// most one [[material]] (the blocks' density; meshed blocks' deformable_fraction,
/// young, poisson), what `bbm calibrate` writes — read by the model file's own
/// readers (the same keys, bounds and messages); or a whole model file, whose rock
/// is its bonded region (rock_of_model). What the file does not give keeps `base`'s.
RockSpec read_rock(const std::string& path, RockSpec base = paper_rock());
RockSpec parse_rock(std::string_view text, const std::string& name, RockSpec base = paper_rock());

/// The rock of a model file (read from `file`, named in errors): its first region
/// with a block pattern (not `single`) — the pattern, size and its measure, Lloyd
/// iterations and seed; the joint property the [[joint_assignment]] rules give the
/// joints between two of its blocks (in order, a later match overriding an
/// earlier one, as the solver applies them); its material's density and, for
/// meshed blocks, the deformable fraction, modulus, Poisson's ratio and triangle
/// size. What a specimen cannot carry is refused with an InputError naming the
/// file and the key: trigon regions whose radial and peripheral joints get
/// different properties, meshed blocks whose material has no deformable fraction,
/// a rotated lattice, bricks of another aspect or bond, a given shortest edge.
RockSpec rock_of_model(const ModelFile& model, const std::string& file, RockSpec base = paper_rock());

/// A softening curve written as a model file writes it, "[[1.7, 0.5], [4.0, 0]]"
/// (a flag's value), checked by the reader's rules; errors name `flag` and the point.
std::vector<std::pair<double, double>> parse_curve(std::string_view text, const std::string& flag);

/// A [[joint_property]] table's text for a set, from its law's key declarations:
/// every key the law reads that differs from its default, numbers exact
/// (shortest round-trip text). parse_rock reads it back to the same set.
std::string joint_property_toml(const JointPropertySpec& j);


/// The text of a model file with keys set (`set`: full key as in messages,
/// "joint_property[0].tensile" or "region[1].pattern.size", and a TOML value) and
/// the seeds of random patterns (voronoi, trigon, delaunay) moved by `seed_offset`
/// (`bbm sweep`). Comments are not kept. Throws InputError naming --set and the
/// key if the key's tables do not exist; the result is checked by parse_model.
std::string edit_model_text(std::string_view text, const std::string& name,
                            const std::vector<std::pair<std::string, std::string>>& set, long seed_offset);

/// "file:line: region[i].key: message" for a defect found by meshing/.
InputError to_input_error(const ModelSource& source, const GeometryError& error);

} // namespace bbm::io
