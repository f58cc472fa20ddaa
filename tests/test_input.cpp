// Tests of the model-file reader (apps/model_input): a complete file reads into the
// right geometry description, and every kind of mistake is reported at the right
// line and key.
#include "apps/model_input.hpp"

#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

using bbm::GeometryError;
using bbm::InputError;
using bbm::Vec2;
using bbm::io::parse_model;
using bbm::meshing::OutlineSpec;
using bbm::meshing::PatternSpec;

namespace {

/// 1-based line of the first occurrence of `needle`, so that tests need not count.
int line_of(std::string_view text, std::string_view needle) {
    const auto pos = text.find(needle);
    REQUIRE(pos != std::string_view::npos);
    int line = 1;
    for (std::size_t i = 0; i < pos; ++i)
        line += text[i] == '\n';
    return line;
}

std::optional<InputError> error_of(std::string_view text) {
    try {
        parse_model(text, "t.toml");
    } catch (const InputError& e) {
        return e;
    }
    return std::nullopt;
}

/// Checks the error of `text`: at the line holding `at`, for `key`, with a message
/// containing `words`.
void check_error(std::string_view text, std::string_view at, const std::string& key,
                 const std::string& words) {
    const auto e = error_of(text);
    REQUIRE_MESSAGE(e.has_value(), "no error for:\n" << text);
    INFO(std::string(e->what()));
    CHECK(e->file() == "t.toml");
    CHECK(e->line() == line_of(text, at));
    CHECK(e->key() == key);
    CHECK(std::string(e->what()).find(words) != std::string::npos);
    CHECK(std::string(e->what()).find("t.toml:" + std::to_string(e->line()) + ": " + key + ": ") ==
          0);
}

// The tunnel of docs/input.md (a half model, cut on x = 0), plus a joint set, an
// explicit joint and a hole, so that every kind of table is read.
constexpr std::string_view tunnel = R"(# tunnel
[model]
title = "Tunnel, Voronoi bonded-block region"
max_segment = 0.2

[[region]]
name = "outer"
outline = { type = "rectangle", min = [0, -20], max = [20.0, 20.0] }
minus = ["bonded"]
pattern = { type = "single" }

[[region]]
name = "bonded"
outline = { type = "rectangle", min = [0.0, -8.0], max = [8.0, 8.0] }
holes = [ { type = "circle", center = [6.0, 6.0], radius = 0.5, max_segment = 0.05 } ]
minus = ["opening"]
pattern = { type = "voronoi", size = 0.3, lloyd = 2, min_edge = 0.03, seed = 7 }
joints = [ { from = [0.0, -6.0], to = [8.0, -5.0] } ]

[[region.joint_set]]
angle = 30.0
spacing = 2
trace = 3.0
gap = 1.0
angle_deviation = 5.0
spacing_deviation = 0.2
length_deviation = 0.3
origin = [1.0, 2.0]
seed = 11

[[region]]
name = "opening"
outline = { type = "path", start = [0.0, -4.0], steps = [ { to = [0.0, 4.0], center = [0.0, 0.0] } ] }
pattern = { type = "voronoi", size = 0.3 }
)";

constexpr std::string_view one_region = R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = 0.3 }
)";

} // namespace

