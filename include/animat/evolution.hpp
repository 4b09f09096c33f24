#pragma once
// The genetic algorithm of paper §5 and its parameters.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "animat/errors.hpp"
#include "animat/genome.hpp"
#include "animat/params.hpp"

namespace animat {

inline constexpr std::string_view kReferenceCheckNames[] = {"record", "select", "off"};
/// Allowed values of evaluation.objective: the built-in objectives (kObjectiveNames in objective.hpp;
/// a new one is added to both lists) and "python:NAME" (the trailing * is a wildcard).
inline constexpr std::string_view kObjectiveChoices[] = {"distance", "distance_per_size", "speed_toward", "distance_x",
                                                         "distance_minus_energy", "distance_per_energy", "chemotaxis",
                                                         "python:*"};
inline constexpr std::string_view kPushCellNames[] = {"all", "front"};

/// How an evaluation is run and scored: the swim horizon, the objective (objective.hpp), the
/// invariants checked, and the exploit guard.
struct EvaluationParams {
  int steps = 4000;  ///< swim steps at physics.dt [paper: 4000 or 8000]
  /// distance (the paper's), distance_per_size, speed_toward, or "python:NAME" (a Python callable).
  std::string objective = "distance";
  std::vector<double> direction = {1.0, 0.0};  ///< speed_toward's direction (normalised when used)
  /// Check the body's planar embedding after every step (no region inverted, the skin simple); a
  /// swim that breaks it is invalid and gets fitness 0, like an unstable one.
  bool check_embedding = true;
  /// "record": each time the GA's best changes, re-evaluate it with physics.substeps multiplied by
  /// reference_substeps (the same horizon at a finer step) and record both fitnesses; "select": the
  /// same, and elites are ranked by the reference fitness; "off".
  std::string reference_check = "record";
  int reference_substeps = 16;             ///< refinement factor of the reference evaluation
  double reference_tolerance = 0.01;       ///< relative fitness difference that is warned about...
  double reference_abs_tolerance = 0.05;   ///< ...when it also exceeds this many length units
  /// Control steps simulated before the fitness clock starts, with actuation off (the crawl world:
  /// the body settles onto the ground); 0 = none, today's swims bit for bit (docs/worlds.md).
  int settle_steps = 0;
  /// λ of distance_minus_energy: distance − λ·(positive actuation work) [choose: docs/worlds.md; a
  /// 20-generation d_N = 2 best swims 12.8 for W⁺ = 6.5e4, so λ = 1e-4 weighs both alike]
  double energy_weight = 1e-4;
  /// W₀ of distance_per_energy: distance / (positive actuation work + W₀) [choose: docs/worlds.md; of
  /// the order of a swimmer's W⁺, so that barely moving bodies do not win on the ratio]
  double energy_offset = 1e4;
  // Directional tasks and disruption (issue 18, docs/control.md).
  int source_directions = 4;   ///< objective chemotaxis: swims per evaluation, one per source direction [choose]
  int source_seed = 1;         ///< objective chemotaxis: seed of the source directions (the same for every genome) [choose]
  int push_step = -1;          ///< control step (from the fitness clock's start) of a push; -1 = none
  std::vector<double> push_impulse = {0.0, 0.0};  ///< impulse [Jx, Jy] given to every pushed cell
  std::string push_cells = "all";  ///< pushed cells: all, or front (x >= the centre of mass's x)
  /// Keep the energy books of every swim (EvaluationResult::energy): slower, results unchanged.
  bool energy_accounting = false;
};

template <class V>
void visit_fields(EvaluationParams& p, V&& v) {
  v(FieldInfo{"steps", "swim steps per evaluation [paper: 4000, or 8000]", Bounds::closed(0, 10000000)}, p.steps);
  v(FieldInfo{"objective", "what the GA maximises: distance (straight-line distance of the centre of mass, the paper's); "
                           "distance_per_size (distance / body length); speed_toward (centre-of-mass speed along "
                           "evaluation.direction); distance_x (|horizontal displacement| of the centre of mass, the "
                           "crawl world's); distance_minus_energy (distance - energy_weight * positive actuation work); "
                           "distance_per_energy (distance / (positive actuation work + energy_offset)); python:NAME (a "
                           "Python callable, set by animat.evolve)",
              Bounds::any(), kObjectiveChoices},
    p.objective);
  v(FieldInfo{"direction", "direction [x, y] of speed_toward (normalised; not both 0)", Bounds::closed(-kMaxLength, kMaxLength)}, p.direction);
  v(FieldInfo{"check_embedding", "check after every step that no region is inverted and the skin is a simple polygon; a swim that breaks it gets fitness 0", Bounds::any()}, p.check_embedding);
  v(FieldInfo{"reference_check", "exploit guard: re-evaluate each new best at a finer step and record both fitnesses (record), also rank elites by it (select), or off", Bounds::any(), kReferenceCheckNames}, p.reference_check);
  v(FieldInfo{"reference_substeps", "the reference evaluation uses physics.substeps times this (dt/16 by default)", Bounds::closed(1, 1024)}, p.reference_substeps);
  v(FieldInfo{"reference_tolerance", "warn when the best's fitness and its reference differ by more than this fraction...", Bounds::upto(1e6)}, p.reference_tolerance);
  v(FieldInfo{"reference_abs_tolerance", "...and by more than this many length units", Bounds::upto(kMaxLength)}, p.reference_abs_tolerance);
  v(FieldInfo{"settle_steps", "control steps simulated with actuation off before the fitness clock starts (crawl world: the body settles onto the ground; docs/worlds.md); 0 = none", Bounds::closed(0, 10000000)}, p.settle_steps);
  v(FieldInfo{"energy_weight", "lambda of objective distance_minus_energy: distance - lambda * positive actuation work, length per energy unit [choose]", Bounds::upto(1e6)}, p.energy_weight);
  v(FieldInfo{"energy_offset", "W0 of objective distance_per_energy: distance / (positive actuation work + W0), energy units, > 0 [choose]", Bounds::positive_upto(1e12)}, p.energy_offset);
  v(FieldInfo{"source_directions", "objective chemotaxis: swims per evaluation, each with scene.chemical_source rotated to a random direction; fitness = mean progress toward the source (docs/control.md) [choose]", Bounds::closed(1, 64)}, p.source_directions);
  v(FieldInfo{"source_seed", "objective chemotaxis: seed of the source directions, the same for every genome [choose]", Bounds::closed(0, 2147483647)}, p.source_seed);
  v(FieldInfo{"push_step", "disruption: control step (from the fitness clock's start) at which the pushed cells get push_impulse; -1 = never (docs/control.md)", Bounds::closed(-1, 10000000)}, p.push_step);
  v(FieldInfo{"push_impulse", "disruption: impulse [Jx, Jy] given to every pushed cell (velocity change impulse / cell_mass), mass * length / time", Bounds::closed(-kMaxCoefficient, kMaxCoefficient)}, p.push_impulse);
  v(FieldInfo{"push_cells", "disruption: which cells are pushed: all, or front (x >= the centre of mass's x, a push that also turns the body)", Bounds::any(), kPushCellNames}, p.push_cells);
  v(FieldInfo{"energy_accounting", "keep the energy books of every swim: actuation work in; fluid drag (normal, tangential), spring damping, collisions and ground out; kinetic and potential energies stored (include/animat/energy.hpp). Slower; fitness unchanged", Bounds::any()}, p.energy_accounting);
}

struct Config;
/// Whether a fitness and its reference differ by more than both evaluation.reference_tolerance
/// (relative to the reference) and evaluation.reference_abs_tolerance: the exploit guard warns.
[[nodiscard]] bool reference_disagrees(double fitness, double reference, const EvaluationParams& params);
/// The config of the reference evaluation of the exploit guard: physics.substeps multiplied by
/// evaluation.reference_substeps, everything else equal.
[[nodiscard]] Config reference_config(const Config& config);

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
  v(FieldInfo{"wall_seconds", "wall-clock budget in seconds; 0 = none", Bounds::upto(1e10)}, p.wall_seconds);
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
  bool valid = true;    ///< false if the swim broke an invariant (embedding, collisions); fitness 0
  /// Edge-component steps where drag_scheme "stable" scaled eq. 5 down (0 with every other scheme):
  /// the swim was not integrated as written there.
  long drag_limited = 0;
  friend bool operator==(const Fitness&, const Fitness&) = default;
};

