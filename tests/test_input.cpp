// Tests of the model-file reader (io/model_input): a complete file reads into the
// right geometry description, and every kind of mistake is reported at the right
// line and key.
#include "io/dxf.hpp"
#include "io/model_input.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <vector>
#include <fstream>
#include <optional>
#include <string>

using bbm::GeometryError;
using bbm::InputError;
using bbm::Vec2;
using bbm::io::parse_model;
using bbm::meshing::JointTag;
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
pattern = { type = "voronoi", size = 0.3, size_measure = "area", lloyd = 2, min_edge = 0.03, seed = 7 }
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
    CHECK(bonded.pattern.size_measure == PatternSpec::SizeMeasure::area);
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
    CHECK(opening.pattern.size_measure == PatternSpec::SizeMeasure::feret); // the default
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

TEST_CASE("characters beyond ASCII: fine in strings and comments, a syntax error elsewhere (not undefined behaviour)") {
    // Found by fuzzing: "1×" in a value sent toml++ 3.3 to __builtin_unreachable.
    const auto ok = parse_model("# σ1 at 5 MPa: 40 MPa, φ 34°\n[model]\ntitle = \"σ × φ\" # ν\n"
                                "[[region]]\nname = \"a\"\noutline = { type = \"rectangle\", min = [0, 0], max = [1, 1] }\n"
                                "pattern = { type = \"single\" }\n",
                                "t.toml");
    CHECK(ok.title == "σ × φ");
    const auto e = error_of("[model]\nmax_segment = 1×\n");
    REQUIRE(e.has_value());
    CHECK(e->line() == 2);
    CHECK(std::string(e->what()).find("a character beyond ASCII (U+00D7) outside a string or comment") !=
          std::string::npos);
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
    check_error(std::string(one_region) + "[materials]\nE = 1\n", "[materials]", "materials",
                "unknown key 'materials' at top level (did you mean 'material'?)");
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
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "voronoi", size = 0.3, size_measure = "diameter" }
)",
                "size_measure", "region[0].pattern.size_measure",
                "unknown size measure 'diameter'; expected one of: feret, area");
    check_error(R"([[region]]
name = "a"
outline = { type = "circle", center = [0, 0], radius = 1 }
pattern = { type = "brick", size = 0.3, size_measure = "area" }
)",
                "size_measure", "region[0].pattern.size_measure", "does not apply to a brick pattern");
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
                "lloyd", "region[0].pattern.lloyd", "expected a whole number in [0, 2147483647], got float 1.5");
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
                "region[0].pattern.lloyd", "must be a whole number in [0, 2147483647], got -1");
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

// --- the analysis tables -------------------------------------------------------------

namespace {

// A model with every analysis table, every key given at least once.
constexpr std::string_view analysis = R"([[region]]
name = "outer"
outline = { type = "rectangle", min = [0, -20], max = [20.0, 20.0] }
minus = ["bonded"]
pattern = { type = "single" }
material = "rock"

[[region]]
name = "bonded"
outline = { type = "rectangle", min = [0.0, -8.0], max = [8.0, 8.0] }
minus = ["opening"]
pattern = { type = "voronoi", size = 0.3 }
material = "soft"

[[region]]
name = "opening"
outline = { type = "circle", center = [0, 0], radius = 4 }
pattern = { type = "voronoi", size = 0.3 }

[solver]
mode = "dynamic"
damping = 0.1
safety = 0.2
timestep = 1e-5
gravity = [0.0, -9.81]
detection_tolerance = 0.01
corner_radius = 0.002
new_contact_property = "unbonded"
new_contact_length = "overlap"
output_every = 1000
history_every = 20

[[material]]
name = "rock"
density = 2650

[[material]]
name = "soft"

[[joint_property]]
name = "bond"
law = "softening"
kn = 96.6e9
ks = 40.3e9
friction = 35.0
residual_friction = 25.0
cohesion = 9.5e6
tensile = 3.0e6
tension_softening = [[1.7, 0.5], [4.0, 0.0]]
shear_softening = [[1.3, 0.5], [2.1, 0.0]]

[[joint_property]]
name = "unbonded"
law = "coulomb"
kn = 10e9
ks = 5e9

[[joint_property]]
name = "glue"
law = "elastic"
kn = 1e10
ks = 4e9

[[joint_assignment]]
property = "bond"

[[joint_assignment]]
property = "glue"
tags = ["interface", "real_joint"]
regions = ["outer", "bonded"]

[[boundary]]
name = "top"
type = "stress"
box = { min = [0.0, 19.9], max = [20.0, 20.1] }
sxx = -7.5e6
syy = -15e6
sxy = 2
y_ref = 20.0
dsxx_dy = 13.5e3
dsyy_dy = 27e3
dsxy_dy = 3

[[boundary]]
name = "sides"
type = "velocity"
regions = ["outer"]
vx = 0

[[boundary]]
name = "spin"
type = "velocity"
vy = -0.5
omega = 0.25

[[history]]
name = "ratio"
quantity = "unbalanced_ratio"

[[history]]
name = "crown"
quantity = "displacement_y"
point = [0.0, 4.0]

[[history]]
name = "top force"
quantity = "boundary_force_y"
boundary = "top"

[[stage]]
name = "insitu"
type = "initialize"
sxx = -7.5e6
syy = -15e6
sxy = 1e5
y_ref = 20
dsxx_dy = 13.5e3
dsyy_dy = 27e3
dsxy_dy = 1.0

[[stage]]
type = "solve"
ratio = 1e-6
max_steps = 50000

[[stage]]
name = "dig"
type = "excavate"
regions = ["opening"]
relax_steps = 2000

[[stage]]
type = "cycle"
steps = 100

[[stage]]
type = "solve"
)";

// A softening property to which tests add one line, and the model it sits in.
constexpr std::string_view bond = R"(
[[joint_property]]
name = "bond"
law = "softening"
kn = 1e10
ks = 4e9
cohesion = 1e6
tensile = 5e5
)";

std::string with(std::string_view extra) {
    return std::string(one_region) + std::string(extra);
}

} // namespace

