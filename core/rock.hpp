// bbm core: a rock as a bonded-block model makes it — the block pattern, the bond
// between two of its blocks and the blocks' material. Plain data.
//
// One value is what every study of a rock takes: a lab test's specimen is cut
// from it (studies/lab/labtest.hpp), `bbm shear` bonds its box with it,
// `bbm calibrate` fits its bonds, `bbm envelope` measures it. It is read the
// same way wherever it comes from — a rock file or a model file's bonded region
// (io::read_rock), the rock's flags (apps/flags.hpp: one flag per declared key,
// `--pattern`, `--size`, ...), or the Python module's keywords (the flags'
// names). The specimen's shape and loading are the test's, not the rock's.
#pragma once

#include "contact/joint_property.hpp"
#include "core/model_spec.hpp"
#include "meshing/spec.hpp"

namespace bbm {

struct RockSpec {
    /// The blocks: kind, size and what it measures, Lloyd iterations, seed. A
    /// specimen uses the default shortest edge, an unrotated lattice and running bond.
    meshing::PatternSpec pattern{.kind = meshing::PatternSpec::Kind::voronoi, .size = 0.3};
    /// The bond of the joints between two of its blocks (its law and keys).
    JointPropertySpec bonds;
    /// The blocks' material: density; with 0 < deformable_fraction < 1 every block
    /// is meshed and takes the fraction f of the deformation (blocks young / f,
    /// joints kn / (1 − f), ks / (1 − f); young the rock mass's modulus E).
    MaterialSpec material{.name = "rock", .density = 2700.0, .young = 20.0e9, .poisson = 0.2, .deformable_fraction = 0.0};
    /// The deformable blocks' triangles, m (0: half the block size).
    double mesh_size = 0.0;
};

/// The paper's calibrated Voronoi rock (SPEC §8): blocks of 0.3 m, the softening
/// bond kn 96.6 GPa/m, ks 40.3 GPa/m, σt 3 MPa, c 9.5 MPa, φ 25°, the curves
/// (1.7, 0.5), (4, 0) in tension and (1.3, 0.5), (2.1, 0) in shear; rigid blocks.
inline RockSpec paper_rock() {
    RockSpec r;
    JointPropertySpec& j = r.bonds;
    j.name = "bond";
    j.law = "softening";
    j.kn = 96.6e9;
    j.ks = 40.3e9;
    j.tensile = 3e6;
    j.cohesion = 9.5e6;
    j.friction = 25.0;
    j.tension_softening = {{1.7, 0.5}, {4.0, 0.0}};
    j.shear_softening = {{1.3, 0.5}, {2.1, 0.0}};
    return r;
}

} // namespace bbm
