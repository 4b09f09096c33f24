#pragma once
// One GA over the ranks of an MPI job (Open MPI; `mpirun -np R animat_evolve ...`):
// rank 0 owns the population, the checkpoints and the output; every rank, rank 0 too, evaluates
// with its OpenMP threads. Rank 0 hands out genomes (or initial individuals to seed) in small
// batches as ranks ask for them: an evaluation takes 0.1 ms (non-viable) to 30 ms (a viable swim),
// so a static split would leave ranks idle. Results are stored by index: bit-identical to one
// process with one thread, for any ranks x threads, and the rank count may change across a resume.
//
// This header needs no MPI headers; without MPI (ANIMAT_WITH_MPI=OFF or Open MPI absent at build
// time) Job throws an Error that says how to get it.
#include <atomic>
#include <memory>
#include <string>

#include "animat/errors.hpp"

namespace animat {
struct Config;
class Evaluator;
}  // namespace animat

namespace animat::mpi {

/// What the environment says about an MPI launch (mpirun, mpiexec, srun set these variables).
struct Launch {
  bool launched = false;  ///< started by an MPI launcher
  int size = 1;           ///< ranks in the job (1 when unknown)
  int rank = 0;
  std::string variable;  ///< the variable that told, e.g. "OMPI_COMM_WORLD_SIZE=3"
};
[[nodiscard]] Launch detect_launch();

/// True when this build has the MPI evaluator.
[[nodiscard]] bool built_with_mpi();

/// How to get a build with MPI (install Open MPI, rebuild).
[[nodiscard]] std::string how_to_get_mpi();

/// The MPI job stopped mid-evaluation because the process was told to stop (under mpirun: a rank
/// died, or the job was cancelled). Unlike animat::Interrupted (a stop request the run honours and
/// continues from), the job cannot go on: rank 0 leaves at once. The generation being evaluated is
/// lost; the last checkpoint stands.
class JobStopped : public Error {
 public:
  using Error::Error;
};

/// A rank stopped answering the protocol (exited, or sent something unexpected).
class RankFailure : public Error {
 public:
  using Error::Error;
};

/// Threads that evolution.threads = `requested` means for one of `local_ranks` ranks on this node:
/// 0 = the cores this process may run on, shared among the ranks of the node unless the launcher
/// bound each rank to its own cores.
[[nodiscard]] int threads_per_rank(int requested, int local_ranks);

/// One MPI job (MPI_Init_thread with MPI_THREAD_FUNNELED in the constructor, MPI_Finalize in the
/// destructor). Rank 0 calls start() and runs the GA with the evaluator it returns; every other
/// rank calls serve().
class Job {
 public:
  Job(int& argc, char**& argv);
  ~Job();
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;

  [[nodiscard]] int rank() const;
  [[nodiscard]] int size() const;

  /// Ranks > 0: receive the config from rank 0, evaluate what it hands out until it says stop.
  /// Returns the process exit status (0, or 0 too when rank 0 ended without a run).
  int serve();

  /// Rank 0: sends the config to every rank and returns the evaluator that uses them all. `stop`
  /// (a signal flag) interrupts an evaluation with JobStopped.
  [[nodiscard]] std::shared_ptr<Evaluator> start(const Config& config,
                                                 const std::atomic<bool>* stop);

  /// Rank 0, after a JobStopped or a RankFailure: end this process now without waiting for ranks
  /// that may be gone (no MPI_Finalize; the launcher ends the others).
  [[noreturn]] static void abandon(int status);

  struct State;

 private:
  std::shared_ptr<State> state_;
};

}  // namespace animat::mpi