TEST_CASE("a complete analysis reads into the analysis description") {
    using bbm::BoundarySpec;
    using bbm::HistorySpec;
    using bbm::JointPropertySpec;
    using bbm::SolverSpec;
    using bbm::StageSpec;
    const auto mf = parse_model(analysis, "a.toml");
    const auto& an = mf.analysis;

    CHECK(an.solver.mode == SolverSpec::Mode::dynamic);
    CHECK(an.solver.damping == 0.1);
    CHECK(an.solver.safety == 0.2);
    CHECK(an.solver.timestep == 1e-5);
    CHECK(an.solver.gravity == Vec2{0.0, -9.81});
    CHECK(an.solver.detection_tolerance == 0.01);
    CHECK(an.solver.new_contact_property == "unbonded");
    CHECK(an.solver.corner_radius == 0.002);
    CHECK(an.solver.new_contact_length == SolverSpec::NewContactLength::overlap);
    CHECK(an.solver.output_every == 1000);
    CHECK(an.solver.history_every == 20);

    REQUIRE(an.materials.size() == 2);
    CHECK(an.materials[0].name == "rock");
    CHECK(an.materials[0].density == 2650.0);
    CHECK(an.materials[1].name == "soft");
    CHECK(an.materials[1].density == 2700.0);
    using Pair = std::pair<std::string, std::string>;
    CHECK(an.region_material == std::vector<Pair>{{"outer", "rock"}, {"bonded", "soft"}});

    REQUIRE(an.joint_properties.size() == 3);
    const auto& b = an.joint_properties[0];
    CHECK(b.name == "bond");
    CHECK(b.law == "softening");
    CHECK(b.kn == 96.6e9);
    CHECK(b.ks == 40.3e9);
    CHECK(b.friction == 35.0);
    CHECK(b.residual_friction == 25.0);
    CHECK(b.cohesion == 9.5e6);
    CHECK(b.tensile == 3.0e6);
    using Curve = std::vector<std::pair<double, double>>;
    CHECK(b.tension_softening == Curve{{1.7, 0.5}, {4.0, 0.0}});
    CHECK(b.shear_softening == Curve{{1.3, 0.5}, {2.1, 0.0}});
    const auto& u = an.joint_properties[1];
    CHECK(u.law == "coulomb");
    CHECK(u.friction == 30.0);
    CHECK(u.residual_friction == -1.0);
    CHECK(u.cohesion == 0.0);
    CHECK(u.tensile == 0.0);
    CHECK(an.joint_properties[2].law == "elastic");
    CHECK(an.joint_properties[2].kn == 1e10);

    REQUIRE(an.joint_assignments.size() == 2);
    CHECK(an.joint_assignments[0].property == "bond");
    CHECK(an.joint_assignments[0].tags.empty());
    CHECK(an.joint_assignments[0].regions.empty());
    CHECK(an.joint_assignments[1].property == "glue");
    CHECK(an.joint_assignments[1].tags ==
          std::vector<JointTag>{JointTag::interface, JointTag::real_joint});
    CHECK(an.joint_assignments[1].regions == std::vector<std::string>{"outer", "bonded"});

    REQUIRE(an.boundaries.size() == 3);
    const auto& top = an.boundaries[0];
    CHECK(top.name == "top");
    CHECK(top.kind == BoundarySpec::Kind::stress);
    CHECK(top.select.regions.empty());
    REQUIRE(top.select.box);
    CHECK(top.select.box->lo == Vec2{0.0, 19.9});
    CHECK(top.select.box->hi == Vec2{20.0, 20.1});
    CHECK(top.stress.sxx == -7.5e6);
    CHECK(top.stress.syy == -15e6);
    CHECK(top.stress.sxy == 2.0);
    CHECK(top.stress.y_ref == 20.0);
    CHECK(top.stress.dsxx_dy == 13.5e3);
    CHECK(top.stress.dsyy_dy == 27e3);
    CHECK(top.stress.dsxy_dy == 3.0);
    CHECK_FALSE(top.vx);
    const auto& sides = an.boundaries[1];
    CHECK(sides.kind == BoundarySpec::Kind::velocity);
    CHECK(sides.select.regions == std::vector<std::string>{"outer"});
    CHECK_FALSE(sides.select.box);
    CHECK(sides.vx == 0.0);
    CHECK_FALSE(sides.vy);
    CHECK_FALSE(sides.omega);
    CHECK_FALSE(an.boundaries[2].vx);
    CHECK(an.boundaries[2].vy == -0.5);
    CHECK(an.boundaries[2].omega == 0.25);

    REQUIRE(an.histories.size() == 3);
    CHECK(an.histories[0].name == "ratio");
    CHECK(an.histories[0].quantity == HistorySpec::Quantity::unbalanced_ratio);
    CHECK_FALSE(an.histories[0].point);
    CHECK(an.histories[1].quantity == HistorySpec::Quantity::displacement_y);
    CHECK(an.histories[1].point == Vec2{0.0, 4.0});
    CHECK(an.histories[2].quantity == HistorySpec::Quantity::boundary_force_y);
    CHECK(an.histories[2].boundary == "top");

    REQUIRE(an.stages.size() == 5);
    const auto& init = an.stages[0];
    CHECK(init.name == "insitu");
    CHECK(init.kind == StageSpec::Kind::initialize);
    CHECK(init.stress.sxx == -7.5e6);
    CHECK(init.stress.syy == -15e6);
    CHECK(init.stress.sxy == 1e5);
    CHECK(init.stress.y_ref == 20.0);
    CHECK(init.stress.dsxx_dy == 13.5e3);
    CHECK(init.stress.dsyy_dy == 27e3);
    CHECK(init.stress.dsxy_dy == 1.0);
    CHECK(an.stages[1].name == "stage 2");
    CHECK(an.stages[1].kind == StageSpec::Kind::solve);
    CHECK(an.stages[1].ratio == 1e-6);
    CHECK(an.stages[1].max_steps == 50000);
    CHECK(an.stages[2].name == "dig");
    CHECK(an.stages[2].kind == StageSpec::Kind::excavate);
    CHECK(an.stages[2].regions == std::vector<std::string>{"opening"});
    CHECK(an.stages[2].relax_steps == 2000);
    CHECK(an.stages[3].kind == StageSpec::Kind::cycle);
    CHECK(an.stages[3].steps == 100);
    CHECK(an.stages[4].ratio == 1e-5);
    CHECK(an.stages[4].max_steps == 200000);

    // Lines of analysis keys, for errors the solver finds later.
    CHECK(mf.source.line_of("boundary[0].box") == line_of(analysis, "box = {"));
    CHECK(mf.source.line_of("boundary[0].box.min[1]") == line_of(analysis, "box = {"));
    CHECK(mf.source.line_of("stage[2].regions[0]") == line_of(analysis, "regions = [\"opening\"]"));
    CHECK(mf.source.line_of("history[1]") == line_of(analysis, "[[history]]\nname = \"crown\""));
    CHECK(mf.source.line_of("solver.gravity") == line_of(analysis, "gravity"));
    CHECK(mf.source.line_of("nothing[3]") == 0);
    CHECK(mf.source.line_of(0, "material") == line_of(analysis, "material = \"rock\""));
}

TEST_CASE("a model without analysis tables gets the defaults") {
    const auto an = parse_model(one_region, "t.toml").analysis;
    CHECK(an.materials.empty());
    CHECK(an.region_material.empty());
    CHECK(an.joint_properties.empty());
    CHECK(an.joint_assignments.empty());
    CHECK(an.boundaries.empty());
    CHECK(an.histories.empty());
    CHECK(an.stages.empty());
    CHECK(an.solver.mode == bbm::SolverSpec::Mode::quasi_static);
    CHECK(an.solver.damping == 0.8);
    CHECK(an.solver.safety == 0.5);
    CHECK(an.solver.timestep == 0.0);
    CHECK(an.solver.gravity == Vec2{0, 0});
    CHECK(an.solver.new_contact_property.empty());
    CHECK(an.solver.output_every == 0);
    CHECK(an.solver.history_every == 10);
    // A softening law without curves is brittle.
    const auto j = parse_model(with(bond), "t.toml").analysis.joint_properties.at(0);
    CHECK(j.tension_softening.empty());
    CHECK(j.shear_softening.empty());
    CHECK(j.friction == 30.0);
    CHECK(j.residual_friction == -1.0);
}

TEST_CASE("solver and material mistakes") {
    check_error(with("[solver]\ndampng = 0.5\n"), "dampng", "solver.dampng",
                "unknown key 'dampng' in solver (did you mean 'damping'?)");
    check_error(with("[solver]\ndamping = 1\n"), "damping", "solver.damping",
                "must be in [0, 1), got 1");
    check_error(with("[solver]\nsafety = 0\n"), "safety", "solver.safety",
                "must be in (0, 1], got 0");
    check_error(with("[solver]\nmode = \"static\"\n"), "mode", "solver.mode",
                "unknown solver mode 'static'; expected one of: quasi_static, dynamic");
    check_error(with("[solver]\nnew_contact_length = \"half\"\n"), "new_contact_length",
                "solver.new_contact_length", "unknown new contact length 'half'; expected one of: edge, overlap");
    check_error(with("[solver]\ncorner_radius = -1\n"), "corner_radius", "solver.corner_radius",
                "must be >= 0 m, got -1");
    check_error(with("[solver]\nhistory_every = 0\n"), "history_every", "solver.history_every",
                "must be a whole number in [1, 2147483647] steps, got 0");
    check_error(with("[solver]\ngravity = -9.81\n"), "gravity", "solver.gravity",
                "expected a point [x, y], got float -9.81");
    check_error(with("[solver]\nnew_contact_property = \"slip\"\n"), "new_contact_property",
                "solver.new_contact_property",
                "unknown joint property 'slip': the file has no [[joint_property]] tables");
    check_error(with(std::string(bond) + "[solver]\nnew_contact_property = \"bnd\"\n"),
                "new_contact_property", "solver.new_contact_property",
                "unknown joint property 'bnd' (did you mean 'bond'?); joint properties are: bond");
    check_error(with("[material]\nname = \"rock\"\n"), "[material]", "material",
                "expected an array of [[material]] tables (double brackets), got a table");
    check_error(with("[[material]]\ndensity = 2000\n"), "[[material]]", "material[0].name",
                "missing required key 'name'");
    check_error(with("[[material]]\nname = \"rock\"\ndensity = 0\n"), "density",
                "material[0].density", "must be > 0 kg/m³, got 0");
    check_error(with("[[material]]\nname = \"rock\"\n\n[[material]]\nname = \"rock\" # again\n"),
                "# again", "material[1].name",
                "material name 'rock' is already used by material[0] (line 5)");
    const std::string region_rock = std::string(one_region) + "material = \"rok\"\n";
    check_error(region_rock + "[[material]]\nname = \"rock\"\n", "rok", "region[0].material",
                "unknown material 'rok' (did you mean 'rock'?); materials are: rock");
    check_error(region_rock, "rok", "region[0].material",
                "unknown material 'rok': the file has no [[material]] tables");
}

