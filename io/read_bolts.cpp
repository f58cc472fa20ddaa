// bbm io: the [[bolt]] and [[dowel]] tables of a model file — rock bolts and
// cables (core/bolts.hpp), dowels (core/dowels.hpp); docs/input.md "Rock bolts
// and cables", "Dowels".
#include "core/bolt_keys.hpp"
#include "io/reader.hpp"

namespace bbm::io::reader {

namespace {

BoltSetSpec::Ring read_ring(const Ctx& c, const toml::node& node, const Path& p) {
    const toml::table& t = to_table(c, node, p, "a table {center, radius, length, count or spacing, from, to}");
    static constexpr std::array<std::string_view, 7> keys{"center", "radius", "length", "count",
                                                          "spacing", "from",  "to"};
    check_keys(c, t, p, keys);
    BoltSetSpec::Ring r;
    r.center = required_point(c, t, p, "center");
    r.radius = required_number(c, t, p, "radius", above(0, metres));
    r.length = required_number(c, t, p, "length", above(0, metres));
    const auto count = integer(c, t, p, "count", 1, 100000);
    const auto spacing = number(c, t, p, "spacing", above(0, metres));
    if (count.has_value() == spacing.has_value())
        c.fail(t, p, "give the bolts' 'count' or their 'spacing' along the wall (one of them)");
    r.count = int(count.value_or(0));
    r.spacing = spacing.value_or(0.0);
    r.from = number(c, t, p, "from", unbounded(degrees)).value_or(0.0);
    r.to = number(c, t, p, "to", unbounded(degrees)).value_or(r.from + 360.0);
    if (!(r.to > r.from) || r.to - r.from > 360.0 + 1e-9)
        c.fail(t, p, "'to' must be above 'from' by at most 360 degrees, got from " + fmt(r.from) + " to " + fmt(r.to));
    return r;
}

/// A [[bolt]] (`type` "bolt") or [[dowel]] table: the keys of core/bolt_keys.hpp
/// that belong to it.
DowelSetSpec read_bolt_set(Ctx& c, const toml::table& t, const Path& p, Names& names, std::string_view type) {
    static constexpr auto all_keys = key_names(bolt_keys);
    check_keys(c, t, p, keys_of_type(bolt_keys, type), all_keys, "a " + std::string(type) + " set");
    DowelSetSpec b;
    b.name = read_name(c, t, p, names);
    if (const toml::node* n = find(c, t, p, "bolts")) {
        const Path bp = p.key("bolts");
        const toml::array& a = to_array(c, *n, bp, "an array of bolts [[x1, y1], [x2, y2]] (head, toe)");
        for_each_element(c, a, bp, [&](const toml::node& e, const Path& ep) {
            const toml::array& pair = to_array(c, e, ep, "a bolt [[x1, y1], [x2, y2]] (head, toe)");
            if (pair.size() != 2) c.fail(e, ep, "a bolt is 2 points [head, toe], got " + std::to_string(pair.size()));
            const Vec2 head = to_vec2(c, pair[0], ep.at(0)), toe = to_vec2(c, pair[1], ep.at(1));
            if (!(norm(toe - head) > 0)) c.fail(e, ep, "head and toe are the same point " + fmt(head));
            b.bolts.push_back({head, toe});
        });
    }
    if (const toml::node* n = find(c, t, p, "ring")) b.ring = read_ring(c, *n, p.key("ring"));
    if (b.bolts.empty() && !b.ring)
        c.fail(t, p, c.in_owner() + "no bolts: give 'bolts' (head and toe of each) or a 'ring' around an opening");
    for (const BoltKey& k : bolt_keys)
        if (k.set && key_applies(k, type)) read_declared_key(c, t, p, k, b);
    const auto area = number(c, t, p, "area", find_key(bolt_keys, "area")->bounds);
    const auto diameter = number(c, t, p, "diameter", find_key(bolt_keys, "diameter")->bounds);
    if (area && diameter) c.fail(t, p.key("diameter"), "give the steel's 'area' or its 'diameter', not both");
    if (area) b.area = *area;
    if (diameter) b.area = 0.25 * 3.141592653589793 * *diameter * *diameter;
    return b;
}

} // namespace

void read_bolt_sets(Ctx& c, const toml::table& doc, std::vector<BoltSetSpec>& bolts, Names& names) {
    read_tables(c, doc, "bolt", [&](const toml::table& t, const Path& p, std::size_t) {
        bolts.push_back(read_bolt_set(c, t, p, names, "bolt"));
    });
}

void read_dowel_sets(Ctx& c, const toml::table& doc, std::vector<DowelSetSpec>& dowels, Names& names) {
    read_tables(c, doc, "dowel", [&](const toml::table& t, const Path& p, std::size_t) {
        const DowelSetSpec d = read_bolt_set(c, t, p, names, "dowel");
        if (d.pretension > 0.0 && !(d.face_plate && d.end_anchor))
            c.fail(t, p.key("pretension"),
                   "a pretension is held by the face plate and the end anchor: set face_plate = true and "
                   "end_anchor = true");
        if (d.yield_force > 0.0 && d.pretension >= d.yield_force)
            c.fail(t, p.key("pretension"),
                   "the pretension " + fmt(d.pretension) + " N must be below the yield force " + fmt(d.yield_force) +
                       " N");
        dowels.push_back(d);
    });
}

} // namespace bbm::io::reader
