// bbm core: the world built from a block assembly and a model's analysis.
#pragma once

#include "core/world.hpp"
#include "meshing/blocks.hpp"

namespace bbm {

/// The world of a model (core/build_world.cpp): blocks with exact polygon mass
/// properties, FE nodes and zones, property sets and the contacts of the initial
/// assembly, detection, boundaries and the support types (nothing installed), at
/// its first time step, with its fingerprint taken. Throws InputError (file ""
/// with the key) if a joint has no property set or a name does not resolve.
World build_world(const meshing::BlockAssembly& blocks, const AnalysisSpec& analysis);

} // namespace bbm
