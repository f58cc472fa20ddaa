// bbm apps: reading the model file (see model_input.hpp and docs/input.md).
//
// The reader walks the toml++ tree with a Path beside every node: its full dotted
// key for messages ("region[1].pattern.size") and its key inside the region
// ("pattern.size") under which its line is kept in ModelSource. Every table is
// checked for unknown keys before its values are read, so a misspelt key is
// reported as such (with a suggestion), not as the required key it failed to be.
// toml++ is compiled once, here (TOML_HEADER_ONLY=0 for the io target).
#define TOML_IMPLEMENTATION
#include "io/reader.hpp"

#include "contact/joint_keys.hpp"
#include "contact/joint_law.hpp"
#include "core/boundary_keys.hpp"
#include "core/event_keys.hpp"
#include "core/history_keys.hpp"
#include "core/material_keys.hpp"
#include "core/solver_keys.hpp"

#include "core/verdict.hpp"
#include "core/viscous.hpp"
#include "meshing/model_keys.hpp"
#include "meshing/region_keys.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <span>
#include <sstream>

namespace bbm::io {

using meshing::JointSetSpec;
using meshing::MeshSpec;
using meshing::ModelGeometrySpec;
using meshing::OutlineSpec;
using meshing::PatternSpec;
using meshing::RegionSpec;
using meshing::SegmentSpec;

namespace {

using namespace reader;

// --- the model's tables ------------------------------------------------------------

/// A path step's arc must end on its circle: the radius is taken from the start.
void check_arc(const Ctx& c, const toml::node& n, const Path& p, Vec2 from,
               const OutlineSpec::Step& s) {
    const double r0 = norm(from - s.center), r1 = norm(s.to - s.center);
    if (r0 == 0.0) c.fail(n, p, "arc center " + fmt(s.center) + " coincides with the arc's start");
    if (std::abs(r1 - r0) > 1e-6 * std::max(r0, r1))
        c.fail(n, p,
               "arc end " + fmt(s.to) + " is " + fmt(r1) + " m from center " + fmt(s.center) +
                   " but its start " + fmt(from) + " is " + fmt(r0) +
                   " m from it; the two must agree within 1e-6 relative");
}

void read_rectangle_outline(const Ctx& c, const toml::table& t, const Path& p, OutlineSpec& o) {
    o.min = required_point(c, t, p, "min");
    o.max = required_point(c, t, p, "max");
    if (!(o.max.x > o.min.x && o.max.y > o.min.y))
        c.fail(*t.get("max"), p.key("max"),
               "must exceed min = " + fmt(o.min) + " in both x and y, got " + fmt(o.max));
}

void read_polygon_outline(const Ctx& c, const toml::table& t, const Path& p, OutlineSpec& o) {
    const Path pp = p.key("points");
    const toml::array& pts =
        to_array(c, need(c, t, p, "points", "an array of points [[x, y], ...]"), pp,
                 "an array of points [[x, y], ...]");
    if (pts.size() < 3)
        c.fail(pts, pp, "a polygon needs at least 3 points, got " + std::to_string(pts.size()));
    for_each_element(c, pts, pp, [&](const toml::node& n, const Path& ep) {
        o.points.push_back(to_position(c, n, ep));
    });
}

/// One step of a path outline, from the point `from`: straight, or an arc (with a center).
OutlineSpec::Step read_path_step(const Ctx& c, const toml::node& n, const Path& ep, Vec2 from) {
    const toml::table& st =
        to_table(c, n, ep, "a step { to = [x, y] } or { to = [x, y], center = [x, y] }");
    static constexpr std::array<std::string_view, 3> step_keys{"to", "center", "clockwise"};
    check_keys(c, st, ep, step_keys);
    OutlineSpec::Step s;
    s.to = required_point(c, st, ep, "to");
    const auto center = point(c, st, ep, "center");
    const auto clockwise = boolean(c, st, ep, "clockwise");
    if (clockwise && !center)
        c.fail(*st.get("clockwise"), ep.key("clockwise"),
               "applies only to an arc step (one with a center); this step is straight");
    if (center) {
        s.arc = true;
        s.center = *center;
        s.clockwise = clockwise.value_or(false);
        check_arc(c, n, ep, from, s);
    }
    return s;
}

void read_path_outline(const Ctx& c, const toml::table& t, const Path& p, OutlineSpec& o) {
    o.start = required_point(c, t, p, "start");
    const Path sp = p.key("steps");
    const std::string expected = "an array of steps [{ to = [x, y] }, ...]";
    const toml::array& steps = to_array(c, need(c, t, p, "steps", expected), sp, expected);
    if (steps.empty()) c.fail(steps, sp, "a path needs at least one step, got none");
    Vec2 from = o.start;
    for_each_element(c, steps, sp, [&](const toml::node& n, const Path& ep) {
        o.steps.push_back(read_path_step(c, n, ep, from));
        from = o.steps.back().to;
    });
}

void read_opening_outline(const Ctx& c, const toml::table& t, const Path& p, OutlineSpec& o) {
    const auto bounds = [](std::string_view key) -> const Bounds& { return bounds_of(meshing::outline_keys, key); };
    o.center = required_point(c, t, p, "center");
    o.width = required_number(c, t, p, "width", bounds("width"));
    o.floor_y = required_number(c, t, p, "floor", bounds("floor"));
    if (!(o.floor_y < o.center.y))
        c.fail(*t.get("floor"), p.key("floor"),
               "must be below the springline center.y = " + fmt(o.center.y) + " m, got " +
                   fmt(o.floor_y));
    o.half = boolean(c, t, p, "half").value_or(false);
}

OutlineSpec read_outline(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "an outline table { type = ..., ... }");
    static constexpr auto all_keys = key_names(meshing::outline_keys);
    check_keys(c, t, p, all_keys);
    OutlineSpec o;
    o.kind = static_cast<OutlineSpec::Kind>(
        read_typed_keys(c, t, p, meshing::outline_keys, "type", "outline type", "outline"));
    const auto bounds = [](std::string_view key) -> const Bounds& { return bounds_of(meshing::outline_keys, key); };

