#include "io/picture.hpp"

#include "core/measures.hpp"
#include "core/supports/ties.hpp"

#include <cairo-svg.h>
#include <cairo.h>
#include <png.h>

#include <algorithm>
#include <cstring>
#include <array>
#include <cmath>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace bbm::io {
namespace {

struct Rgb { double r, g, b; };

constexpr std::array<Rgb, 6> region_fill{{{0.93, 0.90, 0.82}, {0.80, 0.87, 0.93}, {0.85, 0.93, 0.82},
                                          {0.95, 0.85, 0.85}, {0.88, 0.85, 0.95}, {0.95, 0.93, 0.80}}};
constexpr Rgb tensile_red{0.85, 0.10, 0.10}, shear_blue{0.10, 0.30, 0.90};

Rgb joint_colour(meshing::JointTag t) {
    using T = meshing::JointTag;
    switch (t) {
    case T::inner: return {0.35, 0.35, 0.35};
    case T::radial: return {0.45, 0.65, 0.95};
    case T::peripheral: return {0.10, 0.25, 0.65};
    case T::real_joint: return {0.85, 0.10, 0.10};
    case T::interface: return {0.0, 0.0, 0.0};
    case T::fracture: return {0.80, 0.40, 0.0};
    }
    return {0, 0, 0};
}

/// Writes an opaque cairo image surface as an RGB PNG. cairo's own writer uses
/// zlib's default level with every row filter tried: 0.12-0.14 s for a 1200 x
/// 2400 failure.png, the largest serial piece of a short run's output. zlib level
/// 3 with no filter writes these flat-coloured line drawings in 0.035 s and a few
/// percent smaller. Returns an error message, empty on success.
std::string write_png_fast(cairo_surface_t* surface, const char* path) {
    cairo_surface_flush(surface);
    const int w = cairo_image_surface_get_width(surface), h = cairo_image_surface_get_height(surface);
    const int stride = cairo_image_surface_get_stride(surface);
    const unsigned char* data = cairo_image_surface_get_data(surface);
    if (!data) return "no image data";
    std::vector<unsigned char> row(3 * std::size_t(w));
    FILE* file = std::fopen(path, "wb");
    if (!file) return std::strerror(errno);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    // libpng reports errors by longjmp to here; no C++ object is created between
    // this point and the calls that may jump.
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(file);
        return "libpng could not write the image";
    }
    png_init_io(png, file);
    png_set_compression_level(png, 3);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < h; ++y) {
        // CAIRO_FORMAT_ARGB32 is one native-endian 32-bit word per pixel; the
        // canvas is painted white first, so alpha is 255 and nothing is premultiplied.
        const auto* px = reinterpret_cast<const std::uint32_t*>(data + std::size_t(y) * std::size_t(stride));
        for (int x = 0; x < w; ++x) {
            row[3 * x] = static_cast<unsigned char>(px[x] >> 16);
            row[3 * x + 1] = static_cast<unsigned char>(px[x] >> 8);
            row[3 * x + 2] = static_cast<unsigned char>(px[x]);
        }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return std::fclose(file) == 0 ? std::string() : std::string(std::strerror(errno));
}

/// A cairo surface writing to `file` + ".tmp", renamed over `file` by finish().
class Canvas {
public:
    Canvas(const std::filesystem::path& file, int w, int h)
        : file_(file), tmp_(file.string() + ".tmp"), svg_(file.extension() == ".svg") {
        surface_ = svg_ ? cairo_svg_surface_create(tmp_.c_str(), w, h)
                        : cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h);
        cr = cairo_create(surface_);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_paint(cr);
    }
    ~Canvas() {
        if (cr) cairo_destroy(cr);
        if (surface_) cairo_surface_destroy(surface_);
        if (!done_) {
            std::error_code ec;
            std::filesystem::remove(tmp_, ec);
        }
    }
    Canvas(const Canvas&) = delete;
    Canvas& operator=(const Canvas&) = delete;

    void finish() {
        cairo_destroy(cr);
        cr = nullptr;
        std::string error;
        if (svg_) {
            cairo_surface_finish(surface_);
            const cairo_status_t status = cairo_surface_status(surface_);
            if (status != CAIRO_STATUS_SUCCESS) error = cairo_status_to_string(status);
        } else {
            error = write_png_fast(surface_, tmp_.c_str());
        }
        cairo_surface_destroy(surface_);
        surface_ = nullptr;
        if (!error.empty()) throw std::runtime_error("cannot write '" + file_.string() + "': " + error);
        std::filesystem::rename(tmp_, file_);
        done_ = true;
    }

    cairo_t* cr = nullptr;

