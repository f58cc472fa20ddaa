// Benchmark of the hybrid loop and of the paper's tunnel (issues 4 and 6).
//   1. hybrid_scene.toml (~10k rigid blocks, ~20k zones): steps/s of the whole
//      explicit loop, contact-updates/s and zone-updates/s over it, and the zone
//      kernel alone (fem::zone_pass) — 1 and 2 threads of the contact loop;
//   2. examples/tunnel_voronoi.toml end to end (mesh, in-situ, implicit elastic
//      stage, excavation, failure stage): wall time per stage, on 2 threads.
//   3. The contact loop's cost per contact in the paper's tunnel, the trigon
//      tunnel and the Mine-by model (issue 24): each run to its end, then the
//      contact pass alone timed on its final, cracked contacts, 1 and 2 threads —
//      nanoseconds per contact-update and the ratio to the paper's tunnel.
// Prints a table and writes JSON. Usage: bench_tunnel [out.json] (run from the
// repository root, or set BBM_SOURCE_DIR).
#include "io/model_input.hpp"
#include "core/stages.hpp"
#include "core/solver.hpp"
#include "fem/cst.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <omp.h>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sys/resource.h>

using namespace bbm;
using clock_type = std::chrono::steady_clock;

namespace {

/// Wall seconds of `passes` contact passes alone (the contact loop: kinematics,
/// laws, forces) on `threads` threads, over a copy of the contacts in their
/// present state; the model is not changed.
double time_contact_passes(const World& w, long passes, int threads) {
    contact::Contacts copy = w.contacts;
    const auto view = block_view(w);
    const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
        const auto [first, last] = contact::contact_share(copy, omp_get_thread_num(), omp_get_num_threads());
        for (long k = 0; k < passes; ++k) {
            contact::contact_pass(copy, w.properties.laws, view, w.clock.dt, w.detection.corner_radius, first, last);
#pragma omp barrier
        }
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
double seconds_since(clock_type::time_point t0) {
    return std::chrono::duration<double>(clock_type::now() - t0).count();
}
double peak_mb() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024.0;
}
struct Quiet : StageObserver {};
} // namespace

