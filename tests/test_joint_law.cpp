// Joint laws (contact/joint_law.hpp) against SPEC §4: the softening curves pass
// through their points, fracture energies equal the areas under the curves,
// unloading is elastic with the initial stiffness, damage persists.
#include "contact/joint_keys.hpp"
#include "contact/joint_law.hpp"
#include "core/rock.hpp"

#include "tests/softening_reference.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>
#include <numbers>

using namespace bbm;
using namespace bbm::contact;

namespace {

/// The paper's Voronoi calibration (SPEC §8).
JointPropertySpec paper_bond() { return paper_rock().bonds; }


} // namespace

TEST_CASE("softening law, monotonic opening: SPEC §4 curve points and G_I") {
    const auto p = paper_bond();
    const SofteningLaw law(p);
    const double u0 = p.tensile / p.kn;
    for (int steps_per_u0 : {7, 100, 1000}) {
        INFO("steps per u_t0: " << steps_per_u0);
        JointHistory h;
        const double du = u0 / steps_per_u0;
        double work = 0.0, max_err = 0.0;
        double prev = 0.0;
        for (int k = 1; k <= 5 * steps_per_u0; ++k) {
            law.update(h, du, 0.0);
            const double tension = -h.sn;
            work += 0.5 * (prev + tension) * du;
            prev = tension;
            const double x = h.un / u0;
            max_err = std::max(max_err, std::abs(tension / p.tensile - softening_reference(x, 1.7, 0.5, 4.0)));
        }
        // Exact return on the piecewise-linear curve: every sample is on it.
        CHECK(max_err < 1e-6);
        CHECK(h.broken == JointState::broken_tension);
        CHECK(h.damage == 1.0);
        const double gi = 1.6 * p.tensile * p.tensile / p.kn; // 149.07 J/m²
        CHECK(gi == doctest::Approx(149.07).epsilon(1e-4));
        if (steps_per_u0 >= 100) {
            CHECK(work == doctest::Approx(gi).epsilon(0.01));
            CHECK(h.dissipated == doctest::Approx(gi).epsilon(0.01));
        }
    }
}

TEST_CASE("softening law, shear at sigma_n = 0: curve points and G_II") {
    const auto p = paper_bond();
    const SofteningLaw law(p);
    const double u0 = p.cohesion / p.ks;
    JointHistory h;
    const int n = 1000;
    const double du = u0 / n;
    double work = 0.0, prev = 0.0, max_err = 0.0;
    for (int k = 1; k <= 3 * n; ++k) {
        law.update(h, 0.0, du);
        work += 0.5 * (prev + h.tau) * du;
        prev = h.tau;
        max_err = std::max(max_err, std::abs(h.tau / p.cohesion - softening_reference(h.us / u0, 1.3, 0.5, 2.1)));
    }
    CHECK(max_err < 1e-6);
    CHECK(h.broken == JointState::broken_shear);
    const double gii = 0.925 * p.cohesion * p.cohesion / p.ks; // 2071.5 J/m²
    CHECK(gii == doctest::Approx(2071.5).epsilon(1e-4));
    CHECK(work == doctest::Approx(gii).epsilon(0.01));
}

TEST_CASE("softening law with fracture energies: the same G_I and G_II at any stiffness and strength") {
    // The paper's curves' areas in units of peak·u0 (SPEC §4): 1.6 and 0.925.
    CHECK(SofteningCurve::normalised_energy({{1.7, 0.5}, {4.0, 0.0}}) == doctest::Approx(1.6).epsilon(1e-12));
    CHECK(SofteningCurve::normalised_energy({{1.3, 0.5}, {2.1, 0.0}}) == doctest::Approx(0.925).epsilon(1e-12));
    const double gi = 300.0, gii = 4000.0;
    for (const double stiffer : {1.0, 2.5})       // a finer block size calibrates stiffer joints
        for (const double stronger : {1.0, 1.3}) { // and may move the peaks
            INFO("stiffness x" << stiffer << ", strengths x" << stronger);
            auto p = paper_bond();
            p.kn *= stiffer, p.ks *= stiffer, p.tensile *= stronger, p.cohesion *= stronger;
            p.tension_fracture_energy = gi, p.shear_fracture_energy = gii;
            const SofteningLaw law(p);
            // Tension: pulled until broken; the peak is still σt at σt/kn, the
            // curve ends (zero stress) at the plastic displacement 4.0 · G_I / (1.6 σt).
            JointHistory h;
            const double end = 4.0 * gi / (1.6 * p.tensile), du = end / 20000;
            double work = 0.0, prev = 0.0, peak = 0.0;
            while (h.bonded) {
                law.update(h, du, 0.0);
                work += 0.5 * (prev - h.sn) * du;
                prev = -h.sn;
                peak = std::max(peak, -h.sn);
            }
            CHECK(peak == doctest::Approx(p.tensile).epsilon(1e-3));
            CHECK(h.un == doctest::Approx(end).epsilon(1e-3));
            CHECK(work == doctest::Approx(gi).epsilon(0.005));
            CHECK(h.dissipated == doctest::Approx(gi).epsilon(0.005));
            // Shear at σn = 0.
            JointHistory s;
            const double ds = 2.1 * gii / (0.925 * p.cohesion) / 20000;
            work = prev = 0.0;
            while (s.bonded) {
                law.update(s, 0.0, ds);
                work += 0.5 * (prev + s.tau) * ds;
                prev = s.tau;
            }
            CHECK(work == doctest::Approx(gii).epsilon(0.005));
        }
}

