// bbm core: what walks the world's field list (core/world.hpp) — checkpoints,
// the state hash, the model fingerprint, the memory report and the generic views.
//
// A checkpoint saves everything a step reads that the model file does not
// determine: block and node kinematics and (scaled) masses, contacts in their
// order with their full histories (detection adds and removes them), the count of
// contacts created since the last renumbering (it decides when the next one
// happens, and the numbering fixes the order of every sum), zone stresses,
// relaxation and detection bookkeeping, loads and support velocities that a study
// may have changed (a lab test's servo, a confinement ramp), time and counters,
// installed supports, and the stage monitor's samples (core/verdict.hpp) that the
// verdict is taken from. Geometry, property sets and the initial boundary
// conditions are rebuilt from the model file, which generates the same assembly
// every time; a checkpoint carries its format version, the fingerprint of the
// model it belongs to, the number of blocks, nodes and zones and the state hash
// at save time, and refuses to load into a world built from another model or
// into another format. Not saved, on purpose: the broad-phase grid of detection
// (a conservative superset of the pairs within the tolerance, rebuilt on load:
// which pairs it offers never changes which contacts form) and the fields marked
// `rebuilt` (indices and per-step scratch).
#pragma once

#include "core/world.hpp"

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace bbm {

/// Writes the evolving state (binary). A world built from the same model file
/// and given this state continues exactly as the saved one would.
void save_state(const World& w, std::ostream& out);
/// Throws std::runtime_error if the data is truncated, corrupt or of another model.
void load_state(World& w, std::istream& in);
/// Hash of every field marked hashed: equal hashes, the same evolving state bit for bit.
std::uint64_t state_hash(const World& w);
/// Hash of what the model file determines (initial geometry, masses, loads,
/// every parameter of every property set and support set): a checkpoint records
/// it and refuses another model. build_world takes it (World::fingerprint).
std::uint64_t model_fingerprint(const World& w);

/// Bytes the world holds (capacity of its arrays), by what they are indexed by.
struct Memory {
    std::size_t blocks = 0, vertices = 0, nodes = 0, zones = 0, contacts = 0, other = 0;
    std::size_t total() const { return blocks + vertices + nodes + zones + contacts + other; }
};
Memory memory(const World& w);

/// Every field of the list, by name, over its bytes in place (Python's
/// Model.state, the tests). Writing through it changes the world.
std::vector<StateField> state_fields(World& w);

} // namespace bbm
