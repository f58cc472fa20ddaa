// bbm core: running the stages of a model file, and sampling its histories.
//
// run_stages() drives the solver through initialize / elastic / solve / excavate / cycle
// stages (core/model_spec.hpp) and tells an observer about every step and every
// stage end; the program (apps/) writes output and progress from the observer,
// so the loop knows nothing of files or terminals.
#pragma once

#include "core/solver.hpp"

#include <string>
#include <vector>

namespace bbm {

struct StageReport {
    std::string name, kind;
    long steps = 0;
    double ratio = 0.0;
    double seconds = 0.0;
    bool converged = true; ///< solve: reached the ratio within the step limit
    std::string method;    ///< elastic: the factorisation used
};

/// Where a run stands: the stage, whether its action (initialise, excavate, the
/// elastic solve) is done, and the steps taken in it. A checkpoint stores one; a
/// resumed run starts from it.
struct StageCursor {
    int stage = 0;
    bool started = false;
    long step = 0;
};

class StageObserver {
public:
    virtual ~StageObserver() = default;
    /// Before a stage's action (not called again for a resumed stage).
    virtual void stage_started(const Solver&, const StageSpec&) {}
    /// After a stage's action and after every step, with the position reached
    /// (a checkpoint taken here resumes exactly).
    virtual void at(const Solver&, const StageCursor&) {}
    /// After every step; `stage_step` counts from 1 within the stage.
    virtual void step_done(const Solver&, const StageSpec&, long stage_step) { (void)stage_step; }
    virtual void stage_done(const Solver&, const StageReport&) {}
    /// Polled every step: true ends the run after the current step.
    virtual bool stop_requested() { return false; }
};

/// Runs stages[start.stage ...]; a started stage skips its action and continues
/// from start.step.
std::vector<StageReport> run_stages(Solver& solver, const std::vector<StageSpec>& stages,
                                    StageObserver& observer, StageCursor start = {});

/// Evaluates named history quantities; blocks named by a point are found once.
class HistoryRecorder {
public:
    HistoryRecorder(const Solver& solver, std::vector<HistorySpec> histories);
    const std::vector<HistorySpec>& histories() const { return histories_; }
    std::vector<double> sample(const Solver& solver) const;

private:
    std::vector<HistorySpec> histories_;
    std::vector<int> block_;
    std::vector<int> node_; ///< a point in a deformable block: its nearest node (else -1)
};

const char* to_string(StageSpec::Kind k);

/// Measures of an excavation a tunnel engineer looks at (paper §4.3), about the
/// opening's centre: the wall points at the springline and the crown (the
/// material points that started nearest them; convergence = displacement towards
/// the centre, positive inwards), cracks in the ±30° sectors around both
/// directions, and the depth of the failed zone beyond the opening's radius in
/// each direction (±15°): the depth within which 90% of those cracks lie, zero
/// with fewer than 3.
struct OpeningMeasures {
    Vec2 springline_displacement{}, crown_displacement{};
    double springline_convergence = 0, crown_convergence = 0;
    int cracks_springline_sector = 0, cracks_crown_sector = 0;
    double failed_depth_springline = 0, failed_depth_crown = 0;
    int tensile_springline_sector = 0, shear_springline_sector = 0;
};
OpeningMeasures measure_opening(const Solver& s, Vec2 center, Vec2 springline, Vec2 crown);

/// Hoop stress (tension positive) at distance r from `center` along the direction
/// `towards`: the area-weighted mean of the block-averaged stress of rigid blocks
/// and of the zone stresses whose centroids lie within `band` of that point (the
/// scatter of discrete blocks needs an average; SPEC §7). NaN if none is there.
double hoop_stress_at(const Solver& s, const std::vector<std::array<double, 3>>& block_stress, Vec2 center,
                      Vec2 towards, double r, double band);

} // namespace bbm
