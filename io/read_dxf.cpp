// bbm io: fracture traces from an ASCII DXF drawing (io/dxf.hpp).
//
// A DXF file is a list of pairs of lines: an integer group code, then its value.
// Sections (0 SECTION / 2 name ... 0 ENDSEC) hold the header variables and the
// entities; an entity starts at a group code 0 naming its type and owns the pairs
// up to the next 0. The codes read here (AutoCAD DXF Reference, "ENTITIES"):
//   8 layer; LINE 10/20 start, 11/21 end; LWPOLYLINE 90 vertex count, 70 flags
//   (1 = closed), 10/20 a vertex, 42 the bulge of the segment leaving it (tan of a
//   quarter of the arc's included angle, > 0 counter-clockwise), 210/220/230 the
//   extrusion direction; POLYLINE 70 flags (1 closed, 16/64 meshes), followed by
//   VERTEX entities (10/20, 42) up to SEQEND. Polyline coordinates are in the
//   entity's object coordinate system, which for an extrusion of (0, 0, -1) mirrors
//   x; LINE coordinates are in world coordinates.
#include "io/dxf.hpp"

#include "base/error.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>

namespace bbm::io {

namespace {

struct Group {
    int code = 0;
    std::string value;
    int line = 0; ///< of the code
};

std::string trimmed(const std::string& s) {
    const auto a = s.find_first_not_of(" \t\r\n");
    if (a == std::string::npos) return "";
    const auto b = s.find_last_not_of(" \t\r\n");
    return s.substr(a, b - a + 1);
}

/// Reads the file as group code / value pairs, skipping 999 comments.
class GroupReader {
public:
    GroupReader(const std::string& path, const std::string& key) : path_(path), key_(key), in_(path) {
        if (!in_) throw InputError(path, 0, key, "cannot open the DXF file");
    }
    [[noreturn]] void fail(int line, const std::string& message) const { throw InputError(path_, line, key_, message); }

    bool next(Group& g) {
        for (;;) {
            std::string code_text;
            if (!std::getline(in_, code_text)) return false;
            ++line_;
            if (line_ == 1 && code_text.starts_with("\xEF\xBB\xBF")) code_text.erase(0, 3); // UTF-8 mark
            if (line_ == 1 && code_text.starts_with("AutoCAD Binary DXF"))
                fail(1, "a binary DXF file; save the drawing as ASCII DXF (any version from R12)");
            const std::string c = trimmed(code_text);
            int code = 0;
            const auto r = std::from_chars(c.data(), c.data() + c.size(), code);
            if (c.empty() || r.ec != std::errc() || r.ptr != c.data() + c.size())
                fail(line_, "expected a DXF group code (an integer) on this line, got \"" + c.substr(0, 40) +
                                "\": not an ASCII DXF file, or its pairs of lines are out of step");
            std::string value;
            if (!std::getline(in_, value)) fail(line_, "the file ends after a group code, without its value");
            ++line_;
            if (code == 999) continue; // comment
            g = {code, trimmed(value), line_ - 1};
            return true;
        }
    }

private:
    std::string path_, key_;
    std::ifstream in_;
    int line_ = 0;
};

/// Metres per drawing unit for the $INSUNITS codes a map can be drawn in.
std::optional<double> metres_per(int insunits) {
    switch (insunits) {
    case 0: return 1.0; // unitless: metres, as every length in a model file
    case 1: return 0.0254;
    case 2: return 0.3048;
    case 3: return 1609.344;
    case 4: return 1e-3;
    case 5: return 1e-2;
    case 6: return 1.0;
    case 7: return 1e3;
    case 10: return 0.9144;
    case 14: return 0.1;
    default: return std::nullopt;
    }
}

/// One entity's pairs (after its "0 TYPE").
struct Entity {
    std::string type;
    int line = 0;
    std::vector<Group> groups;
};

/// A polyline being read: its vertices in object coordinates and the bulge of the
/// segment leaving each.
struct Polyline {
    std::string layer = "0";
    int line = 0;
    bool closed = false;
    Vec2 extrusion_xy{0, 0};
    double extrusion_z = 1.0;
    std::vector<Vec2> vertices;
    std::vector<double> bulges;
};

class DrawingReader {
public:
    DrawingReader(GroupReader& in, DxfDrawing& out) : in_(in), out_(out) {}

