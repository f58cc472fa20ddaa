// bbm io: the [[history]] and [[stage]] tables of a model file (docs/input.md).
#include "io/reader.hpp"

#include "core/history_keys.hpp"
#include "core/stage_keys.hpp"
#include "core/verdict.hpp"

namespace bbm::io::reader {

HistorySpec read_history(Ctx& c, const toml::table& t, const Path& p, Names& names,
                         const Names& boundaries) {
    static constexpr auto all_keys = key_names(history_keys);
    const auto quantities = key_words(history_quantity_words);
    static constexpr std::array<std::string_view, 3> point_keys{"name", "quantity", "point"};
    static constexpr std::array<std::string_view, 3> boundary_keys{"name", "quantity", "boundary"};
    check_keys(c, t, p, all_keys);
    HistorySpec h;
    using Q = HistorySpec::Quantity;
    h.name = read_name(c, t, p, names);
    h.quantity = static_cast<Q>(choice(c, t, p, "quantity", quantities, "history quantity"));
    const std::string_view q = quantities[static_cast<std::size_t>(h.quantity)];
    const bool at_point = h.quantity >= Q::displacement_x && h.quantity <= Q::rotation;
    const bool at_boundary = h.quantity == Q::boundary_force_x || h.quantity == Q::boundary_force_y;
    check_keys(c, t, p,
               at_point      ? Keys(point_keys)
               : at_boundary ? Keys(boundary_keys)
                             : Keys(all_keys).first(2),
               all_keys, article(q) + " history");
    if (at_point) {
        const toml::node& n = need(c, t, p, "point",
                                   "a point [x, y]: the " + std::string(q) +
                                       " of the block containing (or nearest to) it is recorded");
        h.point = to_vec2(c, n, p.key("point"));
    }
    if (at_boundary) {
        const Path bp = p.key("boundary");
        const toml::node& n = need(c, t, p, "boundary", "the name of a [[boundary]]");
        h.boundary = to_str(c, n, bp);
        check_ref(c, line(n), bp, h.boundary, boundaries);
    }
    return h;
}

StageSpec read_stage(Ctx& c, const toml::table& t, const Path& p, std::size_t index, Names& names,
                     const Names& regions, const Names& supports) {
    static constexpr auto all_keys = key_names(stage_keys);
    check_keys(c, t, p, all_keys);
    StageSpec s;
    using Kind = StageSpec::Kind;
    const Path np = p.key("name");
    int name_line = line(t);
    if (const toml::node* n = find(c, t, p, "name")) {
        s.name = to_str(c, *n, np);
        if (s.name.empty()) c.fail(*n, np, "must be a non-empty string, got \"\"");
        name_line = line(*n);
    } else {
        s.name = "stage " + std::to_string(index + 1);
    }
    add_name(c, names, s.name, name_line, np, line(t));
    c.owner = "stage " + quoted(s.name);
    s.kind = static_cast<Kind>(read_typed_keys(c, t, p, stage_keys, "type", "stage type", "stage"));
    const auto bounds = stage_key_bounds;
    switch (s.kind) {
    case Kind::initialize:
        s.stress = read_stress(c, t, p);
        break;
    case Kind::solve:
        s.ratio = number(c, t, p, "ratio", bounds("ratio")).value_or(s.ratio);
        s.max_steps = whole_number(c, t, p, "max_steps", bounds("max_steps")).value_or(s.max_steps);
        if (const toml::node* n = find(c, t, p, "until"))
            s.until = StageSpec::Until(
                to_choice(c, *n, p.key("until"), key_words(find_key(stage_keys, "until")->words), "stopping rule"));
        s.quiet_steps = whole_number(c, t, p, "quiet_steps", bounds("quiet_steps")).value_or(s.quiet_steps);
        break;
    case Kind::excavate:
        s.regions = name_list(c, t, p, "regions", regions, "");
        s.relax_steps = whole_number(c, t, p, "relax_steps", bounds("relax_steps")).value_or(0);
        // Steps run in this stage: fewer than relax_steps stops part-way through the
        // relaxation (which goes on in the next stages), e.g. to install support.
        s.steps = whole_number(c, t, p, "steps", bounds("steps")).value_or(s.relax_steps);
        s.keep = number(c, t, p, "keep", bounds("keep")).value_or(0.0);
        s.pressure = number(c, t, p, "pressure", bounds("pressure")).value_or(0.0);
        if (s.steps > s.relax_steps)
            c.fail(*find(c, t, p, "steps"), p.key("steps"),
                   "must be at most relax_steps (" + std::to_string(s.relax_steps) + "), got " + std::to_string(s.steps));
        break;
    case Kind::cycle:
        // A cycle runs at least one step.
        s.steps = required_integer(c, t, p, "steps", 1, std::numeric_limits<long>::max());
        break;
    case Kind::elastic:
        break;
    case Kind::install:
        s.supports = name_list(c, t, p, "supports", supports, "");
        break;
    case Kind::pressurise:
        s.pressure = required_number(c, t, p, "pressure", bounds("pressure"));
        s.steps = whole_number(c, t, p, "steps", bounds("steps")).value_or(0);
        break;
    }
    return s;
}

} // namespace bbm::io::reader
