// bbm io: VTK output of a block assembly, for ParaView.
//
// Two unstructured grids (.vtu) describe a model: the blocks, one polygon cell
// each, and the joints, one line cell each (the bonds and contacts live on the
// joints, so they are drawn apart and can be coloured by their own fields).
// Enums and region indices are written as Int32 cell data; the names they stand
// for go along as string field data (`pattern_names`, `region_names`,
// `tag_names`, indexed by the value), so a ParaView user can decode them without
// this code. Points are 3D in VTK: z = 0.
//
// The files are VTK XML with appended raw binary data, zlib-compressed, 64-bit
// headers, double-precision points. A time series is a .pvd collection that
// names one .vtu per step; VTK 9.1 has no writer for it, so write_pvd() writes
// the few lines of XML itself.
//
// Every writer here is atomic: it writes `file` + ".tmp" in the same directory
// and renames it over `file`, so a run killed mid-write never leaves a truncated
// file and a failed write never destroys the previous good one. (It guards
// against a killed process, not against power loss: nothing is fsync'ed.)
// Failures throw std::runtime_error naming the file.
#pragma once

#include "core/world.hpp"
#include "meshing/blocks.hpp"

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bbm::io {

/// One VTK_POLYGON per block, cell data block_id, region, area, pattern, parent.
void write_blocks_vtu(const meshing::BlockAssembly& a, const std::filesystem::path& file);

/// One VTK_LINE per JointRecord (p0 to p1), cell data tag, block_a, block_b, length.
void write_joints_vtu(const meshing::BlockAssembly& a, const std::filesystem::path& file);

/// The discrete fracture network as built: one VTK_LINE per trace (clipped to its
/// region), cell data set, region, length; field data set_names.
void write_fractures_vtu(const meshing::BlockAssembly& a, const std::filesystem::path& file);

/// A ParaView collection: each step is (time, path of a .vtu relative to the .pvd's
/// directory). Files sharing a time become parts 0, 1, ... of that time step, so
/// blocks and joints of one step can sit in one collection.
void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& steps);

/// Creates the output directory `dir` (and its parents) and checks that files can
/// be written in it; otherwise throws InputError naming --out and the reason (a
/// file in the way, no permission), before any work is done.
void make_output_directory(const std::filesystem::path& dir);

/// Writes `text` to `file` atomically (summary.json, logs of a finished run).
void write_text_atomically(const std::filesystem::path& file, std::string_view text);

/// The world's current state in one grid: rigid blocks as polygons at their
/// current place, then the zones (triangles) of deformable blocks. Cell data
/// block_id, region, material, zone (0 rigid block, 1 zone), cell_displacement,
/// velocity, rotation, stress and strain as symmetric tensors XX YY ZZ XY YZ XZ
/// (tension positive; rigid blocks: block-averaged stress, zero strain); point
/// data displacement (of every vertex and node). Excavated blocks are left out.
void write_state_blocks_vtu(const World& w, const std::filesystem::path& file);
/// Contacts as line cells along their share of the joint (cell data sn, tau, un,
/// us, damage, state (0 intact, 1 softening, 2 broken-tension, 3 broken-shear,
/// 4 sliding), property, length).
void write_state_contacts_vtu(const World& w, const std::filesystem::path& file);
/// Water in the joints (a model with [flow]): the network's domains as points
/// (point data pressure, head, held, drained) and its pipes as line cells (cell
/// data aperture, flow_rate from pipe_from to pipe_to in m²/s per m, joint).
void write_flow_vtu(const World& w, const std::filesystem::path& file);
/// An installed support type (core/supports/support.hpp) as line cells with the
/// arrays its lines() names (each type's header documents its own).
/// The seismic events (core/events.hpp) as points: magnitude, moment, type
/// (1 tensile, 0 shear, −1 implosive), time and energies as cell data.
void write_events_vtu(const std::vector<SeismicEvent>& events, const std::filesystem::path& file);
void write_support_vtu(const SupportLines& lines, const std::filesystem::path& file);

} // namespace bbm::io