TEST_CASE("softening law, shear at sigma_n = 5 MPa: peak c + sn tan phi, residual sn tan phi") {
    const auto p = paper_bond();
    const SofteningLaw law(p);
    JointHistory h;
    const double sn = 5e6;
    law.update(h, -sn / p.kn, 0.0);
    CHECK(h.sn == doctest::Approx(sn));
    const double du = p.cohesion / p.ks / 1000;
    double peak = 0;
    for (int k = 0; k < 6000; ++k) {
        law.update(h, 0.0, du);
        peak = std::max(peak, h.tau);
    }
    // The sampled peak lies on the curve within the step that crosses the peak:
    // at most one elastic increment ks·du below it, never above.
    const double strength = p.cohesion + sn * tan_deg(25);
    CHECK(peak <= strength * (1 + 1e-12));
    CHECK(peak >= strength - p.ks * du);
    CHECK(h.tau == doctest::Approx(sn * tan_deg(25)).epsilon(1e-9));
    CHECK(h.broken == JointState::broken_shear);
}

TEST_CASE("softening law with a confined friction: the bonded cap steepens above sigma_star and broken joints keep phi_r") {
    auto p = paper_bond();
    p.friction = 5.0, p.residual_friction = 35.0;
    p.confined_friction = 45.0, p.confined_friction_from = 60e6;
    const SofteningLaw law(p);
    const double c = p.cohesion, sigma_star = 60e6;
    // The peak shear stress at a held normal stress, sampled finely enough to
    // read it within one increment.
    auto shear_peak = [&](double sn, JointHistory* end) {
        JointHistory h;
        law.update(h, -sn / p.kn, 0.0);
        const double du = (c + sn) / p.ks / 2000;
        double peak = 0;
        for (int k = 0; k < 20000 && h.bonded; ++k) {
            law.update(h, 0.0, du);
            peak = std::max(peak, h.tau);
        }
        for (int k = 0; k < 200; ++k) law.update(h, 0.0, du); // on, broken
        if (end) *end = h;
        return std::pair{peak, p.ks * du};
    };
    // Below σ*: c + σn tan φ, as without the key.
    {
        const auto [peak, step] = shear_peak(40e6, nullptr);
        const double strength = c + 40e6 * tan_deg(5);
        CHECK(peak <= strength * (1 + 1e-12));
        CHECK(peak >= strength - step);
    }
    // Above σ*: c + σ* tan φ + (σn − σ*) tan φ2 (the cap continuous at σ*).
    JointHistory broken;
    {
        const double sn = 150e6;
        const auto [peak, step] = shear_peak(sn, &broken);
        const double strength = c + sigma_star * tan_deg(5) + (sn - sigma_star) * tan_deg(45);
        CHECK(strength == doctest::Approx(c + 95.25e6).epsilon(1e-3));
        CHECK(peak <= strength * (1 + 1e-12));
        CHECK(peak >= strength - step);
    }
    // Broken: friction φr at any normal stress, the confined friction gone.
    CHECK(broken.broken == JointState::broken_shear);
    CHECK(broken.tau == doctest::Approx(150e6 * tan_deg(35)).epsilon(1e-9));
    // The elastic limit the lab tests preload by sees the same cap.
    JointHistory before, trial;
    before.sn = trial.sn = 100e6;
    trial.tau = 2 * (c + sigma_star * tan_deg(5) + 40e6 * tan_deg(45));
    CHECK(elastic_limit(JointLaw(law), before, trial, 1.0) == doctest::Approx(0.5).epsilon(1e-9));
    // A friction that flattens instead (φ2 < φ) is read the same way: the peak at
    // σn = 150 MPa is c + σ* tan 30° + (σn − σ*) tan 10°, not the lower bound
    // σn tan 10° that the elastic path tests first.
    {
        auto f = p;
        f.friction = 30.0, f.confined_friction = 10.0, f.confined_friction_from = 60e6;
        const SofteningLaw flat(f);
        JointHistory h;
        flat.update(h, -150e6 / f.kn, 0.0);
        const double strength = c + 60e6 * tan_deg(30) + 90e6 * tan_deg(10), du = strength / f.ks / 2000;
        double peak = 0;
        for (int k = 0; k < 4000 && h.bonded; ++k) {
            flat.update(h, 0.0, du);
            peak = std::max(peak, h.tau);
        }
        CHECK(peak <= strength * (1 + 1e-12));
        CHECK(peak >= strength - f.ks * du);
    }
    // A Coulomb law ignores it: the key is the softening law's.
    auto q = p;
    q.law = "coulomb";
    const CoulombLaw coulomb(q);
    CHECK(coulomb.friction(150e6) == doctest::Approx(150e6 * tan_deg(5)));
}