TEST_CASE("joint property mistakes") {
    check_error(with(std::string(bond) + "law2 = 1\n"), "law2", "joint_property[0].law2",
                "did you mean 'law'?");
    std::string unknown_law = with(bond);
    unknown_law.replace(unknown_law.find("\"softening\""), 11, "\"softning\"");
    check_error(unknown_law, "softning", "joint_property[0].law",
                "unknown joint law 'softning' (did you mean 'softening'?); expected one of: "
                "elastic, coulomb, softening, barton_bandis");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"elastic\"\nks = 1e9\n"),
                "[[joint_property]]", "joint_property[0].kn",
                "joint property 'j': missing required key 'kn': expected a number > 0 Pa/m");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"coulomb\"\nkn = -1\nks = 1\n"),
                "kn", "joint_property[0].kn", "must be > 0 Pa/m, got -1");
    check_error(with(std::string(bond) + "friction = 90\n"), "friction",
                "joint_property[0].friction", "must be in [0, 90) degrees, got 90");
    // The confined friction: both keys or neither, a stress > 0, softening law only.
    {
        const auto read = parse_model(with(std::string(bond) + "confined_friction = 45\nconfined_friction_from = 60e6\n"),
                                      "t.toml");
        CHECK(read.analysis.joint_properties[0].confined_friction == 45.0);
        CHECK(read.analysis.joint_properties[0].confined_friction_from == 60e6);
    }
    check_error(with(std::string(bond) + "confined_friction = 45 # alone\n"), "# alone",
                "joint_property[0].confined_friction", "go together");
    check_error(with(std::string(bond) + "confined_friction = 45\nconfined_friction_from = 0 # zero\n"), "# zero",
                "joint_property[0].confined_friction_from", "must be > 0 Pa, got 0");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"coulomb\"\nkn = 1\nks = 1\n"
                     "confined_friction = 45\n"),
                "confined_friction", "joint_property[0].confined_friction",
                "key 'confined_friction' does not apply to a coulomb joint property");
    // A fracture energy stretches a curve: it needs one.
    {
        const auto read = parse_model(
            with(std::string(bond) + "tension_softening = [[1.7, 0.5], [4.0, 0.0]]\ntension_fracture_energy = 250\n"),
            "t.toml");
        CHECK(read.analysis.joint_properties[0].tension_fracture_energy == 250.0);
        CHECK(read.analysis.joint_properties[0].shear_fracture_energy < 0.0);
    }
    check_error(with(std::string(bond) + "shear_fracture_energy = 900 # no curve\n"), "# no curve",
                "joint_property[0].shear_fracture_energy", "needs shear_softening");
    check_error(with(std::string(bond) + "tension_fracture_energy = 0 # zero\n"), "# zero",
                "joint_property[0].tension_fracture_energy", "must be > 0 J/m2, got 0");
    // A softening law needs both peaks; a curve only belongs to a softening law.
    std::string no_peak = with(bond);
    no_peak.replace(no_peak.find("tensile = 5e5"), 13, "tensile = 0  ");
    check_error(no_peak, "tensile = 0", "joint_property[0].tensile",
                "a softening law needs tensile > 0 Pa, the peak the tension softening curve is "
                "normalised by; got 0");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"softening\"\nkn = 1\nks = 1\n"
                     "tensile = 1\n"),
                "[[joint_property]]", "joint_property[0].cohesion",
                "joint property 'j': missing required key 'cohesion'");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"coulomb\"\nkn = 1\nks = 1\n"
                     "tension_softening = [[2, 0]]\n"),
                "tension_softening", "joint_property[0].tension_softening",
                "key 'tension_softening' does not apply to a coulomb joint property; its keys "
                "are: name, law, kn, ks, face_shear, friction, residual_friction, cohesion, tensile");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"elastic\"\nkn = 1\nks = 1\n"
                     "friction = 30\n"),
                "friction", "joint_property[0].friction",
                "key 'friction' does not apply to an elastic joint property");
    // Barton-Bandis: JRC in [0, 20], JCS > 0 required, a length > 0; no bond keys.
    {
        const auto read = parse_model(with("[[joint_property]]\nname = \"rough\"\nlaw = \"barton_bandis\"\n"
                                           "kn = 1e10\nks = 1e10\nfriction = 28\njrc = 12\njcs = 80e6\n"
                                           "joint_length = 0.5\n"),
                                      "t.toml");
        const auto& j = read.analysis.joint_properties[0];
        CHECK(j.law == "barton_bandis");
        CHECK(j.friction == 28.0);
        CHECK(j.jrc == 12.0);
        CHECK(j.jcs == 80e6);
        CHECK(j.joint_length == 0.5);
    }
    const std::string rough = "[[joint_property]]\nname = \"rough\"\nlaw = \"barton_bandis\"\nkn = 1\nks = 1\n";
    check_error(with(rough + "jcs = 80e6\njrc = 21\n"), "jrc = 21", "joint_property[0].jrc",
                "must be in [0, 20], got 21");
    check_error(with(rough + "jrc = 10\n"), "[[joint_property]]", "joint_property[0].jcs",
                "joint property 'rough': missing required key 'jcs'");
    check_error(with(rough + "jrc = 10\njcs = 80e6\ncohesion = 1e6\n"), "cohesion", "joint_property[0].cohesion",
                "key 'cohesion' does not apply to a barton_bandis joint property; its keys are: name, law, kn, ks, "
                "face_shear, friction, jrc, jcs, joint_length");
    check_error(with("[[joint_property]]\nname = \"j\"\nlaw = \"coulomb\"\nkn = 1\nks = 1\njrc = 5\n"), "jrc",
                "joint_property[0].jrc", "key 'jrc' does not apply to a coulomb joint property");
    check_error(with(std::string(bond) + "[[joint_property]]\nname = \"bond\" # again\n"),
                "# again", "joint_property[1].name",
                "joint property name 'bond' is already used by joint_property[0]");
}

TEST_CASE("softening curves must soften") {
    const std::string b = with(bond);
    check_error(b + "tension_softening = [[1.7, 0.5], [4.0, 0.1]]\n", "tension_softening",
                "joint_property[0].tension_softening[1][1]",
                "the last point must have beta = 0 (the curve must end at zero strength), got 0.1");
    check_error(b + "shear_softening = [[2.0, 0.2], [2.1, 0.6], [3, 0]]\n", "shear_softening",
                "joint_property[0].shear_softening[1]",
                "the curve snaps back: alpha - beta (the plastic displacement) must increase "
                "from point to point, got 2.1 - 0.6 = 1.5 after 2 - 0.2 = 1.8 at "
                "shear_softening[0]");
    check_error(b + "tension_softening = [[1.7, 0.5], [1.5, 0.0]]\n", "tension_softening",
                "joint_property[0].tension_softening[1][0]",
                "the curve snaps back: alpha must increase from point to point, got 1.5 after 1.7");
    check_error(b + "tension_softening = [[1.0, 0.5], [4.0, 0.0]]\n", "tension_softening",
                "joint_property[0].tension_softening[0][0]",
                "the first alpha must be > 1 (alpha = 1 is the peak), got 1");
    check_error(b + "tension_softening = [[1.7, 1.5], [4.0, 0.0]]\n", "tension_softening",
                "joint_property[0].tension_softening[0][1]", "must be in [0, 1], got 1.5");
    check_error(b + "tension_softening = [[1.7, 0.0], [4.0, 0.0]]\n", "tension_softening",
                "joint_property[0].tension_softening[1]",
                "the curve already ends at tension_softening[0]");
    check_error(b + "tension_softening = [[1.7, 0.5, 1]]\n", "tension_softening",
                "joint_property[0].tension_softening[0]",
                "expected a point [alpha, beta] of 2 numbers, got an array of 3");
    // Each point on its own line: the error is at the point's line.
    check_error(b + "tension_softening = [\n  [1.7, 0.5],\n  [4.0, 0.2],\n]\n", "[4.0, 0.2]",
                "joint_property[0].tension_softening[1][1]", "the last point must have beta = 0");
}

TEST_CASE("joint assignment and boundary mistakes") {
    const std::string b = with(bond);
    check_error(b + "[[joint_assignment]]\nproperty = \"bnd\"\n", "bnd",
                "joint_assignment[0].property",
                "unknown joint property 'bnd' (did you mean 'bond'?); joint properties are: bond");
    check_error(b + "[[joint_assignment]]\ntags = [\"inner\"]\n", "[[joint_assignment]]",
                "joint_assignment[0].property", "missing required key 'property'");
    check_error(b + "[[joint_assignment]]\nproperty = \"bond\"\ntags = [\"inner\", \"radail\"]\n",
                "radail", "joint_assignment[0].tags[1]",
                "unknown joint tag 'radail' (did you mean 'radial'?); expected one of: inner, "
                "radial, peripheral, real_joint, interface");
    check_error(b + "[[joint_assignment]]\nproperty = \"bond\"\ntags = [\"inner\", \"inner\"]\n",
                "tags", "joint_assignment[0].tags[1]", "'inner' is already listed as tags[0]");
    check_error(b + "[[joint_assignment]]\nproperty = \"bond\"\nregions = []\n", "regions",
                "joint_assignment[0].regions",
                "must list at least one region, got an empty array; leave 'regions' out for "
                "joints of any region");
    check_error(b + "[[joint_assignment]]\nproperty = \"bond\"\nregions = [\"b\"]\n", "regions",
                "joint_assignment[0].regions[0]", "unknown region 'b'; regions are: a");

    check_error(with("[[boundary]]\nname = \"top\"\ntype = \"stress\"\nsyy = -1e6\nvx = 0\n"), "vx",
                "boundary[0].vx",
                "key 'vx' does not apply to a stress boundary; its keys are: name, type, "
                "regions, box, sxx, syy, sxy, y_ref, dsxx_dy, dsyy_dy, dsxy_dy");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"velocity\"\nsyy = 0\n"), "syy",
                "boundary[0].syy", "key 'syy' does not apply to a velocity boundary");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"velocity\"\nregions = [\"a\"]\n"),
                "[[boundary]]", "boundary[0]",
                "boundary 'fix': a velocity boundary needs at least one of vx, vy, omega");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"traction\"\n"), "traction",
                "boundary[0].type", "unknown boundary type 'traction'");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"velocity\"\nvx = 0\n"
                     "box = { min = [0, 1], max = [1, 1] }\n"),
                "box", "boundary[0].box.max",
                "must exceed min = [0, 1] in both x and y, got [1, 1]");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"velocity\"\nvx = 0\n"
                     "box = { min = [0, 1] }\n"),
                "box", "boundary[0].box.max", "missing required key 'max'");
    check_error(with("[[boundary]]\nname = \"fix\"\ntype = \"velocity\"\nvx = \"0\"\n"),
                "vx =", "boundary[0].vx", "expected a number, got string \"0\"");
}