TEST_CASE("a complete model file reads into the geometry description") {
    const auto mf = parse_model(tunnel, "tunnel.toml");
    CHECK(mf.title == "Tunnel, Voronoi bonded-block region");
    CHECK(mf.geometry.max_segment == 0.2);
    REQUIRE(mf.geometry.regions.size() == 3);

    const auto& outer = mf.geometry.regions[0];
    CHECK(outer.name == "outer");
    CHECK(outer.outline.kind == OutlineSpec::Kind::rectangle);
    CHECK(outer.outline.min == Vec2{0, -20});
    CHECK(outer.outline.max == Vec2{20, 20});
    CHECK(outer.minus == std::vector<std::string>{"bonded"});
    CHECK(outer.pattern.kind == PatternSpec::Kind::single);

    const auto& bonded = mf.geometry.regions[1];
    CHECK(bonded.name == "bonded");
    REQUIRE(bonded.holes.size() == 1);
    CHECK(bonded.holes[0].kind == OutlineSpec::Kind::circle);
    CHECK(bonded.holes[0].center == Vec2{6, 6});
    CHECK(bonded.holes[0].radius == 0.5);
    CHECK(bonded.holes[0].max_segment == 0.05);
    CHECK(bonded.minus == std::vector<std::string>{"opening"});
    CHECK(bonded.pattern.kind == PatternSpec::Kind::voronoi);
    CHECK(bonded.pattern.size == 0.3);
    CHECK(bonded.pattern.lloyd_iterations == 2);
    CHECK(bonded.pattern.min_edge == 0.03);
    CHECK(bonded.pattern.seed == 7);
    REQUIRE(bonded.joints.size() == 1);
    CHECK(bonded.joints[0].a == Vec2{0, -6});
    CHECK(bonded.joints[0].b == Vec2{8, -5});
    REQUIRE(bonded.joint_sets.size() == 1);
    const auto& js = bonded.joint_sets[0];
    CHECK(js.angle == 30.0);
    CHECK(js.spacing == 2.0);
    CHECK(js.trace_length == 3.0);
    CHECK(js.gap == 1.0);
    CHECK(js.angle_deviation == 5.0);
    CHECK(js.spacing_deviation == 0.2);
    CHECK(js.length_deviation == 0.3);
    CHECK(js.origin == Vec2{1, 2});
    CHECK(js.seed == 11);

    const auto& opening = mf.geometry.regions[2];
    CHECK(opening.outline.kind == OutlineSpec::Kind::path);
    CHECK(opening.outline.start == Vec2{0, -4});
    REQUIRE(opening.outline.steps.size() == 1);
    CHECK(opening.outline.steps[0].arc);
    CHECK(opening.outline.steps[0].to == Vec2{0, 4});
    CHECK_FALSE(opening.outline.steps[0].clockwise);
    CHECK(opening.outline.max_segment == 0.0); // the model's default
    CHECK(opening.pattern.lloyd_iterations == 0);
    CHECK(opening.pattern.min_edge < 0.0); // default: 0.1 x size, applied by meshing/
    CHECK(opening.pattern.seed == 1);
    CHECK(opening.joint_sets.empty());

    // Lines of regions and keys, for GeometryError reports.
    CHECK(mf.source.file == "tunnel.toml");
    CHECK(mf.source.region_line ==
          std::vector<int>{line_of(tunnel, "[[region]]\nname = \"outer\""),
                           line_of(tunnel, "[[region]]\nname = \"bonded\""),
                           line_of(tunnel, "[[region]]\nname = \"opening\"")});
    CHECK(mf.source.line_of(1, "holes[0]") == line_of(tunnel, "holes ="));
    CHECK(mf.source.line_of(1, "minus[0]") == line_of(tunnel, "minus = [\"opening\"]"));
    CHECK(mf.source.line_of(1, "joint_set[0].spacing") == line_of(tunnel, "spacing = 2"));
    CHECK(mf.source.line_of(1, "joint_set[0]") == line_of(tunnel, "[[region.joint_set]]"));
    CHECK(mf.source.line_of(2, "outline.steps[0]") == line_of(tunnel, "start = [0.0, -4.0]"));
}

TEST_CASE("the other outline and pattern types read with their defaults") {
    constexpr std::string_view text = R"(
[[region]]
name = "poly"
outline = { type = "polygon", points = [[0, 0], [4, 0], [4, 3], [0, 3]] }
pattern = { type = "hexagonal", size = 0.5, origin = [1, 1], angle = 30 }

[[region]]
name = "path"
outline = { type = "path", start = [2, 0], steps = [ { to = [0, 2], center = [0, 0] }, { to = [0, 0] }, { to = [-2, 0], center = [-1, 0], clockwise = true } ] }
pattern = { type = "brick", size = 0.2, aspect = 3, bond = "stack" }

[[region]]
name = "tunnel"
outline = { type = "opening", center = [0, 1], width = 4, floor = -1, half = true, max_segment = 0.1 }
pattern = { type = "trigon", size = 0.4 }

[[region]]
name = "tri"
outline = { type = "rectangle", min = [0, 0], max = [1, 1] }
pattern = { type = "delaunay", size = 0.1 }

[[region]]
name = "bricks"
outline = { type = "rectangle", min = [0, 0], max = [1, 1] }
pattern = { type = "brick", size = 0.1 }
)";
    const auto mf = parse_model(text, "t.toml");
    const auto& r = mf.geometry.regions;
    REQUIRE(r.size() == 5);
    CHECK(r[0].outline.kind == OutlineSpec::Kind::polygon);
    CHECK(r[0].outline.points == std::vector<Vec2>{{0, 0}, {4, 0}, {4, 3}, {0, 3}});
    CHECK(r[0].pattern.kind == PatternSpec::Kind::hexagonal);
    CHECK(r[0].pattern.origin == Vec2{1, 1});
    CHECK(r[0].pattern.angle == 30.0);

    CHECK(r[1].outline.kind == OutlineSpec::Kind::path);
    CHECK(r[1].outline.start == Vec2{2, 0});
    REQUIRE(r[1].outline.steps.size() == 3);
    CHECK(r[1].outline.steps[0].arc);
    CHECK(r[1].outline.steps[0].center == Vec2{0, 0});
    CHECK_FALSE(r[1].outline.steps[0].clockwise);
    CHECK_FALSE(r[1].outline.steps[1].arc);
    CHECK(r[1].outline.steps[2].clockwise);
    CHECK(r[1].pattern.kind == PatternSpec::Kind::brick);
    CHECK(r[1].pattern.aspect == 3.0);
    CHECK_FALSE(r[1].pattern.running_bond);

    CHECK(r[2].outline.kind == OutlineSpec::Kind::opening);
    CHECK(r[2].outline.center == Vec2{0, 1});
    CHECK(r[2].outline.width == 4.0);
    CHECK(r[2].outline.floor_y == -1.0);
    CHECK(r[2].outline.half);
    CHECK(r[2].outline.max_segment == 0.1);
    CHECK(r[2].pattern.kind == PatternSpec::Kind::trigon);

    CHECK(r[3].pattern.kind == PatternSpec::Kind::delaunay);
    CHECK(r[4].pattern.aspect == 2.0);
    CHECK(r[4].pattern.running_bond);
    CHECK(mf.geometry.max_segment == 0.1);
    CHECK(mf.title.empty());
}