TEST_CASE("softening law: unloading is elastic with the initial stiffness, damage persists") {
    const auto p = paper_bond();
    const SofteningLaw law(p);
    const double u0 = p.cohesion / p.ks, du = u0 / 500;
    JointHistory h;
    // Load into softening, to 1.15 u0 (between the peak and the first point).
    for (int k = 0; k < 575; ++k) law.update(h, 0.0, du);
    const double tau_soft = h.tau, d = h.damage;
    CHECK(d > 0.0);
    CHECK(d < 1.0);
    CHECK(tau_soft < p.cohesion);
    // Unload by 100 steps: stress falls with the initial stiffness ks.
    for (int k = 0; k < 100; ++k) law.update(h, 0.0, -du);
    CHECK(h.tau == doctest::Approx(tau_soft - 100 * du * p.ks).epsilon(1e-12));
    CHECK(h.damage == d);
    // Reload: the cap is the softened strength, not c.
    double peak = 0;
    for (int k = 0; k < 101; ++k) {
        law.update(h, 0.0, du);
        peak = std::max(peak, h.tau);
    }
    CHECK(peak == doctest::Approx(tau_soft).epsilon(1e-9));
    CHECK(peak < p.cohesion);
    // Coupled damage: the tensile strength is softened by the same D.
    JointHistory t = h;
    for (int k = 0; k < 2000 && -t.sn < 2 * p.tensile; ++k) {
        law.update(t, p.tensile / p.kn / 1000, 0.0);
        if (t.upn > 0) break;
    }
    CHECK(-t.sn <= p.tensile * (1 - d) * (1 + 1e-9));
}

TEST_CASE("brittle softening (no post-peak points) and the Coulomb law") {
    auto p = paper_bond();
    p.tension_softening.clear();
    const SofteningLaw brittle(p);
    JointHistory h;
    const double du = p.tensile / p.kn / 10;
    for (int k = 0; k < 10; ++k) brittle.update(h, du, 0.0);
    CHECK(-h.sn == doctest::Approx(p.tensile));
    brittle.update(h, du, 0.0);
    CHECK(h.sn == 0.0);
    CHECK(h.broken == JointState::broken_tension);

    JointPropertySpec c;
    c.law = "coulomb";
    c.kn = 1e9;
    c.ks = 1e9;
    c.friction = 30;
    const CoulombLaw coulomb(c);
    JointHistory s;
    s.bonded = false;
    coulomb.update(s, -1e-3, 0.0); // 1 MPa compression
    CHECK(s.sn == doctest::Approx(1e6));
    for (int k = 0; k < 10; ++k) coulomb.update(s, 0.0, 1e-3);
    CHECK(s.tau == doctest::Approx(1e6 * tan_deg(30)));
    CHECK(s.slipping);
    coulomb.update(s, 2e-3, 0.0); // opens: no tension, no shear
    CHECK(s.sn == 0.0);
    CHECK(s.tau == 0.0);
}

