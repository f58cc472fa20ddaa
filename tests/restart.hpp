// Exact restart (issue 27), shared by the fast, determinism and long suites: a
// model runs once to the end, its solver state saved at given steps on the way;
// each saved state is loaded into a new solver (on a chosen thread count) that
// runs the remaining stages and must end in the uninterrupted run's state hash,
// step count and crack counts.
#pragma once

#include "core/solver.hpp"
#include "core/stages.hpp"
#include "meshing/blocks.hpp"
#include "studies/lab/labtest.hpp"

#include <doctest/doctest.h>

#include <sstream>
#include <string>
#include <vector>

namespace bbm::test {

/// Saves the solver's state after each of the given total steps (ascending).
struct SaveAt : StageObserver {
    std::vector<long> stops;
    struct Saved {
        long step;
        StageCursor cursor;
        std::string state;
    };
    std::vector<Saved> saved;
    explicit SaveAt(std::vector<long> s) : stops(std::move(s)) {}
    void at(const Solver& s, const StageCursor& c) override {
        if (c.step == 0 || saved.size() == stops.size() || s.world().clock.steps != stops[saved.size()]) return;
        std::ostringstream o(std::ios::binary);
        save_state(s.world(), o);
        saved.push_back({s.world().clock.steps, c, o.str()});
    }
};

struct RestartModel {
    meshing::BlockAssembly blocks;
    AnalysisSpec analysis;
};

/// Runs the model through its stages once on `reference_threads` threads,
/// saving at `stops`; resumes each saved state on every thread count of
/// `threads` and checks the end state against the uninterrupted run.
inline void check_exact_restart(RestartModel m, const std::vector<long>& stops, const std::vector<int>& threads,
                                int reference_threads = 1) {
    m.analysis.solver.threads = reference_threads;
    Solver whole(m.blocks, m.analysis);
    SaveAt save(stops);
    run_stages(whole, m.analysis.stages, save);
    REQUIRE(save.saved.size() == stops.size()); // every stop is inside the run
    const int tensile = cracks(whole.world(), contact::JointState::broken_tension);
    const int shear = cracks(whole.world(), contact::JointState::broken_shear);
    MESSAGE("uninterrupted: " << whole.world().clock.steps << " steps, " << tensile << " / " << shear
                              << " tensile / shear cracks, " << whole.world().detection.totals.created
                              << " contacts created, hash " << state_hash(whole.world()));
    for (const auto& saved : save.saved)
        for (int t : threads) {
            m.analysis.solver.threads = t;
            Solver resumed(m.blocks, m.analysis);
            std::istringstream in(saved.state, std::ios::binary);
            load_state(resumed.world(), in);
            StageObserver quiet;
            run_stages(resumed, m.analysis.stages, quiet, saved.cursor);
            INFO("stopped at step " << saved.step << " (stage " << saved.cursor.stage << "), resumed on " << t
                                    << " thread(s): " << cracks(resumed.world(), contact::JointState::broken_tension) << " / "
                                    << cracks(resumed.world(), contact::JointState::broken_shear) << " cracks");
            CHECK(resumed.world().clock.steps == whole.world().clock.steps);
            CHECK(cracks(resumed.world(), contact::JointState::broken_tension) == tensile);
            CHECK(cracks(resumed.world(), contact::JointState::broken_shear) == shear);
            CHECK(state_hash(resumed.world()) == state_hash(whole.world()));
        }
}

/// A lab test as a model: the specimen of `o` loaded at its constant platen rate
/// (no servo, no implicit preload) for `steps` steps — through the peak and into
/// failure when `steps` is long enough.
inline RestartModel labtest_model(const LabTestOptions& o, long steps) {
    RestartModel m{meshing::generate_blocks(labtest_geometry(o)), labtest_analysis(o)};
    StageSpec load;
    load.name = "loading";
    load.kind = StageSpec::Kind::cycle;
    load.steps = steps;
    m.analysis.stages = {load};
    return m;
}

} // namespace bbm::test