private:
    std::filesystem::path file_, tmp_;
    bool svg_;
    bool done_ = false;
    cairo_surface_t* surface_ = nullptr;
};

/// Model coordinates (y up) over `box`, fitted to width_px; returns the pixel size.
struct View {
    int w, h;
    double margin, scale;
    View(const Box2& box, int width_px, double extra_bottom = 0.0)
        : w(width_px), margin(0.02 * width_px), scale((width_px - 2 * margin) / box.width()) {
        h = int(box.height() * scale + 2 * margin + extra_bottom);
    }
    void apply(cairo_t* cr, const Box2& box, double extra_bottom = 0.0) const {
        cairo_save(cr);
        cairo_translate(cr, margin, h - margin - extra_bottom);
        cairo_scale(cr, scale, -scale);
        cairo_translate(cr, -box.lo.x, -box.lo.y);
        cairo_rectangle(cr, box.lo.x, box.lo.y, box.width(), box.height());
        cairo_clip(cr);
    }
};

void polygon_path(cairo_t* cr, std::span<const Vec2> p) {
    cairo_move_to(cr, p[0].x, p[0].y);
    for (std::size_t i = 1; i < p.size(); ++i) cairo_line_to(cr, p[i].x, p[i].y);
    cairo_close_path(cr);
}

void text(cairo_t* cr, double x, double y, const std::string& s, double size = 14, bool centred = false) {
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    cairo_move_to(cr, centred ? x - 0.5 * e.width : x, y);
    cairo_show_text(cr, s.c_str());
}

} // namespace

void draw_blocks(const meshing::BlockAssembly& a, const std::filesystem::path& file,
                 const PictureOptions& options) {
    Box2 box = options.window;
    if (box.empty()) box = bounding_box(a.points);
    const View view(box, options.width_px);
    Canvas canvas(file, view.w, view.h);
    cairo_t* cr = canvas.cr;
    view.apply(cr, box);
    const double px = 1.0 / view.scale;
    for (int b = 0; b < a.block_count(); ++b) {
        polygon_path(cr, a.block(b));
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
            const bool strong = j.tag == meshing::JointTag::real_joint || j.tag == meshing::JointTag::interface ||
                                j.tag == meshing::JointTag::fracture;
            cairo_set_line_width(cr, (strong ? 2.0 : 0.8) * px);
            cairo_move_to(cr, j.p0.x, j.p0.y);
            cairo_line_to(cr, j.p1.x, j.p1.y);
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);
    canvas.finish();
}