/// Deterministic, thread-safe fitness of a genome. The real one develops and swims (swim_fitness);
/// tests plug in cheap stubs.
using FitnessFunction = std::function<Fitness(const Genome&)>;

class Objective;

/// genome → development → body → swim, per `config` (see evaluate.hpp), scored by the config's
/// objective (evaluation.objective; objective.hpp).
[[nodiscard]] FitnessFunction swim_fitness(const Config& config);
/// The same chain scored by `objective` (e.g. a Python callable) instead of the config's.
[[nodiscard]] FitnessFunction objective_fitness(const Config& config, std::shared_ptr<const Objective> objective);

struct Individual {
  Genome genome;
  Fitness result;
  int tries = 0;  ///< random genomes drawn to find this one (initial population only)
  /// Fitness at the reference step (the exploit guard, evaluation.reference_check); NaN = not
  /// evaluated.
  double reference = std::numeric_limits<double>::quiet_NaN();
};

/// One row of history.csv.
struct GenerationStats {
  int generation = 0;
  double best = 0.0;     ///< best fitness in the population (all-time best, thanks to elitism)
  /// Over viable individuals; finite whenever their fitnesses are (no overflow: see finite_mean in
  /// evolution.cpp), so that a checkpoint always holds it.
  double mean = 0.0;
  double median = 0.0;   ///< over viable individuals (finite likewise)
  double viable_fraction = 0.0;
  int best_cells = 0;
  std::int64_t evaluations = 0;  ///< cumulative fitness evaluations (swims and non-viable developments)
  double wall_seconds = 0.0;     ///< cumulative wall time of the run (the only machine-dependent column)
  double evaluations_per_second = 0.0;  ///< of this generation alone (its evaluations / its wall time)
  bool best_changed = false;     ///< the best genome differs from the previous generation's
  int crossovers = 0;            ///< offspring made by crossover in this generation
  /// The best's fitness at the reference step (evaluation.reference_check); NaN when off.
  double best_reference = std::numeric_limits<double>::quiet_NaN();
  int invalid = 0;               ///< viable individuals whose swim was unstable or broke an invariant (fitness 0)
  /// Individuals whose swim the drag limiter altered (drag_scheme "stable" only; Fitness::drag_limited > 0).
  int drag_limited = 0;
};