namespace {

/// Barton (1982), "Modelling rock joint behaviour from in situ block tests":
/// JRC_mob / JRC against δ / δp, the mobilised angle φr + (JRC_mob/JRC) i with
/// i = JRC log10(JCS/σn); −φr/i at δ = 0 (φ_mob = 0).
double barton_mobilised_deg(double r, double residual, double i) {
    constexpr std::array<std::pair<double, double>, 8> table{
        {{0.3, 0.0}, {0.6, 0.75}, {1.0, 1.0}, {2.0, 0.85}, {4.0, 0.70}, {10.0, 0.5}, {100.0, 0.0}, {1e9, 0.0}}};
    if (r < 0.3) return residual * r / 0.3;
    for (std::size_t k = 0; k + 1 < table.size(); ++k)
        if (r < table[k + 1].first) {
            const auto [r0, f0] = table[k];
            const auto [r1, f1] = table[k + 1];
            return residual + i * (f0 + (f1 - f0) * (r - r0) / (r1 - r0));
        }
    return residual;
}

/// A joint sheared at a held normal stress: (shear displacement, τ) every step.
std::vector<std::pair<double, double>> shear_at_constant_normal_stress(const contact::BartonBandisLaw& bb, double kn,
                                                                      double sn, double du, double to,
                                                                      contact::JointHistory* end = nullptr) {
    contact::JointHistory h;
    h.bonded = false;
    std::vector<std::pair<double, double>> curve;
    for (double u = 0.0; u < to; u += du) {
        const double dun = (h.upn - sn / kn) - h.un; // keep σn = kn (upn − un) at sn
        bb.update(h, dun, du);
        curve.emplace_back(h.us, h.tau);
    }
    if (end) *end = h;
    return curve;
}

} // namespace

TEST_CASE("Barton-Bandis joint: Barton's mobilisation curve before and after the peak, its peak displacement") {
    // A 0.2 m joint of JRC 7, JCS 100 MPa, φr 30°, ks 43 GPa/m as a new user would
    // give it: δp = (L/500)(JRC/L)^0.33 = 1.3 mm (Barton & Bandis 1982), where
    // elastic to the peak it would have peaked at τp/ks = 0.02-0.16 mm.
    JointPropertySpec p;
    p.law = "barton_bandis";
    p.kn = 100e9, p.ks = 43e9;
    p.friction = 30.0, p.jrc = 7.0, p.jcs = 100e6, p.joint_length = 0.2;
    const contact::JointLaw law = contact::make_law(p);
    const auto& bb = std::get<contact::BartonBandisLaw>(law);
    CHECK_FALSE(contact::starts_bonded(law));
    CHECK(p.law == "barton_bandis");
    const double deg = std::numbers::pi / 180.0;
    const double dp = 0.2 / 500.0 * std::pow(7.0 / 0.2, 0.33);
    CHECK(dp == doctest::Approx(1.30e-3).epsilon(0.01));
    CHECK(bb.peak_displacement == doctest::Approx(dp).epsilon(1e-12));

    for (double sn : {0.8e6, 9e6}) {
        CAPTURE(sn);
        const double i = 7.0 * std::log10(100e6 / sn);
        const double du = dp / 4000;
        const auto curve = shear_at_constant_normal_stress(bb, p.kn, sn, du, 12.0 * dp);
        // The peak where Barton has it, at δp (within two increments), and its value.
        const auto peak = *std::max_element(curve.begin(), curve.end(),
                                            [](const auto& a, const auto& b) { return a.second < b.second; });
        CHECK(peak.first == doctest::Approx(dp).epsilon(2.0 / 4000));
        CHECK(peak.second == doctest::Approx(sn * std::tan((30.0 + i) * deg)).epsilon(1e-3));
        // The whole curve: τ(δ) = σn tan φ_mob(δ/δp) at every step, within the
        // lag of one increment (its slope times du).
        double worst = 0.0;
        for (const auto& [u, tau] : curve) {
            const double expected = sn * std::tan(barton_mobilised_deg(u / dp, 30.0, i) * deg);
            worst = std::max(worst, std::abs(tau - expected) / (sn * std::tan((30.0 + i) * deg)));
        }
        CHECK(worst < 2e-3);
    }
}