namespace {

/// The picture's frame: the model as it was built (blocks thrown far off would
/// shrink the rest), unless a window is given.
Box2 failure_frame(const World& w, const FailurePlotOptions& o) {
    const auto& b = w.blocks;
    Box2 box = o.window;
    if (!box.empty()) return box;
    for (int i = 0; i < b.count(); ++i)
        for (auto v = b.first[i]; v < b.first[i + 1]; ++v) box.add(b.centroid0[i] + w.vertices.local[v]);
    const double m = 0.03 * std::max(box.width(), box.height());
    box.lo -= Vec2{m, m};
    box.hi += Vec2{m, m};
    return box;
}

/// What a failure picture's blocks and zones are shaded by: their displacement
/// (light grey to ochre; rigid blocks' centroids, zones' mean of their nodes; the
/// scale ends at the 99.5th percentile: one fragment fallen far must not wash out
/// the rest) or, in a wet model on request, the water's pressure in their joints
/// (light grey to blue, to the largest; the dry far field grey).
struct Shade {
    bool water = false;
    std::vector<double> block, zone; ///< per block (rigid), per zone
    double top = 0.0, largest = 0.0;
    Shade(const World& w, bool by_pressure) : water(by_pressure && w.flow) {
        const auto& b = w.blocks;
        const auto& z = w.zones;
        const auto& nodes = w.nodes;
        const auto& removed = w.bodies.removed;
        block.assign(b.count(), 0.0), zone.assign(z.size(), 0.0);
        if (water) {
            // A block's pressure: the length-weighted mean of its contacts' water pressure.
            const auto& c = w.contacts;
            std::vector<double> length(b.count(), 0.0);
            for (int i = 0; i < c.size(); ++i)
                for (int blk : {c.vertex_block[i], c.edge_block[i]})
                    block[blk] += c.fluid_pressure[i] * c.length[i], length[blk] += c.length[i];
            for (int i = 0; i < b.count(); ++i) block[i] = length[i] > 0 ? block[i] / length[i] : 0.0;
        } else {
            for (int i = 0; i < b.count(); ++i) block[i] = norm(w.bodies.state[i].centroid - b.centroid0[i]);
            for (int k = 0; k < z.size(); ++k) {
                Vec2 u{};
                for (int nd : z.node[k]) u += (nodes.position[nd] - nodes.position0[nd]) / 3.0;
                zone[k] = norm(u);
            }
        }
        std::vector<double> v;
        for (int i = 0; i < b.count(); ++i)
            if (!removed[i] && !b.deformable[i]) v.push_back(block[i]);
        for (int k = 0; k < z.size(); ++k)
            if (!removed[z.block[k]]) v.push_back(zone[k]);
        std::sort(v.begin(), v.end());
        largest = v.empty() ? 0.0 : v.back();
        top = v.empty() ? 0.0 : water ? largest : v[std::size_t(0.995 * double(v.size() - 1))];
    }
    void set(cairo_t* cr, double u) const {
        if (water) {
            const double f = top > 0 ? std::min(1.0, u / top) : 0.0;
            cairo_set_source_rgb(cr, 0.92 - 0.75 * f, 0.92 - 0.5 * f, 0.92 - 0.05 * f);
            return;
        }
        const double f = top > 0 ? std::sqrt(std::min(1.0, u / top)) : 0.0;
        cairo_set_source_rgb(cr, 0.92 - 0.05 * f, 0.92 - 0.25 * f, 0.92 - 0.6 * f);
    }
    /// The legend's words for the shading.
    std::string words() const {
        char buf[120];
        if (water) std::snprintf(buf, sizeof buf, "shading: water pressure 0 to %.3g MPa", 1e-6 * top);
        else std::snprintf(buf, sizeof buf, "shading: displacement 0 to %.3g mm (max %.3g mm)", 1e3 * top, 1e3 * largest);
        return buf;
    }
};

/// Zones and blocks shaded; deformable blocks outlined.
void draw_material(cairo_t* cr, const World& w, const Shade& shade, double px) {
    const auto& b = w.blocks;
    const auto& nodes = w.nodes;
    const auto& z = w.zones;
    const auto& removed = w.bodies.removed;
    const auto& vertex = w.vertices.position;
    for (int k = 0; k < z.size(); ++k) {
        if (removed[z.block[k]]) continue;
        const auto& t = z.node[k];
        const Vec2 corners[3] = {nodes.position[t[0]], nodes.position[t[1]], nodes.position[t[2]]};
        polygon_path(cr, corners);
        shade.set(cr, shade.zone[k]);
        cairo_fill_preserve(cr);
        cairo_set_source_rgba(cr, 0.7, 0.7, 0.7, 0.5);
        cairo_set_line_width(cr, 0.25 * px);
        cairo_stroke(cr);
    }
    for (int i = 0; i < b.count(); ++i) {
        if (removed[i]) continue;
        polygon_path(cr, {vertex.data() + b.first[i], vertex.data() + b.first[i + 1]});
        if (b.deformable[i]) { // outline only: its zones are drawn above
            cairo_set_source_rgba(cr, 0.3, 0.3, 0.3, 0.9);
            cairo_set_line_width(cr, 0.8 * px);
            cairo_stroke(cr);
            continue;
        }
        shade.set(cr, shade.block[i]);
        cairo_fill_preserve(cr);
        cairo_set_source_rgba(cr, 0.55, 0.55, 0.55, 0.7);
        cairo_set_line_width(cr, 0.4 * px);
        cairo_stroke(cr);
    }
}

/// Each broken contact as a short line along its joint: red tensile, blue shear.
void draw_cracks(cairo_t* cr, const World& w, double px) {
    const auto& vertex = w.vertices.position;
    const auto& c = contacts(w);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    for (int i = 0; i < c.size(); ++i) {
        const auto mode = c.history[i].broken;
        if (mode == contact::JointState::intact) continue;
        const Rgb col = mode == contact::JointState::broken_tension ? tensile_red : shear_blue;
        const Vec2 x = vertex[c.vertex_id[i]];
        const Vec2 mid = 0.5 * (vertex[c.edge_id[i]] + vertex[c.edge_end[i]]);
        const Vec2 t = contact::tangent_of(c.normal[i]);
        const Vec2 y = x + (dot(mid - x, t) >= 0 ? 1.0 : -1.0) * c.length[i] * t;
        cairo_set_source_rgb(cr, col.r, col.g, col.b);
        cairo_set_line_width(cr, 2.0 * px);
        cairo_move_to(cr, x.x, x.y);
        cairo_line_to(cr, y.x, y.y);
        cairo_stroke(cr);
    }
}

/// Supports (core/supports/support.hpp), each line cell shaded by its headline force
/// against the largest now. Bars: green (none) to purple, yielded
/// segments thicker, broken ones dashed black. Linings: a thick line along the
/// wall, darker blue the higher its thrust. Returns their legend.
std::string draw_supports(cairo_t* cr, const World& w, double px) {
    std::string support_legend;
    for (const auto& [name, lines] : support_lines(w)) {
        const auto& shading = lines.cell_data[lines.shade].values;
        double largest = 0.0;
        for (double v : shading) largest = std::max(largest, std::abs(v));
        char label[160];
        std::snprintf(label, sizeof label, "   %s: %s %.0f %s", name.c_str(),
                      lines.look == SupportLines::Look::lining ? "light to dark blue" : "green 0 to purple", largest,
                      lines.shade_label.c_str());
        support_legend += label;
        for (std::size_t cell = 0; cell < lines.cells.size(); ++cell) {
            const Vec2 from = lines.points[lines.cells[cell][0]], to = lines.points[lines.cells[cell][1]];
            const double f = largest > 0 ? std::abs(shading[cell]) / largest : 0.0;
            if (lines.look == SupportLines::Look::lining) {
                cairo_set_source_rgb(cr, 0.55 - 0.45 * f, 0.75 - 0.55 * f, 0.95 - 0.35 * f);
                cairo_set_line_width(cr, 5.0 * px);
            } else {
                if (lines.mark[cell] == 2) {
                    cairo_set_source_rgb(cr, 0, 0, 0);
                    const double dash[2] = {3.0 * px, 3.0 * px};
                    cairo_set_dash(cr, dash, 2, 0.0);
                } else {
                    cairo_set_source_rgb(cr, 0.1 + 0.5 * f, 0.6 - 0.5 * f, 0.2 + 0.5 * f);
                }
                cairo_set_line_width(cr, (lines.mark[cell] == 1 ? 4.0 : 2.5) * px);
            }
            cairo_move_to(cr, from.x, from.y);
            cairo_line_to(cr, to.x, to.y);
            cairo_stroke(cr);
            cairo_set_dash(cr, nullptr, 0, 0.0);
        }
    }
    return support_legend;
}

/// The failed zone's outline, dashed.
void draw_outline(cairo_t* cr, const std::vector<Vec2>& outline, double px) {
    if (outline.empty()) return;
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_set_line_width(cr, 2.0 * px);
    const double dash[2] = {8.0 * px, 5.0 * px};
    cairo_set_dash(cr, dash, 2, 0.0);
    cairo_move_to(cr, outline.front().x, outline.front().y);
    for (const Vec2& p : outline) cairo_line_to(cr, p.x, p.y);
    cairo_close_path(cr);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0.0);
}

