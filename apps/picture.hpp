// bbm apps: pictures drawn with cairo (PNG and SVG), for machines without a
// display or ParaView: the block model with its joints coloured by tag. Later
// analyses draw their failure plots (cracks by mode) through the same module.
#pragma once

#include "core/vec2.hpp"
#include "meshing/blocks.hpp"

#include <filesystem>

namespace bbm::io {

struct PictureOptions {
    int width_px = 1600;
    /// Part of the model to draw; empty = everything.
    Box2 window;
    bool draw_joints = true;
};

/// Blocks filled by region, joints drawn by tag (inner grey, radial and peripheral
/// in two blues, real joints red, region interfaces black). The format follows
/// the file extension (.png or .svg); written atomically.
void draw_blocks(const meshing::BlockAssembly& a, const std::filesystem::path& file,
                 const PictureOptions& options = {});

} // namespace bbm::io