    double number(const Entity& e, const Group& g) const {
        double v = 0;
        const char* end = g.value.data() + g.value.size();
        const auto r = std::from_chars(g.value.data(), end, v);
        if (g.value.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
            in_.fail(g.line + 1, "group code " + std::to_string(g.code) + " of the " + e.type + " at line " +
                                     std::to_string(e.line) + " must be a number, got \"" + g.value + "\"");
        return v;
    }
    int integer(const Entity& e, const Group& g) const {
        const double v = number(e, g);
        if (v != std::floor(v) || std::abs(v) > 1e9)
            in_.fail(g.line + 1, "group code " + std::to_string(g.code) + " of the " + e.type + " must be an integer, got \"" +
                                     g.value + "\"");
        return int(v);
    }

    void line(const Entity& e) {
        std::string layer = "0";
        std::array<std::optional<double>, 4> v; // x1 y1 x2 y2
        for (const Group& g : e.groups) {
            if (g.code == 8) layer = g.value;
            else if (g.code == 10) v[0] = number(e, g);
            else if (g.code == 20) v[1] = number(e, g);
            else if (g.code == 11) v[2] = number(e, g);
            else if (g.code == 21) v[3] = number(e, g);
        }
        if (!v[0] || !v[1] || !v[2] || !v[3])
            in_.fail(e.line, "a LINE without its " + std::string(!v[0] || !v[1] ? "start point (group codes 10, 20)" : "end point (group codes 11, 21)"));
        ++out_.entities_read["LINE"];
        add({*v[0], *v[1]}, {*v[2], *v[3]}, layer, e.line, false);
    }

    /// The polyline header: layer, closed, extrusion (LWPOLYLINE: and its vertices).
    Polyline polyline(const Entity& e, bool lightweight) {
        Polyline p;
        p.line = e.line;
        std::optional<int> count;
        for (const Group& g : e.groups) {
            if (g.code == 8) p.layer = g.value;
            else if (g.code == 70) {
                const int flags = integer(e, g);
                p.closed = flags & 1;
                if (!lightweight && (flags & (16 | 64)))
                    in_.fail(e.line, "a POLYLINE mesh (flags " + std::to_string(flags) + "): traces are lines or polylines");
            } else if (g.code == 90 && lightweight) count = integer(e, g);
            else if (g.code == 210) p.extrusion_xy.x = number(e, g);
            else if (g.code == 220) p.extrusion_xy.y = number(e, g);
            else if (g.code == 230) p.extrusion_z = number(e, g);
            else if (lightweight && g.code == 10) p.vertices.push_back({number(e, g), NAN}), p.bulges.push_back(0.0);
            else if (lightweight && g.code == 20) {
                if (p.vertices.empty() || !std::isnan(p.vertices.back().y))
                    in_.fail(g.line, "a y coordinate (20) without its x (10) in the LWPOLYLINE at line " + std::to_string(e.line));
                p.vertices.back().y = number(e, g);
            } else if (lightweight && g.code == 42 && !p.vertices.empty()) p.bulges.back() = number(e, g);
        }
        if (lightweight) {
            for (const Vec2& v : p.vertices)
                if (std::isnan(v.y)) in_.fail(e.line, "a LWPOLYLINE vertex without its y coordinate (group code 20)");
            if (count && *count != int(p.vertices.size()))
                in_.fail(e.line, "the LWPOLYLINE says it has " + std::to_string(*count) + " vertices (group code 90) but lists " +
                                     std::to_string(p.vertices.size()));
        }
        return p;
    }

    void vertex(const Entity& e, Polyline& p) {
        std::optional<double> x, y;
        double bulge = 0.0;
        for (const Group& g : e.groups) {
            if (g.code == 10) x = number(e, g);
            else if (g.code == 20) y = number(e, g);
            else if (g.code == 42) bulge = number(e, g);
            else if (g.code == 70 && (integer(e, g) & 16)) return; // a spline's frame point, not on the curve
        }
        if (!x || !y) in_.fail(e.line, "a VERTEX without its coordinates (group codes 10, 20)");
        p.vertices.push_back({*x, *y});
        p.bulges.push_back(bulge);
    }

    /// The polyline's segments as traces; a bulged segment as chords of <= 5 degrees.
    void emit(const Polyline& p, const std::string& type) {
        if (std::abs(p.extrusion_xy.x) > 1e-9 || std::abs(p.extrusion_xy.y) > 1e-9 || p.extrusion_z == 0.0)
            in_.fail(p.line, "the " + type + " is not drawn in the XY plane (extrusion direction [" +
                                 std::to_string(p.extrusion_xy.x) + ", " + std::to_string(p.extrusion_xy.y) + ", " +
                                 std::to_string(p.extrusion_z) + "])");
        if (p.vertices.size() < 2) in_.fail(p.line, "a " + type + " with fewer than 2 vertices");
        ++out_.entities_read[type];
        const bool mirrored = p.extrusion_z < 0.0; // object x runs along world -x
        const std::size_t n = p.vertices.size(), segments = p.closed ? n : n - 1;
        for (std::size_t i = 0; i < segments; ++i) {
            const Vec2 a = p.vertices[i], b = p.vertices[(i + 1) % n];
            const double bulge = p.bulges[i];
            if (bulge == 0.0) {
                add(a, b, p.layer, p.line, mirrored);
                continue;
            }
            // Included angle theta = 4 atan(bulge); the centre lies (c/2) cot(theta/2)
            // to the left of the chord's midpoint.
            const double theta = 4.0 * std::atan(bulge), c = norm(b - a);
            if (c == 0.0) continue;
            const Vec2 mid = 0.5 * (a + b), left{-(b - a).y / c, (b - a).x / c};
            const Vec2 centre = mid + (0.5 * c / std::tan(0.5 * theta)) * left;
            const double r = norm(a - centre), start = std::atan2(a.y - centre.y, a.x - centre.x);
            const int pieces = std::max(1, int(std::ceil(std::abs(theta) / (std::numbers::pi / 36.0) - 1e-9)));
            Vec2 from = a;
            for (int k = 1; k <= pieces; ++k) {
                const double t = start + theta * k / pieces;
                const Vec2 to = k == pieces ? b : centre + r * Vec2{std::cos(t), std::sin(t)};
                add(from, to, p.layer, p.line, mirrored);
                from = to;
            }
        }
    }

    void add(Vec2 a, Vec2 b, const std::string& layer, int line, bool mirrored) {
        if (mirrored) a.x = -a.x, b.x = -b.x;
        if (a == b) return; // a repeated vertex
        out_.traces.push_back({a, b, layer, line}); // scaled to metres once the header's units are known
    }

private:
    GroupReader& in_;
    DxfDrawing& out_;
};

/// The walk through a file's groups: the section it is in, the entity being
/// gathered (its groups follow its 0 group), an open POLYLINE, the header's units.
struct DxfWalk {
    GroupReader& in;
    DxfDrawing& out;
    DrawingReader reader;
    enum class Section { none, header, entities, other } section = Section::none;
    bool any_section = false, ended = false, units_next = false;
    std::optional<Entity> entity;
    std::optional<Polyline> polyline; // an open POLYLINE, gathering its VERTEXes
    int units_line = 0;