/// Probability that the fitter of two wins a tournament at generation g (linear ramp, paper §5).
[[nodiscard]] double tournament_probability(const EvolutionParams& p, int generation);

/// Index of the tournament winner among two distinct random eligible individuals.
[[nodiscard]] std::size_t tournament(const std::vector<Individual>& population, const std::vector<std::size_t>& eligible,
                                     double p_fitter, Rng& rng);

/// A run (or its initial population, or one generation) stopped by a StopRequest before it finished;
/// what was completed before it is kept (see Evolution::initialize and Evolution::step).
struct Interrupted : Error {
  using Error::Error;
};

/// Asks a running evolution to stop early. Checked between evaluations and between the random genomes
/// drawn for the initial population, so a stop is honoured within one evaluation (27 ms at the paper's
/// setting), not only between generations.
struct StopRequest {
  const std::atomic<bool>* flag = nullptr;  ///< set asynchronously (a signal handler, another thread)
  /// Called on the thread that runs the evolution only, about every 20 ms while it works (e.g. Python's
  /// PyErr_CheckSignals with the GIL briefly acquired); returning true stops the run. Must not throw.
  std::function<bool()> poll;

  [[nodiscard]] bool empty() const { return flag == nullptr && !poll; }
};

/// Calls once, before any parallel region: Box2D's lazily-initialised globals (docs/model.md §4,
/// "Evaluation, determinism, threads").
void prepare_parallel_evaluation();

/// Evaluates genomes in parallel (OpenMP, dynamic schedule); results in input order, independent of
/// the thread count. threads = 0 means all cores.
[[nodiscard]] std::vector<Fitness> evaluate_all(const std::vector<Genome>& genomes, const FitnessFunction& fitness,
                                               int threads);

/// The genetic algorithm (paper §5). Every random number of generation g, offspring i derives from
/// Rng::derive(seed, g, i), so a run is bit-identical for any thread count and across resumes.
///
/// It runs by itself (initialize(), step(): evaluating with its fitness function in parallel) or is
/// driven from outside by ask()/tell(), for genomes evaluated elsewhere; both are the same engine
/// and give identical results.
class Evolution {
 public:
  /// `fitness` may be empty for an engine driven only by ask() and tell(). `reference` is the
  /// exploit guard's fitness at the reference step (reference_config()); with none,
  /// evaluation.reference_check has no effect. `evaluator` runs the evaluations (evaluator.hpp);
  /// null = the OpenMP threads of this process with `fitness`.
  explicit Evolution(const Config& config, FitnessFunction fitness = {}, FitnessFunction reference = {},
                     std::shared_ptr<Evaluator> evaluator = nullptr);

