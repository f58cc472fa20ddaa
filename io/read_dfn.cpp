// bbm io: the [[region.dfn]] tables of a model file — fracture sets of a discrete
// fracture network, generated (meshing/dfn.hpp) or read from a CSV file of traces
// (docs/input.md "Fracture networks"), or from a DXF drawing (io/dxf.hpp).
#include "io/dxf.hpp"
#include "io/reader.hpp"
#include "meshing/dfn_keys.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace bbm::io::reader {

using meshing::DfnSetSpec;
using meshing::FractureLengthSpec;
using meshing::FractureOrientationSpec;
using meshing::SegmentSpec;

namespace {

using meshing::dfn_keys;
using meshing::fracture_length_keys;
using meshing::fracture_orientation_keys;

FractureLengthSpec read_length(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a length table { distribution = ..., ... }");
    using K = FractureLengthSpec::Kind;
    FractureLengthSpec l;
    l.kind = static_cast<K>(
        read_typed_keys(c, t, p, fracture_length_keys, "distribution", "length distribution", "length distribution"));
    const std::string_view law = key_words(meshing::length_law_words)[static_cast<std::size_t>(l.kind)];
    for (const meshing::FractureLengthKey& k : fracture_length_keys)
        if (k.set && key_applies(k, law)) read_declared_key(c, t, p, k, l);
    const auto bounds = [](std::string_view key) -> const Bounds& { return bounds_of(fracture_length_keys, key); };
    if (l.kind == K::power_law) {
        // A power law has no mass at zero: both ends are required, the lower above 0.
        l.min = required_number(c, t, p, "min", above(0, metres));
        l.max = required_number(c, t, p, "max", bounds("max"));
    } else if (l.kind != K::fixed) {
        l.min = number(c, t, p, "min", bounds("min")).value_or(0.0);
        l.max = number(c, t, p, "max", bounds("max")).value_or(0.0);
    }
    if (l.max > 0.0 && !(l.max > l.min))
        c.fail(*t.get("max"), p.key("max"), "must be above min = " + fmt(l.min) + " m, got " + fmt(l.max));
    return l;
}

FractureOrientationSpec read_orientation(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "an orientation table { distribution = ..., ... }");
    using K = FractureOrientationSpec::Kind;
    FractureOrientationSpec o;
    o.kind = static_cast<K>(read_typed_keys(c, t, p, fracture_orientation_keys, "distribution",
                                            "orientation distribution", "orientation distribution"));
    const std::string_view law = key_words(meshing::orientation_law_words)[static_cast<std::size_t>(o.kind)];
    for (const meshing::FractureOrientationKey& k : fracture_orientation_keys)
        if (k.set && key_applies(k, law)) read_declared_key(c, t, p, k, o);
    if (o.kind == K::list) {
        auto numbers = [&](std::string_view key, const Range& r, std::vector<double>& out) {
            const toml::node* n = key == "angles" ? &need(c, t, p, key, "an array of angles in degrees")
                                                  : find(c, t, p, key);
            if (!n) return;
            const Path kp = p.key(key);
            const toml::array& a = to_array(c, *n, kp, "an array of numbers");
            if (a.empty()) c.fail(*n, kp, "must list at least one number, got an empty array");
            for_each_element(c, a, kp, [&](const toml::node& e, const Path& ep) { out.push_back(checked_number(c, e, ep, r)); });
        };
        numbers("angles", bounds_of(fracture_orientation_keys, "angles"), o.angles);
        numbers("weights", bounds_of(fracture_orientation_keys, "weights"), o.weights);
        if (!o.weights.empty() && o.weights.size() != o.angles.size())
            c.fail(*t.get("weights"), p.key("weights"),
                   "must give one weight per angle: " + std::to_string(o.angles.size()) + " angles, " +
                       std::to_string(o.weights.size()) + " weights");
        for (double& a : o.angles) a = std::fmod(std::fmod(a, 180.0) + 180.0, 180.0);
    }
    return o;
}