/// The plot area of draw_curves() and where a value lands on it: the data's
/// range (log10 of y on a log axis), pixels from the data.
struct CurveFrame {
    static constexpr int w = 900, h = 600;
    static constexpr double left = 100, right = 30, top = 50, bottom = 70;
    bool log_y = false;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;

    double ty(double y) const { return log_y ? std::log10(std::max(y, 1e-300)) : y; }
    double px(double x) const { return left + (x - x0) / (x1 - x0) * (w - left - right); }
    double py(double y) const { return h - bottom - (ty(y) - y0) / (y1 - y0) * (h - top - bottom); }
    double py_raw(double yt) const { return h - bottom - (yt - y0) / (y1 - y0) * (h - top - bottom); }
};

/// The range of every series' points (on a log axis, the positive ones).
CurveFrame curve_frame(const std::vector<Series>& series, bool log_y, bool y_from_zero) {
    CurveFrame f;
    f.log_y = log_y;
    for (const auto& s : series)
        for (std::size_t i = 0; i < s.x.size(); ++i) {
            if (log_y && !(s.y[i] > 0)) continue;
            f.x0 = std::min(f.x0, s.x[i]), f.x1 = std::max(f.x1, s.x[i]);
            f.y0 = std::min(f.y0, f.ty(s.y[i])), f.y1 = std::max(f.y1, f.ty(s.y[i]));
        }
    // Nothing to draw (a run stopped at its first record: one ratio of 0, which a
    // log axis leaves out) gives empty unit axes; infinite bounds made the tick
    // loops of draw_axes() endless (a run stopped by a signal hung drawing history.png).
    if (!std::isfinite(f.x0) || !std::isfinite(f.x1)) f.x0 = 0, f.x1 = 1;
    if (!std::isfinite(f.y0) || !std::isfinite(f.y1)) f.y0 = 0, f.y1 = 1;
    if (!(f.x1 > f.x0)) f.x1 = f.x0 + 1;
    if (!(f.y1 > f.y0)) f.y1 = f.y0 + 1;
    if (!log_y && y_from_zero) f.y0 = std::min(f.y0, 0.0);
    if (!log_y && !y_from_zero) { // the data's range, a twentieth of it to spare each side
        const double pad = 0.05 * (f.y1 - f.y0);
        f.y0 -= pad, f.y1 += pad;
    }
    return f;
}

