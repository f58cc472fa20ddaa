// bbm core: the keys of the [events] table — the seismic events recorded from
// breaking bonds (core/events.hpp) — one declaration each (base/keys.hpp). The
// model file's reader checks [events] by them (io/model_input.cpp) and
// docs/reference/events.md is generated from them (tests/test_reference.cpp).
#pragma once

#include "base/keys.hpp"
#include "core/model_spec.hpp"

#include <string>

namespace bbm {

using EventKey = Key<EventSpec>;

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
/// Every key of [events]; the table's presence turns the catalogue on.
inline constexpr EventKey event_keys[] = {
    {.key = "join_distance", .bounds = at_least(0, " m"),
     .meaning = "Bonds that start to fail within this distance of a bond of an open event join it (Hazzard and "
                "Young 2002); at most twice the model's size",
     .absent = "0: twice the mean size of the rigid blocks", BBM_KEY_FIELD(EventSpec, join_distance)},
    {.key = "window", .kind = KeyKind::integer, .bounds = between(0, 1e9, " steps"),
     .meaning = "An event closes this many steps after its last bond broke or started to fail; its moment tensor "
                "is the largest over that time",
     .absent = "0: 50 steps", BBM_KEY_FIELD(EventSpec, window)},
    {.key = "thickness", .bounds = at_least(0, " m"),
     .meaning = "Out-of-plane extent that turns a plane-strain moment (N·m per m) into M0 (N·m) for Mw; at most "
                "100 times the model's size",
     .absent = "0: each event's own length (an equidimensional crack)", BBM_KEY_FIELD(EventSpec, thickness)},
};
#pragma GCC diagnostic pop

/// docs/reference/events.md: the table of keys.
inline std::string event_keys_markdown() {
    return "# [events] keys\n\n"
           "Generated from core/event_keys.hpp by tests/test_reference.cpp (`BBM_WRITE_REFERENCE=1` rewrites it; the "
           "test fails when it is stale). What an event is, its moment tensor, magnitude and type: "
           "[theory.md](../theory.md) §18; the catalogue and the b-value: [events.md](../events.md).\n\n" +
           key_table_markdown(event_keys);
}

} // namespace bbm