/// Traces from a CSV file: x1, y1, x2, y2[, set] per line; blank lines, lines
/// starting with '#' and a header line are skipped. With `only`, the rows whose
/// fifth column is that set. Coordinates times `scale` (metres per file unit).
std::vector<SegmentSpec> read_trace_csv(const Ctx& c, const toml::node& n, const Path& p, const std::string& path,
                                        const std::optional<std::string>& only, double scale) {
    std::ifstream in(path);
    if (!in) c.fail(n, p, "cannot open the trace file " + path);
    std::vector<SegmentSpec> traces;
    std::string text;
    int line_no = 0;
    bool seen_data = false;
    while (std::getline(in, text)) {
        ++line_no;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        const auto first = text.find_first_not_of(" \t");
        if (first == std::string::npos || text[first] == '#') continue;
        std::vector<std::string> cells;
        std::stringstream row(text);
        for (std::string cell; std::getline(row, cell, ',');) {
            const auto a = cell.find_first_not_of(" \t"), b = cell.find_last_not_of(" \t");
            cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
        }
        double v[4];
        bool numeric = cells.size() >= 4;
        for (int k = 0; numeric && k < 4; ++k) {
            std::size_t used = 0;
            try {
                v[k] = std::stod(cells[k], &used);
            } catch (const std::exception&) {
                used = 0;
            }
            numeric = used == cells[k].size() && used > 0 && std::isfinite(v[k]);
        }
        if (!numeric && !seen_data) { // a header
            seen_data = true;
            continue;
        }
        seen_data = true;
        if (!numeric || cells.size() > 5)
            throw InputError(path, line_no, p.full,
                             "expected x1, y1, x2, y2[, set] (numbers, then an optional set name), got \"" + text +
                                 "\"");
        if (only && (cells.size() < 5 || cells[4] != *only)) continue;
        const SegmentSpec s{{scale * v[0], scale * v[1]}, {scale * v[2], scale * v[3]}};
        if (s.a == s.b) throw InputError(path, line_no, p.full, "the trace's two ends are the same point");
        traces.push_back(s);
    }
    return traces;
}

/// Traces from an ASCII DXF drawing (io/dxf.hpp); with `only`, those on that layer.
/// `note` says what was read and what was left out, for `bbm mesh`.
std::vector<SegmentSpec> read_trace_dxf(const Ctx& c, const toml::node& n, const Path& p, const std::string& path,
                                        const std::optional<std::string>& only, double scale, std::string& note) {
    const DxfDrawing d = read_dxf(path, p.full, scale);
    std::vector<SegmentSpec> traces;
    std::vector<std::string> layers;
    for (const DxfTrace& t : d.traces) {
        if (std::ranges::find(layers, t.layer) == layers.end()) layers.push_back(t.layer);
        if (!only || t.layer == *only) traces.push_back({t.a, t.b});
    }
    auto counts = [](const std::map<std::string, int>& kinds) {
        std::string s;
        for (const auto& [type, count] : kinds) s += (s.empty() ? "" : ", ") + std::to_string(count) + " " + type;
        return s;
    };
    note = "DXF: " + (d.entities_read.empty() ? std::string("no LINE or polyline") : counts(d.entities_read)) +
           " on layers " + join(std::vector<std::string_view>(layers.begin(), layers.end())) + "; units " +
           (scale > 0.0 ? "given by 'units'" : dxf_unit_name(d.insunits)) + " (" + fmt6(d.metres_per_unit) + " m)";
    if (!d.entities_skipped.empty()) note += "; left out: " + counts(d.entities_skipped);
    if (traces.empty() && only && !layers.empty())
        c.fail(n, p,
               "the DXF file " + path + " has no traces on layer " + reader::quoted(*only) + "; its layers with traces are " +
                   join(std::vector<std::string_view>(layers.begin(), layers.end())));
    return traces;
}

/// The box an outline lies in (arcs and circles by their whole circle: an upper bound).
Box2 outline_box(const meshing::OutlineSpec& o) {
    using K = meshing::OutlineSpec::Kind;
    Box2 b;
    auto circle = [&](Vec2 centre, double r) {
        b.add(centre - Vec2{r, r});
        b.add(centre + Vec2{r, r});
    };
    switch (o.kind) {
    case K::rectangle: b.add(o.min), b.add(o.max); break;
    case K::polygon: for (Vec2 q : o.points) b.add(q); break;
    case K::circle: circle(o.center, o.radius); break;
    case K::path:
        b.add(o.start);
        for (const auto& s : o.steps) {
            b.add(s.to);
            if (s.arc) circle(s.center, norm(s.to - s.center));
        }
        break;
    case K::opening:
        circle(o.center, 0.5 * o.width);
        b.add({o.center.x, o.floor_y});
        break;
    }
    return b;
}

