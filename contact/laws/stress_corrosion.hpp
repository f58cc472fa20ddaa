// bbm contact: stress corrosion of a bond — the paper's softening bond whose
// load-carrying section is eaten away over real time while it is loaded above a
// micro-activation stress (after Potyondy 2007, "Simulating stress corrosion with
// a bonded-particle model for rock", Int. J. Rock Mech. Min. Sci. 44, 677-691;
// docs/theory.md §17, SPEC §12).
//
// Potyondy's parallel bond shrinks, dD/dt = −β1 exp(β2 σ/σc) for σ ≥ σa. Here a
// bond's remaining section ω (1 when intact, a fraction of the joint's length,
// contacts.bond_section) goes as
//     dω/dt = −ω̇1 exp(−β (1 − s))   for s ≥ sa,   0 below,
// with s the bond's stress ratio — the larger of −σn/σt and |τ| over its Coulomb
// cap c + σn tan φ, of the stresses on the remaining section — ω̇1 the rate at
// s = 1 (Potyondy's β1 / D0 · e^β2) and β his β2. The section carries the
// contact's force: its length is the joint's share times ω, so the joint's
// stiffness and strength go with it and the same load puts the stress σ/ω on
// what is left, until the bond breaks by the law's own criterion. The step's
// mechanics are the softening law's (softening.hpp): time enters only through
// the creep step (core/creep.hpp) that a `creep` stage takes at equilibrium.
#pragma once

#include "contact/laws/softening.hpp"

#include <array>
#include <cmath>
#include <string_view>

namespace bbm::contact {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
// Its own keys keep their values in JointPropertySpec::values (law_value).
inline constexpr JointKey key_corrosion_rate{
    .key = "corrosion_rate", .bounds = above(0, " /s"), .required = true,
    .meaning = "stress_corrosion: ω̇1, the rate at which a bond's section is lost at the stress ratio 1 (the "
               "fraction of the intact section per second; Potyondy's β1/D0 · e^β2)",
    .get = [](const JointPropertySpec& j) { return law_value(j, "corrosion_rate", 0.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "corrosion_rate", v); }};
inline constexpr JointKey key_corrosion_exponent{
    .key = "corrosion_exponent", .bounds = between(0, 1000, ""), .required = true,
    .meaning = "stress_corrosion: β, how steeply the rate grows with the stress ratio s: ω̇1 exp(−β (1 − s)) "
               "(a decade of time to failure per ln 10 / β of s)",
    .get = [](const JointPropertySpec& j) { return law_value(j, "corrosion_exponent", -1.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "corrosion_exponent", v); }};
inline constexpr JointKey key_corrosion_threshold{
    .key = "corrosion_threshold", .bounds = below(0, 1, ""),
    .meaning = "stress_corrosion: sa, the stress ratio below which a bond does not corrode (the micro-activation "
               "stress over the strength): the rock's long-term strength",
    .absent = "0",
    .get = [](const JointPropertySpec& j) { return law_value(j, "corrosion_threshold", 0.0); },
    .set = [](JointPropertySpec& j, double v) { set_law_value(j, "corrosion_threshold", v); }};
#pragma GCC diagnostic pop

struct StressCorrosionLaw : SofteningLaw {
    static constexpr std::string_view name = "stress_corrosion";
    static constexpr std::array<const JointKey*, 21> keys = [] {
        std::array<const JointKey*, 21> k{};
        for (std::size_t i = 0; i < SofteningLaw::keys.size(); ++i) k[i] = SofteningLaw::keys[i];
        k[18] = &key_corrosion_rate, k[19] = &key_corrosion_exponent, k[20] = &key_corrosion_threshold;
        return k;
    }();
    /// The softening bond's rules.
    static std::optional<KeyProblem> check(const JointPropertySpec& j);

    double rate_at_strength; ///< ω̇1, 1/s
    double exponent;         ///< β
    double threshold;        ///< sa

    explicit StressCorrosionLaw(const JointPropertySpec& p);

    /// The bond's stress ratio s on its remaining section (0 once broken).
    double stress_ratio(const JointHistory& h) const {
        if (!h.bonded) return 0.0;
        const double cap = cohesion + friction(h.sn);
        return std::max(std::max(-h.sn, 0.0) / tensile, std::abs(h.tau) / cap);
    }
    /// A section below this is corroded through: the creep step breaks the bond
    /// (a bond among stiff neighbours sheds its load as it shrinks, so that its
    /// stress ratio need not reach 1 before nothing is left of it).
    static constexpr double section_left_at_break = 0.01;
    /// Breaks a corroded-through bond as the law breaks one (softening.hpp): a
    /// tensile crack if its tension ratio is the larger, a shear crack otherwise.
    void corrode_through(JointHistory& h) const;
    /// dω/dt's magnitude at the stress ratio s: 0 below the threshold.
    double section_rate(double s) const {
        return s < threshold ? 0.0 : rate_at_strength * std::exp(-exponent * (1.0 - std::min(s, 1.0)));
    }
};

} // namespace bbm::contact