TEST_CASE("history and stage mistakes") {
    const std::string top = with("[[boundary]]\nname = \"top\"\ntype = \"stress\"\nsyy = -1e6\n");
    check_error(top + "[[history]]\nname = \"crown\"\nquantity = \"displacement_y\"\n",
                "[[history]]", "history[0].point",
                "history 'crown': missing required key 'point': expected a point [x, y]");
    check_error(top + "[[history]]\nname = \"r\"\nquantity = \"unbalanced_ratio\"\n"
                      "point = [0, 0]\n",
                "point", "history[0].point",
                "key 'point' does not apply to an unbalanced_ratio history; its keys are: name, "
                "quantity");
    check_error(top + "[[history]]\nname = \"f\"\nquantity = \"boundary_force_x\"\n"
                      "boundary = \"tpo\"\n",
                "tpo", "history[0].boundary",
                "unknown boundary 'tpo' (did you mean 'top'?); boundaries are: top");
    check_error(top + "[[history]]\nname = \"f\"\nquantity = \"boundary_force_x\"\n", "[[history]]",
                "history[0].boundary", "missing required key 'boundary'");
    check_error(top + "[[history]]\nname = \"f\"\nquantity = \"displacment_x\"\n", "displacment_x",
                "history[0].quantity", "(did you mean 'displacement_x'?)");

    check_error(with("[[stage]]\ntype = \"solve\"\n\n[[stage]]\nname = \"dig\"\n"
                     "type = \"excavate\"\nregions = [\"a\", \"tunnel\"]\n"),
                "regions", "stage[1].regions[1]", "unknown region 'tunnel'; regions are: a");
    check_error(with("[[stage]]\ntype = \"excavate\"\n"), "[[stage]]", "stage[0].regions",
                "stage 'stage 1': missing required key 'regions': expected a non-empty array of "
                "region names");
    check_error(with("[[stage]]\ntype = \"excavate\"\nregions = []\n"), "regions",
                "stage[0].regions", "must list at least one region, got an empty array");
    check_error(with("[[stage]]\ntype = \"cycle\"\nsteps = 10\nratio = 1e-4\n"), "ratio",
                "stage[0].ratio",
                "key 'ratio' does not apply to a cycle stage; its keys are: name, type, steps");
    check_error(with("[[stage]]\ntype = \"cycle\"\n"), "[[stage]]", "stage[0].steps",
                "missing required key 'steps': expected an integer >= 1");
    check_error(with("[[stage]]\ntype = \"cycle\"\nsteps = 0\n"), "steps", "stage[0].steps",
                "must be an integer >= 1, got 0");
    check_error(with("[[stage]]\ntype = \"solve\"\nratio = 1\n"), "ratio", "stage[0].ratio",
                "must be in (0, 1), got 1");
    check_error(with("[[stage]]\ntype = \"solve\"\nmax_steps = 1.5\n"), "max_steps",
                "stage[0].max_steps", "expected a whole number >= 1 steps, got float 1.5");
    check_error(with("[[stage]]\ntype = \"initialize\"\nratio = 1e-5\n"), "ratio", "stage[0].ratio",
                "does not apply to an initialize stage");
    check_error(with("[[stage]]\ntype = \"run\"\n"), "run", "stage[0].type",
                "unknown stage type 'run'; expected one of: initialize, solve, excavate, cycle, "
                "elastic, install");
    check_error(with("[[stage]]\ntype = \"elastic\"\nsteps = 10\n"), "steps", "stage[0].steps",
                "key 'steps' does not apply to an elastic stage; its keys are: name, type");
    check_error(with("[[stage]]\ntype = \"solve\"\n\n[[stage]]\nname = \"stage 1\"\n"
                     "type = \"solve\"\n"),
                "name = \"stage 1\"", "stage[1].name",
                "stage name 'stage 1' is already used by stage[0] (line 5)");
}

TEST_CASE("excavate: a support kept as a fraction or as a pressure, and their mistakes") {
    const auto mf = parse_model(with("[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\nrelax_steps = 100\n"
                                     "keep = 0.25\npressure = 2e6\n"),
                                "t.toml");
    CHECK(mf.analysis.stages[0].keep == 0.25);
    CHECK(mf.analysis.stages[0].pressure == 2e6);
    check_error(with("[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\nkeep = 1.0\n"), "keep",
                "stage[0].keep", "must be in [0, 1), got 1");
    check_error(with("[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\npressure = -1e6\n"), "pressure",
                "stage[0].pressure", "must be >= 0 Pa, got -1e+06");
    check_error(with("[[stage]]\ntype = \"cycle\"\nsteps = 10\npressure = 1e6\n"), "pressure",
                "stage[0].pressure", "");
}

TEST_CASE("excavate: a support path, and its mistakes") {
    const std::string initialize = "[[stage]]\ntype = \"initialize\"\nsxx = -2e6\n\n";
    const std::string excavate = "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\nrelax_steps = 100\n";
    const auto mf = parse_model(with(initialize + excavate + "support_path = [[0, 1, 1], [0.4, 0.6, 0.9], [1, 0, 0]]\n"),
                                "t.toml");
    const auto& path = mf.analysis.stages[1].support_path;
    REQUIRE(path.size() == 3);
    CHECK(path[1] == std::array<double, 3>{0.4, 0.6, 0.9});
    auto fails = [&](const std::string& rows, const std::string& at, const std::string& path_key,
                     const std::string& message) {
        check_error(with(initialize + excavate + "support_path = " + rows + "\n"), at, path_key, message);
    };
    fails("[[0.1, 1, 1], [1, 0, 0]]", "support_path", "stage[1].support_path[0][0]",
          "the first row must be at t = 0 (the excavation), got 0.1");
    fails("[[0, 1, 1], [0.5, 0.5, 0.5], [0.5, 0, 0], [1, 0, 0]]", "support_path", "stage[1].support_path[2][0]",
          "t must increase from row to row, got 0.5 after 0.5");
    fails("[[0, 1, 1], [0.5, 0.5, 0.5]]", "support_path", "stage[1].support_path",
          "needs at least two rows, from t = 0 to t = 1 (the end of relax_steps), got the last at t = 0.5");
    fails("[[0, 1, 1], [1, 0]]", "support_path", "stage[1].support_path[1]",
          "expected a row [t, k_mean, k_deviator] of 3 numbers, got an array of 2");
    fails("[[0, 1, 1], [1, 3, 0]]", "support_path", "stage[1].support_path[1][1]", "must be in [-1, 2], got 3");
    check_error(with(excavate + "support_path = [[0, 1, 1], [1, 0, 0]]\n"), "support_path", "stage[0].support_path",
                "needs an initialize stage before it: the in-situ stress whose mean and deviator it relaxes");
    check_error(with(initialize + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\n"
                                  "support_path = [[0, 1, 1], [1, 0, 0]]\n"),
                "support_path", "stage[1].support_path", "needs relax_steps >= 1: the steps the path is run over");
    check_error(with(initialize + excavate + "keep = 0.2\nsupport_path = [[0, 1, 1], [1, 0, 0]]\n"), "keep",
                "stage[1].keep", "cannot go with support_path: the path's last row is the support kept");
}