/// A trace file drawn in other coordinates (a mine grid, millimetres) would leave
/// the region uncut without a word: refuse a set none of whose traces reaches the
/// region's outline box.
void check_reaches_region(const Ctx& c, const toml::node& n, const Path& p, const std::vector<SegmentSpec>& traces,
                          const meshing::OutlineSpec& outline) {
    const Box2 region = outline_box(outline);
    Box2 all;
    for (const SegmentSpec& t : traces) {
        Box2 tb;
        tb.add(t.a), tb.add(t.b);
        all.add(t.a), all.add(t.b);
        if (!(tb.hi.x < region.lo.x || tb.lo.x > region.hi.x || tb.hi.y < region.lo.y || tb.lo.y > region.hi.y)) return;
    }
    c.fail(n, p,
           "none of its " + std::to_string(traces.size()) + " traces reaches the region: they span x " + fmt6(all.lo.x) +
               " to " + fmt6(all.hi.x) + ", y " + fmt6(all.lo.y) + " to " + fmt6(all.hi.y) + " m, the region x " +
               fmt6(region.lo.x) + " to " + fmt6(region.hi.x) + ", y " + fmt6(region.lo.y) + " to " + fmt6(region.hi.y) +
               " m (other coordinates or units? see 'units')");
}


/// The set's name (new in its region) and the joint property it names, if any.
void read_dfn_names(const Ctx& c, const toml::table& t, const Path& p, const std::vector<std::string>& earlier,
                    DfnSetSpec& s) {
    const Path np = p.key("name");
    const toml::node& name = need(c, t, p, "name", "a non-empty string");
    s.name = to_str(c, name, np);
    if (s.name.empty()) c.fail(name, np, "must be a non-empty string, got \"\"");
    for (std::size_t j = 0; j < earlier.size(); ++j)
        if (earlier[j] == s.name)
            c.fail(name, np, "fracture set name " + reader::quoted(s.name) + " is already used by dfn[" + std::to_string(j) + "]");
    if (const toml::node* n = find(c, t, p, "property")) {
        s.property = to_str(c, *n, p.key("property"));
        if (s.property.empty()) c.fail(*n, p.key("property"), "must be a non-empty string, got \"\"");
    }
}

/// A set read from a trace file (DXF or CSV, beside the model file), which must
/// reach the region.
void read_dfn_file(Ctx& c, const toml::table& t, const Path& p, const meshing::OutlineSpec& outline, DfnSetSpec& s) {
    const toml::node& f = *find(c, t, p, "file");
    const Path fp = p.key("file");
    s.file = to_str(c, f, fp);
    std::optional<std::string> only;
    if (const toml::node* n = find(c, t, p, "set")) only = to_str(c, *n, p.key("set"));
    double scale = 0.0; // metres per file unit; 0 = the file's own (a DXF's header) or metres
    if (const toml::node* n = find(c, t, p, "units"))
        scale = meshing::length_unit_metres[to_choice(c, *n, p.key("units"),
                                                      key_words(meshing::length_unit_words), "length unit")];
    const std::string path = (std::filesystem::path(c.file).parent_path() / s.file).string();
    std::string ext = std::filesystem::path(s.file).extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".dxf") {
        if (!std::filesystem::exists(path)) c.fail(f, fp, "cannot open the trace file " + path);
        s.traces = read_trace_dxf(c, f, fp, path, only, scale, s.import_note);
    } else {
        s.traces = read_trace_csv(c, f, fp, path, only, scale > 0.0 ? scale : 1.0);
    }
    if (s.traces.empty())
        c.fail(f, fp, "the trace file " + path + " has no traces" + (only ? " of set " + reader::quoted(*only) : std::string()));
    check_reaches_region(c, f, fp, s.traces, outline);
}

