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
    /// solve, cycle: what the rock did at the end (core/verdict.hpp); the target
    /// ratio of a cycle stage is the solve stage's default.
    Verdict verdict;
    /// creep: the creep time at its end (s) and its creep steps; whether the rock
    /// collapsed under its held load (the stage ends there: creep_time is then
    /// its time to failure).
    double creep_time = 0.0;
    long creep_steps = 0;
    bool failed = false;
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
    HistoryRecorder(const World& w, std::vector<HistorySpec> histories);
    const std::vector<HistorySpec>& histories() const { return histories_; }
    std::vector<double> sample(const World& w) const;

private:
    std::vector<HistorySpec> histories_;
    std::vector<int> block_;
    std::vector<int> node_; ///< a point in a deformable block: its nearest node (else -1)
};

const char* to_string(StageSpec::Kind k);

} // namespace bbm