    DxfWalk(GroupReader& i, DxfDrawing& o) : in(i), out(o), reader(i, o) {}

    /// The entity gathered so far, its groups all read: its traces, or a VERTEX of
    /// the open POLYLINE.
    void finish() {
        if (!entity) return;
        const Entity& e = *entity;
        if (polyline) {
            if (e.type == "VERTEX") reader.vertex(e, *polyline);
            else if (e.type == "SEQEND") reader.emit(*polyline, "POLYLINE"), polyline.reset();
            else in.fail(e.line, "a " + e.type + " inside the POLYLINE at line " + std::to_string(polyline->line) + " (no SEQEND)");
        } else if (e.type == "LINE") {
            reader.line(e);
        } else if (e.type == "LWPOLYLINE") {
            reader.emit(reader.polyline(e, true), "LWPOLYLINE");
        } else if (e.type == "POLYLINE") {
            polyline = reader.polyline(e, false);
        } else {
            ++out.entities_skipped[e.type];
        }
        entity.reset();
    }

    /// A group whose code is not 0: the entity's, or in the header the value of $INSUNITS.
    void value(const Group& g) {
        if (entity) entity->groups.push_back(g);
        else if (section == Section::header) {
            if (g.code == 9) units_next = g.value == "$INSUNITS";
            else if (units_next && g.code == 70) {
                const Entity header{"HEADER", g.line, {}};
                out.insunits = reader.integer(header, g);
                units_line = g.line;
                units_next = false;
            }
        }
    }

