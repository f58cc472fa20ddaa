// bbm core: yielding, energy-absorbing rockbolts (D-bolt, cone bolt, Garford and
// Roofex type) — a support type of one registry row, for rock that bursts.
//
// The bar runs free in its hole between its face plate (the head) and its anchor
// (the toe), each tied to the rock it lies in with no slip (a smooth or
// debonded bar: Li 2010, "A new energy-absorbing bolt for rock support in high
// stress rock masses", Int. J. Rock Mech. Min. Sci. 47, 396-404; Jager 1992 for
// the cone bolt, whose cone ploughs through its grout at a constant force). Its
// elongation δ = |x_toe − x_head| − L (the rock points, since installation)
// carries the axial force
//     N = (EA/L) (δ − δp),  0 ≤ N ≤ F_y,
// with δp the plastic elongation (the steel's yield, a cone's ploughing): elastic
// up to F_y at δy = F_y L / EA, then held at F_y while δp grows, until δp passes
// `slip_capacity`: the bolt ruptures (N = 0 for good). No compression (a free bar
// pushed slides or buckles). The energy it absorbs is the work done on it,
// ∫ N dδ: F_y² L / 2EA + F_y δp at yield, F_y (δy / 2 + slip_capacity) by its
// rupture. Plane strain: a set at out-of-plane spacing S acts with EA and F_y
// divided by S; its figures are per bolt. The bar has no nodes of its own (its
// mass is the rock's business): two ties per bolt, the plate and the anchor.
#pragma once

#include "base/keys.hpp"
#include "base/table_reader.hpp"
#include "core/supports/bars.hpp"
#include "core/supports/support.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bbm {

/// A [[yielding_bolt]] table: one set of bolts with one property set.
struct YieldingBoltSpec {
    std::string name;
    std::vector<std::array<Vec2, 2>> bolts; ///< head (at the wall), toe (the anchor)
    std::optional<BarRing> ring;
    double young = 200e9;      ///< Pa
    double area = 3.80e-4;     ///< m² (a 22 mm bar)
    double yield_force = 0.0;  ///< N per bolt (required)
    double slip_capacity = 0.0; ///< m of plastic elongation at the yield force before rupture (required)
    double spacing = 1.0;      ///< m, out of plane
};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
inline constexpr Key<YieldingBoltSpec> yielding_bolt_keys[] = {
    {.key = "name", .kind = KeyKind::text, .required = true,
     .meaning = "Non-empty, unique among the support sets of every type; install stages name it"},
    {.key = "bolts", .kind = KeyKind::segments, .bounds = unbounded(" m"),
     .meaning = "Each bolt's head (its face plate, at the wall) and toe (its anchor); with a ring or instead of it",
     .absent = "none"},
    {.key = "ring", .kind = KeyKind::table,
     .meaning = "Radial bolts around a circular opening, as a [[bolt]]'s ring: center, radius, length, count or "
                "spacing, from, to",
     .absent = "none"},
    {.key = "young", .bounds = above(0, " Pa"), .meaning = "The bar's Young's modulus", .absent = "200e9",
     BBM_KEY_FIELD(YieldingBoltSpec, young)},
    {.key = "area", .bounds = above(0, " m²"), .meaning = "The bar's cross-section; not with diameter",
     .absent = "3.80e-4 (22 mm)"},
    {.key = "diameter", .bounds = above(0, " m"), .meaning = "The bar's diameter, for its area; not with area",
     .absent = "22 mm"},
    {.key = "yield_force", .bounds = above(0, " N"), .required = true,
     .meaning = "The axial force the bolt holds while it elongates (the steel's yield, a cone's ploughing force)",
     BBM_KEY_FIELD(YieldingBoltSpec, yield_force)},
    {.key = "slip_capacity", .bounds = above(0, " m"), .required = true,
     .meaning = "The plastic elongation the bolt takes at its yield force before it ruptures",
     BBM_KEY_FIELD(YieldingBoltSpec, slip_capacity)},
    {.key = "spacing", .bounds = above(0, " m"), .meaning = "Out of plane, between the rows of bolts", .absent = "1",
     BBM_KEY_FIELD(YieldingBoltSpec, spacing)},
};
#pragma GCC diagnostic pop