    switch (o.kind) {
    case OutlineSpec::Kind::rectangle: read_rectangle_outline(c, t, p, o); break;
    case OutlineSpec::Kind::polygon: read_polygon_outline(c, t, p, o); break;
    case OutlineSpec::Kind::circle:
        o.center = required_point(c, t, p, "center");
        o.radius = required_number(c, t, p, "radius", bounds("radius"));
        break;
    case OutlineSpec::Kind::path: read_path_outline(c, t, p, o); break;
    case OutlineSpec::Kind::opening: read_opening_outline(c, t, p, o); break;
    }
    if (key_applies(*find_key(meshing::outline_keys, "max_segment"),
                    key_words(meshing::outline_type_words)[static_cast<std::size_t>(o.kind)]))
        o.max_segment = number(c, t, p, "max_segment", bounds("max_segment")).value_or(0.0);
    return o;
}

PatternSpec read_pattern(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a pattern table { type = ..., size = ... }");
    static constexpr auto all_keys = key_names(meshing::pattern_keys);
    check_keys(c, t, p, all_keys);
    PatternSpec s;
    s.kind = static_cast<PatternSpec::Kind>(
        read_typed_keys(c, t, p, meshing::pattern_keys, "type", "pattern type", "pattern"));
    if (s.kind == PatternSpec::Kind::single) return s;
    const auto bounds = [](std::string_view key) -> const Bounds& { return bounds_of(meshing::pattern_keys, key); };

    s.size = required_number(c, t, p, "size", bounds("size"));
    if (const auto e = number(c, t, p, "min_edge", bounds("min_edge"))) {
        if (!(*e < s.size))
            c.fail(*t.get("min_edge"), p.key("min_edge"),
                   "must be smaller than size = " + fmt(s.size) + " m, got " + fmt(*e));
        s.min_edge = *e;
    }
    if (t.contains("size_measure"))
        s.size_measure = static_cast<PatternSpec::SizeMeasure>(choice(
            c, t, p, "size_measure", key_words(find_key(meshing::pattern_keys, "size_measure")->words), "size measure"));
    s.lloyd_iterations = static_cast<int>(whole_number(c, t, p, "lloyd", bounds("lloyd")).value_or(0));
    s.seed = seed(c, t, p).value_or(1);
    s.origin = point(c, t, p, "origin").value_or(Vec2{});
    s.angle = number(c, t, p, "angle", bounds("angle")).value_or(0.0);
    s.aspect = number(c, t, p, "aspect", bounds("aspect")).value_or(2.0);
    if (t.contains("bond"))
        s.running_bond =
            choice(c, t, p, "bond", key_words(find_key(meshing::pattern_keys, "bond")->words), "brick bond") == 0;
    return s;
}

SegmentSpec read_joint(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a joint { from = [x, y], to = [x, y] }");
    static constexpr std::array<std::string_view, 2> keys{"from", "to"};
    check_keys(c, t, p, keys);
    return {required_point(c, t, p, "from"), required_point(c, t, p, "to")};
}

JointSetSpec read_joint_set(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a joint set table ([[region.joint_set]])");
    static constexpr auto keys = key_names(meshing::joint_set_keys);
    check_keys(c, t, p, keys);
    JointSetSpec s;
    for (const meshing::JointSetKey& k : meshing::joint_set_keys)
        if (k.set) read_declared_key(c, t, p, k, s);
    s.origin = point(c, t, p, "origin").value_or(Vec2{});
    s.seed = seed(c, t, p).value_or(1);
    return s;
}

/// The array-valued `key` of t, each element read by f; nothing when absent.
template <class F>
void read_list(const Ctx& c, const toml::table& t, const Path& p, std::string_view key,
               std::string_view expected, F&& f) {
    const toml::node* n = find(c, t, p, key);
    if (!n) return;
    const Path kp = p.key(key);
    for_each_element(c, to_array(c, *n, kp, expected), kp, f);
}

/// A region's mesh: its blocks become deformable (SPEC §6). The `toward` names are
/// checked with the other region names, once all regions are read.
MeshSpec read_mesh(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a mesh table { size = ..., ... }");
    static constexpr auto keys = key_names(meshing::mesh_keys);
    check_keys(c, t, p, keys);
    MeshSpec m;
    m.enabled = true;
    for (const meshing::MeshKey& k : meshing::mesh_keys)
        if (k.set) read_declared_key(c, t, p, k, m);
    if (const auto far = number(c, t, p, "size_far", bounds_of(meshing::mesh_keys, "size_far"))) {
        if (!(*far >= m.size))
            c.fail(*t.get("size_far"), p.key("size_far"),
                   "must be >= size = " + fmt(m.size) + " m, got " + fmt(*far));
        m.size_far = *far;
    }
    read_list(c, t, p, "toward", "an array of region names",
              [&](const toml::node& n, const Path& ep) { m.toward.push_back(to_str(c, n, ep)); });
    if (m.grading > 0 && m.toward.empty())
        c.fail(*t.get("grading"), p.key("grading"),
               "grades the mesh by the distance from the regions listed in 'toward', but none "
               "are listed");
    return m;
}

/// A region; the name in its `material` key (checked once materials are read) goes
/// to `material`.
RegionSpec read_region(Ctx& c, const toml::node& node, const Path& p,
                       std::optional<std::string>& material) {
    const toml::table& t = to_table(c, node, p, "a [[region]] table");
    static constexpr auto keys = key_names(meshing::region_keys);
    check_keys(c, t, p, keys);
    RegionSpec r;
    const Path np = p.key("name");
    const toml::node& name = need(c, t, p, "name", "a non-empty string");
    r.name = to_str(c, name, np);
    if (r.name.empty()) c.fail(name, np, "must be a non-empty string, got \"\"");
    c.owner = "region " + quoted(r.name);
    if (const toml::node* m = find(c, t, p, "material"))
        material = to_str(c, *m, p.key("material"));

    r.outline = read_outline(c, need(c, t, p, "outline", "an outline table"), p.key("outline"));
    read_list(
        c, t, p, "holes", "an array of outline tables",
        [&](const toml::node& n, const Path& ep) { r.holes.push_back(read_outline(c, n, ep)); });
    read_list(c, t, p, "minus", "an array of region names",
              [&](const toml::node& n, const Path& ep) { r.minus.push_back(to_str(c, n, ep)); });
    r.pattern = read_pattern(c, need(c, t, p, "pattern", "a pattern table"), p.key("pattern"));
    read_list(
        c, t, p, "joints", "an array of joints [{ from = [x, y], to = [x, y] }, ...]",
        [&](const toml::node& n, const Path& ep) { r.joints.push_back(read_joint(c, n, ep)); });
    read_list(c, t, p, "joint_set", "an array of joint set tables ([[region.joint_set]])",
              [&](const toml::node& n, const Path& ep) {
                  r.joint_sets.push_back(read_joint_set(c, n, ep));
              });
    std::vector<std::string> sets;
    read_list(c, t, p, "dfn", "an array of fracture set tables ([[region.dfn]])",
              [&](const toml::node& n, const Path& ep) { r.dfn.push_back(read_dfn_set(c, n, ep, sets, r.outline)); });
    if (const toml::node* m = find(c, t, p, "mesh")) r.mesh = read_mesh(c, *m, p.key("mesh"));
    return r;
}

/// Names are checked once all regions are read: `minus` may name a later region.
void check_names(const Ctx& c, const ModelFile& mf) {
    const auto& rs = mf.geometry.regions;
    std::vector<std::string_view> names;
    for (const RegionSpec& r : rs)
        names.push_back(r.name);
    for (std::size_t i = 0; i < rs.size(); ++i) {
        const Path p{"region[" + std::to_string(i) + "]", ""};
        const auto& lines = mf.source.key_line[i];
        for (std::size_t j = 0; j < i; ++j)
            if (rs[j].name == rs[i].name)
                c.fail(lines.at("name"), p.key("name"),
                       "region name " + quoted(rs[i].name) + " is already used by region[" +
                           std::to_string(j) + "] (line " +
                           std::to_string(mf.source.region_line[j]) + ")");
        // A list of other regions' names: `key` in the region, `verb` for messages.
        auto check_list = [&](const std::vector<std::string>& list, const std::string& key,
                              const std::string& verb, const std::string& itself) {
            for (std::size_t k = 0; k < list.size(); ++k) {
                const std::string& m_name = list[k];
                const Path mp = p.key(key).at(k);
                const int at = lines.at(mp.rel);
                if (m_name == rs[i].name)
                    c.fail(at, mp, "region " + quoted(m_name) + " cannot " + itself);
                if (std::ranges::find(names, m_name) == names.end())
                    c.fail(at, mp,
                           "region " + quoted(rs[i].name) + " " + verb + " " + quoted(m_name) +
                               ", but there is no region of that name" +
                               did_you_mean(m_name, names) + "; regions are: " + join(names));
                for (std::size_t q = 0; q < k; ++q)
                    if (list[q] == m_name)
                        c.fail(at, mp,
                               quoted(m_name) + " is already listed as " + key + "[" +
                                   std::to_string(q) + "]");
            }
        };
        check_list(rs[i].minus, "minus", "subtracts", "subtract itself");
        check_list(rs[i].mesh.toward, "mesh.toward", "refines its mesh toward",
                   "refine its mesh toward itself");
    }
}

// --- the analysis tables -----------------------------------------------------------

/// A length of [solver] that is a fraction of a block (the corners' rounding, the
/// detection's reach): one of `most` of the smallest block size or more is no
/// longer a corner's or a gap's (a length in another unit?), refused.
void check_within_block(const Ctx& c, const toml::table& t, const Path& p, std::string_view key, double v,
                        double most, std::string_view what) {
    const double d = c.scale ? c.scale->block_size : 0.0;
    if (d > 0.0 && v >= most * d)
        c.fail(*t.get(key), p.key(key),
               shortest_text(v) + " m is not below " + shortest_text(most) + " of the model's smallest block size (" +
                   shortest_text(d) + " m), so it is no longer " + std::string(what) +
                   ": a length in another unit? Give it in metres");
}

SolverSpec read_solver(const Ctx& c, const toml::node& node, const Path& p,
                       const Names& properties) {
    const toml::table& t = to_table(c, node, p, "a [solver] table");
    static constexpr auto keys = key_names(solver_keys);
    check_keys(c, t, p, keys);
    SolverSpec s;
    for (const SolverKey& k : solver_keys)
        if (k.set) read_declared_key(c, t, p, k, s);
    check_within_block(c, t, p, "corner_radius", s.corner_radius, 0.5, "a corner's rounding");
    check_within_block(c, t, p, "detection_tolerance", s.detection_tolerance, 1.0, "the reach of a contact's gap");
    if (t.contains("mode"))
        s.mode = static_cast<SolverSpec::Mode>(
            choice(c, t, p, "mode", key_words(find_key(solver_keys, "mode")->words), "solver mode"));
    // Local damping is a quasi-static device: a dynamic run has none unless asked.
    if (s.mode == SolverSpec::Mode::dynamic && !t.contains("damping")) s.damping = 0.0;
    // Rayleigh damping: its ratio and centre frequency together, in real time.
    if (t.contains("rayleigh_ratio") != t.contains("rayleigh_frequency")) {
        const char* given = t.contains("rayleigh_ratio") ? "rayleigh_ratio" : "rayleigh_frequency";
        c.fail(*find(c, t, p, given), p.key(given),
               "Rayleigh damping needs both rayleigh_ratio (the critical ratio) and rayleigh_frequency (Hz, where it "
               "holds)");
    }
    if (t.contains("rayleigh_ratio") && s.mode != SolverSpec::Mode::dynamic)
        c.fail(*find(c, t, p, "rayleigh_ratio"), p.key("rayleigh_ratio"),
               "Rayleigh damping is for the dynamic mode (real masses, real time): a quasi-static run's time and "
               "masses are fictitious; give [solver] mode = \"dynamic\" or use `damping`");
    s.gravity = vector(c, t, p, "gravity").value_or(s.gravity);
    if (t.contains("new_contact_length"))
        s.new_contact_length = static_cast<SolverSpec::NewContactLength>(choice(
            c, t, p, "new_contact_length", key_words(find_key(solver_keys, "new_contact_length")->words),
            "new contact length"));
    if (t.contains("new_contact_overlap"))
        s.new_contact_overlap = static_cast<SolverSpec::NewContactOverlap>(choice(
            c, t, p, "new_contact_overlap", key_words(find_key(solver_keys, "new_contact_overlap")->words),
            "new contact overlap"));
    if (const toml::node* n = find(c, t, p, "new_contact_property")) {
        const Path np = p.key("new_contact_property");
        s.new_contact_property = to_str(c, *n, np);
        if (!s.new_contact_property.empty())
            check_ref(c, line(*n), np, s.new_contact_property, properties);
    }
    return s;
}

MaterialSpec read_material(Ctx& c, const toml::table& t, const Path& p, Names& names) {
    static constexpr auto keys = key_names(material_keys);
    check_keys(c, t, p, keys);
    MaterialSpec m;
    m.name = read_name(c, t, p, names);
    for (const MaterialKey& k : material_keys)
        if (k.kind == KeyKind::number) read_declared_key(c, t, p, k, m);
    // Without E there is no elasticity for them to describe.
    for (std::string_view key : {"poisson", "deformable_fraction"})
        if (m.young == 0 && t.contains(key))
            c.fail(*t.get(key), p.key(key),
                   c.in_owner() + "applies to deformable blocks and needs 'young', which is not "
                                  "given");
    return m;
}

/// A softening curve: points (alpha, beta) after the peak (1, 1), SPEC §4.
std::vector<std::pair<double, double>> read_curve(const Ctx& c, const toml::table& t, const Path& p,
                                                  std::string_view key) {
    std::vector<std::pair<double, double>> pts;
    const toml::node* n = find(c, t, p, key);
    if (!n) return pts;
    const Path kp = p.key(key);
    const toml::array& a = to_array(c, *n, kp, "an array of points [[alpha, beta], ...]");
    for_each_element(c, a, kp, [&](const toml::node& e, const Path& ep) {
        const auto* pa = e.as_array();
        if (!pa) c.fail(e, ep, "expected a point [alpha, beta], got " + describe(e));
        if (pa->size() != 2)
            c.fail(e, ep,
                   "expected a point [alpha, beta] of 2 numbers, got an array of " +
                       std::to_string(pa->size()));
        const double alpha = to_number(c, (*pa)[0], ep.at(0));
        const double beta =
            checked_number(c, (*pa)[1], ep.at(1), Range{.lo = 0, .hi = 1, .unit = ""});
        if (pts.empty()) {
            if (!(alpha > 1))
                c.fail((*pa)[0], ep.at(0),
                       "the first alpha must be > 1 (alpha = 1 is the peak), got " + fmt(alpha));
        } else {
            const auto [a0, b0] = pts.back();
            const std::string prev = std::string(key) + "[" + std::to_string(pts.size() - 1) + "]";
            if (b0 == 0)
                c.fail(e, ep,
                       "the curve already ends at " + prev +
                           " (beta = 0: the bond is broken); "
                           "remove the points after it");
            if (!(alpha > a0))
                c.fail((*pa)[0], ep.at(0),
                       "the curve snaps back: alpha must increase from point to point, got " +
                           fmt(alpha) + " after " + fmt(a0) + " at " + prev);
            if (!(alpha - beta > a0 - b0))
                c.fail(e, ep,
                       "the curve snaps back: alpha - beta (the plastic displacement) must "
                       "increase from point to point, got " +
                           fmt(alpha) + " - " + fmt(beta) + " = " + fmt6(alpha - beta) + " after " +
                           fmt(a0) + " - " + fmt(b0) + " = " + fmt6(a0 - b0) + " at " + prev);
        }
        pts.emplace_back(alpha, beta);
    });
    if (!pts.empty() && pts.back().second != 0) {
        const toml::node& beta = (*a.back().as_array())[1];
        c.fail(beta, kp.at(pts.size() - 1).at(1),
               "the last point must have beta = 0 (the curve must end at zero strength), got " +
                   fmt(pts.back().second));
    }
    return pts;
}

/// strength_classes and strength_seed go with a Weibull modulus.
void check_heterogeneity_keys(const Ctx& c, const toml::table& t, const Path& p, const JointPropertySpec& j) {
    if (j.weibull_modulus > 0.0) return;
    for (const char* key : {"strength_classes", "strength_seed"})
        if (t.contains(key)) c.fail(*t.get(key), p.key(key), "goes with weibull_modulus > 0");
}

JointPropertySpec read_joint_property(Ctx& c, const toml::table& t, const Path& p, Names& names) {
    const Keys all = contact::joint_key_names();
    check_keys(c, t, p, all);
    JointPropertySpec j;
    j.name = read_name(c, t, p, names);
    j.law = std::string(contact::law_names[choice(c, t, p, "law", contact::law_names, "joint law")]);
    const std::vector<std::string_view> keys = contact::law_key_names(j.law);
    check_keys(c, t, p, keys, all, article(j.law) + " joint property");
    for (const contact::JointKey* k : contact::law_keys(j.law)) {
        if (k->set) read_declared_key(c, t, p, *k, j);
        else if (k->set_curve) k->set_curve(j, read_curve(c, t, p, k->key));
    }
    // The rules between keys, by law (the flags keep the same ones).
    if (const auto problem = contact::check_joint_property(j)) {
        const toml::node* n = t.get(problem->key);
        if (!n)
            c.fail(t, p.key(problem->key),
                   c.in_owner() + "missing required key " + quoted(problem->key) + ": " + problem->message);
        c.fail(*n, p.key(problem->key), problem->message);
    }
    check_heterogeneity_keys(c, t, p, j);
    return j;
}

JointAssignmentSpec read_joint_assignment(Ctx& c, const toml::table& t, const Path& p,
                                          const Names& properties, const Names& regions) {
    static constexpr auto keys = key_names(assignment_keys);
    check_keys(c, t, p, keys);
    const auto joint_tags = key_words(joint_tag_words);
    JointAssignmentSpec a;
    const Path pp = p.key("property");
    const toml::node& n = need(c, t, p, "property", "the name of a [[joint_property]]");
    a.property = to_str(c, n, pp);
    check_ref(c, line(n), pp, a.property, properties);
    for (const std::string& tag :
         string_list(c, t, p, "tags", "joint tag", "for every tag",
                     [&](const std::string&, const toml::node&e, const Path&ep) {
                         to_choice(c, e, ep, joint_tags, "joint tag");
                     }))
        a.tags.push_back(static_cast<meshing::JointTag>(std::ranges::find(joint_tags, tag) -
                                                        joint_tags.begin()));
    a.regions = name_list(c, t, p, "regions", regions, "for joints of any region");
    return a;
}

/// An incident wave's record: rows time, particle velocity (CSV; a header line,
/// blank lines and # comments skipped), times increasing, at least two rows.
std::vector<std::pair<double, double>> read_pulse_record(const Ctx& c, const toml::node& n, const Path& p,
                                                         const std::string& path) {
    std::ifstream in(path);
    if (!in) c.fail(n, p, "cannot open the pulse record " + path);
    std::vector<std::pair<double, double>> rows;
    std::string text;
    int line_no = 0;
    bool header_allowed = true;
    while (std::getline(in, text)) {
        ++line_no;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        const auto first = text.find_first_not_of(" \t");
        if (first == std::string::npos || text[first] == '#') continue;
        const auto comma = text.find(',');
        double v[2] = {0.0, 0.0};
        bool numeric = comma != std::string::npos && text.find(',', comma + 1) == std::string::npos;
        for (int k = 0; numeric && k < 2; ++k) {
            const std::string cell = k == 0 ? text.substr(0, comma) : text.substr(comma + 1);
            const auto a = cell.find_first_not_of(" \t"), b = cell.find_last_not_of(" \t");
            const std::string trimmed = a == std::string::npos ? "" : cell.substr(a, b - a + 1);
            const auto [end, ec] = std::from_chars(trimmed.data(), trimmed.data() + trimmed.size(), v[k]);
            numeric = ec == std::errc() && end == trimmed.data() + trimmed.size() && !trimmed.empty() && std::isfinite(v[k]);
        }
        if (!numeric && header_allowed) {
            header_allowed = false;
            continue;
        }
        header_allowed = false;
        if (!numeric)
            throw InputError(path, line_no, p.full, "expected time (s), particle velocity (m/s), got \"" + text + "\"");
        if (v[0] < 0.0)
            throw InputError(path, line_no, p.full, "a time before the pulse's start (" + shortest_text(v[0]) +
                                                        " s): times are from `start`");
        if (!rows.empty() && !(v[0] > rows.back().first))
            throw InputError(path, line_no, p.full,
                             "time " + shortest_text(v[0]) + " s does not come after the row before's " +
                                 shortest_text(rows.back().first) + " s: a record's times go forward");
        rows.emplace_back(v[0], v[1]);
    }
    if (rows.size() < 2) c.fail(n, p, "the pulse record " + path + " has fewer than two rows of time, velocity");
    return rows;
}

/// A viscous boundary's incident wave: its pulse, kind and the numbers of its
/// formula (a frequency with every named pulse; a record with a file).
void read_incident_wave(const Ctx& c, const toml::table& t, const Path& p, BoundarySpec& b) {
    using Wave = IncidentWaveSpec;
    for (const BoundaryKey& k : boundary_keys)
        if (k.set && key_applies(k, "viscous")) read_declared_key(c, t, p, k, b);
    if (t.contains("pulse"))
        b.incident.pulse = static_cast<Wave::Pulse>(
            choice(c, t, p, "pulse", key_words(find_key(boundary_keys, "pulse")->words), "pulse"));
    if (t.contains("wave"))
        b.incident.wave =
            static_cast<Wave::Wave>(choice(c, t, p, "wave", key_words(find_key(boundary_keys, "wave")->words), "wave"));
    const bool pulse = b.incident.pulse != Wave::Pulse::none, recorded = b.incident.pulse == Wave::Pulse::file;
    if (recorded) {
        if (!t.contains("file")) c.fail(t, p, c.in_owner() + "pulse = \"file\" needs its record (file = \"...csv\")");
        for (const char* key : {"frequency", "cycles"})
            if (const toml::node* n = t.get(key))
                c.fail(*n, p.key(key), c.in_owner() + "'" + key + "' is a named pulse's: a record has its own times");
        const toml::node& f = *find(c, t, p, "file");
        b.incident.record_file = to_str(c, f, p.key("file"));
        // Relative to the model file's folder (as a DFN's traces are).
        const std::size_t slash = c.file.find_last_of('/');
        const std::string& name = b.incident.record_file;
        const std::string path = name.starts_with('/') || slash == std::string::npos ? name : c.file.substr(0, slash + 1) + name;
        b.incident.record = read_pulse_record(c, f, p.key("file"), path);
        if (!t.contains("velocity")) b.incident.velocity = 1.0;
        return;
    }
    if (const toml::node* n = t.get("file"))
        c.fail(*n, p.key("file"), c.in_owner() + "'file' is a recorded pulse's: give pulse = \"file\"");
    if (pulse && !t.contains("frequency"))
        c.fail(t, p, c.in_owner() + "a pulse needs its frequency (Hz)");
    if (pulse && !t.contains("velocity"))
        c.fail(t, p, c.in_owner() + "a pulse needs its peak particle velocity (velocity, m/s)");
    if (!pulse)
        for (const char* key : {"velocity", "frequency", "cycles", "start", "wave"})
            if (const toml::node* n = t.get(key))
                c.fail(*n, p.key(key), c.in_owner() + "'" + key + "' describes the incident wave: give its pulse too");
}

BoundarySpec read_boundary(Ctx& c, const toml::table& t, const Path& p, Names& names,
                           const Names& regions) {
    static constexpr auto all_keys = key_names(boundary_keys);
    check_keys(c, t, p, all_keys);
    BoundarySpec b;
    using Kind = BoundarySpec::Kind;
    b.name = read_name(c, t, p, names);
    b.kind = static_cast<Kind>(read_typed_keys(c, t, p, boundary_keys, "type", "boundary type", "boundary"));
    b.select.regions = name_list(c, t, p, "regions", regions, "to select by box only (or all)");
    if (const toml::node* n = find(c, t, p, "box")) b.select.box = read_box(c, *n, p.key("box"));
    if (b.kind == Kind::stress) {
        b.stress = read_stress(c, t, p);
        return b;
    }
    if (b.kind == Kind::viscous) {
        read_incident_wave(c, t, p, b);
        return b;
    }
    b.select.touching = boolean(c, t, p, "touching").value_or(false);
    b.vx = number(c, t, p, "vx", find_key(boundary_keys, "vx")->bounds);
    b.vy = number(c, t, p, "vy", find_key(boundary_keys, "vy")->bounds);
    b.omega = number(c, t, p, "omega", find_key(boundary_keys, "omega")->bounds);
    if (!b.vx && !b.vy && !b.omega)
        c.fail(t, p,
               c.in_owner() + "a velocity boundary needs at least one of vx, vy, omega "
                              "(the components it prescribes; 0 fixes one)");
    return b;
}

/// A deformable region (one with a mesh) needs the elasticity of its material. A region
/// takes the material it names; if no region names one, every region takes the first
/// [[material]] (as core/build_world.cpp resolves them); otherwise it has none (rigid).
void check_deformable_materials(const Ctx& c, const ModelFile& mf) {
    const AnalysisSpec& an = mf.analysis;
    const auto& rs = mf.geometry.regions;
    for (std::size_t i = 0; i < rs.size(); ++i) {
        const MaterialSpec* m = nullptr;
        for (const auto& [region, material] : an.region_material)
            if (region == rs[i].name)
                m = &*std::ranges::find(an.materials, material, &MaterialSpec::name);
        if (an.region_material.empty() && !an.materials.empty()) m = &an.materials.front();
        if (!rs[i].mesh.enabled) {
            // Rigid blocks take none of the deformation: a share given to them would
            // stiffen the region's joints by 1 / (1 - f) and nothing else.
            if (m && m->deformable_fraction > 0.0) {
                const auto& lines = mf.source.key_line[i];
                const bool named = lines.contains("material");
                c.fail(named ? lines.at("material") : mf.source.region_line[i],
                       {"region[" + std::to_string(i) + "]" + (named ? ".material" : ""), ""},
                       "region " + quoted(rs[i].name) + " has rigid blocks (no mesh) but its material " +
                           quoted(m->name) + " gives deformable blocks a share of the deformation "
                           "(deformable_fraction " + fmt(m->deformable_fraction) + "), which would stiffen "
                           "its joints by 1 / (1 - f): give the region a mesh, or it a material without "
                           "deformable_fraction");
            }
            continue;
        }
        const Path p{"region[" + std::to_string(i) + "].mesh", ""};
        const int at = mf.source.key_line[i].at("mesh");
        const std::string head =
            "region " + quoted(rs[i].name) + " is deformable (has a mesh) but ";
        if (!m)
            c.fail(at, p,
                   head + "has no material; name a [[material]] with a young modulus in its "
                          "'material' key");
        if (m->young == 0)
            c.fail(at, p, head + "its material " + quoted(m->name) + " has no young modulus");
    }
}

/// The [[stage]] tables, in order; a pressurise stage must follow an excavate
/// stage with a pressure (the opening whose pressure it changes).
void read_stages(Ctx& c, const toml::table& doc, std::vector<StageSpec>& out, const Names& regions,
                 const Names& supports) {
    Names stages{"stage", "stages", "stage", {}, {}};
    double opening_pressure = -1.0; // the latest excavate stage's pressure (-1: none yet)
    bool initialized = false;
    read_tables(c, doc, "stage", [&](const toml::table& t, const Path& p, std::size_t i) {
        out.push_back(read_stage(c, t, p, i, stages, regions, supports));
        const StageSpec& st = out.back();
        if (st.kind == StageSpec::Kind::initialize) initialized = true;
        if (!st.support_path.empty() && !initialized)
            c.fail(*find(c, t, p, "support_path"), p.key("support_path"),
                   "needs an initialize stage before it: the in-situ stress whose mean and deviator it relaxes");
        if (st.kind == StageSpec::Kind::excavate) opening_pressure = st.pressure;
        if (st.kind == StageSpec::Kind::pressurise && !(opening_pressure > 0.0))
            c.fail(*find(c, t, p, "type"), p.key("type"),
                   opening_pressure < 0.0
                       ? "a pressurise stage needs an excavate stage before it: it changes the pressure in the opening"
                       : "a pressurise stage changes the pressure of an opening excavated with one: give the excavate "
                         "stage before it a pressure > 0 (it sets where the water pushes)");
    });
}

/// The optional [report] table: the opening to measure and the window to draw.
void read_report(Ctx& c, const toml::table& doc, ReportSpec& r) {
    if (const toml::node* n = find(c, doc, Path{}, "report")) {
        const Path p = Path{}.key("report");
        const toml::table& t = to_table(c, *n, p, "a [report] table");
        static constexpr auto keys = key_names(report_keys);
        check_keys(c, t, p, keys);
        if (find(c, t, p, "center") || find(c, t, p, "springline") || find(c, t, p, "crown")) {
            r.opening = true;
            r.center = required_point(c, t, p, "center");
            r.springline = required_point(c, t, p, "springline");
            r.crown = required_point(c, t, p, "crown");
            if (!(norm(r.springline - r.center) > 0) || !(norm(r.crown - r.center) > 0))
                c.fail(t, p, "springline and crown must differ from center (they are points on the opening's wall)");
        }
        if (const toml::node* w = find(c, t, p, "window")) r.window = read_box(c, *w, p.key("window"));
        r.ejection_speed =
            number(c, t, p, "ejection_speed", bounds_of(report_keys, "ejection_speed")).value_or(r.ejection_speed);
    }
}

/// The optional [events] table: the seismic events' catalogue on, and how its
/// bonds are joined into events.
void read_events(Ctx& c, const toml::table& doc, EventSpec& e) {
    const toml::node* n = find(c, doc, Path{}, "events");
    if (!n) return;
    const Path p = Path{}.key("events");
    const toml::table& t = to_table(c, *n, p, "an [events] table");
    static constexpr auto keys = key_names(event_keys);
    check_keys(c, t, p, keys);
    for (const EventKey& k : event_keys)
        if (k.set) read_declared_key(c, t, p, k, e);
    e.on = true;
    const double size = c.scale ? c.scale->size() : 0.0;
    if (size > 0.0 && e.join_distance > 2.0 * size)
        c.fail(*find(c, t, p, "join_distance"), p.key("join_distance"),
               "join_distance " + shortest_text(e.join_distance) + " m is more than twice the model's size (" +
                   shortest_text(size) + " m across): bonds are joined into an event within it (a length in mm?)");
    if (size > 0.0 && e.thickness > 100.0 * size)
        c.fail(*find(c, t, p, "thickness"), p.key("thickness"),
               "thickness " + shortest_text(e.thickness) + " m is more than 100 times the model's size (" +
                   shortest_text(size) + " m)");
}

/// How large the model is (base/table_reader.hpp): its regions' outlines and the
/// smallest size of their block patterns, for the checks of lengths and positions.
ModelScale model_scale(const meshing::ModelGeometrySpec& g) {
    ModelScale scale;
    for (const RegionSpec& r : g.regions) {
        // A coarse polygon is enough for the extent (every circle an octagon).
        for (Vec2 p : meshing::outline_polygon(r.outline, 1e30)) scale.extent.add(p);
        if (r.pattern.kind != meshing::PatternSpec::Kind::single && r.pattern.size > 0.0)
            scale.block_size = scale.block_size > 0.0 ? std::min(scale.block_size, r.pattern.size) : r.pattern.size;
    }
    return scale;
}

/// The [[material]] tables, and the regions' `material` keys that name them.
void read_materials(Ctx& c, const toml::table& doc, ModelFile& mf, const Names& regions,
                    const std::vector<std::optional<std::string>>& region_material) {
    AnalysisSpec& an = mf.analysis;
    Names materials{"material", "materials", "material", {}, {}};
    read_tables(c, doc, "material", [&](const toml::table& t, const Path& p, std::size_t) {
        an.materials.push_back(read_material(c, t, p, materials));
    });
    for (std::size_t i = 0; i < region_material.size(); ++i) {
        if (!region_material[i]) continue;
        const Path p{"region[" + std::to_string(i) + "].material", ""};
        check_ref(c, mf.source.key_line[i].at("material"), p, *region_material[i], materials);
        an.region_material.emplace_back(regions.names[i], *region_material[i]);
    }
    check_deformable_materials(c, mf);
}

/// The [[joint_property]] and [[joint_assignment]] tables, and the regions'
/// fracture sets' `property` keys that name them; the properties' names.
Names read_joint_properties(Ctx& c, const toml::table& doc, ModelFile& mf, const Names& regions) {
    AnalysisSpec& an = mf.analysis;
    Names properties{"joint property", "joint properties", "joint_property", {}, {}};
    read_tables(c, doc, "joint_property", [&](const toml::table& t, const Path& p, std::size_t) {
        an.joint_properties.push_back(read_joint_property(c, t, p, properties));
    });
    read_tables(c, doc, "joint_assignment", [&](const toml::table& t, const Path& p, std::size_t) {
        an.joint_assignments.push_back(read_joint_assignment(c, t, p, properties, regions));
    });
    for (std::size_t i = 0; i < mf.geometry.regions.size(); ++i)
        for (std::size_t k = 0; k < mf.geometry.regions[i].dfn.size(); ++k)
            if (const auto& name = mf.geometry.regions[i].dfn[k].property; !name.empty()) {
                const std::string rel = "dfn[" + std::to_string(k) + "].property";
                check_ref(c, mf.source.key_line[i].at(rel), Path{"region[" + std::to_string(i) + "]." + rel, ""}, name,
                          properties);
            }
    return properties;
}

/// What needs water in the joints: an inflow history needs a [flow] table, and
/// transient flow a dynamic solver.
void check_flow_needs(const Ctx& c, const ModelFile& mf) {
    const AnalysisSpec& an = mf.analysis;
    for (std::size_t i = 0; i < an.histories.size(); ++i)
        if (an.histories[i].quantity == HistorySpec::Quantity::inflow && !an.flow.on) {
            const Path hp = Path{}.key("history").at(i).key("quantity");
            c.fail(mf.source.line_of(hp.full), hp, "an inflow history needs a [flow] table (water in the joints)");
        }
    if (an.flow.on && an.flow.mode == FlowSpec::Mode::transient && an.solver.mode != SolverSpec::Mode::dynamic) {
        const Path mp = Path{}.key("flow").key("mode");
        c.fail(mf.source.line_of(mp.full), mp,
               "transient flow needs [solver] mode = \"dynamic\": a quasi-static run's time is not real time "
               "(use mode = \"steady\": drained)");
    }
}

/// What a dynamic run's time needs: a cycle stage given in model time the dynamic
/// mode; a pulse no longer than the run, where the run's model time is known when
/// it is read (every stage that steps given in time, or a fixed time step).
void check_dynamic_needs(const Ctx& c, const ModelFile& mf) {
    const AnalysisSpec& an = mf.analysis;
    const bool dynamic = an.solver.mode == SolverSpec::Mode::dynamic;
    double run_time = 0.0;
    bool known = true;
    for (std::size_t i = 0; i < an.stages.size(); ++i) {
        const StageSpec& st = an.stages[i];
        const Path tp = Path{}.key("stage").at(i).key("time");
        if (st.time > 0.0 && !dynamic)
            c.fail(mf.source.line_of(tp.full), tp,
                   "a stage in model time needs [solver] mode = \"dynamic\": a quasi-static run's time is not real "
                   "time (give steps)");
        using K = StageSpec::Kind;
        if (st.time > 0.0) run_time += st.time;
        else if (an.solver.timestep > 0.0 && (st.kind == K::cycle || st.kind == K::excavate || st.kind == K::pressurise))
            run_time += double(st.steps) * an.solver.timestep;
        else if (st.kind == K::cycle || st.kind == K::excavate || st.kind == K::pressurise || st.kind == K::solve)
            known = false;
    }
    if (!dynamic || !known || an.stages.empty()) return;
    for (std::size_t i = 0; i < an.boundaries.size(); ++i) {
        const IncidentWaveSpec& wave = an.boundaries[i].incident;
        if (an.boundaries[i].kind != BoundarySpec::Kind::viscous || wave.pulse == IncidentWaveSpec::Pulse::none) continue;
        if (const double end = incident_end(wave); end > run_time) {
            const Path pp = Path{}.key("boundary").at(i).key("pulse");
            c.fail(mf.source.line_of(pp.full), pp,
                   "the pulse of boundary " + quoted(an.boundaries[i].name) + " lasts until " + fmt(end) +
                       " s, after the run ends (" + fmt(run_time) + " s of model time in its stages): run longer, or "
                       "start it earlier");
        }
    }
}

/// The analysis tables, after the regions (whose names they refer to) are read.
/// `region_material` is the `material` key of each region, if given.
void read_analysis(Ctx& c, const toml::table& doc, ModelFile& mf,
                   const std::vector<std::optional<std::string>>& region_material) {
    AnalysisSpec& an = mf.analysis;
    Names regions{"region", "regions", "region", {}, mf.source.region_line};
    for (const RegionSpec& r : mf.geometry.regions)
        regions.names.push_back(r.name);
    // Every point and box from here on is checked against the regions' extent.
    const ModelScale scale = model_scale(mf.geometry);
    c.scale = &scale;

    read_materials(c, doc, mf, regions, region_material);
    Names properties = read_joint_properties(c, doc, mf, regions);
    Names boundaries{"boundary", "boundaries", "boundary", {}, {}};
    read_tables(c, doc, "boundary", [&](const toml::table& t, const Path& p, std::size_t) {
        an.boundaries.push_back(read_boundary(c, t, p, boundaries, regions));
    });
    if (const toml::node* n = find(c, doc, Path{}, "solver"))
        an.solver = read_solver(c, *n, Path{}.key("solver"), properties);
    Names histories{"history", "histories", "history", {}, {}};
    read_tables(c, doc, "history", [&](const toml::table& t, const Path& p, std::size_t) {
        an.histories.push_back(read_history(c, t, p, histories, boundaries));
    });
    // Support sets of every registered type, named apart from each other;
    // install stages name any of them.
    std::string support_tables_text;
    for (const std::string_view t : support_tables())
        support_tables_text += (support_tables_text.empty() ? "" : "]], [[") + std::string(t);
    Names supports{"support", "supports", support_tables_text, {}, {}};
    read_supports(c, doc, an.supports, supports, scale);
    read_flow(c, doc, an.flow, regions);
    check_flow_needs(c, mf);
    read_stages(c, doc, an.stages, regions, supports);
    check_dynamic_needs(c, mf);
    read_report(c, doc, an.report);
    read_events(c, doc, an.events);
    c.scale = nullptr;
}

} // namespace

