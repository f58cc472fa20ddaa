// bbm io: the [flow], [[flow_boundary]] and [[flow_source]] tables of a model file —
// water in the joints (core/joint_flow.hpp); docs/input.md "Water in the joints".
#include "core/flow_keys.hpp"
#include "io/reader.hpp"

namespace bbm::io::reader {

namespace {

void read_flow_table(Ctx& c, const toml::table& t, const Path& p, FlowSpec& f, const Names& regions) {
    static constexpr auto keys = key_names(flow_keys);
    check_keys(c, t, p, keys);
    f.on = true;
    for (const FlowKey& k : flow_keys)
        if (k.set) read_declared_key(c, t, p, k, f);
    auto& fl = f.fluid;
    if (const auto g = vector(c, t, p, "gravity")) fl.gravity = *g, f.gravity_given = true;
    if (!(fl.max_aperture > fl.residual_aperture))
        c.fail(t, p.key("max_aperture"),
               "must exceed residual_aperture = " + fmt(fl.residual_aperture) + " m, got " + fmt(fl.max_aperture));
    if (f.aperture > fl.max_aperture)
        c.fail(t, p.key("aperture"),
               "must be at most max_aperture = " + fmt(fl.max_aperture) + " m, got " + fmt(f.aperture));
    f.regions = name_list(c, t, p, "regions", regions, "for every region with a block pattern");
    if (f.water_table && t.contains("pressure"))
        c.fail(t, p.key("pressure"), "give a 'water_table' (hydrostatic) or a uniform 'pressure', not both");
    if (find(c, t, p, "mode"))
        f.mode = FlowSpec::Mode(choice(c, t, p, "mode", key_words(find_key(flow_keys, "mode")->words), "flow mode"));
    if (find(c, t, p, "far_field"))
        f.far_field_held = choice(c, t, p, "far_field", key_words(find_key(flow_keys, "far_field")->words),
                                  "far-field condition") == 0;
}


} // namespace

void read_flow(Ctx& c, const toml::table& doc, FlowSpec& f, const Names& regions) {
    if (const toml::node* n = find(c, doc, Path{}, "flow")) {
        const Path p = Path{}.key("flow");
        read_flow_table(c, to_table(c, *n, p, "a [flow] table"), p, f, regions);
    }
    Names names{"flow boundary", "flow boundaries", "flow_boundary", {}, {}};
    read_tables(c, doc, "flow_boundary", [&](const toml::table& t, const Path& p, std::size_t) {
        static constexpr auto keys = key_names(flow_boundary_keys);
        check_keys(c, t, p, keys);
        FlowBoundarySpec b;
        b.name = read_name(c, t, p, names);
        b.box = read_box(c, need(c, t, p, "box", "a box { min = [x, y], max = [x, y] }"), p.key("box"));
        b.pressure = number(c, t, p, "pressure", find_key(flow_boundary_keys, "pressure")->bounds);
        b.head = number(c, t, p, "head", find_key(flow_boundary_keys, "head")->bounds);
        if (b.pressure.has_value() == b.head.has_value())
            c.fail(t, p, c.in_owner() + "give the held 'pressure' or the 'head' (one of them)");
        if (!f.on) c.fail(t, p, "a [[flow_boundary]] needs a [flow] table (the fluid and the joints' apertures)");
        f.boundaries.push_back(b);
    });
    read_tables(c, doc, "flow_source", [&](const toml::table& t, const Path& p, std::size_t) {
        static constexpr auto keys = key_names(flow_source_keys);
        check_keys(c, t, p, keys);
        FlowSourceSpec s;
        s.at = required_point(c, t, p, "at");
        s.rate = required_number(c, t, p, "rate", find_key(flow_source_keys, "rate")->bounds);
        if (!f.on) c.fail(t, p, "a [[flow_source]] needs a [flow] table (the fluid and the joints' apertures)");
        f.sources.push_back(s);
    });
}

} // namespace bbm::io::reader
