// bbm core: the keys of the [[history]] and [report] tables — what a run records
// every few steps and what it measures around an opening at its end — one
// declaration each (base/keys.hpp). The model file's reader checks both by them
// (io/read_stages.cpp, io/model_input.cpp) and docs/reference/history.md is
// generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using HistoryKey = Key<HistorySpec>;
using ReportKey = Key<ReportSpec>;

/// The history quantities, in the order of HistorySpec::Quantity.
inline constexpr std::string_view history_quantity_words =
    "unbalanced_ratio, displacement_x, displacement_y, velocity_x, velocity_y, rotation, boundary_force_x, "
    "boundary_force_y, cracks_tensile, cracks_shear, kinetic_energy, strain_energy, dissipated_energy, work, inflow, absorbed_energy, "
    "wave_energy, creep_time, damping_energy, energy_error, ejected_mass, ejection_speed";

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [[history]]: a quantity recorded every [solver] history_every steps.
inline constexpr HistoryKey history_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true, .meaning = "Non-empty, unique; history.csv's column"},
    {.key = "quantity", .kind = KeyKind::choice, .required = true,
     .meaning = "What is recorded (units and meanings: input.md, [[history]])", .words = history_quantity_words},
    {.key = "point", .kind = KeyKind::point, .bounds = unbounded(" m"),
     .meaning = "The block containing (or nearest to) it; for displacement_*, velocity_* and rotation only, and "
                "required by them"},
    {.key = "boundary", .kind = KeyKind::text,
     .meaning = "The name of a [[boundary]]; for boundary_force_* only, and required by them"},
};

/// Every key of [report]: the opening measured (center, springline and crown go
/// together) and the part of the model drawn.
inline constexpr ReportKey report_keys[] = {
    {.key = "center", .kind = KeyKind::point, .bounds = unbounded(" m"), .meaning = "The opening's centre",
     .absent = "no opening measured"},
    {.key = "springline", .kind = KeyKind::point, .bounds = unbounded(" m"),
     .meaning = "A point on the opening's wall at the springline (side wall), not center: the radius that way",
     .absent = "no opening measured"},
    {.key = "crown", .kind = KeyKind::point, .bounds = unbounded(" m"),
     .meaning = "A point on the wall at the crown (roof), not center: the radius that way",
     .absent = "no opening measured"},
    {.key = "window", .kind = KeyKind::table, .bounds = unbounded(" m"),
     .meaning = "{ min = [x, y], max = [x, y] }: the part drawn in failure.png and failure.svg",
     .absent = "±2.2 radii around the opening, or the whole model"},
    {.key = "ejection_speed", .kind = KeyKind::number, .bounds = above(0.0, " m/s"),
     .meaning = "Dynamic mode: rock detached from the rock mass and moving into the opening (in any direction "
                "without an opening) faster than this is ejected (summary.json's ejecta)",
     .absent = "1 m/s"},
};
#pragma GCC diagnostic pop

/// docs/reference/history.md: the tables of keys.
inline std::string history_keys_markdown() {
    return "# [[history]] and [report] keys\n\n"
           "Generated from core/history_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; "
           "the test fails when it is stale). Each quantity's unit and meaning, and what summary.json's `opening` "
           "holds: [input.md](../input.md); the measures: [theory.md](../theory.md) §11.\n\n"
           "## [[history]]\n\n" +
           key_table_markdown(history_keys) + "\n## [report]\n\n" + key_table_markdown(report_keys);
}

} // namespace bbm