/// Where a generated set's fractures are centred: the `centres` key, and the
/// cluster table clustered centres need (and no other takes).
void read_dfn_centres(const Ctx& c, const toml::table& t, const Path& p, DfnSetSpec& s) {
    if (const toml::node* n = find(c, t, p, "centres"))
        s.centres = static_cast<DfnSetSpec::Centres>(
            to_choice(c, *n, p.key("centres"), key_words(meshing::centre_words), "centres"));
    const toml::node* cluster = find(c, t, p, "cluster");
    if (s.centres == DfnSetSpec::Centres::clustered) {
        if (!cluster) c.fail(t, p.key("cluster"), "clustered centres need cluster = { size = ..., radius = ... }");
        const Path cp = p.key("cluster");
        const toml::table& ct = to_table(c, *cluster, cp, "a cluster table { size = ..., radius = ... }");
        static constexpr std::array<std::string_view, 2> cluster_keys{"size", "radius"};
        check_keys(c, ct, cp, cluster_keys);
        s.cluster_size = required_number(c, ct, cp, "size", above(0, ""));
        s.cluster_radius = required_number(c, ct, cp, "radius", above(0, metres));
    } else if (cluster) {
        c.fail(*cluster, p.key("cluster"), "applies to clustered centres only (centres = \"clustered\")");
    }
}

/// The optional terminate table: the earlier sets of the region the set's
/// fractures end at, and how likely.
void read_dfn_termination(const Ctx& c, const toml::table& t, const Path& p, const std::vector<std::string>& earlier,
                          DfnSetSpec& s) {
    if (const toml::node* n = find(c, t, p, "terminate")) {
        const Path tp = p.key("terminate");
        const toml::table& tt = to_table(c, *n, tp, "a table { at = [set names], probability = ... }");
        static constexpr std::array<std::string_view, 2> terminate_keys{"at", "probability"};
        check_keys(c, tt, tp, terminate_keys);
        string_list(c, tt, tp, "at", "earlier fracture set", "", [&](const std::string& m, const toml::node& e, const Path& ep) {
            const auto it = std::ranges::find(earlier, m);
            if (it == earlier.end())
                c.fail(e, ep,
                       "a fracture set ends only at an earlier set of its region; " +
                           (earlier.empty() ? std::string("there is none before ") + reader::quoted(s.name)
                                            : "earlier sets are: " + join(std::vector<std::string_view>(earlier.begin(), earlier.end()))) +
                           ", got " + reader::quoted(m));
            s.terminate_at.push_back(int(it - earlier.begin()));
        });
        s.terminate_probability = required_number(c, tt, tp, "probability", Range{.lo = 0, .hi = 1, .lo_open = true, .unit = ""});
    }
}

/// A generated set: its seed, centres, orientation, lengths, intensity and terminations.
void read_generated_dfn(const Ctx& c, const toml::table& t, const Path& p, const std::vector<std::string>& earlier,
                        DfnSetSpec& s) {
    s.seed = seed(c, t, p).value_or(1);
    read_dfn_centres(c, t, p, s);
    s.orientation = read_orientation(c, need(c, t, p, "orientation", "an orientation table"), p.key("orientation"));
    s.length = read_length(c, need(c, t, p, "length", "a length table"), p.key("length"));
    const auto p21 = number(c, t, p, "p21", bounds_of(dfn_keys, "p21"));
    const auto count = whole_number(c, t, p, "count", bounds_of(dfn_keys, "count"));
    if (p21.has_value() == count.has_value())
        c.fail(t, p, c.in_owner() + "give the set's intensity as 'p21' (trace length per m²) or 'count', one of them");
    s.p21 = p21.value_or(0.0);
    s.count = long(count.value_or(0));
    read_dfn_termination(c, t, p, earlier, s);
}

} // namespace

meshing::DfnSetSpec read_dfn_set(Ctx& c, const toml::node& node, const Path& p, std::vector<std::string>& earlier,
                                 const meshing::OutlineSpec& outline) {
    const toml::table& t = to_table(c, node, p, "a fracture set table ([[region.dfn]])");
    static constexpr auto all = key_names(dfn_keys);
    const bool from_file = t.contains("file");
    check_keys(c, t, p, keys_of_type(dfn_keys, from_file ? "file" : "generated"), all,
               from_file ? "a fracture set read from a file" : "a generated fracture set");
    DfnSetSpec s;
    read_dfn_names(c, t, p, earlier, s);
    if (from_file) read_dfn_file(c, t, p, outline, s);
    else read_generated_dfn(c, t, p, earlier, s);
    earlier.push_back(s.name);
    return s;
}

} // namespace bbm::io::reader