TEST_CASE("Barton-Bandis joint: dilation while sliding, the residual, the bounds of its angle, unloading") {
    JointPropertySpec p;
    p.law = "barton_bandis";
    p.kn = 100e9, p.ks = 50e9;
    p.friction = 28.0, p.jrc = 12.0, p.jcs = 80e6, p.joint_length = 0.5;
    const contact::JointLaw law = contact::make_law(p);
    const auto& bb = std::get<contact::BartonBandisLaw>(law);
    const double deg = std::numbers::pi / 180.0;
    const double dp = 0.5 / 500.0 * std::pow(12.0 / 0.5, 0.33);
    for (double sn : {2e6, 10e6}) {
        CAPTURE(sn);
        contact::JointHistory h;
        const auto curve = shear_at_constant_normal_stress(bb, p.kn, sn, dp / 1000, 110.0 * dp, &h);
        const double roughness = 12.0 * std::log10(80e6 / sn);
        // Past δ/δp = 100 the residual σn tan φr.
        CHECK(curve.back().second == doctest::Approx(sn * std::tan(28.0 * deg)).epsilon(1e-6));
        // The opening while sliding: ∫ tan(½ (φ_mob − φr)) dups, where positive:
        // above the peak's rate over the stretch from 0.6 δp to 2 δp, where
        // φ_mob − φr ≥ 0.75 i, and below the peak's rate over the whole slide.
        CHECK(h.upn > 1.4 * dp * std::tan(0.5 * 0.75 * roughness * deg) * 0.99);
        CHECK(h.upn < 110.0 * dp * std::tan(0.5 * roughness * deg));
    }
    // Bounds: φr + JRC log10(JCS/σn) at most 70°; σn above JCS gives φr (at the peak, δ = δp).
    CHECK(bb.strength(1.0, dp) == doctest::Approx(1.0 * std::tan(70.0 * deg)));
    CHECK(bb.strength(100e6, dp) == doctest::Approx(100e6 * std::tan(28.0 * deg)));
    // Unloaded past its peak and reloaded: elastic with ks, then the softened strength.
    contact::JointHistory h;
    (void)shear_at_constant_normal_stress(bb, p.kn, 5e6, dp / 1000, 3.0 * dp, &h);
    const double tau = h.tau, worn = h.ups;
    bb.update(h, 0.0, -tau / p.ks / 2);
    CHECK(h.tau == doctest::Approx(tau / 2).epsilon(1e-9));
    CHECK(h.ups == worn);
    contact::JointHistory open;
    open.bonded = false;
    bb.update(open, 1e-4, 1e-4);
    CHECK(open.sn == 0.0);
    CHECK(open.tau == 0.0);
}

namespace {

/// A CWFS bond after Hajiabdolmajid, Kaiser & Martin (2002): cohesion 50 → 15 MPa
/// over 0.2 mm of plastic slip, friction 0 → 48° over 0.5 mm (their Lac du Bonnet
/// parameters, with their plastic strains 0.2% and 0.5% read as slips over 0.1 m).
JointPropertySpec cwfs_bond() {
    JointPropertySpec p;
    p.name = "cwfs";
    p.law = "cwfs";
    p.kn = 500e9, p.ks = 200e9;
    p.cohesion = 50e6, p.tensile = 10e6, p.friction = 0.0;
    set_law_value(p, "residual_cohesion", 15e6);
    set_law_value(p, "mobilised_friction", 48.0);
    set_law_value(p, "cohesion_slip", 0.2e-3);
    set_law_value(p, "friction_slip", 0.5e-3);
    return p;
}

void law_update(const contact::JointLaw& law, contact::JointHistory& h, double dun, double dus) {
    std::visit([&](const auto& l) { l.update(h, dun, dus); }, law);
}

} // namespace

