// Exact restart while the rock is breaking (issue 27): a run stopped at any step
// — while contacts are born, broken, removed and renumbered — and resumed in a new
// solver ends in the uninterrupted run's state. Before the fix, a resumed run
// renumbered its contacts at another step (the count of contacts created since the
// last renumbering was not saved) and the trigon tunnel stopped during excavation
// ended with 570 / 539 cracks instead of 541 / 516. More thread counts:
// test_determinism.cpp; the full tunnels: test_long.cpp.
#include "io/model_input.hpp"
#include "tests/restart.hpp"

#include <doctest/doctest.h>

#include <string>

using namespace bbm;

namespace {

/// An example model with its last stage cut to `max_steps` (a test, not a study).
test::RestartModel example(const std::string& name, long max_steps) {
    auto file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/" + name);
    if (max_steps > 0) file.analysis.stages.back().max_steps = max_steps;
    return {meshing::generate_blocks(file.geometry), file.analysis};
}

} // namespace

TEST_CASE("restart: the trigon tunnel stopped at 6 steps of its excavation and failure resumes exactly") {
    // Excavation: steps 1-3000; failure from 3001, cut at 9000 (contacts are
    // renumbered at step 5969 on the way: the step a run resumed from 1413 used
    // to part from the uninterrupted one).
    test::check_exact_restart(example("tunnel_trigon.toml", 6000), {1413, 1570, 1901, 3001, 5969, 7601}, {1});
}

TEST_CASE("restart: a lab test stopped before, at and after its peak resumes exactly (rigid Voronoi, 2 x 4 m)") {
    // Constant platen rate 2e-7 per step: cracking from about step 4,500, the peak
    // (about 31 MPa) near 9,800, failure and new contacts from about 10,000.
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.strain_per_step = 2e-7;
    test::check_exact_restart(test::labtest_model(o, 13000), {4500, 8500, 9800, 10500, 12000}, {1});
}

TEST_CASE("restart: a deformable lab test (f = 0.95, 2 x 4 m) stopped in failure resumes exactly") {
    // Peak near step 7,000 (about 29 MPa); contacts form from about 10,000.
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.strain_per_step = 2e-7, o.deformable_fraction = 0.95;
    test::check_exact_restart(test::labtest_model(o, 13000), {3500, 7000, 10500, 12000}, {1});
}
