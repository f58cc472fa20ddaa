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
        h.point = to_position(c, n, p.key("point"));
    }
    if (at_boundary) {
        const Path bp = p.key("boundary");
        const toml::node& n = need(c, t, p, "boundary", "the name of a [[boundary]]");
        h.boundary = to_str(c, n, bp);
        check_ref(c, line(n), bp, h.boundary, boundaries);
    }
    return h;
}

namespace {

/// An excavate stage's support_path: rows [t, k_mean, k_deviator], t from 0 to 1.
std::vector<std::array<double, 3>> read_support_path(Ctx& c, const toml::table& t, const Path& p) {
    std::vector<std::array<double, 3>> rows;
    const toml::node* n = find(c, t, p, "support_path");
    if (!n) return rows;
    const Path kp = p.key("support_path");
    const toml::array& a = to_array(c, *n, kp, "an array of rows [t, k_mean, k_deviator]");
    // A fraction of the support beyond [-1, 2] is no stress path of an elastic rock.
    const Range fraction{.lo = -1, .hi = 2, .unit = ""};
    for_each_element(c, a, kp, [&](const toml::node& e, const Path& ep) {
        const auto* row = e.as_array();
        if (!row || row->size() != 3)
            c.fail(e, ep,
                   "expected a row [t, k_mean, k_deviator] of 3 numbers, got " +
                       (row ? "an array of " + std::to_string(row->size()) : describe(e)));
        const double at = checked_number(c, (*row)[0], ep.at(0), Range{.lo = 0, .hi = 1, .unit = ""});
        if (rows.empty() && at != 0)
            c.fail((*row)[0], ep.at(0), "the first row must be at t = 0 (the excavation), got " + fmt(at));
        if (!rows.empty() && !(at > rows.back()[0]))
            c.fail((*row)[0], ep.at(0),
                   "t must increase from row to row, got " + fmt(at) + " after " + fmt(rows.back()[0]));
        rows.push_back({at, checked_number(c, (*row)[1], ep.at(1), fraction),
                        checked_number(c, (*row)[2], ep.at(2), fraction)});
    });
    if (rows.size() < 2 || rows.back()[0] != 1)
        c.fail(*n, kp,
               "needs at least two rows, from t = 0 to t = 1 (the end of relax_steps), got " +
                   (rows.empty() ? std::string("none") : "the last at t = " + fmt(rows.back()[0])));
    return rows;
}

/// The stage's name (by default "stage N"), new among the stages; messages
/// about the stage name it from here on.
void read_stage_name(Ctx& c, const toml::table& t, const Path& p, std::size_t index, Names& names, StageSpec& s) {
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
}

void read_solve_stage(Ctx& c, const toml::table& t, const Path& p, StageSpec& s) {
    const auto bounds = stage_key_bounds;
    s.ratio = number(c, t, p, "ratio", bounds("ratio")).value_or(s.ratio);
    s.max_steps = whole_number(c, t, p, "max_steps", bounds("max_steps")).value_or(s.max_steps);
    if (const toml::node* n = find(c, t, p, "until"))
        s.until = StageSpec::Until(
            to_choice(c, *n, p.key("until"), key_words(find_key(stage_keys, "until")->words), "stopping rule"));
    s.quiet_steps = whole_number(c, t, p, "quiet_steps", bounds("quiet_steps")).value_or(s.quiet_steps);
}

void read_excavate_stage(Ctx& c, const toml::table& t, const Path& p, const Names& regions, StageSpec& s) {
    const auto bounds = stage_key_bounds;
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
    s.support_path = read_support_path(c, t, p);
    if (!s.support_path.empty()) {
        const toml::node& n = *find(c, t, p, "support_path");
        if (s.relax_steps < 1)
            c.fail(n, p.key("support_path"), "needs relax_steps >= 1: the steps the path is run over");
        if (find(c, t, p, "keep"))
            c.fail(*find(c, t, p, "keep"), p.key("keep"),
                   "cannot go with support_path: the path's last row is the support kept");
    }
}

} // namespace

StageSpec read_stage(Ctx& c, const toml::table& t, const Path& p, std::size_t index, Names& names,
                     const Names& regions, const Names& supports) {
    static constexpr auto all_keys = key_names(stage_keys);
    check_keys(c, t, p, all_keys);
    StageSpec s;
    using Kind = StageSpec::Kind;
    read_stage_name(c, t, p, index, names, s);
    s.kind = static_cast<Kind>(read_typed_keys(c, t, p, stage_keys, "type", "stage type", "stage"));
    const auto bounds = stage_key_bounds;
    switch (s.kind) {
    case Kind::initialize:
        s.stress = read_stress(c, t, p);
        break;
    case Kind::solve:
        read_solve_stage(c, t, p, s);
        break;
    case Kind::excavate:
        read_excavate_stage(c, t, p, regions, s);
        break;
    case Kind::cycle:
        // A cycle runs at least one step, or a model time (dynamic mode: checked
        // with the solver's table).
        if (const toml::node* n = t.get("time")) {
            if (t.contains("steps"))
                c.fail(*n, p.key("time"), c.in_owner() + "a cycle stage runs its steps or its time, not both");
            s.time = required_number(c, t, p, "time", bounds("time"));
        } else {
            s.steps = required_integer(c, t, p, "steps", 1, std::numeric_limits<long>::max());
        }
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
    case Kind::creep:
        s.duration = required_number(c, t, p, "duration", bounds("duration"));
        s.loss = number(c, t, p, "loss", bounds("loss")).value_or(s.loss);
        s.ratio = number(c, t, p, "ratio", bounds("ratio")).value_or(s.ratio);
        s.max_steps = whole_number(c, t, p, "max_steps", bounds("max_steps")).value_or(10000000);
        s.settle_steps = whole_number(c, t, p, "settle_steps", bounds("settle_steps")).value_or(s.settle_steps);
        break;
    }
    return s;
}

} // namespace bbm::io::reader