/// Installed yielding bolts, per bolt (ties 2b and 2b + 1: plate and anchor).
/// Forces per metre of model (divided by the out-of-plane spacing).
struct YieldingBoltState {
    struct Set {
        double ea, yield_force, slip_capacity, spacing;
    };
    std::vector<Set> sets; ///< one per table, in file order
    std::vector<YieldingBoltSpec> specs;
    std::vector<std::string> names;
    std::vector<std::uint8_t> installed; ///< per set
    enum : std::uint8_t { elastic = 0, yielding = 1, ruptured = 2 };
    std::vector<TieHost> host;           ///< per tie
    std::vector<Vec2> end;               ///< per tie: the rock point, at the last force pass
    std::vector<int> bolt_set;           ///< per bolt
    std::vector<double> rest;            ///< L, m
    std::vector<double> elongation;      ///< δ at the last force pass, m
    std::vector<double> slip;            ///< δp, m
    std::vector<double> axial;           ///< N, per metre of model
    std::vector<double> energy;          ///< ∫ N dδ, J per metre of model
    std::vector<std::uint8_t> state;
    int bolt_count() const { return static_cast<int>(bolt_set.size()); }
};

struct YieldingBolts {
    static constexpr std::string_view name = "yielding_bolts", table = "yielding_bolt";
    using Spec = YieldingBoltSpec;
    using State = YieldingBoltState;
    static constexpr const auto& keys = yielding_bolt_keys;
    static std::string reference();
    static Spec read(TableReader& t);
    static State make(const std::vector<Spec>& specs);
    static const std::vector<std::string>& set_names(const State& s) { return s.names; }
    static bool installed(const State& s, int set) { return s.installed[set] != 0; }
    static void install(State& s, int set, const HostFinder& find);
    static int tie_count(const State& s) { return static_cast<int>(s.host.size()); }
    static const TieHost& host(const State& s, int tie) { return s.host[tie]; }
    static void force_pass(State& s, const SupportRock& rock, Vec2* reaction, double* moment);
    /// No nodes of its own to move.
    static double integrate(State&, const SupportMotion&, double&) { return 0.0; }
    static void add_stiffness(State& s, RockStiffness& k);
    static double time_limit(const State&) { return INFINITY; }
    static void add_force_scale(const State& s, double& terms, double& squares);
    static void add_applied_loads(const State&, double&) {}
    static void parameters(const State& s, std::vector<double>& out);
    template <class S, class V>
    static void visit_fields(S& Y, V&& v);
    static void after_load(State&) {}
    /// ∫ N dδ over its bolts (no nodes of its own: nothing kinetic).
    static double energy(const State& s, const SupportRock&) {
        double e = 0.0;
        for (double x : s.energy) e += x;
        return e;
    }
    /// Per installed set, per bolt: bolts, max_axial_kN, max_slip_mm, energy_kJ
    /// (absorbed by the set), max_energy_kJ (by one bolt), yielding, ruptured.
    static std::vector<SupportSetSummary> summary(const State& s);
    /// One line cell per bolt, plate to anchor: axial_force_kN, slip_mm,
    /// energy_kJ (per bolt), state (0 elastic, 1 yielding, 2 ruptured), set.
    static SupportLines lines(const State& s);
    static constexpr std::array<CompareColumn, 4> compare{{{"bolts", "yielding bolts", true},
                                                           {"max_axial_kN", "largest load kN", false},
                                                           {"energy_kJ", "energy absorbed kJ", true},
                                                           {"ruptured", "ruptured", true}}};
};

template <class S, class V>
void YieldingBolts::visit_fields(S& Y, V&& v) {
    using G = MemoryGroup;
    constexpr unsigned E = field_use::evolving;
    v(FieldInfo{"yielding_bolts.installed", G::other, E}, Y.installed);
    v(FieldInfo{"yielding_bolts.host", G::other, E}, Y.host);
    v(FieldInfo{"yielding_bolts.end", G::other, E}, Y.end);
    v(FieldInfo{"yielding_bolts.bolt_set", G::other, E}, Y.bolt_set);
    v(FieldInfo{"yielding_bolts.rest", G::other, E}, Y.rest);
    v(FieldInfo{"yielding_bolts.elongation", G::other, E}, Y.elongation);
    v(FieldInfo{"yielding_bolts.slip", G::other, E}, Y.slip);
    v(FieldInfo{"yielding_bolts.axial", G::other, E}, Y.axial);
    v(FieldInfo{"yielding_bolts.energy", G::other, E}, Y.energy);
    v(FieldInfo{"yielding_bolts.state", G::other, E}, Y.state);
}

} // namespace bbm