TEST_CASE("cwfs: under a held normal stress the shear stress follows c(ups) + sigma_n tan phi(ups), the closed form") {
    const auto p = cwfs_bond();
    REQUIRE_FALSE(contact::check_joint_property(p));
    const contact::JointLaw law = contact::make_law(p);
    const auto& cwfs = std::get<contact::CwfsLaw>(law);
    const double uc = 0.2e-3, uf = 0.5e-3, deg = std::numbers::pi / 180.0;
    // The closed form: c falls linearly to cr over uc, tan φ rises linearly to tan φm over uf.
    auto c = [&](double ups) { return 50e6 + (15e6 - 50e6) * std::min(ups / uc, 1.0); };
    auto tan_phi = [&](double ups) { return std::tan(48.0 * deg) * std::min(ups / uf, 1.0); };
    for (double sn : {0.0, 10e6, 60e6}) {
        CAPTURE(sn);
        contact::JointHistory h;
        law_update(law, h, -sn / p.kn, 0.0);
        CHECK(h.sn == doctest::Approx(sn));
        // Coarse increments (a tenth of uc): the return is exact on the cap's pieces.
        const double du = uc / 10;
        double worst = 0.0, peak = 0.0;
        for (int k = 0; k < 100; ++k) {
            law_update(law, h, 0.0, du);
            peak = std::max(peak, h.tau);
            if (h.slipping) worst = std::max(worst, std::abs(h.tau - (c(h.ups) + sn * tan_phi(h.ups))) / 50e6);
            CHECK(h.ups == doctest::Approx(std::max(0.0, h.us - h.tau / p.ks)).epsilon(1e-9));
        }
        CHECK(worst < 1e-12);
        // The end: the residual cohesion and the mobilised friction.
        CHECK(h.tau == doctest::Approx(15e6 + sn * std::tan(48.0 * deg)).epsilon(1e-12));
        CHECK(h.bonded); // a residual cohesion: never broken in shear
        // The peak: the cap's largest value, at one of its breakpoints 0, uc, uf (the
        // sampled one at most an elastic increment ks du below it, never above).
        auto cap = [&](double u) { return c(u) + sn * tan_phi(u); };
        const double top = std::max({cap(0.0), cap(uc), cap(uf)});
        CHECK(peak <= top * (1 + 1e-12));
        CHECK(peak >= top - p.ks * du);
        // The plastic work: the area under the cap over the plastic slip.
        double area = 0.0;
        const int n = 200000;
        for (int k = 0; k < n; ++k) area += cap((k + 0.5) * h.ups / n) * h.ups / n;
        CHECK(h.dissipated == doctest::Approx(area).epsilon(1e-6));
    }
    // Friction strengthening: under a high normal stress the residual is stronger than the peak.
    contact::JointHistory deep;
    law_update(law, deep, -200e6 / p.kn, 0.0);
    for (int k = 0; k < 400; ++k) law_update(law, deep, 0.0, uc / 20);
    CHECK(deep.tau == doctest::Approx(15e6 + 200e6 * std::tan(48.0 * deg)).epsilon(1e-12));
    CHECK(deep.tau > 50e6); // above the intact cap c0 + σn tan φ0
    // The tensile strength goes with the cohesion: after half the cohesion slip
    // (c about 32.5 MPa) the bond opens at σt c / c0, about 6.5 MPa, not 10.
    contact::JointHistory t;
    while (t.ups < 0.5 * uc) law_update(law, t, 0.0, uc / 1000); // sheared at σn = 0
    law_update(law, t, 0.0, -t.tau / p.ks);                       // the shear unloaded elastically
    CHECK(std::abs(t.tau) < 1.0);
    const double expected = 10e6 * cwfs.cohesion(t.ups) / 50e6;
    double opened_at = 0.0;
    for (int k = 1; k <= 2000 && t.bonded; ++k) {
        law_update(law, t, 10e6 / p.kn / 1000, 0.0);
        if (t.bonded) opened_at = -t.sn;
    }
    CHECK_FALSE(t.bonded);
    CHECK(t.broken == JointState::broken_tension);
    CHECK(opened_at <= expected);
    CHECK(opened_at > expected - 10e6 / 1000);
    // Without a residual cohesion the bond breaks once the cohesion is lost: a shear crack.
    auto q = p;
    set_law_value(q, "residual_cohesion", 0.0);
    const contact::JointLaw brittle = contact::make_law(q);
    contact::JointHistory b;
    for (int k = 0; k < 100 && b.bonded; ++k) law_update(brittle, b, 0.0, uc / 10);
    CHECK(b.broken == JointState::broken_shear);
    // The rules: a residual above the peak, a friction that weakens, are refused by key.
    auto bad = p;
    set_law_value(bad, "residual_cohesion", 60e6);
    CHECK(contact::check_joint_property(bad)->key == "residual_cohesion");
    bad = p;
    set_law_value(bad, "mobilised_friction", -1.0);
    CHECK(contact::check_joint_property(bad)->key == "mobilised_friction");
}
