// bbm core: the keys of a [[material]] — one declaration each (base/keys.hpp). The
// model file's reader checks a material by them, the lab tests' material flags
// (`--density`, `--young`, `--poisson`, `--deformable-fraction`) are made from them,
// and docs/reference/material.md is generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using MaterialKey = Key<MaterialSpec>;

// Each row names only the members it sets; the rest keep their defaults.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of a [[material]], in the order the reference lists them.
inline constexpr MaterialKey material_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true, .meaning = "The material's name, referred to by [[region]]"},
    {.key = "density", .bounds = above(0, " kg/m³"), .meaning = "Density of the blocks", .absent = "2700",
     BBM_KEY_FIELD(MaterialSpec, density), .flag = true},
    {.key = "young", .bounds = above(0, pascals),
     .meaning = "Young's modulus E of the rock (of the rock mass: the blocks get E / deformable_fraction); "
                "required by deformable blocks",
     .absent = "none: rigid blocks only", BBM_KEY_FIELD(MaterialSpec, young), .flag = true},
    {.key = "poisson", .bounds = below(0, 0.5, ""), .meaning = "Poisson's ratio ν of the deformable blocks; needs young",
     .absent = "0.2", BBM_KEY_FIELD(MaterialSpec, poisson), .flag = true},
    {.key = "deformable_fraction", .bounds = below(0, 1, ""),
     .meaning = "Fraction f of the deformation the deformable blocks take: blocks get young / f, the joints of the "
                "material's regions kn / (1 − f) and ks / (1 − f) (SPEC §6); 0 = not split; needs young",
     .absent = "0", BBM_KEY_FIELD(MaterialSpec, deformable_fraction), .flag = true},
};
#pragma GCC diagnostic pop

/// docs/reference/material.md: the table of keys.
inline std::string material_keys_markdown() {
    std::string md = "# [[material]] keys\n\n"
                     "Generated from core/material_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` "
                     "rewrites it; the test fails when it is stale). The lab tests' flags `--density`, `--young`, "
                     "`--poisson` and `--deformable-fraction` are the same keys, with the same bounds.\n\n";
    return md + key_table_markdown(material_keys);
}

} // namespace bbm