int ModelSource::line_of(int region, const std::string& key) const {
    if (region < 0 || region >= static_cast<int>(key_line.size())) return 0;
    const auto& lines = key_line[static_cast<std::size_t>(region)];
    std::string k = key;
    while (!k.empty()) {
        if (const auto it = lines.find(k); it != lines.end()) return it->second;
        const auto cut = k.find_last_of(".[");
        k.resize(cut == std::string::npos ? 0 : cut);
    }
    return region_line[static_cast<std::size_t>(region)];
}

int ModelSource::line_of(const std::string& key) const {
    std::string k = key;
    while (!k.empty()) {
        if (const auto it = analysis_line.find(k); it != analysis_line.end()) return it->second;
        const auto cut = k.find_last_of(".[");
        k.resize(cut == std::string::npos ? 0 : cut);
    }
    return 0;
}

namespace {

/// TOML allows characters beyond ASCII only in strings and comments. Anywhere else
/// toml++ 3.3 may test them as whitespace, and its test reaches
/// __builtin_unreachable for most code points (undefined behaviour, found by
/// fuzzing "1×" in a value): such a file is refused here first, at its line.
/// Returns the offending line (0 = none) and code point.
std::pair<int, char32_t> non_ascii_outside_strings(std::string_view text) {
    int line = 1;
    std::size_t i = 0;
    auto starts = [&](std::string_view s) { return text.substr(i, s.size()) == s; };
    auto skip_to = [&](std::string_view end, bool escapes) { // past the end of a string
        while (i < text.size() && !starts(end)) {
            if (text[i] == '\n') ++line;
            i += escapes && text[i] == '\\' ? 2 : 1;
        }
        i += end.size();
    };
    while (i < text.size()) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            ++line, ++i;
        } else if (c == '#') {
            while (i < text.size() && text[i] != '\n') ++i;
        } else if (starts("\"\"\"")) {
            i += 3, skip_to("\"\"\"", true);
        } else if (starts("\'\'\'")) {
            i += 3, skip_to("\'\'\'", false);
        } else if (c == '"' || c == '\'') {
            ++i;
            while (i < text.size() && text[i] != char(c) && text[i] != '\n') i += c == '"' && text[i] == '\\' ? 2 : 1;
            if (i < text.size() && text[i] == char(c)) ++i;
        } else if (c >= 0x80) {
            // The code point, for the message (UTF-8; a broken sequence shows its first byte).
            char32_t cp = c;
            const int extra = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC0 ? 1 : 0;
            if (extra > 0 && i + std::size_t(extra) < text.size() + 1) {
                cp = c & (0x3F >> extra);
                for (int k = 1; k <= extra && i + std::size_t(k) < text.size(); ++k)
                    cp = (cp << 6) | (static_cast<unsigned char>(text[i + std::size_t(k)]) & 0x3F);
            }
            return {line, cp};
        } else {
            ++i;
        }
    }
    return {0, 0};
}