TEST_CASE("TOML syntax errors give the line of the parser") {
    const std::string text = std::string(one_region) + "seed = = 3\n";
    const auto e = error_of(text);
    REQUIRE(e);
    CHECK(e->line() == 5);
    CHECK(e->key().empty());
    CHECK(std::string(e->what()).find("t.toml:5: TOML syntax error") == 0);
}

TEST_CASE("unknown keys are errors, with a suggestion when one is close") {
    check_error(std::string(one_region) + "[material]\nE = 1\n", "[material]", "material",
                "unknown key 'material' at top level");
    check_error("[model]\ntitel = \"x\"\n" + std::string(one_region), "titel", "model.titel",
                "did you mean 'title'?");
    check_error(R"([[region]]
name = "a"
outlin = { type = "circle", center = [0, 0], radius = 1 }
)",
                "outlin", "region[0].outlin", "did you mean 'outline'?");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radios = 1 }
)",
                "radios", "region[0].outline.radios", "did you mean 'radius'?");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", sise = 0.3 }
)",
                "sise", "region[0].pattern.sise", "did you mean 'size'?");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "hexagonal", size = 0.3, lloyd = 2 }
)",
                "lloyd", "region[0].pattern.lloyd", "does not apply to a hexagonal pattern");
    check_error(R"([[region]]
name = "a"
outline = { type = "rectangle", min = [0, 0], max = [1, 1], radius = 1 }
)",
                "radius", "region[0].outline.radius", "does not apply to a rectangle outline");
    check_error(std::string(one_region) + "joints = [ { form = [0, 0], to = [1, 1] } ]\n", "form",
                "region[0].joints[0].form", "did you mean 'from'?");
    check_error(std::string(one_region) + "[[region.joint_set]]\nangle = 1\nspaceing = 2\n",
                "spaceing", "region[0].joint_set[0].spaceing", "did you mean 'spacing'?");
    check_error(std::string(one_region) + "boundary = 1\n", "boundary", "region[0].boundary",
                "unknown key 'boundary' in region[0]");
}

TEST_CASE("wrong types are errors that say what was expected and found") {
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = "0.3" }
)",
                "size", "region[0].pattern.size", "expected a number, got string \"0.3\"");
    check_error(R"([[region]]
name = "a"
outline = { type = "polygon", points = [[0, 0], [1, 0], [1, 1, 2]] }
)",
                "points", "region[0].outline.points[2]",
                "expected a point [x, y] of 2 numbers, got an array of 3");
    check_error(R"([[region]]
name = "a"
outline = { type = "polygon", points = [[0, 0], [1, 0], ["x", 1]] }
)",
                "points", "region[0].outline.points[2][0]", "expected a number, got string \"x\"");
    check_error(R"([[region]]
name = "a"
outline = { type = "polygon", points = 3 }
)",
                "points", "region[0].outline.points", "got integer 3");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = 0.3, lloyd = 1.5 }
)",
                "lloyd", "region[0].pattern.lloyd", "expected an integer >= 0, got float 1.5");
    check_error(R"([[region]]
name = 3
)",
                "name = 3", "region[0].name", "expected a string, got integer 3");
    check_error("region = 1\n", "region", "region",
                "expected an array of [[region]] tables (double brackets), got integer 1");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = 0.3 }
