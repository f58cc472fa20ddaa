// bbm io: pictures drawn with cairo (PNG or SVG by the file extension, written
// atomically), for machines without a display or ParaView: the block model with
// its joints coloured by tag; a failure plot (blocks at their current place,
// cracks by mode, like the paper's Figures 4b–7); x–y curves (stress–strain,
// histories).
#pragma once

#include "base/vec2.hpp"
#include "meshing/blocks.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace bbm {
struct World;
}

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

struct FailurePlotOptions {
    int width_px = 1200;
    Box2 window; ///< empty = the whole model
    std::string title;
    /// A closed outline drawn dashed over the cracks (the failed zone about an opening); empty: none.
    std::vector<Vec2> outline;
    /// Shade the blocks by the water's pressure in their joints (a model with
    /// [flow]), not by their displacement.
    bool shade_pressure = false;
};

/// Blocks shaded by displacement magnitude (or the water's pressure), with broken contacts drawn along their
/// joints: tensile cracks red, shear cracks blue; a legend.
void draw_failure(const World& w, const std::filesystem::path& file, const FailurePlotOptions& o = {});

struct Series {
    std::string label;
    std::vector<double> x, y;
    /// Joined by a line, or each point a marker (measurements beside a fitted curve).
    enum class Style { line, points } style = Style::line;
};

/// Plot of one or more series (lines or markers) with axes, ticks, labels and,
/// for several series, a legend.
/// The legend goes top right, or top left with `legend_left` (curves that rise to the right).
/// A linear y axis starts at zero unless `y_from_zero` is false (then it spans the data).
void draw_curves(const std::vector<Series>& series, const std::string& x_label, const std::string& y_label,
                 const std::filesystem::path& file, const std::string& title = {}, bool log_y = false,
                 bool legend_left = false, bool y_from_zero = true);

} // namespace bbm::io