void refuse_non_ascii_outside_strings(std::string_view text, const std::string& name) {
    const auto [line, cp] = non_ascii_outside_strings(text);
    if (line == 0) return;
    char code[16];
    std::snprintf(code, sizeof code, "U+%04X", unsigned(cp));
    throw InputError(name, line, "",
                     std::string("TOML syntax error: a character beyond ASCII (") + code +
                         ") outside a string or comment; TOML allows them only in strings and comments");
}

} // namespace

namespace {
/// A file's TOML, its syntax errors named with file and line.
toml::table parse_toml(std::string_view text, const std::string& name) {
    refuse_non_ascii_outside_strings(text, name);
    try {
        return toml::parse(text, std::string_view{name});
    } catch (const toml::parse_error& e) {
        throw InputError(name, static_cast<int>(e.source().begin.line), "",
                         "TOML syntax error: " + std::string(e.description()));
    }
}
/// A file's text; InputError if it cannot be opened.
std::string file_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "", "cannot open file");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}
} // namespace

ModelFile parse_model(std::string_view text, const std::string& name) {
    toml::table doc = parse_toml(text, name);

    ModelFile mf;
    mf.source.file = name;
    Ctx c;
    c.file = name;
    c.source = &mf.source;
    const Path root{};
    // The sections, and one table per registered support type (core/supports/registry.hpp).
    std::vector<std::string_view> top_keys{"model", "region",  "material", "joint_property", "joint_assignment",
                                           "boundary", "solver", "history", "stage", "report", "events", "flow",
                                           "flow_boundary", "flow_source"};
    for (const std::string_view t : support_tables()) top_keys.push_back(t);
    check_keys(c, doc, root, top_keys);

    if (const toml::node* n = find(c, doc, root, "model")) {
        const Path p = root.key("model");
        const toml::table& t = to_table(c, *n, p, "a [model] table");
        static constexpr auto keys = key_names(meshing::model_keys);
        check_keys(c, t, p, keys);
        if (const toml::node* title = find(c, t, p, "title"))
            mf.title = to_str(c, *title, p.key("title"));
        for (const meshing::ModelKey& k : meshing::model_keys)
            if (k.set) read_declared_key(c, t, p, k, mf.geometry);
    }

    const toml::node* rn = find(c, doc, root, "region");
    if (!rn)
        c.fail(0, root.key("region"), "a model needs at least one [[region]] table, found none");
    const toml::array& regions =
        to_array(c, *rn, root.key("region"), "an array of [[region]] tables (double brackets)");
    if (regions.empty())
        c.fail(*rn, root.key("region"), "a model needs at least one region, found none");
    std::vector<std::optional<std::string>> region_material(regions.size());
    for (std::size_t i = 0; i < regions.size(); ++i) {
        mf.source.region_line.push_back(line(regions[i]));
        mf.source.key_line.emplace_back();
        c.region = static_cast<int>(i);
        c.owner.clear();
        mf.geometry.regions.push_back(read_region(
            c, regions[i], {"region[" + std::to_string(i) + "]", ""}, region_material[i]));
    }
    c.region = -1;
    c.owner.clear();
    check_names(c, mf);
    read_analysis(c, doc, mf, region_material);
    return mf;
}