minus = "b"
)",
                "minus", "region[0].minus", "expected an array of region names, got string \"b\"");
}

TEST_CASE("missing required keys are reported at the table that lacks them") {
    check_error("[[region]]\noutline = { type = \"circle\", center = [0, 0], radius = 1 }\n",
                "[[region]]", "region[0].name", "missing required key 'name'");
    check_error("[[region]]\nname = \"a\"\n", "[[region]]", "region[0].outline",
                "region 'a': missing required key 'outline'");
    check_error(
        "[[region]]\nname = \"a\"\noutline = { center = [0, 0], radius = 1 }\n", "outline",
        "region[0].outline.type",
        "missing required key 'type': expected one of rectangle, polygon, circle, path, opening");
    check_error("[[region]]\nname = \"a\"\noutline = { type = \"circle\", center = [0, 0] }\n",
                "outline", "region[0].outline.radius", "missing required key 'radius'");
    check_error(
        "[[region]]\nname = \"a\"\noutline = { type = \"circle\", center = [0, 0], radius = 1 }\n",
        "[[region]]", "region[0].pattern", "missing required key 'pattern'");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", lloyd = 1 }
)",
                "pattern", "region[0].pattern.size",
                "missing required key 'size': expected a number > 0 m");
    check_error(std::string(one_region) + "[[region.joint_set]]\nangle = 1\n",
                "[[region.joint_set]]", "region[0].joint_set[0].spacing",
                "missing required key 'spacing'");
    const auto e = error_of("[model]\ntitle = \"x\"\n");
    REQUIRE(e);
    CHECK(std::string(e->what()) ==
          "t.toml: region: a model needs at least one [[region]] table, found none");
}

TEST_CASE("out-of-range values are errors that give the range and the value") {
    constexpr std::string_view text = R"(# tunnel
[[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = 0.3 }

[[region]]
name = "b"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = -0.3 }
)";
    const auto e = error_of(text);
    REQUIRE(e);
    CHECK(std::string(e->what()) == "t.toml:10: region[1].pattern.size: must be > 0 m, got -0.3");
    CHECK(e->line() == 10);
    CHECK(e->key() == "region[1].pattern.size");

    auto region = [](std::string_view outline, std::string_view pattern) {
        return "[[region]]\nname = \"a\"\noutline = " + std::string(outline) +
               "\npattern = " + std::string(pattern) + "\n";
    };
    const std::string circle = "{ type = \"circle\", center = [0, 0], radius = 1 }";
    const std::string voronoi = "{ type = \"voronoi\", size = 0.3 }";

    check_error(region("{ type = \"circle\", center = [0, 0], radius = 0 }", voronoi), "radius",
                "region[0].outline.radius", "must be > 0 m, got 0");
    check_error(region(circle, "{ type = \"voronoi\", size = 0.3, lloyd = -1 }"), "lloyd",
                "region[0].pattern.lloyd", "must be an integer >= 0, got -1");
    check_error(region(circle, "{ type = \"voronoi\", size = 0.3, seed = -2 }"), "seed",
                "region[0].pattern.seed", "must be an integer >= 0, got -2");
    check_error(region(circle, "{ type = \"voronoi\", size = 0.3, min_edge = 0.5 }"), "min_edge",
                "region[0].pattern.min_edge", "must be smaller than size = 0.3 m, got 0.5");
    check_error(region("{ type = \"rectangle\", min = [0, 0], max = [1, 0] }", voronoi), "max",
                "region[0].outline.max", "must exceed min = [0, 0] in both x and y, got [1, 0]");
    check_error(region("{ type = \"polygon\", points = [[0, 0], [1, 0]] }", voronoi), "points",
                "region[0].outline.points", "at least 3 points, got 2");
    check_error(
        region("{ type = \"circel\", center = [0, 0], radius = 1 }", voronoi), "circel",
        "region[0].outline.type",
        "unknown outline type 'circel' (did you mean 'circle'?); expected one of: rectangle, "
        "polygon, circle, path, opening");
    check_error(region(circle, "{ type = \"brick\", size = 0.3, bond = \"english\" }"), "english",
                "region[0].pattern.bond", "expected one of: running, stack");
    check_error(region(circle, "{ type = \"brick\", size = 0.3, aspect = 0 }"), "aspect",
                "region[0].pattern.aspect", "must be > 0, got 0");
    check_error(region("{ type = \"opening\", center = [0, 0], width = 2, floor = 1 }", voronoi),
                "floor", "region[0].outline.floor",
                "must be below the springline center.y = 0 m, got 1");
    check_error(region(circle, voronoi) + "[[region.joint_set]]\nangle = 1\nspacing = 1\n"
                                          "angle_deviation = 90\n",
                "angle_deviation", "region[0].joint_set[0].angle_deviation",
                "must be in [0, 90) degrees, got 90");
    check_error(region(circle, voronoi) + "[[region.joint_set]]\nangle = 1\nspacing = 1\n"
                                          "spacing_deviation = -0.1\n",
                "spacing_deviation", "region[0].joint_set[0].spacing_deviation",
                "must be in [0, 1), got -0.1");
    check_error("[model]\nmax_segment = 0\n" + region(circle, voronoi), "max_segment",
                "model.max_segment", "must be > 0 m, got 0");
    check_error(region(circle, voronoi) + "\n[[region]]\nname = \"\"\n", "name = \"\"",
                "region[1].name", "must be a non-empty string");
}