TEST_CASE("bolts: a set, its installation, and its mistakes") {
    const std::string set = "[[bolt]]\nname = \"rebar\"\nbolts = [[[0.0, 0.0], [2.0, 0.0]]]\n"
                            "diameter = 0.025\nyield_force = 200e3\nbond_stiffness = 1e9\nspacing = 1.5\n";
    const auto mf = parse_model(with(set + "\n[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\n"
                                           "relax_steps = 100\nsteps = 40\n\n[[stage]]\ntype = \"install\"\n"
                                           "supports = [\"rebar\"]\n"),
                                "t.toml");
    REQUIRE(support_state<bbm::Bolts>(mf.analysis.supports).size() == 1);
    const auto& b = support_state<bbm::Bolts>(mf.analysis.supports)[0];
    CHECK(b.name == "rebar");
    CHECK(b.bolts.size() == 1);
    CHECK(b.area == doctest::Approx(4.9087e-4).epsilon(1e-4));
    CHECK(b.spacing == 1.5);
    CHECK(b.bond_strength == 0.0);
    CHECK(mf.analysis.stages[0].steps == 40);
    CHECK(mf.analysis.stages[0].keep == 0.0);
    CHECK(mf.analysis.stages[0].pressure == 0.0);
    CHECK(mf.analysis.stages[1].kind == bbm::StageSpec::Kind::install);
    CHECK(mf.analysis.stages[1].supports == std::vector<std::string>{"rebar"});

    check_error(with("[[bolt]]\nname = \"b\"\nbond_stiffness = 1e9\n"), "[[bolt]]", "bolt[0]",
                "bolt set 'b': no bolts: give 'bolts'");
    check_error(with("[[bolt]]\nname = \"b\"\nbolts = [[[1.0, 1.0], [1.0, 1.0]]]\nbond_stiffness = 1e9\n"),
                "bolts =", "bolt[0].bolts[0]", "head and toe are the same point");
    check_error(with("[[bolt]]\nname = \"b\"\nring = { center = [0, 0], radius = 2.0, length = 3.0, count = 4, "
                     "spacing = 1.0 }\nbond_stiffness = 1e9\n"),
                "ring =", "bolt[0].ring", "give the bolts' 'count' or their 'spacing'");
    check_error(with("[[bolt]]\nname = \"b\"\nbolts = [[[0.0, 0.0], [1.0, 0.0]]]\n"),
                "[[bolt]]", "bolt[0].bond_stiffness", "missing required key 'bond_stiffness'");
    check_error(with("[[bolt]]\nname = \"b\"\nbolts = [[[0.0, 0.0], [1.0, 0.0]]]\nbond_stiffness = 1e9\n"
                     "area = 5e-4\ndiameter = 0.025\n"),
                "diameter = 0.025", "bolt[0].diameter", "give the steel's 'area' or its 'diameter', not both");
    check_error(with(set + "[[stage]]\ntype = \"install\"\nsupports = [\"rebars\"]\n"), "supports",
                "stage[0].supports[0]", "unknown support 'rebars' (did you mean 'rebar'?)");
    check_error(with("[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\nrelax_steps = 100\nsteps = 200\n"),
                "steps = 200", "stage[0].steps", "must be at most relax_steps (100), got 200");
}

TEST_CASE("liners: a ring along an opening, and its mistakes") {
    const std::string liner = "[[liner]]\nname = \"shotcrete\"\ncenter = [0.0, 0.0]\nradius = 4.0\nfrom = -90.0\n"
                              "to = 90.0\nthickness = 0.1\nsymmetric_ends = true\n";
    const auto mf = parse_model(with(liner + "\n[[stage]]\ntype = \"install\"\nsupports = [\"shotcrete\"]\n"), "t.toml");
    REQUIRE(support_state<bbm::Liners>(mf.analysis.supports).size() == 1);
    CHECK(support_state<bbm::Liners>(mf.analysis.supports)[0].radius == 4.0);
    CHECK(support_state<bbm::Liners>(mf.analysis.supports)[0].symmetric_ends);
    CHECK(support_state<bbm::Liners>(mf.analysis.supports)[0].young == 30e9);
    check_error(with("[[liner]]\nname = \"l\"\ncenter = [0, 0]\nradius = 1.0\n"), "[[liner]]", "liner[0].thickness",
                "missing required key 'thickness'");
    check_error(with("[[liner]]\nname = \"l\"\ncenter = [0, 0]\nradius = 1.0\nthickness = 0.1\nsymmetric_ends = true\n"),
                "symmetric_ends", "liner[0].symmetric_ends", "a closed ring (from 0 to 360 degrees) has no ends");
    check_error(with("[[liner]]\nname = \"l\"\ncenter = [0, 0]\nradius = 1.0\nthickness = 0.1\nfrom = 90\nto = 0\n"),
                "[[liner]]", "liner[0]", "'to' must be above 'from'");
    check_error(with("[[liner]]\nname = \"l\"\ncenter = [0, 0]\nradius = 1.0\nthickness = 0.1\n"
                     "tension_capacity = 1e5\n"),
                "tension_capacity", "liner[0].tension_capacity", "needs a thrust capacity");
    check_error(with(liner + "[[bolt]]\nname = \"shotcrete\"\nbolts = [[[0.0, 0.0], [1.0, 0.0]]]\nbond_stiffness = 1e9\n"),
                "name = \"shotcrete\"\ncenter", "liner[0].name", "name 'shotcrete' is already used by bolt[0]");
}

TEST_CASE("analysis tables may come before the tables they name") {
    const std::string text = R"([[history]]
name = "f"
quantity = "boundary_force_y"
boundary = "top"

[[boundary]]
name = "top"
type = "velocity"
regions = ["a"]
vy = -1e-6

[[stage]]
type = "excavate"
regions = ["a"]

)" + std::string(one_region) +
                             "material = \"rock\"\n\n[[material]]\nname = \"rock\"\n";
    const auto an = parse_model(text, "t.toml").analysis;
    CHECK(an.histories.at(0).boundary == "top");
    CHECK(an.boundaries.at(0).select.regions == std::vector<std::string>{"a"});
    CHECK(an.stages.at(0).name == "stage 1");
    CHECK(an.region_material.size() == 1);
}

// --- deformable regions ----------------------------------------------------------------

namespace {

// The tunnel's outer region meshed, graded toward the bonded region.
constexpr std::string_view deformable = R"([[region]]
name = "outer"
outline = { type = "rectangle", min = [0, -20], max = [20, 20] }
minus = ["bonded"]
pattern = { type = "single" }
material = "rock"
mesh = { size = 0.4, size_far = 3.0, grading = 0.25, toward = ["bonded"] }

[[region]]
name = "bonded"
outline = { type = "rectangle", min = [0, -8], max = [8, 8] }
pattern = { type = "voronoi", size = 0.3 }
material = "rock"
mesh = { size = 0.1 }

[[material]]
name = "rock"
density = 2650
young = 20e9
poisson = 0.25
deformable_fraction = 0.9

[[stage]]
name = "equilibrium"
type = "elastic"
)";

/// Region "a" of one_region with a mesh, then `extra` (other tables).
std::string meshed(std::string_view mesh, std::string_view extra) {
    return std::string(one_region) + "mesh = " + std::string(mesh) + "\n" + std::string(extra);
}

constexpr std::string_view rock = "\n[[material]]\nname = \"rock\"\nyoung = 1e10\n";

} // namespace

TEST_CASE("a deformable region: its mesh, its material's elasticity, an elastic stage") {
    const auto mf = parse_model(deformable, "d.toml");
    const auto& outer = mf.geometry.regions.at(0).mesh;
    CHECK(outer.enabled);
    CHECK(outer.size == 0.4);
    CHECK(outer.size_far == 3.0);
    CHECK(outer.grading == 0.25);
    CHECK(outer.toward == std::vector<std::string>{"bonded"});
    const auto& bonded = mf.geometry.regions.at(1).mesh;
    CHECK(bonded.enabled);
    CHECK(bonded.size == 0.1);
    CHECK(bonded.size_far == 0.0); // = size
    CHECK(bonded.grading == 0.0);
    CHECK(bonded.toward.empty());
    CHECK_FALSE(parse_model(one_region, "t.toml").geometry.regions.at(0).mesh.enabled);

    const auto& m = mf.analysis.materials.at(0);
    CHECK(m.density == 2650.0);
    CHECK(m.young == 20e9);
    CHECK(m.poisson == 0.25);
    CHECK(m.deformable_fraction == 0.9);
    const auto plain = parse_model(with("[[material]]\nname = \"rock\"\n"), "t.toml");
    CHECK(plain.analysis.materials.at(0).young == 0.0);
    CHECK(plain.analysis.materials.at(0).poisson == 0.2);
    CHECK(plain.analysis.materials.at(0).deformable_fraction == 0.0);

    REQUIRE(mf.analysis.stages.size() == 1);
    CHECK(mf.analysis.stages[0].kind == bbm::StageSpec::Kind::elastic);
    CHECK(mf.analysis.stages[0].name == "equilibrium");

    // Lines for errors found when the blocks are meshed.
    CHECK(mf.source.line_of(0, "mesh") == line_of(deformable, "mesh = { size = 0.4"));
    CHECK(mf.source.line_of(0, "mesh.toward") == line_of(deformable, "mesh = { size = 0.4"));
    CHECK(mf.source.line_of(1, "mesh") == line_of(deformable, "mesh = { size = 0.1"));
    // Regions that name no material take the file's first one.
    CHECK(parse_model(meshed("{ size = 0.1 }", rock), "t.toml").geometry.regions[0].mesh.enabled);
}

