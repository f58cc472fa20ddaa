// bbm io: the [[liner]] tables of a model file — shotcrete or concrete lining
// along a circular opening (core/liners.hpp, docs/input.md "Liners").
#include "core/liner_keys.hpp"
#include "io/reader.hpp"

namespace bbm::io::reader {

namespace {

LinerSpec read_liner(Ctx& c, const toml::table& t, const Path& p, Names& names) {
    static constexpr auto keys = key_names(liner_keys);
    check_keys(c, t, p, keys);
    LinerSpec l;
    l.name = read_name(c, t, p, names);
    l.center = required_point(c, t, p, "center");
    for (const LinerKey& k : liner_keys)
        if (k.set) read_declared_key(c, t, p, k, l);
    l.to = number(c, t, p, "to", find_key(liner_keys, "to")->bounds).value_or(l.from + 360.0);
    if (!(l.to > l.from) || l.to - l.from > 360.0 + 1e-9)
        c.fail(t, p, c.in_owner() + "'to' must be above 'from' by at most 360 degrees, got from " + fmt(l.from) +
                         " to " + fmt(l.to));
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
