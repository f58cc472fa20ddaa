// Joint laws (contact/joint_law.hpp) against SPEC §4: the softening curves pass
// through their points, fracture energies equal the areas under the curves,
// unloading is elastic with the initial stiffness, damage persists.
#include "contact/joint_law.hpp"
#include "studies/labtest.hpp"

#include "tests/softening_reference.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

using namespace bbm;
using namespace bbm::contact;

namespace {

/// The paper's Voronoi calibration (SPEC §8).
JointPropertySpec paper_bond() { return LabTestOptions::paper_ucs().joint; }

double tan_deg(double d) { return std::tan(d * std::numbers::pi / 180.0); }


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
    q.law = JointPropertySpec::Law::coulomb;
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
    c.law = JointPropertySpec::Law::coulomb;
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

TEST_CASE("Barton-Bandis joint: peak, dilation, post-peak mobilisation of JRC and its bounds") {
    JointPropertySpec p;
    p.law = JointPropertySpec::Law::barton_bandis;
    p.kn = 100e9, p.ks = 50e9;
    p.friction = 28.0, p.jrc = 12.0, p.jcs = 80e6, p.joint_length = 0.5;
    const contact::JointLaw law = contact::make_law(p);
    const auto& bb = std::get<contact::BartonBandisLaw>(law);
    CHECK_FALSE(contact::starts_bonded(law));
    CHECK(contact::law_names[std::size_t(p.law)] == "barton_bandis");
    const double deg = std::numbers::pi / 180.0;
    // δp = (L/500)(JRC/L)^0.33 (Barton & Bandis 1982): 0.5 m, JRC 12 -> 2.85 mm.
    const double dp = 0.5 / 500.0 * std::pow(12.0 / 0.5, 0.33);
    CHECK(bb.peak_displacement == doctest::Approx(dp).epsilon(1e-12));

    // Sheared under a constant normal stress: the opening follows the dilation.
    for (double sn : {2e6, 10e6}) {
        CAPTURE(sn);
        contact::JointHistory h;
        h.bonded = false;
        const double du = 1e-6; // shear increment, m
        double peak = 0.0, tau_at_4dp = 0.0, upn_at_peak_slip = -1.0;
        for (int k = 0; k < 400000 && h.ups < 120.0 * dp; ++k) {
            const double dun = (h.upn - sn / p.kn) - h.un; // keep σn = kn (upn − un) at sn
            bb.update(h, dun, du);
            peak = std::max(peak, h.tau);
            if (upn_at_peak_slip < 0 && h.slipping) upn_at_peak_slip = h.upn;
            if (tau_at_4dp == 0.0 && h.ups >= 3.0 * dp) tau_at_4dp = h.tau; // δ/δp = 1 + ups/δp = 4
        }
        const double roughness = 12.0 * std::log10(80e6 / sn);
        CHECK(peak == doctest::Approx(sn * std::tan((28.0 + roughness) * deg)).epsilon(1e-4));
        // JRC_mob = 0.70 JRC at δ/δp = 4 (Barton 1982), the residual σn tan φr beyond 100.
        const double sn_now = -p.kn * (h.un - h.upn);
        CHECK(tau_at_4dp == doctest::Approx(sn * std::tan((28.0 + 0.7 * roughness) * deg)).epsilon(1e-3));
        CHECK(h.tau == doctest::Approx(sn_now * std::tan(28.0 * deg)).epsilon(1e-6));
        // The opening while sliding: ∫ tan(½ JRC_mob log10(JCS/σn)) dups, between
        // the peak's rate and zero: at least the first δp at the peak's rate.
        CHECK(h.upn > dp * std::tan(0.5 * roughness * deg) * 0.99);
        CHECK(h.upn < 120.0 * dp * std::tan(0.5 * roughness * deg));
    }
    // Bounds: φr + JRC log10(JCS/σn) at most 70°; σn above JCS gives φr; apart, no shear.
    CHECK(bb.strength(1.0, 0.0) == doctest::Approx(1.0 * std::tan(70.0 * deg)));
    CHECK(bb.strength(100e6, 0.0) == doctest::Approx(100e6 * std::tan(28.0 * deg)));
    contact::JointHistory open;
    open.bonded = false;
    bb.update(open, 1e-4, 1e-4);
    CHECK(open.sn == 0.0);
    CHECK(open.tau == 0.0);
}