    /// A 0 group (after the entity before it is finished): a section's start or
    /// end, the file's end, or in the entities an entity's start.
    void start(const Group& g) {
        if (g.value == "SECTION") {
            Group name;
            if (!in.next(name) || name.code != 2) in.fail(g.line, "a SECTION without its name (group code 2)");
            section = name.value == "HEADER" ? Section::header : name.value == "ENTITIES" ? Section::entities : Section::other;
            any_section = true;
        } else if (g.value == "ENDSEC") {
            if (polyline) in.fail(polyline->line, "the POLYLINE has no SEQEND before the section ends");
            section = Section::none;
        } else if (g.value == "EOF") {
            ended = true;
        } else if (section == Section::entities) {
            entity = Entity{g.value, g.line, {}};
        }
    }
};

/// The traces from drawing units to metres: `metres_per_unit` if given, else the
/// header's $INSUNITS (at `units_line`).
void scale_to_metres(const GroupReader& in, DxfDrawing& out, double metres_per_unit, int units_line) {
    if (metres_per_unit > 0.0) {
        out.metres_per_unit = metres_per_unit;
    } else {
        const auto m = metres_per(out.insunits);
        if (!m)
            in.fail(units_line, "drawing units $INSUNITS = " + std::to_string(out.insunits) +
                                    " are not a length bbm converts (in, ft, mi, mm, cm, dm, m, km, yd); "
                                    "give the model file's 'units' key");
        out.metres_per_unit = *m;
    }
    for (DxfTrace& t : out.traces) {
        t.a = out.metres_per_unit * t.a, t.b = out.metres_per_unit * t.b;
        if (!std::isfinite(t.a.x) || !std::isfinite(t.a.y) || !std::isfinite(t.b.x) || !std::isfinite(t.b.y) ||
            std::max({std::abs(t.a.x), std::abs(t.a.y), std::abs(t.b.x), std::abs(t.b.y)}) > 1e12)
            in.fail(t.line, "the entity's coordinates lie beyond 1e12 m once in metres");
    }
}

} // namespace

std::string dxf_unit_name(int insunits) {
    switch (insunits) {
    case 0: return "unitless";
    case 1: return "in";
    case 2: return "ft";
    case 3: return "mi";
    case 4: return "mm";
    case 5: return "cm";
    case 6: return "m";
    case 7: return "km";
    case 10: return "yd";
    case 14: return "dm";
    default: return "code " + std::to_string(insunits);
    }
}

DxfDrawing read_dxf(const std::string& path, const std::string& key, double metres_per_unit) {
    GroupReader in(path, key);
    DxfDrawing out;
    DxfWalk walk(in, out);
    Group g;
    while (!walk.ended && in.next(g)) {
        if (g.code != 0) {
            walk.value(g);
            continue;
        }
        walk.finish();
        walk.start(g);
    }
    walk.finish();
    if (!walk.any_section) in.fail(1, "no SECTION in the file: not a DXF drawing");
    scale_to_metres(in, out, metres_per_unit, walk.units_line);
    return out;
}

} // namespace bbm::io
