// bbm core: what the support types made of straight bars share — their bars, as a
// model-file table gives them: one by one (`bolts`: head at the wall, toe), or a
// `ring` of radial bars around a circular opening (evenly spaced by count or by
// spacing along the wall, over a full circle or an arc).
#pragma once

#include "base/table_reader.hpp"
#include "base/vec2.hpp"

#include <array>
#include <optional>
#include <string_view>
#include <vector>

namespace bbm {

/// Radial bars around a circular opening: heads on the circle, evenly spaced
/// (`count`, or `spacing` along the wall) from angle `from` to `to`, degrees
/// counter-clockwise from +x (a full circle when to − from = 360).
struct BarRing {
    Vec2 center{};
    double radius = 0.0, length = 0.0;
    int count = 0;
    double spacing = 0.0;
    double from = 0.0, to = 360.0;
};

/// A table's `bolts` (head, toe pairs) and its `ring`, at least one of them;
/// `what` names the bars in a message ("bolts"). Lengths far below the model's
/// blocks are refused (base/table_reader.hpp).
void read_bars(TableReader& t, std::string_view what, std::vector<std::array<Vec2, 2>>& bars,
               std::optional<BarRing>& ring);

/// The bars as (head, toe) pairs: those given, then the ring's.
std::vector<std::array<Vec2, 2>> expand_bars(const std::vector<std::array<Vec2, 2>>& bars,
                                             const std::optional<BarRing>& ring);

} // namespace bbm