RockSpec parse_rock(std::string_view text, const std::string& name, RockSpec rock) {
    toml::table doc = parse_toml(text, name);
    if (doc.contains("region")) return rock_of_model(parse_model(text, name), name, std::move(rock));
    ModelSource source;
    source.file = name;
    Ctx c;
    c.file = name;
    c.source = &source;
    const Path root{};
    static constexpr std::array<std::string_view, 3> top_keys{"joint_property", "material", "region"};
    check_keys(c, doc, root, top_keys);
    Names properties{"joint property", "joint properties", "joint_property", {}, {}};
    std::vector<JointPropertySpec> joints;
    read_tables(c, doc, "joint_property", [&](const toml::table& t, const Path& p, std::size_t) {
        joints.push_back(read_joint_property(c, t, p, properties));
    });
    if (joints.size() != 1)
        c.fail(joints.empty() ? 0 : properties.lines[1], root.key("joint_property"),
               "a rock file holds the bonds as one [[joint_property]] table (what bbm calibrate writes), found " +
                   std::to_string(joints.size()) + "; a full model file (with its [[region]]s) is read as its rock");
    rock.bonds = joints.front();
    Names materials{"material", "materials", "material", {}, {}};
    std::vector<MaterialSpec> found;
    read_tables(c, doc, "material", [&](const toml::table& t, const Path& p, std::size_t) {
        found.push_back(read_material(c, t, p, materials));
    });
    if (found.size() > 1)
        c.fail(materials.lines[1], root.key("material").at(1), "a rock file holds at most one [[material]], found " +
                                                                   std::to_string(found.size()));
    // Its blocks: the density; meshed blocks' share f of the deformation and their elasticity.
    if (!found.empty()) {
        const MaterialSpec& m = found.front();
        rock.material.density = m.density;
        rock.material.deformable_fraction = m.deformable_fraction;
        if (m.deformable_fraction > 0.0) rock.material.young = m.young, rock.material.poisson = m.poisson;
    }
    return rock;
}

