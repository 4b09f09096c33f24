#pragma once
// The genetic algorithm of paper §5 and its parameters.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animat/genome.hpp"
#include "animat/params.hpp"

namespace animat {

/// How an evaluation is run: the swim horizon.
struct EvaluationParams {
  int steps = 4000;  ///< swim steps at physics.dt [paper: 4000 or 8000]
};

template <class V>
void visit_fields(EvaluationParams& p, V&& v) {
  v(FieldInfo{"steps", "swim steps per evaluation [paper: 4000, or 8000]", Bounds::closed(0, 10000000)}, p.steps);
}

struct EvolutionParams {
  std::int64_t seed = 1;                  ///< run seed; every random number derives from it
  int population = 100;                   ///< [paper: 100]
  int elites = 2;                         ///< best individuals copied unchanged [choose]
  double crossover_fraction = 0.2;        ///< share of offspring made by crossover [paper: 0.2]
  double tournament_p_start = 0.8;        ///< p(fitter wins) at generation 0 [paper: 0.8]
  double tournament_p_end = 1.0;          ///< p(fitter wins) after the ramp [paper: 1]
  int tournament_ramp_generations = 1000; ///< [paper: 1000]
  int generations = 0;                    ///< generation cap; 0 = none
  int stall_generations = 500;            ///< stop after this many generations without improvement [paper: 500]
  double wall_seconds = 0.0;              ///< wall-clock budget; 0 = none
  int threads = 0;                        ///< OpenMP threads; 0 = all cores
  int checkpoint_every = 1;               ///< write a checkpoint every k generations
  int max_init_tries = 1000000;           ///< give up seeding one viable individual after this many tries
  // [islands] islands.hpp; 1 = the paper's single population
  int islands = 1;                        ///< sub-populations evolving apart [not in the paper; 1 = off]
  int migration_interval = 10;            ///< generations between ring migrations
  int migrants = 1;                       ///< best individuals each island sends to the next one
};

template <class V>
void visit_fields(EvolutionParams& p, V&& v) {
  v(FieldInfo{"seed", "run seed", Bounds::non_negative()}, p.seed);
  v(FieldInfo{"population", "population size [paper: 100]", Bounds::closed(2, 100000)}, p.population);
  v(FieldInfo{"elites", "best individuals copied unchanged into the next generation [choose]", Bounds::closed(0, 100000)}, p.elites);
  v(FieldInfo{"crossover_fraction", "share of each generation made by crossover [paper: 0.2]", Bounds::unit()}, p.crossover_fraction);
  v(FieldInfo{"tournament_p_start", "probability that the fitter of 2 wins, at generation 0 [paper: 0.8]", Bounds::unit()}, p.tournament_p_start);
  v(FieldInfo{"tournament_p_end", "probability that the fitter wins after the ramp [paper: 1.0]", Bounds::unit()}, p.tournament_p_end);
  v(FieldInfo{"tournament_ramp_generations", "generations of the linear ramp [paper: 1000]", Bounds::closed(0, 100000000)}, p.tournament_ramp_generations);
  v(FieldInfo{"generations", "generation cap; 0 = no cap", Bounds::closed(0, 100000000)}, p.generations);
  v(FieldInfo{"stall_generations", "stop after this many generations without improvement [paper: 500]; 0 = never", Bounds::closed(0, 100000000)}, p.stall_generations);
  v(FieldInfo{"wall_seconds", "wall-clock budget in seconds; 0 = none", Bounds::non_negative()}, p.wall_seconds);
  v(FieldInfo{"threads", "OpenMP threads; 0 = all cores", Bounds::closed(0, 1024)}, p.threads);
  v(FieldInfo{"checkpoint_every", "write a checkpoint every k generations", Bounds::closed(1, 1000000)}, p.checkpoint_every);
  v(FieldInfo{"max_init_tries", "tries to find one viable random individual before giving up", Bounds::closed(1, 1000000000)}, p.max_init_tries);
  // [islands] last in the section: run_identity() of a run without islands ignores these lines
  v(FieldInfo{"islands", "sub-populations evolving apart with ring migration [not in the paper: 1 = off]", Bounds::closed(1, 10000)}, p.islands);
  v(FieldInfo{"migration_interval", "generations between migrations (islands > 1)", Bounds::closed(1, 100000000)}, p.migration_interval);
  v(FieldInfo{"migrants", "best individuals each island copies to the next island of the ring (islands > 1)", Bounds::closed(0, 100000)}, p.migrants);
}

struct Config;
class Evaluator;  // evaluator.hpp

/// [islands] One migrant (islands.hpp): a copy of population[from] (island from_island) replaced population[to].
struct Migration {
  int generation = 0;
  std::size_t from_island = 0, to_island = 0;
  std::size_t from = 0, to = 0;
  friend bool operator==(const Migration&, const Migration&) = default;
};

/// What the GA needs to know about one evaluated genome.
struct Fitness {
  double fitness = 0.0;
  bool viable = false;  ///< non-viable individuals take no part in creating the next generation
  bool stable = true;   ///< false if the swim was flagged unstable (its fitness is 0)
  int cell_count = 0;
  friend bool operator==(const Fitness&, const Fitness&) = default;
};

/// Deterministic, thread-safe fitness of a genome. The real one develops and swims (swim_fitness);
/// tests plug in cheap stubs.
using FitnessFunction = std::function<Fitness(const Genome&)>;

/// genome → development → body → swim, per `config` (see evaluate.hpp).
[[nodiscard]] FitnessFunction swim_fitness(const Config& config);

struct Individual {
  Genome genome;
  Fitness result;
  int tries = 0;  ///< random genomes drawn to find this one (initial population only)
};

/// One row of history.csv.
struct GenerationStats {
  int generation = 0;
  double best = 0.0;     ///< best fitness in the population (all-time best, thanks to elitism)
  double mean = 0.0;     ///< over viable individuals
  double median = 0.0;   ///< over viable individuals
  double viable_fraction = 0.0;
  int best_cells = 0;
  std::int64_t evaluations = 0;  ///< cumulative fitness evaluations (swims and non-viable developments)
  double wall_seconds = 0.0;     ///< cumulative wall time of the run (the only machine-dependent column)
  double evaluations_per_second = 0.0;
  bool best_changed = false;     ///< the best genome differs from the previous generation's
  int crossovers = 0;            ///< offspring made by crossover in this generation
};

/// Probability that the fitter of two wins a tournament at generation g (linear ramp, paper §5).
[[nodiscard]] double tournament_probability(const EvolutionParams& p, int generation);

/// Index of the tournament winner among two distinct random eligible individuals.
[[nodiscard]] std::size_t tournament(const std::vector<Individual>& population, const std::vector<std::size_t>& eligible,
                                     double p_fitter, Rng& rng);

/// Calls once, before any parallel region: Box2D's lazily-initialised globals (MODEL.md Traps).
void prepare_parallel_evaluation();

/// Evaluates genomes in parallel (OpenMP, dynamic schedule); results in input order, independent of
/// the thread count. threads = 0 means all cores.
[[nodiscard]] std::vector<Fitness> evaluate_all(const std::vector<Genome>& genomes, const FitnessFunction& fitness,
                                               int threads);

/// The genetic algorithm (paper §5). Every random number of generation g, offspring i derives from
/// Rng::derive(seed, g, i), so a run is bit-identical for any thread count and across resumes.
class Evolution {
 public:
  /// `evaluator` runs the evaluations (evaluator.hpp); null = the OpenMP threads of this process with `fitness`.
  Evolution(const Config& config, FitnessFunction fitness, std::shared_ptr<Evaluator> evaluator = nullptr);

