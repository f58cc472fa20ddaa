// bbm io: the [[liner]] tables of a model file — shotcrete or concrete lining
// along a circular opening (core/liners.hpp, docs/input.md "Liners").
#include "io/reader.hpp"

namespace bbm::io::reader {

namespace {

LinerSpec read_liner(Ctx& c, const toml::table& t, const Path& p, Names& names) {
    static constexpr std::array<std::string_view, 19> keys{
        "name",            "center",           "radius",          "from",           "to",
        "segment_length",  "young",            "poisson",         "thickness",      "density",
        "normal_stiffness", "shear_stiffness", "tensile_strength", "cohesion",      "friction",
        "symmetric_ends",  "thrust_capacity",  "tension_capacity", "moment_capacity"};
    check_keys(c, t, p, keys);
    LinerSpec l;
    l.name = read_name(c, t, p, names);
    l.center = required_point(c, t, p, "center");
    l.radius = required_number(c, t, p, "radius", above(0, metres));
    l.from = number(c, t, p, "from", unbounded(degrees)).value_or(0.0);
    l.to = number(c, t, p, "to", unbounded(degrees)).value_or(l.from + 360.0);
    if (!(l.to > l.from) || l.to - l.from > 360.0 + 1e-9)
        c.fail(t, p, c.in_owner() + "'to' must be above 'from' by at most 360 degrees, got from " + fmt(l.from) +
                         " to " + fmt(l.to));
    l.segment_length = number(c, t, p, "segment_length", above(0, metres)).value_or(l.segment_length);
    l.young = number(c, t, p, "young", above(0, " Pa")).value_or(l.young);
    l.poisson = number(c, t, p, "poisson", below(0, 0.5, "")).value_or(l.poisson);
    l.thickness = required_number(c, t, p, "thickness", above(0, metres));
    l.density = number(c, t, p, "density", above(0, " kg/m³")).value_or(l.density);
    l.normal_stiffness = number(c, t, p, "normal_stiffness", above(0, " Pa/m")).value_or(0.0);
    l.shear_stiffness = number(c, t, p, "shear_stiffness", above(0, " Pa/m")).value_or(0.0);
    l.tensile_strength = number(c, t, p, "tensile_strength", above(0, " Pa")).value_or(0.0);
    l.cohesion = number(c, t, p, "cohesion", at_least(0, " Pa")).value_or(0.0);
    l.friction = number(c, t, p, "friction", below(0, 90, degrees)).value_or(l.friction);
    l.symmetric_ends = boolean(c, t, p, "symmetric_ends").value_or(false);
    l.thrust_capacity = number(c, t, p, "thrust_capacity", above(0, " N/m")).value_or(0.0);
    l.tension_capacity = number(c, t, p, "tension_capacity", above(0, " N/m")).value_or(0.0);
    l.moment_capacity = number(c, t, p, "moment_capacity", above(0, " N·m/m")).value_or(0.0);
    if (l.tension_capacity > 0.0 && l.thrust_capacity == 0.0)
        c.fail(*find(c, t, p, "tension_capacity"), p.key("tension_capacity"),
               "a tension capacity needs a thrust capacity (the lining's compressive yield) too");
    if (l.symmetric_ends && std::abs(l.to - l.from - 360.0) < 1e-9)
        c.fail(*find(c, t, p, "symmetric_ends"), p.key("symmetric_ends"),
               "a closed ring (from " + fmt(l.from) + " to " + fmt(l.to) + " degrees) has no ends");
    return l;
}

} // namespace

void read_liners(Ctx& c, const toml::table& doc, std::vector<LinerSpec>& liners, Names& names) {
    read_tables(c, doc, "liner", [&](const toml::table& t, const Path& p, std::size_t) {
        liners.push_back(read_liner(c, t, p, names));
    });
}

} // namespace bbm::io::reader