  /// Draws the initial population: random genomes regenerated until viable (ask/evaluate/tell
  /// rounds with speculative draws; the result equals one-at-a-time drawing). Throws Interrupted
  /// (and stays uninitialised) if the stop request fires first.
  void initialize();
  /// Makes and evaluates the next generation; returns its statistics. Throws Interrupted if the stop
  /// request fires before the generation is complete: the state stays at the previous generation
  /// (resuming recomputes the same generation, every random number derives from (seed, g, i)).
  /// Throws Error if the fitness function returns a non-finite fitness, or a negative one under a
  /// distance objective (evaluation.objective = distance or distance_per_size).
  GenerationStats step();
  /// Checked by initialize() and step() (see StopRequest); empty = never stop.
  void set_stop(StopRequest stop) { stop_ = std::move(stop); }

  /// The genomes that need a fitness next, in order. Before generation 0: the next random draw of
  /// every initial slot not yet holding a viable individual (slot i draws from
  /// Rng::derive(seed, initial, i)); with `lookahead` > 1, that many consecutive draws per slot
  /// (speculative: those after a slot's first viable draw are discarded and not counted, so the run
  /// does not depend on it). After that: the offspring of the next generation that are not copies of
  /// an evaluated genome (elites and unchanged copies keep their fitness; the list may be empty).
  /// ask() again before tell() returns the same genomes.
  std::vector<Genome> ask(int lookahead = 1);
  /// The fitness of every genome of the last ask(), in order. Returns true when this completed a
  /// generation (history().back() holds its statistics). Throws Error for a count mismatch, a value
  /// that the engine's own evaluations refuse (naming its index: a fitness that is not finite, a
  /// negative one under a distance objective, a negative cell_count or drag_limited), or an initial
  /// slot that used up evolution.max_init_tries. With a reference fitness function (the exploit
  /// guard), a tell that completes a generation with a new best evaluates its reference here, as
  /// step() does; if that throws, the engine is left as before the tell (the ask still pending).
  bool tell(const std::vector<Fitness>& fitness);
  /// Whether an ask() awaits its tell().
  [[nodiscard]] bool asked() const { return pending_; }
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

  /// Whole state as JSON text with a checksum; restore() refuses a corrupt or mismatched one, and one
  /// whose content is inconsistent even with a valid checksum (hand-edited): a fitness that is not
  /// finite (and >= 0 under a distance objective), a genome that does not validate or is empty, a history that does not count
  /// 0, 1, ..., generation or whose last row disagrees with the population, a population of the wrong
  /// size, a best_ever or stall counter that the history contradicts.
  [[nodiscard]] std::string checkpoint() const;
  void restore(std::string_view checkpoint_text, std::string_view source = "checkpoint");

  /// Seconds of wall time consumed before this process (restored from a checkpoint).
  void set_wall_offset(double seconds) { wall_offset_ = seconds; }
  /// [islands] Migrants that arrived at the end of the last step (empty without islands).
  [[nodiscard]] const std::vector<Migration>& migrations() const { return migrations_; }

 private:
  GenerationStats statistics(bool best_changed, double wall_seconds) const;
  /// Exploit guard, after a generation is complete: the best's reference fitness (evaluated once
  /// per genome), recorded in the last history row.
  void check_reference();
  /// fitness_ of every genome in parallel, honouring the stop request (throws Interrupted).
  std::vector<Fitness> evaluate_genomes(const std::vector<Genome>& genomes, const std::string& what);
  /// "select": reference fitness of the elite candidates, which are then ranked by it.
  std::vector<std::size_t> reference_ranked(const std::vector<std::size_t>& order, std::size_t elites);

  std::vector<Genome> ask_initial(int lookahead);
  std::vector<Genome> ask_generation();
  bool tell_initial(const std::vector<Fitness>& fitness);
  bool tell_generation(const std::vector<Fitness>& fitness);

  /// One initial individual being drawn (before generation 0).
  struct InitialSlot {
    Rng rng;
    int tries = 0;
    bool filled = false;
    Individual individual;  ///< its first viable draw; the population exists only once every slot is filled
  };

