// bbm studies: running a lab test (studies/lab/labtest.hpp) — the loading loop, its
// gauges, its servo and its stop rules, each a small named piece.
#include "studies/lab/labtest.hpp"

#include "base/error.hpp"
#include "core/solver.hpp"
#include "studies/model/run_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <stdexcept>

namespace bbm {

namespace {
/// The moving platen: the blocks and nodes with a prescribed, non-zero vertical
/// velocity (the top face), whose speed the loading sets.
class MovingPlaten {
public:
    explicit MovingPlaten(Solver& s) : s_(s) {
        const Loads& l = s.world().loads;
        for (int i = 0; i < s.world().bodies.count(); ++i)
            if ((l.block_fixed[i] & 2) && l.block_velocity[i].y != 0.0)
                blocks_.push_back(i), sign_ = l.block_velocity[i].y > 0 ? 1 : -1;
        for (int k = 0; k < s.world().nodes.count(); ++k)
            if ((l.node_fixed[k] & 2) && l.node_velocity[k].y != 0.0)
                nodes_.push_back(k), sign_ = l.node_velocity[k].y > 0 ? 1 : -1;
    }
    /// Vertical speed (m per step), in the loading direction.
    void set_speed(double v) {
        Loads& l = s_.world().loads;
        for (int i : blocks_) l.block_velocity[i].y = sign_ * v;
        for (int k : nodes_) l.node_velocity[k].y = sign_ * v;
    }

private:
    Solver& s_;
    std::vector<int> blocks_, nodes_;
    double sign_ = -1.0;
};

/// Seismic events so far: the catalogue and the open events with a broken bond.
int event_count(const World& w) {
    if (!w.events) return 0;
    int n = w.events->count();
    for (int b : w.events->open_broken) n += b > 0;
    return n;
}

/// Applies the biaxial confinement gradually with the platens held still, then lets
/// the specimen settle; returns the step at which axial loading starts.
long confine(Solver& s, MovingPlaten& platen) {
    Loads& l = s.world().loads;
    const auto block_load = l.block_force;
    const auto block_moment = l.block_moment;
    const auto node_load = l.node_force;
    platen.set_speed(0.0);
    auto scale = [&](double f) {
        for (std::size_t i = 0; i < block_load.size(); ++i)
            l.block_force[i] = f * block_load[i], l.block_moment[i] = f * block_moment[i];
        for (std::size_t k = 0; k < node_load.size(); ++k) l.node_force[k] = f * node_load[k];
    };
    constexpr long ramp = 3000, settle_max = 20000;
    for (long k = 1; k <= ramp; ++k) {
        scale(double(k) / double(ramp));
        s.step();
    }
    for (long k = 0; k < settle_max && !(k > 200 && s.world().clock.ratio < 1e-5); ++k) s.step();
    return s.world().clock.steps;
}


/// The share of the compression the contacts carry (Σ σn L over contacts in
/// compression) that unbonded contacts carry: broken joints and contacts formed
/// during the run.
double unbonded_compression_share(const Solver& s) {
    const auto& c = contacts(s.world());
    double all = 0.0, unbonded = 0.0;
    for (int i = 0; i < c.size(); ++i) {
        const double f = std::max(0.0, c.history[i].sn) * c.length[i];
        all += f;
        if (!c.history[i].bonded) unbonded += f;
    }
    return all > 0.0 ? unbonded / all : 0.0;
}


/// The specimen's gauges: the axial stress from the top platen's reaction (the
/// Brazilian test's 2F/πD), the lateral strain from side bands over the middle
/// half of the height, where a lab specimen carries its lateral gauges (ISRM) —
/// away from the platens, whose friction holds the ends in (the whole height read
/// ν of the hexagonal lattice 16% low: 0.144 against 0.171).
class Gauges {
public:
    Gauges(const Solver& s, const LabTestOptions& o)
        : s_(s), o_(o), brazilian_(o.kind == LabTestOptions::Kind::brazilian),
          sign_(o.kind == LabTestOptions::Kind::tension ? -1.0 : 1.0) {
        const auto& b = s.world().blocks;
        const double h = specimen_height(o), band = 0.5 * o.rock.pattern.size;
        for (int i = 0; i < b.count(); ++i) {
            const Vec2 c = b.centroid0[i];
            if (c.y < std::max(band, 0.25 * h) || c.y > std::min(h - band, 0.75 * h)) continue;
            if (c.x < o.rock.pattern.size) left_.push_back(i);
            if (c.x > o.width - o.rock.pattern.size) right_.push_back(i);
        }
    }
    StressStrainPoint measure(double at_strain, double at_rate) const {
        const double force = sign_ * boundary_force(s_.world(), "top").y;
        StressStrainPoint p;
        p.step = s_.world().clock.steps;
        p.axial_strain = at_strain;
        p.axial_stress = brazilian_ ? 2.0 * force / (std::numbers::pi * o_.width) : force / o_.width;
        p.lateral_strain = (mean_ux(right_) - mean_ux(left_)) / o_.width;
        p.cracks_tensile = cracks(s_.world(), contact::JointState::broken_tension);
        p.cracks_shear = cracks(s_.world(), contact::JointState::broken_shear);
        p.unbalanced_ratio = s_.world().clock.ratio;
        p.strain_per_step = at_rate;
        p.events = event_count(s_.world());
        return p;
    }

private:
    /// A deformable block moves with its nodes: the mean of its boundary nodes.
    double ux_of(int i) const {
        const World& w = s_.world();
        const auto& b = w.blocks;
        if (!b.deformable[i]) return w.bodies.state[i].centroid.x - b.centroid0[i].x;
        const auto& nodes = w.nodes;
        double u = 0.0;
        for (std::uint32_t v = b.first[i]; v < b.first[i + 1]; ++v) {
            const int nd = w.vertices.node[v];
            u += nodes.position[nd].x - nodes.position0[nd].x;
        }
        return u / double(b.first[i + 1] - b.first[i]);
    }
    double mean_ux(const std::vector<int>& ids) const {
        double u = 0;
        for (int i : ids) u += ux_of(i);
        return ids.empty() ? 0.0 : u / ids.size();
    }
    const Solver& s_;
    const LabTestOptions& o_;
    bool brazilian_;
    double sign_;
    std::vector<int> left_, right_;
};

/// σci from the events, as a laboratory reads it from acoustic emission: the
/// first point whose events reach 2% of those at the peak (at least 3).
void measure_event_onset(LabTestResult& r, long peak_step) {
    int at_peak = 0;
    for (const auto& p : r.curve)
        if (p.step <= peak_step) at_peak = p.events;
    r.events_at_peak = at_peak;
    const int onset = std::max(3, int(std::ceil(0.02 * at_peak)));
    if (at_peak < onset) return;
    for (const auto& p : r.curve)
        if (p.events >= onset) {
            r.crack_initiation_events = p.axial_stress;
            return;
        }
}

/// Crack orientation when each crack forms (later the fragments rotate): the
/// angle of its joint from horizontal, 0–180°.
void record_new_cracks(Solver& s, LabTestResult& r) {
    auto& c = contacts(s.world());
    for (int i = 0; i < c.size(); ++i) {
        auto& hist = c.history[i];
        if (hist.broken == contact::JointState::intact || hist.counted) continue;
        hist.counted = true;
        const Vec2 t = contact::tangent_of(c.normal[i]);
        double angle = std::atan2(t.y, t.x) * 180.0 / std::numbers::pi;
        while (angle < 0) angle += 180.0;
        while (angle >= 180.0) angle -= 180.0;
        ++r.crack_orientation[std::min(11, int(angle / 15.0))];
        if (std::abs(angle - 90.0) <= 30.0) ++r.cracks_near_vertical;
        if (angle <= 30.0 || angle >= 150.0) ++r.cracks_near_horizontal;
    }
}

/// The joint set's contacts: the axial stress at which half, and then 90%, of
/// their length slides at its limit.
class JointSetGauge {
public:
    JointSetGauge(const Solver& s, const LabTestOptions& o) {
        for (std::size_t k = 0; k < s.world().properties.names.size(); ++k)
            if (o.joint_set.on && s.world().properties.names[k] == "joint_set") property_ = int(k);
    }
    void record(const Solver& s, const StressStrainPoint& p, LabTestResult& r) const {
        if (property_ < 0 || r.joint_slip_stress > 0.0) return;
        const double share = sliding(s);
        if (share >= 0.5 && !(r.joint_slip_stress_half > 0.0)) r.joint_slip_stress_half = p.axial_stress;
        if (share >= 0.9) r.joint_slip_stress = p.axial_stress;
    }

private:
    double sliding(const Solver& s) const {
        const auto& c = contacts(s.world());
        double all = 0.0, slides = 0.0;
        for (int i = 0; i < c.size(); ++i) {
            if (c.property[i] != property_) continue;
            all += c.length[i];
            if (c.history[i].slipping) slides += c.length[i];
        }
        return all > 0.0 ? slides / all : 0.0;
    }
    int property_ = -1;
};

/// The implicit solve of the trial displacement; false (the preload skipped) when
/// it cannot be solved. A specimen the confinement cracked can hold a block by one
/// point or a loose group (a trigon triangle at 71 MPa on Lac du Bonnet's bonds):
/// the implicit matrix is singular there. The preload is a shortcut, not the
/// test: the explicit loading then starts from the trial displacement.
bool solve_trial(Solver& s, LabTestResult& r) {
    try {
        solve_elastic(s.world());
    } catch (const SingularSystemError&) {
        r.preload_skipped = true;
        return false;
    }
    return true;
}

/// Every body on by (reach − 1) times its trial displacement (from `bodies0`,
/// `position0`): each joint takes the same multiple of its trial increment (no
/// row of joints next to the platen takes the whole of it), then one more solve
/// for the geometric nonlinearity.
void scale_trial(Solver& s, const std::vector<contact::BodyState>& bodies0, const std::vector<Vec2>& position0,
                 double reach) {
    const auto& nd = s.world().nodes;
    const auto& bodies = s.world().bodies.state;
    std::vector<Vec2> du(bodies.size()), dn(nd.count());
    std::vector<double> dtheta(bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i)
        du[i] = (reach - 1.0) * (bodies[i].centroid - bodies0[i].centroid),
        dtheta[i] = (reach - 1.0) * (bodies[i].theta - bodies0[i].theta);
    for (int k = 0; k < nd.count(); ++k) dn[k] = (reach - 1.0) * (nd.position[k] - position0[k]);
    move_bodies(s.world(), du, dtheta, dn);
    try {
        solve_elastic(s.world()); // the geometric correction: without it the linear state stands
    } catch (const SingularSystemError&) {
    }
}

/// The straight line between the preload's two states, exact for the linear
/// response (none when the specimen could not be solved: E then comes from the
/// explicit curve), after the origin.
void add_preload_line(LabTestResult& r, const StressStrainPoint& origin, const StressStrainPoint& end, bool solvable,
                      const std::function<void(const StressStrainPoint&)>& progress) {
    for (int k = 1; k <= (solvable ? 20 : 0); ++k) {
        const double f = k / 20.0;
        StressStrainPoint p = end;
        p.axial_strain = origin.axial_strain + f * (end.axial_strain - origin.axial_strain);
        p.axial_stress = origin.axial_stress + f * (end.axial_stress - origin.axial_stress);
        p.lateral_strain = origin.lateral_strain + f * (end.lateral_strain - origin.lateral_strain);
        r.curve.push_back(p);
        if (progress) progress(p);
    }
    r.curve.insert(r.curve.begin(), origin);
}

/// Elastic preload: until the first joint yields the specimen is linear, and its
/// quasi-static response is one implicit solve — not thousands of damped steps
/// whose start-up transient would bias E. A trial platen displacement gives the
/// response per unit of load; the first joint to reach its strength gives how far
/// it can go; the specimen is set there (preload_fraction of it) exactly, and the
/// explicit loading takes over just before cracking starts. Sets `strain` and
/// returns the leading curve points that are the implicit line.
std::size_t elastic_preload(Solver& s, MovingPlaten& platen, const LabTestOptions& o, const Gauges& gauges,
                            LabTestResult& r, double& strain,
                            const std::function<void(const StressStrainPoint&)>& progress) {
    const auto& c = contacts(s.world());
    const std::vector<contact::JointHistory> before = c.history;
    const std::vector<contact::BodyState> bodies0 = s.world().bodies.state;
    const auto position0 = s.world().nodes.position;
    const StressStrainPoint origin = gauges.measure(0.0, 0.0);
    const double trial = 1e-6;
    platen.set_speed(trial * specimen_height(o));
    move_supports(s.world(), s.world().clock.dt);
    strain = trial;
    const bool solvable = solve_trial(s, r);
    double lambda = solvable ? 1e6 : 0.0;
    for (int i = 0; i < c.size(); ++i)
        lambda = std::min(lambda, contact::elastic_limit(s.world().properties.laws[c.property[i]], before[i], c.history[i], 1e6));
    const double reach = o.preload_fraction * lambda;
    if (solvable && reach > 1.0 && lambda < 1e6) {
        scale_trial(s, bodies0, position0, reach);
        strain = reach * trial;
    }
    add_preload_line(r, origin, gauges.measure(strain, 0.0), solvable, progress);
    return solvable ? r.curve.size() : 0;
}

/// The loading rate: fixed, or (servo) adapted at every record to the cracking —
/// servo.cracks new cracks a record per 5,000 contacts — and, once cracking has
/// started, to the platens' balance. The platens start from rest: slowly, then the
/// servo speeds up.
class Servo {
public:
    Servo(const LabTestOptions& o, int contacts, int cracks_at_start)
        : o_(o), rate_(o.servo.on ? o.strain_per_step * o.servo.min_factor : o.strain_per_step),
          target_(o.servo.cracks * std::max(1.0, contacts / 5000.0)), cracks_at_start_(cracks_at_start),
          cracks_last_(cracks_at_start) {}
    double rate() const { return rate_; }
    /// The rate after record p. Never faster than ×1.1 a record: a change of rate
    /// is a change of the specimen's lag behind the platen, which shows in the curve.
    void adapt(const Solver& s, const StressStrainPoint& p, bool failed) {
        const int cracks_now = p.cracks_tensile + p.cracks_shear;
        const double made = cracks_now - cracks_last_;
        cracks_last_ = cracks_now;
        if (failed) {
            rate_ = std::min(1.1 * rate_, o_.strain_per_step * o_.servo.post_peak_factor);
            return;
        }
        double f = made <= 0 ? 1.1 : std::clamp(target_ / made, 0.5, 1.1);
        if (o_.servo.balance > 0 && cracks_now > cracks_at_start_) {
            const double top = boundary_force(s.world(), "top").y, bottom = boundary_force(s.world(), "bottom").y;
            const double mismatch = std::abs(top + bottom) / std::max(std::abs(top), 1e-300);
            if (mismatch > 0) f = std::min(f, std::clamp(o_.servo.balance / mismatch, 0.5, 1.1));
        }
        rate_ = std::clamp(rate_ * f, o_.strain_per_step * o_.servo.min_factor, o_.strain_per_step * o_.servo.max_factor);
    }

private:
    const LabTestOptions& o_;
    double rate_;
    double target_;
    int cracks_at_start_, cracks_last_;
};

/// The peak, failure and when to stop (studies/lab/labtest.hpp, the stop rules): each
/// rule a member, applied to every record in order by `stop_after`.
class StopRules {
public:
    StopRules(const LabTestOptions& o, int cracks_at_start)
        : o_(o), cracks_at_start_(cracks_at_start), lab_peak_(o.confinement > 0.0 && !o.stop.peak_at_first_stall) {}
    /// True when the run stops after this record.
    bool stop_after(const Solver& s, const StressStrainPoint& p, LabTestResult& r) {
        if (locked(s, p, r)) return true;
        track_peak(p, r);
        watch_failure(p, r);
        return past_peak(p, r) || past_post_peak_strain(p, r) || at_strain_limit(p, r);
    }
    bool failed() const { return failed_; }
    double peak() const { return peak_; }
    long peak_step() const { return peak_step_; }
    double strain_at_peak() const { return strain_at_peak_; }
    /// Stopped unfailed with the stress at its peak (within 2%): the peak is a lower
    /// bound. 2% down from it the specimen has passed its peak, though the drop
    /// rule wants 10%: that peak is a strength.
    bool still_at_peak(const StressStrainPoint& p) const { return p.axial_stress >= 0.98 * peak_; }

private:
    /// After a failure drop the peak is the strength: rigid fragments cannot break
    /// further, and a rubble core jammed between the platens can re-stiffen like
    /// dry masonry. A jam stays above the peak for lock_records records in a row; a
    /// burst of cracks throws a dynamic transient (unbalanced ratio far above 1)
    /// that passes within a few records, and is no locking (docs/calibration.md,
    /// After the peak).
    bool locked(const Solver& s, const StressStrainPoint& p, LabTestResult& r) {
        constexpr int lock_records = 10;
        if (!(failed_ && p.axial_stress > peak_)) {
            records_above_peak_ = 0;
            return false;
        }
        if (++records_above_peak_ < lock_records) return false;
        // Who carries the load now? Bonds still intact: the "failure" was a local
        // burst of cracks in a specimen that had not failed (small specimens, a few
        // blocks across), and loading goes on. Broken and new contacts: fragments
        // jammed between the platens. Confined, the laboratory's peak: loading goes
        // on (a hardening specimen shows itself by its peak against
        // first_stall_stress); the first-stall rule stops here, its peak before the drop.
        if (lab_peak_) {
            failed_ = false, records_above_peak_ = 0, ++r.reloads;
            return false;
        }
        if (o_.confinement <= 0.0 && unbonded_compression_share(s) < 0.5) {
            failed_ = false, records_above_peak_ = 0;
            return false;
        }
        r.post_peak_locking = true;
        r.peak_passed = true;
        return true;
    }
    void track_peak(const StressStrainPoint& p, LabTestResult& r) {
        if (failed_ || !(p.axial_stress > peak_)) return;
        peak_ = p.axial_stress, peak_step_ = p.step, strain_at_peak_ = p.axial_strain;
        r.cracks_near_vertical_at_peak = r.cracks_near_vertical;
        r.cracks_near_horizontal_at_peak = r.cracks_near_horizontal;
    }
    /// Failure: a drop by failure_drop from the peak, or (confined specimens, whose
    /// fragments lock without a drop) a stall — the stress no higher than 2e-4 of
    /// strain ago, with the peak inside that stretch. Only with bonds broken under
    /// the axial load: the start-up transient of the platens is no failure.
    void watch_failure(const StressStrainPoint& p, LabTestResult& r) {
        cracking_ = p.cracks_tensile + p.cracks_shear > cracks_at_start_;
        const bool dropped = peak_ > 0 && p.axial_stress < (1.0 - o_.stop.failure_drop) * peak_;
        while (stall_from_ + 1 < r.curve.size() && r.curve[stall_from_ + 1].axial_strain <= p.axial_strain - 2e-4)
            ++stall_from_;
        bool stalled = false;
        if (r.curve[stall_from_].axial_strain <= p.axial_strain - 2e-4 && r.curve.size() - stall_from_ > 5) {
            const auto& back = r.curve[stall_from_];
            stalled = p.axial_stress <= back.axial_stress && peak_step_ >= back.step;
        }
        if (cracking_ && (dropped || stalled) && !(r.first_stall_stress > 0.0)) r.first_stall_stress = peak_;
        if (lab_peak_) stalled = false; // yielding, not failure: the peak is still ahead or here
        if (!failed_ && cracking_ && (dropped || stalled)) failed_ = true, strain_at_failure_ = p.axial_strain;
    }
    /// Past the peak once the stress is clearly down from it (after cracking: not
    /// in the start-up transient of the platens).
    bool past_peak(const StressStrainPoint& p, LabTestResult& r) const {
        if (!(cracking_ && peak_ > 0 && p.step > peak_step_ && p.axial_stress < o_.stop.fraction * peak_)) return false;
        r.peak_passed = true;
        return true;
    }
    /// Confined: post_peak_strain past the peak (the laboratory's peak: past the
    /// drop, which gives a burst of cracks the room to be climbed back above).
    bool past_post_peak_strain(const StressStrainPoint& p, LabTestResult& r) const {
        if (!(failed_ && o_.confinement > 0.0 && o_.stop.post_peak_strain > 0.0 &&
              p.axial_strain >= (lab_peak_ ? strain_at_failure_ : strain_at_peak_) + o_.stop.post_peak_strain))
            return false;
        r.peak_passed = true;
        return true;
    }
    /// At max_strain: not failed yet, the strength is still ahead — load on to the
    /// cap. Failed after loading on: stop max_strain past the peak at the latest
    /// (the locking rule gets the room it had before max_strain).
    bool at_strain_limit(const StressStrainPoint& p, LabTestResult& r) const {
        if (!(p.axial_strain >= o_.stop.max_strain)) return false;
        const double cap = std::max(o_.stop.max_strain, o_.stop.strain_cap);
        if (!failed_ && p.axial_strain < cap) {
            r.loaded_past_max_strain = true;
            return false;
        }
        if (!failed_) {
            r.still_loading = still_at_peak(p);
            return true;
        }
        return !r.loaded_past_max_strain || p.axial_strain >= cap || p.axial_strain >= strain_at_peak_ + o_.stop.max_strain;
    }

