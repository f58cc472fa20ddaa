// bbm core: the solver — a world and what drives its step table.
//
// The state is a World (core/world.hpp, plain data) and the behaviour free
// functions over it; a Solver owns one world and runs its steps through the
// stage table (core/step.hpp), timing them when asked (`bbm run --profile`).
// Everything else a study does to a model — initialise, excavate, install
// supports, solve elastically, checkpoint, measure — is a free function of the
// headers included below, called on solver.world().
#pragma once

#include "core/build_world.hpp"
#include "core/excavation.hpp"
#include "core/implicit.hpp"
#include "core/measures.hpp"
#include "core/state.hpp"
#include "core/step.hpp"
#include "core/supports/ties.hpp"
#include "core/world.hpp"

namespace bbm {

class Solver {
public:
    /// The world of a model (build_world).
    Solver(const meshing::BlockAssembly& blocks, const AnalysisSpec& analysis) : world_(build_world(blocks, analysis)) {}
    explicit Solver(World world) : world_(std::move(world)) {}

    World& world() { return world_; }
    const World& world() const { return world_; }
    /// One step of the stage table.
    void step() { run_step(world_, &profile_); }
    /// Time per row of the stage table; enable it before stepping.
    StepProfile& profile() { return profile_; }
    const StepProfile& profile() const { return profile_; }

private:
    World world_;
    StepProfile profile_;
};

} // namespace bbm
