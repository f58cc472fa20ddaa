// bbm core: the supports in the world — installing sets of any registered type,
// finding the rock a point lies in, and numbering their ties for the force gather.
#pragma once

#include "core/world.hpp"

#include <string>
#include <vector>

namespace bbm {

/// The rock as the supports see it this step.
SupportRock support_rock(const World& w);

/// Where a point lies in the rock (a rigid block or a zone), else the nearest
/// within `reach`; block −1 if none (install time: a linear scan).
TieHost find_host(const World& w, Vec2 p, double reach);

/// Installs the named support sets, of any registered type: what an `install`
/// stage does. Each node is tied to the rock it lies in now. Throws InputError
/// (key "stage.supports") for an unknown or already installed set.
void install_supports(World& w, const std::vector<std::string>& names);

/// The per-block and per-node lists of support ties, numbered through the
/// support types in registry order (after an install, a load).
void index_support_ties(World& w);

/// The figures of every installed set of every type, by type name (its `name`).
std::vector<std::pair<std::string, std::vector<SupportSetSummary>>> support_summaries(const World& w);

/// The lines of every type that has nodes, by type name, for VTK and pictures.
std::vector<std::pair<std::string, SupportLines>> support_lines(const World& w);

} // namespace bbm