    const LabTestOptions& o_;
    int cracks_at_start_;
    bool lab_peak_;        ///< confined, the laboratory's peak: only a lasting drop is failure, no stall rule
    bool failed_ = false;  ///< the stress has dropped by failure_drop from the peak, or stalled
    bool cracking_ = false;
    double peak_ = 0.0, strain_at_peak_ = 0.0, strain_at_failure_ = 0.0;
    long peak_step_ = 0;
    int records_above_peak_ = 0;
    std::size_t stall_from_ = 0; ///< first record within 2e-4 of strain of the last
};

/// Smooth platens hold the specimen horizontally by the bottom face's middle
/// blocks: there must be one.
void check_smooth_platens_hold(const Solver& s, const LabTestOptions& o) {
    if (o.rough_platens || uses_platen_blocks(o)) return;
    const auto& fixed = s.world().loads.block_fixed;
    if (std::none_of(fixed.begin(), fixed.end(), [](auto f) { return (f & 1) != 0; }))
        throw std::runtime_error("smooth platens: no block on the bottom face's middle to hold the specimen "
                                 "horizontally; use --platens rough or a larger specimen");
}

/// The specimen in the machine: its gauges, the joint set's gauge and the platen.
struct LabRig {
    Solver& s;
    const LabTestOptions& o;
    const Gauges gauges;
    const JointSetGauge joint_set;
    MovingPlaten platen;
};

/// The explicit loading from `strain`, a point of the curve every record_every
/// steps after `start`, until a stop rule or max_steps ends it.
void load_until_stopped(LabRig& rig, long start, double strain, Servo& servo, StopRules& rules, LabTestResult& r,
                        const std::function<void(const StressStrainPoint&)>& progress,
                        const std::function<void(const Solver&, const StressStrainPoint&)>& on_frame) {
    Solver& s = rig.s;
    const LabTestOptions& o = rig.o;
    const double h = specimen_height(o);
    rig.platen.set_speed(servo.rate() * h);
    double ratio_max = 0.0;
    while (s.world().clock.steps - start < o.stop.max_steps) {
        s.step();
        strain += servo.rate();
        ratio_max = std::max(ratio_max, s.world().clock.ratio);
        if ((s.world().clock.steps - start) % o.record_every != 0) continue;
        record_new_cracks(s, r);
        StressStrainPoint p = rig.gauges.measure(strain, servo.rate());
        p.unbalanced_ratio = ratio_max;
        r.curve.push_back(p);
        rig.joint_set.record(s, p, r);
        if (o.servo.on) {
            servo.adapt(s, p, rules.failed());
            rig.platen.set_speed(servo.rate() * h);
        }
        ratio_max = 0.0;
        if (progress) progress(p);
        // Ctrl-C (or a scheduler's SIGTERM): a lab test has no checkpoint, so the
        // command stops at once and writes nothing (apps/cli.cpp: exit status 130).
        if (studies::stop_signal_received()) throw Interrupted("interrupted during a lab test");
        if (on_frame && o.frame_every > 0 && (s.world().clock.steps - start) % o.frame_every == 0) on_frame(s, p);
        if (rules.stop_after(s, p, r)) break;
    }
}

/// The result's figures once loading has stopped: the peak (a lower bound if
/// loading was going on), the moduli and crack thresholds, the residual
/// strength, the cracks.
void finish_labtest_result(Solver& s, const LabTestOptions& o, const StopRules& rules, long start,
                           std::size_t preload_points, LabTestResult& r) {
    const bool brazilian = o.kind == LabTestOptions::Kind::brazilian;
    // Out of steps while loading on: the peak is a lower bound too.
    if (s.world().clock.steps - start >= o.stop.max_steps && r.loaded_past_max_strain && !rules.failed() && !r.curve.empty())
        r.still_loading = rules.still_at_peak(r.curve.back());
    r.steps = s.world().clock.steps;
    r.peak_stress = rules.peak();
    r.strain_at_peak = rules.strain_at_peak();
    if (brazilian) r.tensile_strength = rules.peak();
    if (!brazilian) measure_rock_mechanics(r, preload_points, o.kind == LabTestOptions::Kind::tension, rules.peak_step());
    if (o.kind != LabTestOptions::Kind::tension && !brazilian) measure_residual_strength(r, o.confinement);
    record_new_cracks(s, r);
    r.cracks_tensile = cracks(s.world(), contact::JointState::broken_tension);
    r.cracks_shear = cracks(s.world(), contact::JointState::broken_shear);
    r.events = event_count(s.world());
    if (!brazilian && o.kind != LabTestOptions::Kind::tension) measure_event_onset(r, rules.peak_step());
    if (s.world().events) {
        std::vector<double> magnitudes;
        for (const SeismicEvent& e : event_catalogue(*s.world().events)) magnitudes.push_back(e.magnitude);
        const GutenbergRichter g = gutenberg_richter(magnitudes);
        r.b_value = g.fitted ? g.b : 0.0;
    }
}

} // namespace

LabTestResult run_labtest(const LabTestOptions& o, const std::function<void(const StressStrainPoint&)>& progress,
                          const std::function<void(const Solver&, const LabTestResult&)>& on_finish,
                          const std::function<void(const Solver&, const StressStrainPoint&)>& on_frame) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto blocks = meshing::generate_blocks(labtest_geometry(o));
    Solver s(blocks, labtest_analysis(o));
    check_smooth_platens_hold(s, o);
    LabTestResult r;
    r.blocks = blocks.block_count();
    r.contacts = contacts(s.world()).size();
    LabRig rig{s, o, Gauges(s, o), JointSetGauge(s, o), MovingPlaten(s)};
    // Biaxial: the confinement first, ramped with the platens held, then settled
    // (applied at once it is a shock that cracks the specimen before any axial load).
    const long start = o.kind == LabTestOptions::Kind::biaxial && o.confinement > 0 ? confine(s, rig.platen) : 0;
    const int cracks_at_start = cracks(s.world(), contact::JointState::broken_tension) + cracks(s.world(), contact::JointState::broken_shear);
    double strain = 0.0;
    const std::size_t preload_points =
        o.elastic_preload && !uses_platen_blocks(o) ? elastic_preload(s, rig.platen, o, rig.gauges, r, strain, progress) : 0;
    Servo servo(o, r.contacts, cracks_at_start);
    StopRules rules(o, cracks_at_start);
    load_until_stopped(rig, start, strain, servo, rules, r, progress, on_frame);
    finish_labtest_result(s, o, rules, start, preload_points, r);
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (on_finish) on_finish(s, r);
    return r;
}

} // namespace bbm
