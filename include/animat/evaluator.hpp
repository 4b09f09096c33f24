#pragma once
// How a population is evaluated: one interface over the OpenMP threads of this process
// (LocalEvaluator) and the ranks of an MPI job (mpi.hpp). The GA (evolution.hpp) sees only this.
//
// Every evaluator returns the same results for the same input, whatever its layout: a genome's
// fitness depends only on the genome and the config. Results are stored by index, never in arrival
// order. The GA evaluates only through an Evaluator (its initial population too: ask/tell seeding).
#include <cstddef>
#include <exception>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animat/evolution.hpp"

namespace animat {

struct Config;

class Evaluator {
 public:
  virtual ~Evaluator() = default;

  /// Fitness of every genome, in input order. Throws Interrupted if `stop` fires before every
  /// genome is evaluated (no evaluation starts after it; what was done is dropped); a fitness
  /// function that throws Interrupted itself (Ctrl-C in a Python objective) stops it the same way.
  /// The MPI evaluator honours its job's own stop flag instead (mpi.hpp).
  [[nodiscard]] virtual std::vector<Fitness> evaluate(std::span<const Genome* const> genomes,
                                                      const StopRequest& stop) = 0;
  /// One line for the log: "OpenMP, 2 threads", "MPI, 3 ranks, 6 threads".
  [[nodiscard]] virtual std::string describe() const = 0;

  /// Convenience overload for a contiguous list of genomes.
  [[nodiscard]] std::vector<Fitness> evaluate(const std::vector<Genome>& genomes,
                                              const StopRequest& stop = {});
};

/// Rng stream key of the initial population: individual i draws from Rng::derive(evolution.seed,
/// kInitialStreamKey, i) (Evolution's ask/tell seeding).
inline constexpr std::uint64_t kInitialStreamKey = 0xffffffffffffffffULL;

/// The OpenMP threads of this process (`threads`, resolve_threads), dynamic schedule with one
/// genome per chunk; an exception is rethrown after the loop, the first by index.
[[nodiscard]] std::shared_ptr<Evaluator> make_local_evaluator(FitnessFunction fitness, int threads);
/// The same on evolution.threads of `config`.
[[nodiscard]] std::shared_ptr<Evaluator> make_local_evaluator(const Config& config,
                                                              FitnessFunction fitness);

/// Evaluates genomes on `threads` OpenMP threads (a local evaluator); results in input order,
/// independent of the thread count. threads = 0 means all cores.
[[nodiscard]] std::vector<Fitness> evaluate_all(const std::vector<Genome>& genomes,
                                                const FitnessFunction& fitness, int threads);

/// Threads that evolution.threads = `requested` means on this machine (0 = all available cores).
[[nodiscard]] int resolve_threads(int requested);

/// Runs body(i) for i in [0, n) on `threads` OpenMP threads (resolve_threads), dynamic schedule
/// with one index per chunk; rethrows the first exception by index after the loop.
template <class Body>
void parallel_for(std::size_t n, int threads, Body&& body) {
  std::vector<std::exception_ptr> errors(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(resolve_threads(threads))
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
    try {
      body(static_cast<std::size_t>(i));
    } catch (...) {
      errors[static_cast<std::size_t>(i)] = std::current_exception();
    }
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace animat
