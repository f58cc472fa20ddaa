// bbm core: the verdict of a run — has the rock come to rest, is it still
// failing, or is it collapsing?
//
// A step limit says nothing about the rock. Every `sample_every` steps of a solve
// or cycle stage the monitor records what a rock engineer would look at: cracks
// so far, the unbalanced-force ratio of the whole model and of the rock mass
// alone, its kinetic energy and the speed of its fastest body, and the detached
// fragments. The rock mass is what is connected, through contacts that carry
// force (bonded, or touching with a force), to a supported body or to the
// heaviest group; every other group is a fragment — a piece that fell or was
// thrown off and is moving freely. Its unbalanced force is its weight, not
// unbalanced rock, so the rock mass's own ratio is what decides equilibrium.
//
// Over the last part of the stage (the window: a quarter of it, between 1,000
// and 5,000 steps) the verdict is, in this order:
//   equilibrium                 no crack in the window, the model's ratio at its target;
//   equilibrium with fragments  no crack, the rock mass's ratio at the target, fragments apart;
//   collapsing                  the rock mass accelerating: the mean speed of its fastest
//                               body rising through each of the window's four quarters, by
//                               10% or more in all, and its kinetic energy rising (a block
//                               sliding from rest at constant acceleration gains 25% over
//                               the last quarter of its run; a burst of cracks rises and falls);
//   failing                     cracks still forming in the window;
//   not converged               no crack and no acceleration, but the rock's ratio above target.
// A dynamic run (real masses, real time: a wave, a burst) is not judged on its
// unbalanced force, which a wave in transit keeps high. A cycle stage of the
// dynamic mode runs its steps or its model time and ends on what its energy did
// (judge_dynamic), in this order:
//   settled                     no crack in the window and the rock's kinetic energy in it below
//                               1% of its peak in the stage: the wave has passed, the ejecta stopped;
//   collapsing, failing         as above (collapsing: the kinetic energy up 10% over the window too);
//   moving                      no crack, but kinetic energy above 1% of the peak: the time was
//                               reached with the rock still ringing (run longer, or absorb the
//                               waves: viscous boundaries).
// The samples are part of the solver's checkpoint, so a resumed run gives the
// verdict the uninterrupted one gives.
#pragma once

#include "base/fields.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace bbm {

struct World;

/// What the monitor records at one step.
struct MonitorSample {
    long step = 0;
    long cracks = 0;            ///< broken bonds so far (tension + shear)
    double ratio = 0;           ///< unbalanced-force ratio of the model
    double rock_ratio = 0;      ///< of the rock mass alone (fragments left out)
    double rock_kinetic = 0;    ///< kinetic energy of the rock mass, J/m (real masses)
    double rock_speed = 0;      ///< fastest body of the rock mass, m per step
    int fragments = 0;          ///< groups of bodies detached from the rock mass
    int fragment_blocks = 0;    ///< bodies in them
    double fragment_mass = 0;   ///< their mass, kg/m
    double time = 0;            ///< model time, s (a dynamic stage's start and end)
};
static_assert(sizeof(MonitorSample) == 72); // no padding: saved raw in checkpoints
template <>
struct ElementTraits<MonitorSample> : PackedRecordTraits<MonitorSample> {};

/// Fragments at the current state: per body (block), 1 if it belongs to a
/// detached group; and the group count.
struct Fragments {
    std::vector<std::uint8_t> detached; ///< per block
    int groups = 0, blocks = 0;
    double mass = 0; ///< kg/m
};
Fragments find_fragments(const World& w);

/// Trivially copyable without padding (written raw into checkpoints).
struct Verdict {
    enum class Kind : std::int64_t {
        none, equilibrium, equilibrium_with_fragments, not_converged, failing, collapsing, settled, moving
    };
    Kind kind = Kind::none; ///< none: the stage had too few samples to judge
    long window_steps = 0;  ///< the window the evidence is taken over
    long cracks_in_window = 0;
    double crack_rate = 0;          ///< cracks per 1,000 steps over the window
    double ratio = 0, rock_ratio = 0, target_ratio = 0;
    double kinetic_trend = 0;       ///< rock kinetic energy at the window's end over that at its start
    double speed_trend = 0;         ///< mean rock speed of the window's last quarter over its first
    double rock_speed = 0;          ///< fastest rock body at the end, m per 1,000 steps
    int fragments = 0, fragment_blocks = 0;
    double fragment_mass = 0;       ///< kg/m
    /// Dynamic (judge_dynamic): the model time at the end, s, and the rock's largest
    /// kinetic energy in the window over its peak in the stage.
    double model_time = 0, kinetic_fraction = 0;
    /// Rock at rest: equilibrium, with fragments or not.
    bool at_rest() const {
        return kind == Kind::equilibrium || kind == Kind::equilibrium_with_fragments || kind == Kind::settled;
    }
    bool valid() const { return kind >= Kind::none && kind <= Kind::moving; }
};
static_assert(sizeof(Verdict) == 112);
const char* to_string(Verdict::Kind k);
/// One line of evidence, e.g. "failing: 42 cracks in the last 5000 steps (8.4 per 1000), ...".
std::string describe(const Verdict& v);

/// The verdict over the window ending at the last sample (samples in step order).
Verdict judge(const std::vector<MonitorSample>& samples, double target_ratio);
/// A dynamic stage's verdict over the same window: settled, collapsing, failing
/// or moving (the stage's samples from its start: its kinetic energy's peak).
Verdict judge_dynamic(const std::vector<MonitorSample>& samples);
/// The share of its peak the rock's kinetic energy falls to where a dynamic
/// stage has settled.
inline constexpr double settled_kinetic_fraction = 0.01;

/// What the current stage did so far: its samples (part of the world: a
/// checkpoint saves them, so a resumed run gives the verdict the uninterrupted
/// one gives).
struct StageMonitor {
    static constexpr long sample_every = 100;
    std::vector<MonitorSample> samples;
};

/// A new stage: forget the samples of the last one.
inline void start_stage(StageMonitor& m) { m.samples.clear(); }
/// Records the world's state (run_stages calls it every sample_every steps).
void sample_monitor(StageMonitor& m, const World& w);
/// The verdict over the window ending at the last sample.
inline Verdict verdict(const StageMonitor& m, double target_ratio) { return judge(m.samples, target_ratio); }
/// The model time the current stage started at (its first sample's).
inline double stage_start_time(const StageMonitor& m) { return m.samples.empty() ? 0.0 : m.samples.front().time; }
/// At rest now: no crack over the last `quiet_steps` and the rock's ratio at
/// the target (a stage asked to stop at its verdict stops here).
bool at_rest(const StageMonitor& m, double target_ratio, long quiet_steps);

} // namespace bbm