TEST_CASE("mesh and elasticity mistakes") {
    check_error(meshed("{ size = 0 }", rock), "mesh", "region[0].mesh.size",
                "must be > 0 m, got 0");
    check_error(meshed("{ size = -0.2 }", rock), "mesh", "region[0].mesh.size",
                "must be > 0 m, got -0.2");
    check_error(meshed("{ size_far = 2 }", rock), "mesh", "region[0].mesh.size",
                "region 'a': missing required key 'size': expected a number > 0 m");
    check_error(meshed("{ size = 0.4, size_far = 0.3, toward = [\"b\"] }", rock), "mesh",
                "region[0].mesh.size_far", "must be >= size = 0.4 m, got 0.3");
    check_error(meshed("{ size = 0.4, grading = -1 }", rock), "mesh", "region[0].mesh.grading",
                "must be >= 0 m/m, got -1");
    check_error(meshed("{ size = 0.4, grading = 0.2 }", rock), "mesh", "region[0].mesh.grading",
                "grades the mesh by the distance from the regions listed in 'toward', but none "
                "are listed");
    check_error(meshed("{ sise = 0.4 }", rock), "mesh", "region[0].mesh.sise",
                "unknown key 'sise' in region[0].mesh (did you mean 'size'?)");
    check_error(meshed("0.4", rock), "mesh", "region[0].mesh",
                "expected a mesh table { size = ..., ... }, got float 0.4");

    // `toward` names other regions, like `minus`.
    const std::string b = "\n[[region]]\nname = \"bonded\"\noutline = { type = \"circle\", "
                          "center = [5, 0], radius = 1 }\npattern = { type = \"single\" }\n";
    check_error(
        meshed("{ size = 0.4, grading = 0.1, toward = [\"bonde\"] }", b + std::string(rock)),
        "mesh", "region[0].mesh.toward[0]",
        "region 'a' refines its mesh toward 'bonde', but there is no region of that name "
        "(did you mean 'bonded'?); regions are: a, bonded");
    check_error(meshed("{ size = 0.4, toward = [\"a\"] }", b + std::string(rock)), "mesh",
                "region[0].mesh.toward[0]", "region 'a' cannot refine its mesh toward itself");
    check_error(meshed("{ size = 0.4, toward = [\"bonded\", \"bonded\"] }", b + std::string(rock)),
                "mesh", "region[0].mesh.toward[1]", "'bonded' is already listed as mesh.toward[0]");

    // A deformable region needs the elasticity of its material.
    const std::string no_young = "\n[[material]]\nname = \"rock\"\ndensity = 2600\n";
    check_error(meshed("{ size = 0.1 }", "material = \"rock\"\n" + no_young), "mesh",
                "region[0].mesh",
                "region 'a' is deformable (has a mesh) but its material 'rock' has no young "
                "modulus");
    check_error(meshed("{ size = 0.1 }", no_young), "mesh", "region[0].mesh",
                "region 'a' is deformable (has a mesh) but its material 'rock' has no young "
                "modulus");
    check_error(meshed("{ size = 0.1 }", ""), "mesh", "region[0].mesh",
                "region 'a' is deformable (has a mesh) but has no material");
    // Another region names a material, this one none: it has the default, rigid material.
    check_error(meshed("{ size = 0.1 }", b + "material = \"rock\"\n" + std::string(rock)), "mesh",
                "region[0].mesh", "region 'a' is deformable (has a mesh) but has no material");

    // Rigid blocks take no share of the deformation: a material that gives deformable
    // blocks one would only stiffen the region's joints (it once did, silently).
    const std::string split = "\n[[material]]\nname = \"split\"\nyoung = 1e10\ndeformable_fraction = 0.9\n";
    check_error(std::string(one_region) + "material = \"split\"\n" + split, "material = \"split\"",
                "region[0].material",
                "region 'a' has rigid blocks (no mesh) but its material 'split' gives deformable blocks a "
                "share of the deformation (deformable_fraction 0.9)");
    check_error(std::string(one_region) + split, "[[region]]", "region[0]",
                "region 'a' has rigid blocks (no mesh) but its material 'split'");
    CHECK(parse_model(meshed("{ size = 0.1 }", split), "t.toml").geometry.regions[0].mesh.enabled);

    check_error(with("[[material]]\nname = \"rock\"\nyoung = 1e10\npoisson = 0.5\n"), "poisson",
                "material[0].poisson", "must be in [0, 0.5), got 0.5");
    check_error(with("[[material]]\nname = \"rock\"\nyoung = 1e10\npoisson = -0.1\n"), "poisson",
                "material[0].poisson", "must be in [0, 0.5), got -0.1");
    check_error(with("[[material]]\nname = \"rock\"\nyoung = 1e10\ndeformable_fraction = 1.2\n"),
                "deformable_fraction", "material[0].deformable_fraction",
                "must be in [0, 1), got 1.2");
    check_error(with("[[material]]\nname = \"rock\"\nyoung = 1e10\ndeformable_fraction = 1\n"),
                "deformable_fraction", "material[0].deformable_fraction",
                "must be in [0, 1), got 1");
    check_error(with("[[material]]\nname = \"rock\"\nyoung = 0\n"), "young", "material[0].young",
                "must be > 0 Pa, got 0");
    check_error(with("[[material]]\nname = \"rock\"\npoisson = 0.3\n"), "poisson",
                "material[0].poisson",
                "material 'rock': applies to deformable blocks and needs 'young', which is not "
                "given");
    check_error(with("[[material]]\nname = \"rock\"\nyung = 1e10\n"), "yung", "material[0].yung",
                "did you mean 'young'?");
}

TEST_CASE("fracture sets: a generated set, a set read from a CSV file, and their mistakes") {
    const std::string set = "[[region.dfn]]\nname = \"J1\"\norientation = { distribution = \"von_mises\", mean = 30.0, "
                            "concentration = 20.0 }\nlength = { distribution = \"power_law\", exponent = 2.5, min = "
                            "0.1, max = 1.0 }\np21 = 2.0\nseed = 7\n";
    const auto mf = parse_model(with(set + "\n[[region.dfn]]\nname = \"J2\"\norientation = { distribution = \"list\", "
                                           "angles = [100.0, -10.0], weights = [2.0, 1.0] }\nlength = { distribution "
                                           "= \"lognormal\", mean = 0.5, std = 0.2 }\ncount = 40\ncentres = "
                                           "\"clustered\"\ncluster = { size = 5, radius = 0.1 }\nterminate = { at = "
                                           "[\"J1\"], probability = 0.3 }\n"),
                                "t.toml");
    const auto& dfn = mf.geometry.regions[0].dfn;
    REQUIRE(dfn.size() == 2);
    CHECK(dfn[0].p21 == 2.0);
    CHECK(dfn[0].seed == 7);
    CHECK(dfn[0].length.kind == bbm::meshing::FractureLengthSpec::Kind::power_law);
    CHECK(dfn[0].length.exponent == 2.5);
    CHECK(dfn[1].count == 40);
    CHECK(dfn[1].orientation.angles == std::vector<double>{100.0, 170.0});
    CHECK(dfn[1].centres == bbm::meshing::DfnSetSpec::Centres::clustered);
    CHECK(dfn[1].terminate_at == std::vector<int>{0});
    CHECK(dfn[1].terminate_probability == 0.3);

    check_error(with(set + "count = 10\n"), "[[region.dfn]]", "region[0].dfn[0]",
                "give the set's intensity as 'p21' (trace length per m²) or 'count', one of them");
    check_error(with("[[region.dfn]]\nname = \"J\"\norientation = { distribution = \"uniform\" }\nlength = { "
                     "distribution = \"pareto\", min = 1.0 }\np21 = 1.0\n"),
                "length =", "region[0].dfn[0].length.distribution", "unknown length distribution 'pareto'");
    check_error(with("[[region.dfn]]\nname = \"J\"\norientation = { distribution = \"uniform\" }\nlength = { "
                     "distribution = \"power_law\", exponent = 2.0, max = 1.0 }\np21 = 1.0\n"),
                "length =", "region[0].dfn[0].length.min", "missing required key 'min'");
    check_error(with("[[region.dfn]]\nname = \"J\"\norientation = { distribution = \"uniform\" }\nlength = { "
                     "distribution = \"lognormal\", mean = 1.0, std = 0.5, exponent = 2.0 }\np21 = 1.0\n"),
                "length =", "region[0].dfn[0].length.exponent",
                "does not apply to a lognormal length distribution");
    check_error(with("[[region.dfn]]\nname = \"J\"\norientation = { distribution = \"uniform\" }\nlength = { "
                     "distribution = \"exponential\", mean = 1.0, min = 2.0, max = 2.0 }\np21 = 1.0\n"),
                "length =", "region[0].dfn[0].length.max", "must be above min = 2 m, got 2");
    check_error(with(set + "terminate = { at = [\"J2\"], probability = 0.5 }\n"), "terminate", "region[0].dfn[0].terminate.at[0]",
                "a fracture set ends only at an earlier set of its region; there is none before 'J1', got 'J2'");
    check_error(with("[[region.dfn]]\nname = \"J\"\norientation = { distribution = \"list\", angles = [0.0, 90.0], "
                     "weights = [1.0] }\nlength = { distribution = \"fixed\", value = 1.0 }\ncount = 3\n"),
                "orientation =", "region[0].dfn[0].orientation.weights", "must give one weight per angle");
    check_error(with("[[region.dfn]]\nname = \"J\"\ncentres = \"clustered\"\norientation = { distribution = "
                     "\"uniform\" }\nlength = { distribution = \"fixed\", value = 1.0 }\ncount = 3\n"),
                "[[region.dfn]]", "region[0].dfn[0].cluster", "clustered centres need cluster");
    check_error(with(set + "property = \"joints\"\n" + std::string(bond)), "property = \"joints\"",
                "region[0].dfn[0].property", "unknown joint property 'joints'");
    check_error(with(set + "[[region.dfn]]\nname = \"J1\" # again\n"), "\"J1\" # again",
                "region[0].dfn[1].name", "fracture set name 'J1' is already used by dfn[0]");

    // Traces from a CSV file (a header, comments, a set column), and its mistakes:
    // the CSV file's own line.
    const std::string csv = "/tmp/bbm_test_traces.csv";
    {
        std::ofstream out(csv);
        out << "x1,y1,x2,y2,set\n# mapped on the wall\n-0.5, 0.0, 0.5, 0.1, A\n0.0,-0.5,0.1,0.5,B\n\n0.2,0.2,0.4,0.4,A\n";
    }
    const auto traced = parse_model(with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + csv + "\"\nset = \"A\"\n"), "t.toml");
    REQUIRE(traced.geometry.regions[0].dfn[0].traces.size() == 2);
    CHECK(traced.geometry.regions[0].dfn[0].traces[1].b.x == 0.4);
    check_error(with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + csv + "\"\nset = \"C\"\n"), "file =",
                "region[0].dfn[0].file", "has no traces of set 'C'");
    check_error(with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + csv + "\"\np21 = 1.0\n"), "p21",
                "region[0].dfn[0].p21", "does not apply to a fracture set read from a file");
    {
        std::ofstream out(csv);
        out << "-0.5, 0.0, 0.5, 0.1\n0.0,-0.5,0.1\n";
    }
    try {
        parse_model(with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + csv + "\"\n"), "t.toml");
        FAIL("no error for a short CSV row");
    } catch (const InputError& e) {
        CHECK(e.file() == csv);
        CHECK(e.line() == 2);
        CHECK(e.key() == "region[0].dfn[0].file");
        CHECK(std::string(e.what()).find("expected x1, y1, x2, y2[, set]") != std::string::npos);
    }
    std::remove(csv.c_str());
    check_error(with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + csv + "\"\n"), "file =", "region[0].dfn[0].file",
                "cannot open the trace file");
}

