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
#include "tests/validation.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <sstream>
#include <string>
#include <cstring>

using namespace bbm;

namespace {

/// An example model with its last stage cut to `max_steps` (a test, not a study).
test::RestartModel example(const std::string& name, long max_steps) {
    auto file = io::read_model(std::string(BBM_SOURCE_DIR) + "/examples/" + name);
    if (max_steps > 0) file.analysis.stages.back().max_steps = max_steps;
    return {meshing::generate_blocks(file.geometry), file.analysis};
}

} // namespace

TEST_CASE("restart: the trigon tunnel stopped at 6 steps of its excavation and failure resumes exactly" * validation) {
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

TEST_CASE("restart: a deformable lab test (f = 0.95, 2 x 4 m) stopped in failure resumes exactly" * validation) {
    // Peak near step 7,000 (about 29 MPa); contacts form from about 10,000.
    auto o = LabTestOptions::paper_ucs();
    o.width = 2.0, o.height = 4.0, o.strain_per_step = 2e-7, o.rock.material.deformable_fraction = 0.95;
    test::check_exact_restart(test::labtest_model(o, 13000), {3500, 7000, 10500, 12000}, {1});
}

// The state-field list (core/world.hpp, for_each_field): one list that the checkpoint, the
// state hash and the memory report walk. Every evolving field, perturbed by one
// bit, changes the hash and the checkpoint's bytes, and a checkpoint loaded into a
// new solver restores it; every field's bytes are in the memory report's group.
// A field added to the list with the wrong use, or added to one walker and not
// the list, fails here. Model: bolts, a liner, an elastic far field of FE nodes
// and zones, mid-relaxation (every kind of state non-empty).
TEST_CASE("every field of the state list is saved, hashed and counted") {
    auto m = example("support/tunnel_trigon_bolted_shotcrete.toml", 200);
    Solver solver(m.blocks, m.analysis);
    struct Quiet : StageObserver {} quiet;
    run_stages(solver, m.analysis.stages, quiet);
    REQUIRE(support_state<Bolts>(solver.world().supports).node_count() > 0);
    REQUIRE(support_state<Liners>(solver.world().supports).node_count() > 0);
    REQUIRE(solver.world().nodes.count() > 0);

    auto fields = state_fields(solver.world());
    std::set<std::string> names;
    for (const auto& f : fields) CHECK_MESSAGE(names.insert(f.name).second, "field listed twice: " << f.name);
    auto field = [&](const std::string& name) -> StateField& {
        for (auto& f : fields)
            if (f.name == name) return f;
        FAIL("no field " << name);
        return fields.front();
    };
    // What each walker is known to need is in the list with that use.
    for (const char* name : {"blocks.centroid", "contacts.history", "nodes.velocity", "zones.stress", "bolts.axial",
                             "liners.thrust", "relax.block_force", "solver.steps", "detection.unsorted_contacts"})
        CHECK_MESSAGE((field(name).uses & field_use::evolving) == field_use::evolving, name);
    CHECK(field("monitor.samples").uses == field_use::saved); // the verdict's: saved, not physics
    CHECK(field("relax.block_force").size() > 0);

    auto save = [&](const Solver& s) {
        std::ostringstream o(std::ios::binary);
        save_state(s.world(), o);
        return o.str();
    };
    const std::uint64_t hash = state_hash(solver.world());
    const std::string checkpoint = save(solver);
    int perturbed = 0;
    for (auto& f : fields) {
        if (f.empty() || !(f.uses & (field_use::saved | field_use::hashed))) continue;
        INFO(f.name);
        std::byte& last = f.element(f.size() - 1)[(f.element_size - 1) / 2]; // inside the last element
        last ^= std::byte{1};
        CHECK((state_hash(solver.world()) != hash) == bool(f.uses & field_use::hashed));
        if (f.uses & field_use::saved) CHECK(save(solver) != checkpoint);
        last ^= std::byte{1};
        ++perturbed;
    }
    CHECK(perturbed > 80); // 91 in this model
    CHECK(state_hash(solver.world()) == hash);

    // Loaded into a new solver of the same model, every saved field is restored.
    Solver resumed(m.blocks, m.analysis);
    std::istringstream in(checkpoint, std::ios::binary);
    load_state(resumed.world(), in);
    CHECK(state_hash(resumed.world()) == hash);
    const auto restored = state_fields(resumed.world());
    REQUIRE(restored.size() == fields.size());
    for (std::size_t k = 0; k < fields.size(); ++k)
        if (fields[k].uses & field_use::saved) {
            INFO(fields[k].name);
            REQUIRE(fields[k].size() == restored[k].size());
            for (std::size_t e = 0; e < fields[k].size(); ++e)
                CHECK(std::memcmp(fields[k].element(e), restored[k].element(e), fields[k].element_size) == 0);
        }

    // The memory report is the list's capacities by group.
    std::array<std::size_t, 6> by_group{};
    for (const auto& f : fields) by_group[std::size_t(f.group)] += f.capacity_bytes;
    const auto report = memory(solver.world());
    CHECK(report.blocks == by_group[std::size_t(MemoryGroup::blocks)]);
    CHECK(report.vertices == by_group[std::size_t(MemoryGroup::vertices)]);
    CHECK(report.nodes == by_group[std::size_t(MemoryGroup::nodes)]);
    CHECK(report.zones == by_group[std::size_t(MemoryGroup::zones)]);
    CHECK(report.other == by_group[std::size_t(MemoryGroup::other)]);
    CHECK(report.contacts == by_group[std::size_t(MemoryGroup::contacts)]);
}

// `bbm run --profile` (StepProfile): every step counted, every stage timed, and
// the answer the same bit for bit as without it.
TEST_CASE("the step's stages are timed under --profile without changing the answer") {
    // A small cracking model (134 blocks, 3,000 steps): the trigon tunnel here was
    // 34 s of the checking build's tests for the same assertions.
    auto m = example("verification/determinism.toml", 0);
    Solver timed(m.blocks, m.analysis), plain(m.blocks, m.analysis);
    timed.profile().enabled = true;
    struct Quiet : StageObserver {} quiet;
    run_stages(timed, m.analysis.stages, quiet);
    run_stages(plain, m.analysis.stages, quiet);
    CHECK(state_hash(timed.world()) == state_hash(plain.world()));
    const auto& p = timed.profile();
    CHECK(p.steps == timed.world().clock.steps);
    double total = 0.0;
    for (double t : p.seconds) {
        CHECK(t >= 0.0);
        total += t;
    }
    // The contacts' row, read off the table.
    std::size_t contacts_row = 0;
    while (step_stages[contacts_row].name != "contacts") ++contacts_row;
    CHECK(p.seconds[contacts_row] > 0.0);
    CHECK(p.seconds[contacts_row] < total);
    CHECK(plain.profile().steps == 0);
}
