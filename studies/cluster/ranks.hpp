// bbm studies: independent runs spread over MPI ranks (and threads within a rank).
//
// A study of many independent runs — realizations of a lab test, the runs of a
// sweep, the models of a comparison — hands them to run_spread(): run k goes to
// rank k mod N (a fixed assignment, so which rank ran what never changes a
// result), each rank runs its share on its threads, and every rank gets every
// run's result back, as the text the run returned (JSON). Rank 0 then writes the
// study's files. Without MPI (a build without it, or a program not started by
// mpirun) there is one rank and this is a thread pool.
//
// MPI is seen by ranks.cpp alone; a build with it starts MPI only when the
// environment says mpirun (or srun) launched the process.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace bbm::studies {

class Ranks {
public:
    /// Starts MPI if the process was launched by mpirun/srun (and bbm was built
    /// with MPI); otherwise one rank. Call once, from main.
    static void start(int* argc, char*** argv);
    /// Ends MPI if started (at exit of main).
    static void stop();
    static int rank();
    static int size();
    static bool root() { return rank() == 0; }
    /// Whether this build can use MPI.
    static bool available();
};

/// Runs run(k) for k = 0..n-1 spread over ranks and, within a rank, over
/// `threads` threads; returns every result on every rank, in order of k. A run
/// that throws gives "" and its message in errors[k] (when errors is not null);
/// without `errors`, the first failure is rethrown on every rank after all runs
/// end (as a std::runtime_error with the message, or the InputError itself on the
/// rank that ran it).
std::vector<std::string> run_spread(int n, int threads, const std::function<std::string(int)>& run,
                                    std::vector<std::string>* errors = nullptr);

} // namespace bbm::studies
