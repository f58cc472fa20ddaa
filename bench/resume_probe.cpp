// Not a benchmark: an exact-restart probe. Runs a model to step S, saves the
// solver's state, loads it into a second solver built from the same file, then
// steps both side by side and reports the first step whose state differs — and
// what differs there (contact count and order, masses, time step, detection
// totals, positions) — so a checkpoint that misses state is found at the step it
// first matters, not 20,000 steps later in a crack count.
//
//   resume_probe MODEL.toml STOP_STEP [LAST_STEP] [THREADS_BEFORE] [THREADS_AFTER]
#include "core/stages.hpp"
#include "core/solver.hpp"
#include "io/model_input.hpp"
#include "meshing/blocks.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <cstring>
#include <vector>

using namespace bbm;

namespace {

struct StopAt : StageObserver {
    long stop_at;
    StageCursor cursor;
    bool stop = false;
    explicit StopAt(long n) : stop_at(n) {}
    void at(const Solver& s, const StageCursor& c) override {
        cursor = c;
        stop = s.world().clock.steps >= stop_at;
    }
    bool stop_requested() override { return stop; }
};

template <class V>
long first_difference(const V& a, const V& b) {
    if (a.size() != b.size()) return -2;
    for (std::size_t k = 0; k < a.size(); ++k)
        if (std::memcmp(&a[k], &b[k], sizeof a[k]) != 0) return long(k);
    return -1;
}

void report(const Solver& a, const Solver& b) {
    const auto &ca = contacts(a.world()), &cb = contacts(b.world());
    std::printf("  contacts %d vs %d; dt %.17g vs %.17g; created %d/%d removed %d/%d transferred %d/%d\n", ca.size(),
                cb.size(), a.world().clock.dt, b.world().clock.dt, a.world().detection.totals.created, b.world().detection.totals.created,
                a.world().detection.totals.removed, b.world().detection.totals.removed, a.world().detection.totals.transferred,
                b.world().detection.totals.transferred);
    std::printf("  first difference: vertex_id %ld edge_id %ld length %ld property %ld history %ld\n",
                first_difference(ca.vertex_id, cb.vertex_id), first_difference(ca.edge_id, cb.edge_id),
                first_difference(ca.length, cb.length), first_difference(ca.property, cb.property),
                first_difference(ca.history, cb.history));
    const World &wa = a.world(), &wb = b.world();
    std::printf("  blocks: state %ld mass %ld inertia %ld vertex %ld\n",
                first_difference(wa.bodies.state, wb.bodies.state), first_difference(wa.bodies.mass, wb.bodies.mass),
                first_difference(wa.bodies.inertia, wb.bodies.inertia),
                first_difference(wa.vertices.position, wb.vertices.position));
    std::printf("  nodes: position %ld velocity %ld mass %ld; zones: stress %ld\n",
                first_difference(wa.nodes.position, wb.nodes.position),
                first_difference(wa.nodes.velocity, wb.nodes.velocity), first_difference(wa.nodes.mass, wb.nodes.mass),
                first_difference(wa.zones.stress, wb.zones.stress));
}

} // namespace

/// Records the state hash after every step; stops at `last` steps (0: at the end).
struct Record : StageObserver {
    long last;
    StageCursor cursor;
    std::vector<std::pair<long, std::uint64_t>> hashes;
    explicit Record(long n) : last(n) {}
    void at(const Solver& s, const StageCursor& c) override {
        cursor = c;
        if (c.step > 0) hashes.push_back({s.world().clock.steps, state_hash(s.world())});
    }
    bool stop_requested() override { return last > 0 && !hashes.empty() && hashes.back().first >= last; }
};

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: resume_probe MODEL.toml STOP_STEP [LAST_STEP] [THREADS_BEFORE] [THREADS_AFTER]\n");
        return 2;
    }
    auto file = io::read_model(argv[1]);
    const long stop = std::atol(argv[2]);
    const long last = argc > 3 ? std::atol(argv[3]) : 0;
    const int threads_before = argc > 4 ? std::atoi(argv[4]) : 1, threads_after = argc > 5 ? std::atoi(argv[5]) : 1;
    const auto blocks = meshing::generate_blocks(file.geometry);
    // The stopped run continues in its own solver; the checkpoint is loaded into a new one.
    auto run = [&](long until, Solver*& keep_whole, Solver*& keep_resumed) {
        file.analysis.solver.threads = threads_before;
        auto* whole = new Solver(blocks, file.analysis);
        StopAt at(stop);
        run_stages(*whole, file.analysis.stages, at);
        std::stringstream checkpoint;
        save_state(whole->world(), checkpoint);
        file.analysis.solver.threads = threads_after;
        auto* resumed = new Solver(blocks, file.analysis);
        load_state(resumed->world(), checkpoint);
        Record a(until), b(until);
        run_stages(*whole, file.analysis.stages, a, at.cursor);
        run_stages(*resumed, file.analysis.stages, b, at.cursor);
        keep_whole = whole, keep_resumed = resumed;
        return std::pair{a.hashes, b.hashes};
    };
    Solver *whole = nullptr, *resumed = nullptr;
    const auto [ha, hb] = run(last, whole, resumed);
    std::printf("stopped at step %ld; continued to %ld (whole) and %ld (resumed); contacts created by the end: %d\n", stop,
                ha.empty() ? stop : ha.back().first, hb.empty() ? stop : hb.back().first,
                whole->world().detection.totals.created);
    long first = -1;
    for (std::size_t k = 0; k < std::min(ha.size(), hb.size()) && first < 0; ++k)
        if (ha[k] != hb[k]) first = ha[k].first;
    if (first < 0 && ha.size() == hb.size()) {
        std::printf("identical at every step (final hash %llu)\n", (unsigned long long)state_hash(whole->world()));
        return 0;
    }
    std::printf("first different state after step %ld; at the end: cracks %d/%d vs %d/%d\n", first,
                cracks(whole->world(), contact::JointState::broken_tension), cracks(whole->world(), contact::JointState::broken_shear),
                cracks(resumed->world(), contact::JointState::broken_tension), cracks(resumed->world(), contact::JointState::broken_shear));
    delete whole, delete resumed;
    if (first < 0) return 1;
    run(first, whole, resumed);
    report(*whole, *resumed);
    return 1;
}
