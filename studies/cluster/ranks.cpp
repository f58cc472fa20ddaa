#include "studies/cluster/ranks.hpp"

#include "base/error.hpp"

#ifdef BBM_MPI
#include <mpi.h>
#endif

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace bbm::studies {

namespace {

bool started = false;
int this_rank = 0, rank_count = 1;

/// How a run ended, to raise the same error on every rank.
enum class Outcome : std::uint8_t { ok, input_error, numerical_error, interrupted, other_error };

struct RunResult {
    Outcome outcome = Outcome::ok;
    std::string text; ///< the result, or the error's fields joined by '\0'
};

std::string join_fields(const InputError& e) {
    return e.file() + '\0' + std::to_string(e.line()) + '\0' + e.key() + '\0' + e.message();
}

[[noreturn]] void raise(const RunResult& r) {
    if (r.outcome == Outcome::input_error) {
        std::vector<std::string> f;
        std::size_t start = 0;
        for (int k = 0; k < 3; ++k) {
            const auto end = r.text.find('\0', start);
            f.push_back(r.text.substr(start, end - start));
            start = end + 1;
        }
        throw InputError(f[0], std::atoi(f[1].c_str()), f[2], r.text.substr(start));
    }
    if (r.outcome == Outcome::numerical_error) throw NumericalError(r.text);
    if (r.outcome == Outcome::interrupted) throw Interrupted(r.text);
    throw std::runtime_error(r.text);
}

#ifdef BBM_MPI
/// Every rank's results to every rank: (k, outcome, text) records.
void share_results(std::vector<RunResult>& results, const std::vector<int>& mine) {
    std::string buffer;
    for (int k : mine) {
        const auto& r = results[k];
        const std::int64_t head[3] = {k, std::int64_t(r.outcome), std::int64_t(r.text.size())};
        buffer.append(reinterpret_cast<const char*>(head), sizeof head);
        buffer.append(r.text);
    }
    long long size = static_cast<long long>(buffer.size());
    std::vector<long long> sizes(rank_count);
    MPI_Allgather(&size, 1, MPI_LONG_LONG, sizes.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD);
    std::vector<int> counts(rank_count), offsets(rank_count);
    long long total = 0;
    for (int r = 0; r < rank_count; ++r) {
        if (sizes[r] > (1ll << 30)) throw std::runtime_error("results of one rank exceed 1 GB");
        counts[r] = int(sizes[r]), offsets[r] = int(total), total += sizes[r];
    }
    if (total > (1ll << 31) - 1) throw std::runtime_error("results of a study exceed 2 GB");
    std::string all(std::size_t(total), '\0');
    MPI_Allgatherv(buffer.data(), counts[this_rank], MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR,
                   MPI_COMM_WORLD);
    for (std::size_t at = 0; at < all.size();) {
        std::int64_t head[3];
        std::memcpy(head, all.data() + at, sizeof head);
        at += sizeof head;
        auto& r = results[std::size_t(head[0])];
        r.outcome = Outcome(head[1]);
        r.text = all.substr(at, std::size_t(head[2]));
        at += std::size_t(head[2]);
    }
}
#endif

} // namespace

void Ranks::start(int* argc, char*** argv) {
#ifdef BBM_MPI
    // Launched by mpirun (Open MPI, MPICH) or srun: the launcher's variables are set.
    bool launched = false;
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"})
        launched = launched || std::getenv(v) != nullptr;
    if (!launched) return;
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    started = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &this_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &rank_count);
#else
    (void)argc, (void)argv;
#endif
}

void Ranks::stop() {
#ifdef BBM_MPI
    if (started) MPI_Finalize();
#endif
    started = false;
}

int Ranks::rank() { return this_rank; }
int Ranks::size() { return rank_count; }

bool Ranks::available() {
#ifdef BBM_MPI
    return true;
#else
    return false;
#endif
}

std::vector<std::string> run_spread(int n, int threads, const std::function<std::string(int)>& run,
                                    std::vector<std::string>* errors) {
    std::vector<int> mine;
    for (int k = this_rank; k < n; k += rank_count) mine.push_back(k);
    std::vector<RunResult> results(std::size_t(std::max(n, 0)));
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
        for (std::size_t i = next++; i < mine.size(); i = next++) {
            auto& r = results[std::size_t(mine[i])];
            try {
                r.text = run(mine[i]);
            } catch (const InputError& e) {
                r = {Outcome::input_error, join_fields(e)};
            } catch (const NumericalError& e) {
                r = {Outcome::numerical_error, e.what()};
            } catch (const Interrupted& e) {
                r = {Outcome::interrupted, e.what()};
            } catch (const std::exception& e) {
                r = {Outcome::other_error, e.what()};
            }
        }
    };
    const int pool_size = std::max(1, std::min<int>(threads, int(mine.size())));
    if (pool_size == 1) {
        worker();
    } else {
        std::vector<std::thread> pool;
        for (int t = 0; t < pool_size; ++t) pool.emplace_back(worker);
        for (auto& t : pool) t.join();
    }
#ifdef BBM_MPI
    if (started && rank_count > 1) share_results(results, mine);
#endif
    std::vector<std::string> out(results.size());
    if (errors) errors->assign(results.size(), {});
    for (std::size_t k = 0; k < results.size(); ++k) {
        if (results[k].outcome == Outcome::ok) {
            out[k] = std::move(results[k].text);
            continue;
        }
        if (!errors) raise(results[k]);
        try {
            raise(results[k]);
        } catch (const std::exception& e) {
            (*errors)[k] = e.what();
        }
    }
    return out;
}

} // namespace bbm::studies