TEST_CASE("a path arc must end at its radius") {
    constexpr std::string_view text = R"([[region]]
name = "a"
outline = { type = "path", start = [2, 0], steps = [
    { to = [0, 2], center = [0, 0] },
    { to = [-2.1, 0], center = [0, 0] } ] }
pattern = { type = "voronoi", size = 0.3 }
)";
    check_error(text, "{ to = [-2.1", "region[0].outline.steps[1]",
                "arc end [-2.1, 0] is 2.1 m from center [0, 0] but its start [0, 2] is 2 m");
    check_error(R"([[region]]
name = "a"
outline = { type = "path", start = [2, 0], steps = [ { to = [0, 2], clockwise = true } ] }
)",
                "steps", "region[0].outline.steps[0].clockwise", "applies only to an arc step");
}

TEST_CASE("region names are unique and minus names existing other regions") {
    const std::string a = std::string(one_region);
    const std::string b =
        "\n[[region]]\nname = \"b\"\noutline = { type = \"circle\", center = [0, 0], "
        "radius = 1 }\npattern = { type = \"single\" }\n";
    check_error(a + b + "minus = [\"b\"]\n", "minus", "region[1].minus[0]",
                "region 'b' cannot subtract itself");
    check_error(
        a + b + "minus = [\"aa\"]\n", "minus", "region[1].minus[0]",
        "region 'b' subtracts 'aa', but there is no region of that name (did you mean 'a'?)");
    check_error(a + "minus = [\"b\", \"b\"]\n" + b, "minus", "region[0].minus[1]",
                "'b' is already listed as minus[0]");
    const std::string twice = a + "\n" + a;
    const auto e = error_of(twice);
    REQUIRE(e);
    CHECK(e->line() == 7);
    CHECK(e->key() == "region[1].name");
    CHECK(std::string(e->what()).find("'a' is already used by region[0] (line 1)") !=
          std::string::npos);
    // A later region may be subtracted.
    CHECK(parse_model(a + "minus = [\"b\"]\n" + b, "t.toml").geometry.regions[0].minus.size() == 1);
}

TEST_CASE("a geometry error is reported at the line of its key") {
    const auto mf = parse_model(tunnel, "tunnel.toml");
    const auto e = bbm::io::to_input_error(
        mf.source, GeometryError(1, "holes[0]", "hole outside the outline"));
    CHECK(e.line() == line_of(tunnel, "holes ="));
    CHECK(e.key() == "region[1].holes[0]");
    CHECK(std::string(e.what()) == "tunnel.toml:" + std::to_string(line_of(tunnel, "holes =")) +
                                       ": region[1].holes[0]: hole outside the outline");
    // A key the reader never saw falls back to its parent, then to the region.
    CHECK(bbm::io::to_input_error(mf.source, GeometryError(1, "holes[0].points[3]", "x")).line() ==
          line_of(tunnel, "holes ="));
    CHECK(bbm::io::to_input_error(mf.source, GeometryError(2, "overlap", "x")).line() ==
          line_of(tunnel, "[[region]]\nname = \"opening\""));
    CHECK(bbm::io::to_input_error(mf.source, GeometryError(0, "", "x")).key() == "region[0]");
}

TEST_CASE("reading a file") {
    CHECK_THROWS_WITH_AS(bbm::io::read_model("/nonexistent/model.toml"),
                         "/nonexistent/model.toml: cannot open file", InputError);
    const std::string path = "/tmp/bbm_test_input_tunnel.toml";
    {
        std::ofstream out(path);
        out << tunnel;
    }
    const auto mf = bbm::io::read_model(path);
    std::remove(path.c_str());
    CHECK(mf.source.file == path);
    CHECK(mf.geometry.regions.size() == 3);
}
