// bbm meshing: the keys of the [model] table — the model's title and its
// model-wide geometry defaults — one declaration each (base/keys.hpp). The model
// file's reader checks [model] by them (io/model_input.cpp) and
// docs/reference/model.md is generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "meshing/spec.hpp"

#include <string>

namespace bbm::meshing {

using ModelKey = Key<ModelGeometrySpec>;

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [model].
inline constexpr ModelKey model_keys[] = {
    {.key = "title", .kind = KeyKind::text, .meaning = "The model's name, shown in outputs", .absent = "\"\""},
    {.key = "max_segment", .bounds = above(0, " m"),
     .meaning = "The longest straight piece of a circle or arc turned into a polyline; an outline's own max_segment "
                "overrides it",
     .absent = "0.1", BBM_KEY_FIELD(ModelGeometrySpec, max_segment)},
    {.key = "max_elements", .bounds = above(0, ""),
     .meaning = "The most blocks plus triangles the model may ask for: estimated per region from its area and "
                "pattern size before anything is generated, and refused above it naming the region that dominates "
                "(about 5.3 kB a rigid block, 3.8 kB a triangle); --max-elements overrides it",
     .absent = "half the machine's memory", BBM_KEY_FIELD(ModelGeometrySpec, max_elements)},
};
#pragma GCC diagnostic pop

/// docs/reference/model.md: the table of keys.
inline std::string model_keys_markdown() {
    return "# [model] keys\n\n"
           "Generated from meshing/model_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; "
           "the test fails when it is stale). The whole file's layout: [input.md](../input.md).\n\n" +
           key_table_markdown(model_keys);
}

} // namespace bbm::meshing
