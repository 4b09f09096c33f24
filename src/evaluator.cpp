#include "animat/evaluator.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"

namespace animat {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Watches a StopRequest during one parallel piece of work. Any thread may ask stopped(); only the
// thread that created it (OpenMP's thread 0 of the regions it runs) calls the poll, at most every
// 20 ms.
class StopWatch {
 public:
  explicit StopWatch(const StopRequest& request) : request_(request) {}
  bool stopped() {
    if (stopped_.load(std::memory_order_relaxed)) return true;
    if (request_.empty()) return false;
    if (request_.flag && request_.flag->load()) return stop();
    if (request_.poll && omp_get_thread_num() == 0) {
      const double t = now_seconds();
      if (t - last_poll_ >= 0.02) {
        last_poll_ = t;
        if (request_.poll()) return stop();
      }
    }
    return false;
  }
  /// Whether a stop was seen (no new poll).
  [[nodiscard]] bool fired() const { return stopped_.load(); }
  /// Stops the work from within (an evaluation that was itself interrupted): stopped() is true from
  /// now on.
  void request_stop() { stop(); }

 private:
  bool stop() {
    stopped_.store(true);
    return true;
  }
  const StopRequest& request_;
  std::atomic<bool> stopped_{false};
  double last_poll_ = 0.0;  // touched by thread 0 only
};

class LocalEvaluator final : public Evaluator {
 public:
  LocalEvaluator(FitnessFunction fitness, int threads)
      : fitness_(std::move(fitness)), threads_(resolve_threads(threads)) {
    if (!fitness_) throw Error("LocalEvaluator: no fitness function");
  }

  // One genome per chunk: an evaluation takes 0.1 to 30 ms, and chunks of one keep the tail short.
  std::vector<Fitness> evaluate(std::span<const Genome* const> genomes,
                                const StopRequest& stop) override {
    prepare_parallel_evaluation();
    std::vector<Fitness> out(genomes.size());
    StopWatch watch(stop);
    parallel_for(genomes.size(), threads_, [&](std::size_t i) {
      if (watch.stopped()) return;
      try {
        out[i] = fitness_(*genomes[i]);
      } catch (const Interrupted&) {
        // the fitness function itself was interrupted (Ctrl-C in a Python objective)
        watch.request_stop();
      }
    });
    if (watch.fired()) throw Interrupted("interrupted during an evaluation");
    return out;
  }

  std::string describe() const override {
    return fmt::format("OpenMP, {} thread{}", threads_, threads_ == 1 ? "" : "s");
  }

 private:
  FitnessFunction fitness_;
  int threads_;
};

}  // namespace

std::vector<Fitness> Evaluator::evaluate(const std::vector<Genome>& genomes,
                                         const StopRequest& stop) {
  std::vector<const Genome*> ptrs;
  ptrs.reserve(genomes.size());
  for (const auto& g : genomes) ptrs.push_back(&g);
  return evaluate(std::span<const Genome* const>(ptrs), stop);
}

int resolve_threads(int requested) { return requested > 0 ? requested : omp_get_num_procs(); }

std::shared_ptr<Evaluator> make_local_evaluator(FitnessFunction fitness, int threads) {
  return std::make_shared<LocalEvaluator>(std::move(fitness), threads);
}

std::shared_ptr<Evaluator> make_local_evaluator(const Config& config, FitnessFunction fitness) {
  return make_local_evaluator(std::move(fitness), config.evolution.threads);
}

std::vector<Fitness> evaluate_all(const std::vector<Genome>& genomes,
                                  const FitnessFunction& fitness, int threads) {
  return make_local_evaluator(fitness, threads)->evaluate(genomes);
}

}  // namespace animat