std::vector<std::pair<double, double>> parse_curve(std::string_view text, const std::string& flag) {
    const std::string doc_text = "curve = " + std::string(text);
    try {
        const toml::table doc = parse_toml(doc_text, flag);
        ModelSource source;
        source.file = flag;
        Ctx c;
        c.file = flag;
        c.source = &source;
        return read_curve(c, doc, Path{}, "curve");
    } catch (const InputError& e) {
        // The flag, and the point within its curve: not a line of a one-line text.
        const std::string point = e.key().starts_with("curve") ? e.key().substr(5) : std::string();
        throw InputError(flag, 0, point, e.message());
    }
}

RockSpec read_rock(const std::string& path, RockSpec base) {
    return parse_rock(file_text(path), path, std::move(base));
}

ModelFile read_model(const std::string& path) {
    return parse_model(file_text(path), path);
}

InputError to_input_error(const ModelSource& source, const GeometryError& error) {
    std::string key = "region[" + std::to_string(error.region()) + "]";
    if (!error.key().empty()) key += "." + error.key();
    return InputError(source.file, source.line_of(error.region(), error.key()), key, error.what());
}

} // namespace bbm::io

namespace bbm::io {

namespace {

/// "joint_property[0].tensile" -> {"joint_property", 0, "tensile"}: names and indices.
struct KeyStep {
    std::string name;
    long index = -1; ///< >= 0: an element of the array `name`
};

std::vector<KeyStep> split_key(const std::string& key, const std::string& flag) {
    std::vector<KeyStep> steps;
    std::size_t at = 0;
    while (at < key.size()) {
        const auto end = key.find_first_of(".[", at);
        KeyStep s{key.substr(at, end == std::string::npos ? std::string::npos : end - at)};
        if (s.name.empty()) throw InputError(flag, 0, key, "a key is names joined by '.', with [i] after an array");
        at = end == std::string::npos ? key.size() : end;
        if (at < key.size() && key[at] == '[') {
            const auto close = key.find(']', at);
            if (close == std::string::npos) throw InputError(flag, 0, key, "a '[' without its ']'");
            try {
                s.index = std::stol(key.substr(at + 1, close - at - 1));
            } catch (...) {
                throw InputError(flag, 0, key, "[i] needs a whole number");
            }
            if (s.index < 0) throw InputError(flag, 0, key, "[i] needs a whole number >= 0");
            at = close + 1;
        }
        if (at < key.size()) {
            if (key[at] != '.') throw InputError(flag, 0, key, "a key is names joined by '.', with [i] after an array");
            ++at;
        }
        steps.push_back(std::move(s));
    }
    if (steps.empty()) throw InputError(flag, 0, key, "empty key");
    return steps;
}

/// A value as TOML would read it on the right of '=' (2e6, "trigon", [1, 2], true);
/// a bare word that is not TOML becomes a string.
toml::node_view<toml::node> parse_value(const std::string& text, toml::table& holder) {
    if (non_ascii_outside_strings(text).first != 0) { // not TOML: a bare word
        holder = toml::table{{"v", text}};
        return holder["v"];
    }
    try {
        holder = toml::parse("v = " + text);
    } catch (const toml::parse_error&) {
        holder = toml::table{{"v", text}};
    }
    return holder["v"];
}

/// Sets `key` (a dotted key, [i] after an array; its tables and arrays must
/// exist) of `doc` to `value` read as TOML.
void set_model_key(toml::table& doc, const std::string& name, const std::string& key, const std::string& value) {
    const auto steps = split_key(key, "--set");
    toml::table* table = &doc;
    std::string walked;
    for (std::size_t k = 0; k + 1 <= steps.size(); ++k) {
        const auto& s = steps[k];
        if (!walked.empty()) walked += '.';
        walked += s.name;
        const bool last = k + 1 == steps.size();
        if (last && s.index < 0) {
            toml::table holder;
            auto v = parse_value(value, holder);
            table->insert_or_assign(s.name, *v.node());
            break;
        }
        toml::node* node = table->get(s.name);
        if (!node)
            throw InputError("--set", 0, key, "the model " + name + " has no '" + walked + "' (" +
                             (k == 0 ? "a top-level table" : "a key") + " must exist to be set inside)");
        if (s.index >= 0) {
            auto* array = node->as_array();
            if (!array) throw InputError("--set", 0, key, "'" + walked + "' is not an array");
            if (std::size_t(s.index) >= array->size())
                throw InputError("--set", 0, key,
                                 "'" + walked + "' has " + std::to_string(array->size()) + " entries (index from 0)");
            walked += '[';
            walked += std::to_string(s.index);
            walked += ']';
            if (last) {
                toml::table holder;
                auto v = parse_value(value, holder);
                array->replace(array->begin() + s.index, *v.node());
                break;
            }
            node = array->get(std::size_t(s.index));
        }
        table = node->as_table();
        if (!table) throw InputError("--set", 0, key, "'" + walked + "' is not a table");
    }
}

/// Random patterns (voronoi, trigon, delaunay) of every region draw from seed + offset.
void offset_pattern_seeds(toml::table& doc, long seed_offset) {
    if (auto* regions = doc["region"].as_array())
        for (auto& r : *regions) {
            auto* pattern = r.as_table() ? (*r.as_table())["pattern"].as_table() : nullptr;
            if (!pattern) continue;
            const auto type = (*pattern)["type"].value_or(std::string{});
            if (type != "voronoi" && type != "trigon" && type != "delaunay") continue;
            const auto seed = (*pattern)["seed"].value_or(std::int64_t{1});
            pattern->insert_or_assign("seed", seed + seed_offset);
        }
}

/// Generated fracture sets (region.dfn, not those read from a file) too: a seed
/// study of a jointed rock mass is over networks as well as patterns.
void offset_dfn_seeds(toml::table& doc, long seed_offset) {
    if (auto* regions = doc["region"].as_array())
        for (auto& r : *regions) {
            auto* sets = r.as_table() ? (*r.as_table())["dfn"].as_array() : nullptr;
            if (!sets) continue;
            for (auto& d : *sets) {
                auto* t = d.as_table();
                if (!t || (*t)["file"]) continue;
                const auto seed = (*t)["seed"].value_or(std::int64_t{1});
                t->insert_or_assign("seed", seed + seed_offset);
            }
        }
}

/// Heterogeneous joint strengths draw from strength_seed + offset.
void offset_strength_seeds(toml::table& doc, long seed_offset) {
    if (auto* properties = doc["joint_property"].as_array())
        for (auto& j : *properties) {
            auto* t = j.as_table();
            if (!t || !(*t)["weibull_modulus"]) continue;
            const auto seed = (*t)["strength_seed"].value_or(std::int64_t{1});
            t->insert_or_assign("strength_seed", seed + seed_offset);
        }
}

} // namespace

std::string edit_model_text(std::string_view text, const std::string& name,
                            const std::vector<std::pair<std::string, std::string>>& set, long seed_offset) {
    toml::table doc = parse_toml(text, name);
    for (const auto& [key, value] : set) set_model_key(doc, name, key, value);
    if (seed_offset != 0) {
        offset_pattern_seeds(doc, seed_offset);
        offset_dfn_seeds(doc, seed_offset);
        offset_strength_seeds(doc, seed_offset);
    }
    std::ostringstream out;
    out << "# " << name << (set.empty() && seed_offset == 0 ? "" : ", edited by bbm sweep") << "\n"
        << toml::toml_formatter{doc} << "\n";
    return out.str();
}

} // namespace bbm::io
