// bbm io: the [flow], [[flow_boundary]] and [[flow_source]] tables of a model file —
// water in the joints (core/joint_flow.hpp); docs/input.md "Water in the joints".
#include "io/reader.hpp"

namespace bbm::io::reader {

namespace {

constexpr std::array<std::string_view, 15> flow_keys{
    "viscosity",      "bulk_modulus", "density",     "gravity",       "aperture",
    "bond_aperture",  "residual_aperture", "max_aperture", "regions", "water_table",
    "pressure",       "mode",         "steady_every", "far_field",    "drain_openings"};

void read_flow_table(Ctx& c, const toml::table& t, const Path& p, FlowSpec& f, const Names& regions) {
    check_keys(c, t, p, flow_keys);
    f.on = true;
    auto& fl = f.fluid;
    fl.viscosity = number(c, t, p, "viscosity", above(0, " Pa·s")).value_or(fl.viscosity);
    fl.bulk_modulus = number(c, t, p, "bulk_modulus", above(0, " Pa")).value_or(fl.bulk_modulus);
    fl.density = number(c, t, p, "density", at_least(0, " kg/m³")).value_or(fl.density);
    if (const auto g = point(c, t, p, "gravity")) fl.gravity = *g, f.gravity_given = true;
    f.aperture = number(c, t, p, "aperture", above(0, metres)).value_or(f.aperture);
    f.bond_aperture = number(c, t, p, "bond_aperture", at_least(0, metres)).value_or(f.bond_aperture);
    fl.residual_aperture = number(c, t, p, "residual_aperture", at_least(0, metres)).value_or(fl.residual_aperture);
    fl.max_aperture = number(c, t, p, "max_aperture", above(0, metres)).value_or(fl.max_aperture);
    if (!(fl.max_aperture > fl.residual_aperture))
        c.fail(t, p.key("max_aperture"),
               "must exceed residual_aperture = " + fmt(fl.residual_aperture) + " m, got " + fmt(fl.max_aperture));
    if (f.aperture > fl.max_aperture)
        c.fail(t, p.key("aperture"),
               "must be at most max_aperture = " + fmt(fl.max_aperture) + " m, got " + fmt(f.aperture));
    f.regions = name_list(c, t, p, "regions", regions, "for every region with a block pattern");
    f.water_table = number(c, t, p, "water_table", unbounded(metres));
    if (const auto pr = number(c, t, p, "pressure", at_least(0, " Pa"))) {
        if (f.water_table)
            c.fail(t, p.key("pressure"), "give a 'water_table' (hydrostatic) or a uniform 'pressure', not both");
        f.pressure = *pr;
    }
    static constexpr std::array<std::string_view, 2> modes{"steady", "transient"};
    if (find(c, t, p, "mode")) f.mode = FlowSpec::Mode(choice(c, t, p, "mode", modes, "flow mode"));
    f.steady_every = int(integer(c, t, p, "steady_every", 1, 1000000000).value_or(f.steady_every));
    static constexpr std::array<std::string_view, 2> far{"held", "sealed"};
    if (find(c, t, p, "far_field")) f.far_field_held = choice(c, t, p, "far_field", far, "far-field condition") == 0;
    f.drain_openings = boolean(c, t, p, "drain_openings").value_or(f.drain_openings);
}

constexpr std::array<std::string_view, 4> boundary_keys{"name", "box", "pressure", "head"};
constexpr std::array<std::string_view, 2> source_keys{"at", "rate"};

} // namespace

void read_flow(Ctx& c, const toml::table& doc, FlowSpec& f, const Names& regions) {
    if (const toml::node* n = find(c, doc, Path{}, "flow")) {
        const Path p = Path{}.key("flow");
        read_flow_table(c, to_table(c, *n, p, "a [flow] table"), p, f, regions);
    }
    Names names{"flow boundary", "flow boundaries", "flow_boundary", {}, {}};
    read_tables(c, doc, "flow_boundary", [&](const toml::table& t, const Path& p, std::size_t) {
        check_keys(c, t, p, boundary_keys);
        FlowBoundarySpec b;
        b.name = read_name(c, t, p, names);
        b.box = read_box(c, need(c, t, p, "box", "a box { min = [x, y], max = [x, y] }"), p.key("box"));
        b.pressure = number(c, t, p, "pressure", at_least(0, " Pa"));
        b.head = number(c, t, p, "head", unbounded(metres));
        if (b.pressure.has_value() == b.head.has_value())
            c.fail(t, p, c.in_owner() + "give the held 'pressure' or the 'head' (one of them)");
        if (!f.on) c.fail(t, p, "a [[flow_boundary]] needs a [flow] table (the fluid and the joints' apertures)");
        f.boundaries.push_back(b);
    });
    read_tables(c, doc, "flow_source", [&](const toml::table& t, const Path& p, std::size_t) {
        check_keys(c, t, p, source_keys);
        FlowSourceSpec s;
        s.at = required_point(c, t, p, "at");
        s.rate = required_number(c, t, p, "rate", unbounded(" m²/s per m"));
        if (!f.on) c.fail(t, p, "a [[flow_source]] needs a [flow] table (the fluid and the joints' apertures)");
        f.sources.push_back(s);
    });
}

} // namespace bbm::io::reader
