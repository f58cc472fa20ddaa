// bbm meshing: the keys of a [[region.dfn]] table — a fracture set generated from
// distributions or read from a file of mapped traces — and of its length and
// orientation tables, one declaration each (base/keys.hpp). The model file's reader
// checks them by these (io/read_dfn.cpp) and docs/reference/dfn.md is generated
// from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "meshing/spec.hpp"

#include <string>

namespace bbm::meshing {

using DfnKey = Key<DfnSetSpec>;
using FractureLengthKey = Key<FractureLengthSpec>;
using FractureOrientationKey = Key<FractureOrientationSpec>;

/// In the order of FractureLengthSpec::Kind, FractureOrientationSpec::Kind and DfnSetSpec::Centres.
inline constexpr std::string_view length_law_words = "fixed, power_law, lognormal, exponential";
inline constexpr std::string_view orientation_law_words = "von_mises, uniform, list";
inline constexpr std::string_view centre_words = "poisson, clustered";
/// A file's units and their metres.
inline constexpr std::string_view length_unit_words = "m, cm, mm, ft, in";
inline constexpr double length_unit_metres[] = {1.0, 0.01, 0.001, 0.3048, 0.0254};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[region.dfn]]: `generated` sets give their distributions, `file`
/// sets their traces.
inline constexpr DfnKey dfn_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique within the region; named by terminate.at, in reports and fractures.vtu"},
    {.key = "seed", .kind = KeyKind::integer, .bounds = at_least(0, ""), .only = "generated",
     .meaning = "The set's random seed", .absent = "1"},
    {.key = "centres", .kind = KeyKind::choice, .only = "generated",
     .meaning = "poisson: uniform; clustered: a Thomas process, needs cluster", .absent = "poisson",
     .words = centre_words},
    {.key = "cluster", .kind = KeyKind::table, .only = "generated",
     .meaning = "Clustered centres only: { size = mean fractures per cluster (> 0), radius = the standard deviation "
                "of a fracture's offset from its cluster's centre (> 0 m) }",
     .absent = "none"},
    {.key = "orientation", .kind = KeyKind::table, .required = true, .only = "generated",
     .meaning = "The traces' directions, a table (below)"},
    {.key = "length", .kind = KeyKind::table, .required = true, .only = "generated",
     .meaning = "The traces' lengths, a table (below)"},
    {.key = "p21", .bounds = above(0, " 1/m"), .only = "generated",
     .meaning = "The intensity as trace length per m² of the region; or count", .absent = "count (one is required)"},
    {.key = "count", .kind = KeyKind::integer, .bounds = between(1, 1e8, ""), .only = "generated",
     .meaning = "The intensity as the number of fracture centres in the region; or p21",
     .absent = "p21 (one is required)"},
    {.key = "terminate", .kind = KeyKind::table, .only = "generated",
     .meaning = "{ at = [names of earlier sets of the region], probability = p in (0, 1] }: walking out from its "
                "centre, a fracture ends at each crossing with one of their fractures with probability p",
     .absent = "none"},
    {.key = "file", .kind = KeyKind::text, .only = "file",
     .meaning = "Traces from a file, relative to the model file, instead of distributions: a .dxf drawing (LINE and "
                "polyline entities, each layer a set) or a CSV of x1, y1, x2, y2[, set] rows ('#' comments, blank "
                "lines, one header skipped); a file none of whose traces reaches the region is refused",
     .absent = "a generated set"},
    {.key = "set", .kind = KeyKind::text, .only = "file",
     .meaning = "The CSV rows whose fifth column is this, or the DXF entities on this layer", .absent = "all"},
    {.key = "units", .kind = KeyKind::choice, .only = "file",
     .meaning = "The unit of the file's coordinates; for a DXF drawing it overrides its $INSUNITS",
     .absent = "m; a DXF's own", .words = length_unit_words},
    {.key = "property", .kind = KeyKind::text,
     .meaning = "A [[joint_property]] for the joints on this set's fractures", .absent = "the assignment rules"},
};

/// Every key of a set's length table; `distribution` selects the law and its keys.
inline constexpr FractureLengthKey fracture_length_keys[] = {
    {.key = "distribution", .kind = KeyKind::choice, .required = true,
     .meaning = "The law of the traces' lengths; a truncation that keeps under 0.1% of the law is refused",
     .words = length_law_words},
    {.key = "value", .bounds = above(0, " m"), .required = true, .only = "fixed", .meaning = "Every trace this long",
     BBM_KEY_FIELD(FractureLengthSpec, value)},
    {.key = "exponent", .bounds = above(0, ""), .required = true, .only = "power_law",
     .meaning = "a: the density ∝ l^−a on [min, max]", BBM_KEY_FIELD(FractureLengthSpec, exponent)},
    {.key = "mean", .bounds = above(0, " m"), .required = true, .only = "lognormal, exponential",
     .meaning = "The untruncated law's mean", BBM_KEY_FIELD(FractureLengthSpec, mean)},
    {.key = "std", .bounds = above(0, " m"), .required = true, .only = "lognormal",
     .meaning = "The untruncated law's standard deviation", BBM_KEY_FIELD(FractureLengthSpec, std_dev)},
    {.key = "min", .bounds = at_least(0, " m"), .only = "power_law, lognormal, exponential",
     .meaning = "The shortest trace (power_law: required, > 0)", .absent = "0"},
    {.key = "max", .bounds = above(0, " m"), .only = "power_law, lognormal, exponential",
     .meaning = "The longest trace, above min (power_law: required)", .absent = "the region's diagonal"},
};

/// Every key of a set's orientation table; `distribution` selects the law and its keys.
inline constexpr FractureOrientationKey fracture_orientation_keys[] = {
    {.key = "distribution", .kind = KeyKind::choice, .required = true, .meaning = "The law of the traces' directions",
     .words = orientation_law_words},
    {.key = "mean", .bounds = unbounded(" degrees"), .required = true, .only = "von_mises",
     .meaning = "The mean direction, counter-clockwise from +x", BBM_KEY_FIELD(FractureOrientationSpec, mean)},
    {.key = "concentration", .bounds = at_least(0, ""), .required = true, .only = "von_mises",
     .meaning = "κ: the density ∝ exp(κ cos(θ − mean)); 0 = uniform",
     BBM_KEY_FIELD(FractureOrientationSpec, concentration)},
    {.key = "angles", .kind = KeyKind::numbers, .bounds = unbounded(" degrees"), .required = true, .only = "list",
     .meaning = "The directions, picked at random"},
    {.key = "weights", .kind = KeyKind::numbers, .bounds = above(0, ""), .only = "list",
     .meaning = "One weight per angle", .absent = "equal"},
};
#pragma GCC diagnostic pop

/// docs/reference/dfn.md: the tables of keys.
inline std::string dfn_keys_markdown() {
    return "# [[region.dfn]] keys\n\n"
           "Generated from meshing/dfn_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). A set is *generated* from distributions or read from a *file* of mapped "
           "traces (with `name`, `file`, `set`, `units` and `property` only). How the network is generated and "
           "cut: [theory.md](../theory.md) §15; DXF drawings and an example: [input.md](../input.md), \"Fracture "
           "networks\".\n\n"
           "## [[region.dfn]]\n\n" +
           key_table_markdown(dfn_keys, "sets") + "\n## length\n\n" + key_table_markdown(fracture_length_keys, "laws") +
           "\n## orientation\n\n" + key_table_markdown(fracture_orientation_keys, "laws");
}

} // namespace bbm::meshing