namespace {

/// An ASCII DXF drawing of `entities` (group code / value pairs), padded as CAD
/// programs write it, with CRLF line ends and $INSUNITS `units`.
std::string dxf_drawing(const std::vector<std::string>& entities, int units = 6) {
    std::vector<std::string> g{"999", "a test drawing", "0", "SECTION", "2", "HEADER", "9", "$ACADVER", "1", "AC1015",
                               "9", "$INSUNITS", "70", std::to_string(units), "0", "ENDSEC", "0", "SECTION", "2",
                               "ENTITIES"};
    g.insert(g.end(), entities.begin(), entities.end());
    for (const char* s : {"0", "ENDSEC", "0", "EOF"}) g.emplace_back(s);
    std::string text;
    for (std::size_t i = 0; i < g.size(); ++i)
        text += (i % 2 == 0 ? std::string(3 - std::min<std::size_t>(3, g[i].size()), ' ') : "") + g[i] + "\r\n";
    return text;
}

std::vector<std::string> dxf_line(const std::string& layer, Vec2 a, Vec2 b) {
    return {"0", "LINE", "5", "1F", "100", "AcDbEntity", "8", layer, "100", "AcDbLine", "10", std::to_string(a.x),
            "20", std::to_string(a.y), "30", "0.0", "11", std::to_string(b.x), "21", std::to_string(b.y), "31", "0.0"};
}

void write_file(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

} // namespace

TEST_CASE("fracture traces from a DXF drawing: lines, polylines with arcs, layers, units, and the file's mistakes") {
    using bbm::io::read_dxf;
    const std::string path = "/tmp/bbm_test_traces.dxf";
    auto cat = [](std::vector<std::vector<std::string>> parts) {
        std::vector<std::string> all;
        for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
        return all;
    };
    // A semicircle of bulge 1 from (0, 0) to (2, 0) (counter-clockwise: below the
    // chord), a closed square, an old-style POLYLINE, one mirrored by its extrusion
    // (0, 0, -1), a text to leave out; drawn in millimetres.
    const std::vector<std::string> arc{"0", "LWPOLYLINE", "8", "fault", "90", "2", "70", "0", "10", "0", "20", "0",
                                       "42", "1.0", "10", "2000", "20", "0"};
    const std::vector<std::string> square{"0", "LWPOLYLINE", "8", "frame", "90", "4", "70", "1", "10", "0", "20",
                                          "0", "10", "1000", "20", "0", "10", "1000", "20", "1000", "10", "0", "20", "1000"};
    const std::vector<std::string> old{"0", "POLYLINE", "8", "J2", "66", "1", "70", "0", "0", "VERTEX", "8", "J2", "10",
                                       "0", "20", "0", "0", "VERTEX", "8", "J2", "10", "500", "20", "500", "0",
                                       "VERTEX", "8", "J2", "10", "500", "20", "500", "0", "VERTEX", "8", "J2", "10",
                                       "1000", "20", "0", "0", "SEQEND"};
    const std::vector<std::string> mirrored{"0", "LWPOLYLINE", "8", "J2", "90", "2", "70", "0", "10", "1000", "20",
                                            "0", "10", "2000", "20", "0", "210", "0", "220", "0", "230", "-1"};
    const std::vector<std::string> text{"0", "TEXT", "8", "frame", "10", "0", "20", "0", "1", "map 1"};
    write_file(path, dxf_drawing(cat({dxf_line("J1", {-500, 250}, {1500, 250}), arc, square, old, mirrored, text}), 4));
    const auto d = read_dxf(path, "k");
    CHECK(d.insunits == 4);
    CHECK(d.metres_per_unit == 1e-3);
    CHECK(d.entities_read.at("LINE") == 1);
    CHECK(d.entities_read.at("LWPOLYLINE") == 3);
    CHECK(d.entities_read.at("POLYLINE") == 1);
    CHECK(d.entities_skipped.at("TEXT") == 1);
    std::map<std::string, std::vector<bbm::io::DxfTrace>> by_layer;
    for (const auto& t : d.traces) by_layer[t.layer].push_back(t);
    REQUIRE(by_layer["J1"].size() == 1);
    CHECK(by_layer["J1"][0].a == Vec2{-0.5, 0.25});
    CHECK(by_layer["J1"][0].b == Vec2{1.5, 0.25});
    CHECK(by_layer["J1"][0].line == 21); // its "0 LINE": after 20 lines of header
    // The arc: 180° in chords of 5°, on the circle about (1, 0) of radius 1, below.
    const auto& fault = by_layer["fault"];
    REQUIRE(fault.size() == 36);
    CHECK(fault.front().a == Vec2{0, 0});
    CHECK(fault.back().b == Vec2{2, 0});
    double chords = 0.0;
    for (const auto& t : fault) {
        CHECK(norm(t.b - Vec2{1, 0}) == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(t.b.y <= 1e-15);
        chords += norm(t.b - t.a);
    }
    CHECK(chords == doctest::Approx(72.0 * std::sin(std::numbers::pi / 72.0)).epsilon(1e-12));
    CHECK(by_layer["frame"].size() == 4); // closed: back to the first vertex
    // The repeated vertex of the POLYLINE leaves no zero-length trace.
    REQUIRE(by_layer["J2"].size() == 3);
    CHECK(by_layer["J2"][1].b == Vec2{1.0, 0.0});
    CHECK(by_layer["J2"][2].a == Vec2{-1.0, 0.0}); // mirrored: world x = -object x
    CHECK(by_layer["J2"][2].b == Vec2{-2.0, 0.0});
    // `units` overrides the header.
    CHECK(read_dxf(path, "k", 1.0).traces.front().b == Vec2{1500, 250});

    // In a model: a layer per set, an unknown layer, traces off the region.
    auto model = [&](const std::string& extra) {
        return with("[[region.dfn]]\nname = \"mapped\"\nfile = \"" + path + "\"\n" + extra);
    };
    const auto mf = parse_model(model("set = \"J1\"\n"), "t.toml");
    REQUIRE(mf.geometry.regions[0].dfn[0].traces.size() == 1);
    CHECK(mf.geometry.regions[0].dfn[0].import_note.find("units mm") != std::string::npos);
    CHECK(mf.geometry.regions[0].dfn[0].import_note.find("left out: 1 TEXT") != std::string::npos);
    CHECK(parse_model(model(""), "t.toml").geometry.regions[0].dfn[0].traces.size() == 44);
    check_error(model("set = \"J3\"\n"), "file =", "region[0].dfn[0].file",
                "has no traces on layer 'J3'; its layers with traces are J1, fault, frame, J2");
    check_error(model("set = \"J1\"\nunits = \"m\"\n"), "file =", "region[0].dfn[0].file",
                "none of its 1 traces reaches the region: they span x -500 to 1500, y 250 to 250 m");
    check_error(model("units = \"furlong\"\n"), "units =", "region[0].dfn[0].units", "furlong");
    // `units` on a CSV file.
    {
        const std::string csv = "/tmp/bbm_test_traces_mm.csv";
        write_file(csv, "-500,0,500,100\n");
        const auto in_mm = parse_model(with("[[region.dfn]]\nname = \"m\"\nfile = \"" + csv + "\"\nunits = \"mm\"\n"), "t.toml");
        CHECK(in_mm.geometry.regions[0].dfn[0].traces[0].b == Vec2{0.5, 0.1});
        std::remove(csv.c_str());
    }

    // The file's mistakes, at their line in the DXF file.
    auto dxf_error = [&](const std::string& contents, int line, const std::string& words) {
        write_file(path, contents);
        try {
            read_dxf(path, "region[0].dfn[0].file");
            FAIL("no error for: " << words);
        } catch (const InputError& e) {
            INFO(e.what());
            CHECK(e.file() == path);
            CHECK(e.line() == line);
            CHECK(e.key() == "region[0].dfn[0].file");
            CHECK(std::string(e.what()).find(words) != std::string::npos);
        }
    };
    dxf_error(std::string("AutoCAD Binary DXF\r\n\x1a") + '\0', 1, "a binary DXF file");
    dxf_error("x1,y1,x2,y2\n0,0,1,1\n", 1, "expected a DXF group code");
    auto bad = dxf_line("J1", {0, 0}, {1, 1});
    bad[13] = "1.0.0"; // the start's y (20)
    dxf_error(dxf_drawing(bad), 34, "group code 20 of the LINE at line 21 must be a number, got \"1.0.0\"");
    dxf_error(dxf_drawing(std::vector<std::string>(arc.begin(), arc.end() - 4)), 21,
              "says it has 2 vertices (group code 90) but lists 1");
    dxf_error(dxf_drawing(cat({{"0", "LWPOLYLINE", "90", "2", "210", "1", "230", "0"}, {"10", "0", "20", "0", "10", "1", "20", "0"}})),
              21, "not drawn in the XY plane");
    dxf_error(dxf_drawing({"0", "LINE", "8", "J1", "10", "0", "20", "0"}), 21, "a LINE without its end point");
    dxf_error(dxf_drawing(dxf_line("J1", {0, 0}, {1, 1}), 9), 13, "$INSUNITS = 9 are not a length bbm converts");
    dxf_error(dxf_drawing(old).substr(0, dxf_drawing(old).find("  0\r\nSEQEND")) + "  0\r\nENDSEC\r\n  0\r\nEOF\r\n", 21,
              "the POLYLINE has no SEQEND");
    std::remove(path.c_str());
}

TEST_CASE("the water tables ([flow], [[flow_boundary]], [[flow_source]]) refuse bad input with file, line and key") {
    const std::string base = std::string(one_region);
    check_error(base + "[flow]\naperture = -1e-4\n", "aperture = -1e-4", "flow.aperture", "must be > 0 m");
    check_error(base + "[flow]\nviscosity = 0.0\n", "viscosity = 0.0", "flow.viscosity", "must be > 0 Pa·s");
    check_error(base + "[flow]\nbond_aperture = -1e-6\n", "bond_aperture", "flow.bond_aperture", "must be >= 0 m");
    check_error(base + "[flow]\nmax_aperture = 1e-3\nresidual_aperture = 2e-3\n", "[flow]", "flow.max_aperture",
                "must exceed residual_aperture");
    check_error(base + "[flow]\nwater_table = 10.0\npressure = 1e5\n", "[flow]", "flow.pressure",
                "not both");
    check_error(base + "[flow]\nregions = [\"b\"]\n", "regions", "flow.regions[0]", "region");
    check_error(base + "[flow]\nmode = \"transient\"\n", "mode", "flow.mode", "dynamic");
    check_error(base + "[flow]\nmode = \"unsteady\"\n", "mode", "flow.mode", "did you mean");
    check_error(base + "[flow]\nfar_field = \"open\"\n", "far_field", "flow.far_field", "held");
    check_error(base + "[flow]\n\n[[flow_boundary]]\nname = \"top\"\nbox = { min = [0, 0], max = [1, 1] }\n",
                "[[flow_boundary]]", "flow_boundary[0]", "'pressure' or the 'head'");
    check_error(base + "[[flow_boundary]]\nname = \"top\"\nbox = { min = [0, 0], max = [1, 1] }\npressure = 1e5\n",
                "[[flow_boundary]]", "flow_boundary[0]", "needs a [flow] table");
    check_error(base + "[flow]\n\n[[flow_source]]\nat = [0, 0]\n", "[[flow_source]]", "flow_source[0].rate", "rate");
    check_error(base + "[[history]]\nname = \"q\"\nquantity = \"inflow\"\n", "quantity = \"inflow\"",
                "history[0].quantity", "needs a [flow] table");
}

TEST_CASE("a position or a length in another unit is refused with file, line and key, not snapped to the model") {
    // The region spans [-1, 1] m with 0.3 m blocks: a point typed in millimetres is
    // 500 model sizes away, a length in millimetres a thousand blocks long.
    const std::string base = std::string(one_region);
    const std::string far = "far outside the model (its regions span [-1, -1] to [1, 1])";
    check_error(base + "[[history]]\nname = \"ux\"\nquantity = \"displacement_x\"\npoint = [1000.0, 0.0]\n",
                "point = [1000.0", "history[0].point", far);
    check_error(base + "[report]\ncenter = [0, 0]\nspringline = [1000, 0]\ncrown = [0, 1]\n", "springline",
                "report.springline", far);
    check_error(base + "[report]\nwindow = { min = [2000, 2000], max = [3000, 3000] }\n", "window", "report.window",
                far);
    check_error(base + "[[boundary]]\nname = \"top\"\ntype = \"velocity\"\nbox = { min = [-1000, 990], max = [1000, "
                       "1010] }\nvy = 0.0\n",
                "box = ", "boundary[0].box", far);
    check_error(base + "[flow]\n\n[[flow_source]]\nat = [0, 500]\nrate = 1e-6\n", "at = [0, 500]", "flow_source[0].at",
                far);
    check_error(base + "[flow]\n\n[[flow_boundary]]\nname = \"top\"\nbox = { min = [0, 900], max = [1, 1100] }\n"
                       "pressure = 1e5\n",
                "box = ", "flow_boundary[0].box", far);
    check_error(base + "[solver]\ncorner_radius = 2.0\n", "corner_radius", "solver.corner_radius",
                "is not below 0.5 of the model's smallest block size (0.3 m)");
    check_error(base + "[solver]\ndetection_tolerance = 5.0\n", "detection_tolerance", "solver.detection_tolerance",
                "is not below 1 of the model's smallest block size (0.3 m)");
    // A box may reach far beyond the model to take all of one side, and a level
    // (a boundary's y_ref) may lie far above it (the ground surface): both are right.
    CHECK_NOTHROW(parse_model(base + "[[boundary]]\nname = \"top\"\ntype = \"stress\"\nbox = { min = [-1e6, 0.9], "
                                     "max = [1e6, 1e6] }\nsyy = -1e6\ny_ref = 500.0\ndsyy_dy = 2.7e4\n",
                              "t.toml"));
}

TEST_CASE("a pressurise stage needs an opening excavated with a pressure before it, and says so with file, line and key") {
    const std::string base = std::string(one_region);
    check_error(base + "[[stage]]\ntype = \"pressurise\"\npressure = 1e6\n", "type = \"pressurise\"", "stage[0].type",
                "needs an excavate stage before it");
    check_error(base + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\n\n[[stage]]\ntype = \"pressurise\"\n"
                       "pressure = 1e6\n",
                "type = \"pressurise\"", "stage[1].type", "give the excavate stage before it a pressure > 0");
    check_error(base + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\npressure = 1e6\n\n[[stage]]\n"
                       "type = \"pressurise\"\npressure = -1\n",
                "pressure = -1", "stage[1].pressure", "must be >= 0");
    {
        const std::string text = base + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\npressure = 1e6\n\n"
                                        "[[stage]]\ntype = \"pressurise\"\n";
        const auto e = error_of(text);
        REQUIRE(e.has_value());
        CHECK(e->line() == line_of(text, "type = \"pressurise\"") - 1); // its [[stage]] header
        CHECK(e->key() == "stage[1].pressure");
        CHECK(std::string(e->what()).find("missing required key 'pressure'") != std::string::npos);
    }
    check_error(base + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\npressure = 1e6\n\n[[stage]]\n"
                       "type = \"pressurise\"\npressure = 1e6\nratio = 1e-5\n",
                "ratio", "stage[1].ratio", "does not apply to a pressurise stage");
    // Read: ramps from the excavation's pressure.
    const auto mf = parse_model(base + "[[stage]]\ntype = \"excavate\"\nregions = [\"a\"]\npressure = 1e6\n\n"
                                       "[[stage]]\ntype = \"pressurise\"\npressure = 0\nsteps = 300\n",
                                "p.toml");
    REQUIRE(mf.analysis.stages.size() == 2);
    CHECK(mf.analysis.stages[1].kind == bbm::StageSpec::Kind::pressurise);
    CHECK(mf.analysis.stages[1].pressure == 0.0);
    CHECK(mf.analysis.stages[1].steps == 300);
}