  /// Draws the initial population: random genomes regenerated until viable.
  void initialize();
  /// Makes and evaluates the next generation; returns its statistics.
  GenerationStats step();
  /// Why the run should stop now ("" = keep going): stall, generation cap or wall-clock budget.
  [[nodiscard]] std::string stop_reason() const;

  [[nodiscard]] int generation() const { return generation_; }
  [[nodiscard]] const std::vector<Individual>& population() const { return population_; }
  [[nodiscard]] const Individual& best() const;
  [[nodiscard]] const std::vector<GenerationStats>& history() const { return history_; }
  [[nodiscard]] int generations_without_improvement() const { return stall_; }
  [[nodiscard]] std::int64_t evaluations() const { return evaluations_; }
  /// Tries per initial individual (paper: "a few hundred").
  [[nodiscard]] std::vector<int> initial_tries() const;

  /// Whole state as JSON text with a checksum; restore() refuses a corrupt or mismatched one.
  [[nodiscard]] std::string checkpoint() const;
  void restore(std::string_view checkpoint_text, std::string_view source = "checkpoint");

  /// Seconds of wall time consumed before this process (restored from a checkpoint).
  void set_wall_offset(double seconds) { wall_offset_ = seconds; }
  /// [islands] Migrants that arrived at the end of the last step (empty without islands).
  [[nodiscard]] const std::vector<Migration>& migrations() const { return migrations_; }

 private:
  GenerationStats statistics(bool best_changed, double wall_seconds) const;

  std::shared_ptr<const Config> config_;  ///< own copy: the engine outlives no caller state
  std::uint64_t identity_;
  FitnessFunction fitness_;
  std::shared_ptr<Evaluator> evaluator_;
  std::vector<Migration> migrations_;  // [islands]
  std::vector<Individual> population_;
  std::vector<GenerationStats> history_;
  int generation_ = -1;  ///< -1 before initialize()
  int stall_ = 0;
  double best_ever_ = -1.0;
  std::int64_t evaluations_ = 0;
  double wall_offset_ = 0.0;
  double started_ = 0.0;
};

/// Hash of what defines a run: the config minus its stopping and resource knobs (generations,
/// stall_generations, wall_seconds, threads, checkpoint_every), so a resumed run may extend its cap.
[[nodiscard]] std::uint64_t run_identity(const Config& config);

/// Options of a run on disk (animat_evolve and animat.evolve).
struct RunOptions {
  std::filesystem::path out;           ///< run directory ("" = write nothing)
  bool resume = false;                 ///< continue the run in `out`
  bool quiet = false;
  double progress_interval = 1.0;      ///< seconds between progress lines
  const std::atomic<bool>* stop_flag = nullptr;  ///< set by a signal handler: checkpoint and stop
  std::shared_ptr<Evaluator> evaluator;           ///< how to evaluate (evaluator.hpp); null = OpenMP threads
  /// Called after every generation; return false to stop (checkpointed).
  std::function<bool(const GenerationStats&, const Evolution&)> callback;
};

struct RunSummary {
  std::vector<GenerationStats> history;
  Individual best;
  std::string stop_reason;
};

/// Runs (or resumes) an evolution, writing config.toml, history.csv, best/ lineage and checkpoints.
RunSummary run_evolution(const Config& config, const RunOptions& options, FitnessFunction fitness = {});

}  // namespace animat