/// Ticks at 1, 2 or 5 times a power of ten, about five per axis.
double nice_step(double range) {
    const double raw = range / 5.0, p = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / p;
    return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

/// The plot's box, its ticks and their values, the axes' labels and the title.
void draw_axes(cairo_t* cr, const CurveFrame& f, const std::string& x_label, const std::string& y_label,
               const std::string& title) {
    constexpr int w = CurveFrame::w, h = CurveFrame::h;
    constexpr double left = CurveFrame::left, right = CurveFrame::right, top = CurveFrame::top,
                     bottom = CurveFrame::bottom;
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, left, top, w - left - right, h - top - bottom);
    cairo_stroke(cr);
    char buf[64];
    const double xs = nice_step(f.x1 - f.x0), ys = f.log_y ? 1.0 : nice_step(f.y1 - f.y0);
    // At most a few dozen ticks whatever the values (a huge range over a tiny step
    // would not advance xv).
    int ticks = 0;
    for (double xv = std::ceil(f.x0 / xs) * xs; xv <= f.x1 + 1e-9 * xs && ticks < 50; xv += xs, ++ticks) {
        cairo_move_to(cr, f.px(xv), h - bottom), cairo_line_to(cr, f.px(xv), h - bottom + 5), cairo_stroke(cr);
        std::snprintf(buf, sizeof buf, "%g", std::abs(xv) < 1e-12 * xs ? 0.0 : xv);
        text(cr, f.px(xv), h - bottom + 20, buf, 12, true);
    }
    ticks = 0;
    for (double yv = std::ceil(f.y0 / ys) * ys; yv <= f.y1 + 1e-9 * ys && ticks < 50; yv += ys, ++ticks) {
        cairo_move_to(cr, left - 5, f.py_raw(yv)), cairo_line_to(cr, left, f.py_raw(yv)), cairo_stroke(cr);
        std::snprintf(buf, sizeof buf, f.log_y ? "1e%g" : "%g", std::abs(yv) < 1e-12 * ys ? 0.0 : yv);
        cairo_text_extents_t e;
        cairo_set_font_size(cr, 12);
        cairo_text_extents(cr, buf, &e);
        text(cr, left - 9 - e.width, f.py_raw(yv) + 4, buf, 12);
    }
    text(cr, 0.5 * (left + w - right), h - 20, x_label, 14, true);
    cairo_save(cr);
    cairo_translate(cr, 18, 0.5 * (top + h - bottom));
    cairo_rotate(cr, -M_PI / 2);
    text(cr, 0, 0, y_label, 14, true);
    cairo_restore(cr);
    if (!title.empty()) text(cr, 0.5 * w, 30, title, 16, true);
}

void curve_marker(cairo_t* cr, double x, double y) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, 3.5, 0, 2 * M_PI);
}