  std::shared_ptr<const Config> config_;  ///< own copy: the engine outlives no caller state
  std::uint64_t identity_;
  FitnessFunction fitness_;
  FitnessFunction reference_;
  std::shared_ptr<Evaluator> evaluator_;
  std::vector<Migration> migrations_;  // [islands]
  std::vector<Individual> population_;
  std::vector<InitialSlot> slots_;          ///< before generation 0 only
  bool pending_ = false;                    ///< an ask() awaits its tell()
  std::vector<Genome> asked_;               ///< the genomes of that ask()
  std::vector<std::size_t> asked_index_;    ///< their initial slot, or their index in next_
  std::vector<Individual> next_;            ///< the generation being made
  int next_crossovers_ = 0;
  std::vector<GenerationStats> history_;
  int generation_ = -1;  ///< -1 before initialize()
  int stall_ = 0;
  double best_ever_ = -1.0;
  std::int64_t evaluations_ = 0;
  double wall_offset_ = 0.0;
  double started_ = 0.0;
  StopRequest stop_;
};

/// Hash of what defines a run: the config minus its stopping and resource knobs (resumable_keys()),
/// so a resumed run may extend its cap.
[[nodiscard]] std::uint64_t run_identity(const Config& config);
/// The config keys that may change when a run is resumed (caps, budgets, threads, checkpoint interval);
/// every other key is part of run_identity().
[[nodiscard]] const std::vector<std::string>& resumable_keys();
/// Keys added to the config after runs were first checkpointed: at their default value they change
/// nothing, and run_identity() then hashes the config without them, so older runs still resume.
/// A new key whose default keeps today's results belongs here.
[[nodiscard]] const std::vector<std::string>& late_keys();

/// Options of a run on disk (animat_evolve and animat.evolve).
struct RunOptions {
  std::filesystem::path out;           ///< run directory ("" = write nothing)
  bool resume = false;                 ///< continue the run in `out`
  /// Start afresh in `out` even when it holds a run: the run's files (run_file_names()) are removed
  /// once the directory is locked. Contradicts `resume`.
  bool overwrite = false;
  bool quiet = false;
  double progress_interval = 1.0;      ///< seconds between progress lines
  const std::atomic<bool>* stop_flag = nullptr;  ///< set by a signal handler: checkpoint and stop
  /// Polled like StopRequest::poll (on the calling thread, about every 20 ms): true = checkpoint and stop.
  std::function<bool()> stop_poll;
  std::shared_ptr<Evaluator> evaluator;           ///< how to evaluate (evaluator.hpp); null = OpenMP threads
  /// Called after every generation, generation 0 of a new run included; return false to stop
  /// (checkpointed).
  std::function<bool(const GenerationStats&, const Evolution&)> callback;
  /// Called once every check has passed and the run directory is locked, before the first write to it
  /// (animat_evolve shows and removes stopped.txt here, so that a refused command leaves it in place).
  std::function<void()> on_start;
};

/// Another process holds the run directory's lock (RUN/.lock): the message names its pid and host.
struct RunDirectoryBusy : IoError {
  using IoError::IoError;
};
/// The run directory holds a run (a checkpoint, or the files of a run without one) and neither resume
/// nor overwrite was asked for.
struct RunExists : IoError {
  using IoError::IoError;
};

/// The files and folders of a run directory that a run writes (and RunOptions::overwrite removes).
[[nodiscard]] const std::vector<std::string>& run_file_names();

struct RunSummary {
  std::vector<GenerationStats> history;
  Individual best;
  std::string stop_reason;
  std::vector<Individual> population;  ///< the final population
};

/// Runs (or resumes) an evolution, writing config.toml, history.csv, best/ lineage and checkpoints.
/// Everything that can refuse the command is checked before any file is written: the run directory
/// (path length, an existing run, a missing checkpoint), and on resume the checkpoint itself and the
/// settings, which may differ from the run's config.toml only in resumable_keys() (the others are
/// named in the ConfigError). Accepted changes are written to config.toml and noted in resume.log.
/// A stop (stop_flag, stop_poll, or the callback returning false) leaves a checkpoint of the last
/// complete generation; stop_reason is then "interrupted" (history empty if it came before
/// generation 0 was complete, and nothing to resume).
/// `fitness` defaults to swim_fitness(config), and then `reference` to the exploit guard's
/// swim_fitness(reference_config(config)) unless evaluation.reference_check is "off".
RunSummary run_evolution(const Config& config, const RunOptions& options, FitnessFunction fitness = {},
                         FitnessFunction reference = {});

}  // namespace animat