int main(int argc, char** argv) {
    const char* out = argc > 1 ? argv[1] : "bench_tunnel.json";
    const char* env = std::getenv("BBM_SOURCE_DIR");
    const std::string root = env ? env : ".";
    nlohmann::json result;

    // 1. Hybrid scene.
    auto scene = io::read_model(root + "/bench/hybrid_scene.toml");
    auto t0 = clock_type::now();
    const auto blocks = meshing::generate_blocks(scene.geometry);
    const double mesh_s = seconds_since(t0);
    nlohmann::json hybrid = nlohmann::json::array();
    std::printf("hybrid scene: generated in %.2f s\n", mesh_s);
    std::printf("%7s %8s %8s %9s %7s %9s %9s %13s %13s %13s\n", "threads", "rigid", "zones", "contacts", "steps",
                "seconds", "steps/s", "c-upd/s", "z-upd/s", "zone kernel/s");
    for (int threads : {1, 2}) {
        scene.analysis.solver.threads = threads;
        Solver s(blocks, scene.analysis);
        int rigid = 0;
        for (int i = 0; i < s.world().bodies.count(); ++i) rigid += !s.world().blocks.deformable[i];
        for (int k = 0; k < 20; ++k) s.step(); // warm up
        const long steps = scene.analysis.stages[0].steps;
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep) {
            t0 = clock_type::now();
            for (long k = 0; k < steps; ++k) s.step();
            best = std::min(best, seconds_since(t0));
        }
        // The zone kernel alone, on a copy of the model's zones and nodes.
        fem::Zones z = s.world().zones;
        std::vector<std::uint8_t> keep(s.world().bodies.count(), 0);
        const long kernel_steps = 300;
        t0 = clock_type::now();
        for (long k = 0; k < kernel_steps; ++k)
            fem::zone_pass(z, s.world().nodes.position.data(), s.world().nodes.velocity.data(), 1.0, keep.data(), 0,
                           fem::zone_items(z));
        const double kernel_s = seconds_since(t0);
        const double cups = double(contacts(s.world()).size()) * steps / best, zups = double(s.world().zones.size()) * steps / best;
        const double kernel = double(z.size()) * kernel_steps / kernel_s;
        std::printf("%7d %8d %8d %9d %7ld %9.3f %9.0f %13.3g %13.3g %13.3g\n", threads, rigid, s.world().zones.size(),
                    contacts(s.world()).size(), steps, best, steps / best, cups, zups, kernel);
        hybrid.push_back({{"threads", threads}, {"rigid_blocks", rigid}, {"zones", s.world().zones.size()},
                          {"nodes", s.world().nodes.count()}, {"contacts", contacts(s.world()).size()}, {"steps", steps},
                          {"best_seconds", best}, {"steps_per_second", steps / best},
                          {"contact_updates_per_second", cups}, {"zone_updates_per_second", zups},
                          {"zone_kernel_updates_per_second", kernel}});
    }
    result["hybrid_scene"] = hybrid;
    result["hybrid_scene_generation_seconds"] = mesh_s;

    // 2. The paper's tunnel end to end.
    auto tunnel = io::read_model(root + "/examples/tunnel_voronoi.toml");
    tunnel.analysis.solver.threads = 2;
    t0 = clock_type::now();
    const auto tb = meshing::generate_blocks(tunnel.geometry);
    Solver s(tb, tunnel.analysis);
    const double setup = seconds_since(t0);
    Quiet q;
    const auto reports = run_stages(s, tunnel.analysis.stages, q);
    const double total = seconds_since(t0);
    nlohmann::json stages = nlohmann::json::array();
    std::printf("\ntunnel_voronoi.toml on 2 threads: setup %.2f s\n", setup);
    for (const auto& r : reports) {
        std::printf("  %-12s %-10s %7ld steps %8.2f s  ratio %.2e\n", r.name.c_str(), r.kind.c_str(), r.steps,
                    r.seconds, r.ratio);
        stages.push_back({{"name", r.name}, {"steps", r.steps}, {"seconds", r.seconds}, {"ratio", r.ratio}});
    }
    std::printf("  total %.2f s, %ld steps, %d contacts, %d zones, peak memory %.0f MB\n", total, s.world().clock.steps,
                contacts(s.world()).size(), s.world().zones.size(), peak_mb());
    result["tunnel_voronoi"] = {{"threads", 2}, {"setup_seconds", setup}, {"total_seconds", total},
                                {"steps", s.world().clock.steps}, {"contacts", contacts(s.world()).size()}, {"zones", s.world().zones.size()},
                                {"stages", stages}};

    // 3. The contact loop's cost per contact, model against model.
    struct CostModel {
        const char* name;
        const char* file;
    };
    const CostModel cost_models[] = {{"paper's tunnel", "examples/tunnel_voronoi.toml"},
                                     {"trigon tunnel", "examples/tunnel_trigon.toml"},
                                     {"Mine-by", "examples/field/mineby_in_situ.toml"}};
    nlohmann::json costs = nlohmann::json::array();
    std::printf("\ncontact loop per contact, on each model's final contacts (best of 3)\n");
    std::printf("%-16s %8s %9s %8s %7s %10s %9s\n", "model", "blocks", "contacts", "broken", "threads", "ns/c-upd",
                "vs paper");
    double paper_ns[3] = {0, 0, 0};
    for (const auto& m : cost_models) {
        auto model = io::read_model(root + "/" + m.file);
        model.analysis.solver.threads = 2;
        const auto mb = meshing::generate_blocks(model.geometry);
        Solver run(mb, model.analysis);
        run_stages(run, model.analysis.stages, q);
        const int nc = contacts(run.world()).size();
        const long broken = cracks(run.world(), contact::JointState::broken_tension) + cracks(run.world(), contact::JointState::broken_shear);
        const long passes = std::max(50L, long(3e7 / std::max(1, nc)));
        for (int threads : {1, 2}) {
            double best = 1e30;
            for (int rep = 0; rep < 3; ++rep) best = std::min(best, time_contact_passes(run.world(), passes, threads));
            const double ns = best / (double(passes) * nc) * 1e9;
            if (&m == &cost_models[0]) paper_ns[threads] = ns;
            std::printf("%-16s %8d %9d %8ld %7d %10.2f %9.3f\n", m.name, run.world().bodies.count(), nc, broken, threads, ns,
                        ns / paper_ns[threads]);
            costs.push_back({{"model", m.name}, {"file", m.file}, {"blocks", run.world().bodies.count()}, {"contacts", nc},
                             {"broken_joints", broken}, {"threads", threads}, {"passes", passes},
                             {"ns_per_contact_update", ns}, {"relative_to_paper_tunnel", ns / paper_ns[threads]}});
        }
    }
    result["contact_cost_by_model"] = costs;
    result["peak_memory_mb"] = peak_mb();
    std::ofstream(out) << result.dump(2) << "\n";
    std::printf("wrote %s\n", out);
}
