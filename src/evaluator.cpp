#include "animat/evaluator.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <exception>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"

namespace animat {

namespace {


class LocalEvaluator final : public Evaluator {
 public:
  LocalEvaluator(const Config& config, FitnessFunction fitness)
      : config_(std::make_shared<const Config>(config)), fitness_(std::move(fitness)), threads_(resolve_threads(config.evolution.threads)) {
    if (!fitness_) throw Error("LocalEvaluator: no fitness function");
  }

  std::vector<Fitness> evaluate(std::span<const Genome* const> genomes) override {
    std::vector<Fitness> out(genomes.size());
    parallel_for(genomes.size(), [&](std::size_t i) { out[i] = fitness_(*genomes[i]); });
    return out;
  }

  std::vector<Individual> seed(std::size_t first, std::size_t count) override {
    std::vector<Individual> out(count);
    parallel_for(count, [&](std::size_t i) { out[i] = seed_individual(*config_, fitness_, first + i); });
    return out;
  }

  std::string describe() const override { return fmt::format("OpenMP, {} thread{}", threads_, threads_ == 1 ? "" : "s"); }

 private:
  // Runs body(i) for i in [0, n) on the threads, one index per chunk (an evaluation takes 0.1 to
  // 30 ms: chunks of one keep the tail short); rethrows the first exception by index afterwards.
  template <class Body>
  void parallel_for(std::size_t n, Body&& body) {
    prepare_parallel_evaluation();
    animat::parallel_for(n, threads_, std::forward<Body>(body));
  }

  std::shared_ptr<const Config> config_;
  FitnessFunction fitness_;
  int threads_;
};

}  // namespace

std::vector<Fitness> Evaluator::evaluate(const std::vector<Genome>& genomes) {
  std::vector<const Genome*> ptrs;
  ptrs.reserve(genomes.size());
  for (const auto& g : genomes) ptrs.push_back(&g);
  return evaluate(std::span<const Genome* const>(ptrs));
}

int resolve_threads(int requested) { return requested > 0 ? requested : omp_get_num_procs(); }

Individual seed_individual(const Config& config, const FitnessFunction& fitness, std::size_t index) {
  const EvolutionParams& ep = config.evolution;
  Rng rng = Rng::derive(static_cast<std::uint64_t>(ep.seed), kInitialStreamKey, index);
  Individual ind;
  for (ind.tries = 1; ind.tries <= ep.max_init_tries; ++ind.tries) {
    ind.genome = random_genome(config.genome, rng);
    ind.result = fitness(ind.genome);
    if (ind.result.viable) return ind;
  }
  throw Error(fmt::format("initial population: no viable random genome in evolution.max_init_tries = {} tries "
                          "(individual {}); the development or genome settings make viability too rare",
                          ep.max_init_tries, index));
}

std::shared_ptr<Evaluator> make_local_evaluator(const Config& config, FitnessFunction fitness) {
  return std::make_shared<LocalEvaluator>(config, std::move(fitness));
}

}  // namespace animat
