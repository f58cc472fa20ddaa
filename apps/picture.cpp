#include "apps/picture.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <array>
#include <stdexcept>

namespace bbm::io {
namespace {

struct Rgb { double r, g, b; };

constexpr std::array<Rgb, 6> region_fill{{{0.93, 0.90, 0.82}, {0.80, 0.87, 0.93}, {0.85, 0.93, 0.82},
                                          {0.95, 0.85, 0.85}, {0.88, 0.85, 0.95}, {0.95, 0.93, 0.80}}};

Rgb joint_colour(meshing::JointTag t) {
    using T = meshing::JointTag;
    switch (t) {
    case T::inner: return {0.35, 0.35, 0.35};
    case T::radial: return {0.45, 0.65, 0.95};
    case T::peripheral: return {0.10, 0.25, 0.65};
    case T::real_joint: return {0.85, 0.10, 0.10};
    case T::interface: return {0.0, 0.0, 0.0};
    }
    return {0, 0, 0};
}

} // namespace

void draw_blocks(const meshing::BlockAssembly& a, const std::filesystem::path& file,
                 const PictureOptions& options) {
    Box2 box = options.window;
    if (box.empty()) box = bounding_box(a.points);
    const double margin = 0.02 * std::max(box.width(), box.height());
    const double scale = (options.width_px - 2 * margin) / box.width();
    const int w = options.width_px, h = int(box.height() * scale + 2 * margin);
    const auto tmp = std::filesystem::path(file.string() + ".tmp");
    const bool svg = file.extension() == ".svg";
    cairo_surface_t* surface = svg ? cairo_svg_surface_create(tmp.c_str(), w, h)
                                   : cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h);
    cairo_t* cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    // Model coordinates, y up.
    cairo_translate(cr, margin, h - margin);
    cairo_scale(cr, scale, -scale);
    cairo_translate(cr, -box.lo.x, -box.lo.y);
    cairo_rectangle(cr, box.lo.x, box.lo.y, box.width(), box.height());
    cairo_clip(cr);
    const double px = 1.0 / scale;
    for (int b = 0; b < a.block_count(); ++b) {
        const auto p = a.block(b);
        cairo_move_to(cr, p[0].x, p[0].y);
        for (std::size_t i = 1; i < p.size(); ++i) cairo_line_to(cr, p[i].x, p[i].y);
        cairo_close_path(cr);
        const Rgb c = region_fill[a.region[b] % region_fill.size()];
        cairo_set_source_rgb(cr, c.r, c.g, c.b);
        cairo_fill_preserve(cr);
        cairo_set_source_rgba(cr, 0.6, 0.6, 0.6, 0.6);
        cairo_set_line_width(cr, 0.5 * px);
        cairo_stroke(cr);
    }
    if (options.draw_joints) {
        for (const auto& j : a.joints) {
            const Rgb c = joint_colour(j.tag);
            cairo_set_source_rgb(cr, c.r, c.g, c.b);
            const bool strong = j.tag == meshing::JointTag::real_joint || j.tag == meshing::JointTag::interface;
            cairo_set_line_width(cr, (strong ? 2.0 : 0.8) * px);
            cairo_move_to(cr, j.p0.x, j.p0.y);
            cairo_line_to(cr, j.p1.x, j.p1.y);
            cairo_stroke(cr);
        }
    }
    cairo_destroy(cr);
    cairo_status_t status = CAIRO_STATUS_SUCCESS;
    if (svg) {
        cairo_surface_finish(surface);
        status = cairo_surface_status(surface);
    } else {
        status = cairo_surface_write_to_png(surface, tmp.c_str());
    }
    cairo_surface_destroy(surface);
    if (status != CAIRO_STATUS_SUCCESS) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw std::runtime_error("cannot write '" + file.string() + "': " + cairo_status_to_string(status));
    }
    std::filesystem::rename(tmp, file);
}

} // namespace bbm::io