/// One series in its colour: a line (broken where a log axis leaves a point
/// out) or dots.
void draw_series(cairo_t* cr, const CurveFrame& f, const Series& s, Rgb col) {
    const bool points = s.style == Series::Style::points;
    cairo_set_source_rgb(cr, col.r, col.g, col.b);
    cairo_set_line_width(cr, 1.8);
    bool pen = false;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (f.log_y && !(s.y[i] > 0)) { pen = false; continue; }
        if (points) curve_marker(cr, f.px(s.x[i]), f.py(s.y[i]));
        else if (pen) cairo_line_to(cr, f.px(s.x[i]), f.py(s.y[i]));
        else cairo_move_to(cr, f.px(s.x[i]), f.py(s.y[i]));
        pen = true;
    }
    if (points) cairo_fill(cr);
    else cairo_stroke(cr);
}

/// The legend's line `k` for series `s`, drawn in its colour (set by draw_series()).
void draw_legend_entry(cairo_t* cr, const Series& s, std::size_t k, bool legend_left) {
    const double ly = CurveFrame::top + 20 + 18 * k,
                 lx = legend_left ? CurveFrame::left + 215 : CurveFrame::w - CurveFrame::right;
    if (s.style == Series::Style::points) {
        curve_marker(cr, lx - 187.5, ly);
        cairo_fill(cr);
    } else {
        cairo_move_to(cr, lx - 200, ly), cairo_line_to(cr, lx - 175, ly);
        cairo_stroke(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    text(cr, lx - 168, ly + 5, s.label, 12);
}

} // namespace

void draw_failure(const World& w, const std::filesystem::path& file, const FailurePlotOptions& o) {
    const Box2 box = failure_frame(w, o);
    const double legend = 40.0;
    const View view(box, o.width_px, legend);
    Canvas canvas(file, view.w, view.h);
    cairo_t* cr = canvas.cr;
    const Shade shade(w, o.shade_pressure);
    view.apply(cr, box, legend);
    const double px = 1.0 / view.scale;
    draw_material(cr, w, shade, px);
    draw_cracks(cr, w, px);
    const std::string support_legend = draw_supports(cr, w, px);
    draw_outline(cr, o.outline, px);
    cairo_restore(cr);
    // Legend.
    const double y0 = view.h - 0.5 * legend + 5;
    char buf[400];
    cairo_set_line_width(cr, 3);
    cairo_set_source_rgb(cr, tensile_red.r, tensile_red.g, tensile_red.b);
    cairo_move_to(cr, 20, y0 - 5), cairo_line_to(cr, 45, y0 - 5), cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    std::snprintf(buf, sizeof buf, "tensile cracks (%d)", cracks(w, contact::JointState::broken_tension));
    text(cr, 52, y0, buf);
    cairo_set_source_rgb(cr, shear_blue.r, shear_blue.g, shear_blue.b);
    cairo_move_to(cr, 260, y0 - 5), cairo_line_to(cr, 285, y0 - 5), cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    std::snprintf(buf, sizeof buf, "shear cracks (%d)   %s%s%s%s%s", cracks(w, contact::JointState::broken_shear),
                  shade.words().c_str(),
                  o.outline.empty() ? "" : "   dashed: failed zone", support_legend.c_str(), o.title.empty() ? "" : "   ",
                  o.title.c_str());
    text(cr, 292, y0, buf);
    canvas.finish();
}

void draw_curves(const std::vector<Series>& series, const std::string& x_label, const std::string& y_label,
                 const std::filesystem::path& file, const std::string& title, bool log_y, bool legend_left,
                 bool y_from_zero) {
    Canvas canvas(file, CurveFrame::w, CurveFrame::h);
    cairo_t* cr = canvas.cr;
    const CurveFrame frame = curve_frame(series, log_y, y_from_zero);
    draw_axes(cr, frame, x_label, y_label, title);
    constexpr std::array<Rgb, 6> colours{
        {{0.1, 0.2, 0.7}, {0.8, 0.1, 0.1}, {0.1, 0.55, 0.2}, {0.5, 0.3, 0.6}, {0.9, 0.55, 0.0}, {0.3, 0.3, 0.3}}};
    for (std::size_t k = 0; k < series.size(); ++k) {
        draw_series(cr, frame, series[k], colours[k % colours.size()]);
        if (series.size() > 1) draw_legend_entry(cr, series[k], k, legend_left);
    }
    canvas.finish();
}

} // namespace bbm::io
