#include "studies/lab/residual_friction.hpp"

#include "studies/cluster/ranks.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace bbm {

ResidualFrictionStep measure_rubble_friction(const JointPropertySpec& joint, const ResidualFrictionTarget& t,
                                             const CalibrationOptions& o, std::uint64_t first_seed) {
    const auto t0 = std::chrono::steady_clock::now();
    auto run = [&](int k) -> std::string {
        LabTestOptions lo = o.base;
        lo.rock.bonds = joint;
        lo.rock.pattern.seed = first_seed + std::uint64_t(k);
        lo.threads = 1;
        lo.kind = LabTestOptions::Kind::biaxial;
        lo.confinement = t.confinement;
        // On to max_strain whatever the stress does: the rubble's sliding is the measure.
        lo.stop.fraction = 0.0, lo.stop.max_strain = t.max_strain, lo.stop.strain_cap = t.max_strain;
        lo.stop.post_peak_strain = 0.0;
        lo.frame_every = 0;
        const LabTestResult r = run_labtest(lo);
        char text[96];
        std::snprintf(text, sizeof text, "%.17g %.17g %.17g", r.residual_friction_angle, r.residual_stress,
                      r.peak_stress);
        return text;
    };
    const auto texts = studies::run_spread(o.realizations, o.threads, run);
    ResidualFrictionStep step;
    step.residual_friction = joint.residual_friction >= 0.0 ? joint.residual_friction : joint.friction;
    std::vector<double> phi, residual, peak;
    for (const auto& text : texts) {
        double a = 0, sr = 0, sp = 0;
        if (std::sscanf(text.c_str(), "%lf %lf %lf", &a, &sr, &sp) != 3)
            throw std::runtime_error("residual friction: a run's result did not arrive");
        peak.push_back(sp);
        if (!(sr > 0.0 && a > 0.0)) {
            ++step.unmeasured;
            continue;
        }
        phi.push_back(a), residual.push_back(sr);
    }
    double sd = 0;
    mean_std(phi, step.rubble_friction, step.rubble_std);
    mean_std(residual, step.residual_stress, sd);
    mean_std(peak, step.peak_stress, sd);
    step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return step;
}

double next_residual_friction(double phi_prev, double measured_prev, double phi, double measured, double target) {
    double slope = 1.4; // degrees of rubble friction per degree of φr, Lac du Bonnet's in-situ set (header)
    if (phi_prev >= 0.0 && std::abs(phi - phi_prev) > 1e-6) {
        const double secant = (measured - measured_prev) / (phi - phi_prev);
        if (secant >= 0.3 && secant <= 5.0) slope = secant;
    }
    return std::clamp(phi + std::clamp((target - measured) / slope, -10.0, 10.0), 0.0, 60.0);
}

std::vector<ResidualFrictionStep> calibrate_residual_friction(JointPropertySpec joint, const ResidualFrictionTarget& t,
                                                              const CalibrationOptions& o,
                                                              const std::function<void(const ResidualFrictionStep&)>& report) {
    if (!(t.friction > 0.0 && t.confinement > 0.0))
        throw std::invalid_argument("a residual-friction calibration needs the rubble's friction and a confinement");
    if (joint.residual_friction < 0.0) joint.residual_friction = joint.friction;
    std::vector<ResidualFrictionStep> steps;
    double phi_prev = -1.0, measured_prev = 0.0;
    for (int iteration = 0; iteration < t.max_iterations; ++iteration) {
        ResidualFrictionStep step = measure_rubble_friction(joint, t, o, o.base.rock.pattern.seed);
        // A rubble no run measured (every curve ended too soon after its peak) cannot steer.
        const bool measured = step.unmeasured < o.realizations;
        step.converged = measured && std::abs(step.rubble_friction - t.friction) <= t.tolerance;
        steps.push_back(step);
        if (report) report(step);
        if (step.converged || !measured) break;
        const double phi = joint.residual_friction;
        joint.residual_friction = next_residual_friction(phi_prev, measured_prev, phi, step.rubble_friction, t.friction);
        phi_prev = phi, measured_prev = step.rubble_friction;
        if (std::abs(joint.residual_friction - phi) < 1e-9) break; // at a bound: no further to go
    }
    return steps;
}

const ResidualFrictionStep& best_residual_step(const std::vector<ResidualFrictionStep>& steps, double target) {
    if (steps.empty()) throw std::logic_error("best_residual_step: no iterations");
    const ResidualFrictionStep* best = nullptr;
    for (const auto& s : steps) {
        if (s.converged) return s;
        if (s.unmeasured == 0 || s.rubble_friction > 0.0)
            if (!best || std::abs(s.rubble_friction - target) < std::abs(best->rubble_friction - target)) best = &s;
    }
    return best ? *best : steps.front();
}

} // namespace bbm
