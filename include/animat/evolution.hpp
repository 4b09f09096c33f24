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
#include <type_traits>
#include <vector>

#include "animat/errors.hpp"
#include "animat/evaluation_params.hpp"
#include "animat/evolution_params.hpp"
#include "animat/genome.hpp"
#include "animat/params.hpp"

namespace animat {

struct Config;
/// Whether a fitness and its reference differ by more than both evaluation.reference_tolerance
/// (relative to the reference) and evaluation.reference_abs_tolerance: the exploit guard warns.
[[nodiscard]] bool reference_disagrees(double fitness, double reference,
                                       const EvaluationParams& params);
/// The config of the reference evaluation of the exploit guard: physics.substeps multiplied by
/// evaluation.reference_substeps and evaluation.reference_check "off" (the reference swim has no
/// reference of its own), everything else equal.
[[nodiscard]] Config reference_config(const Config& config);

class Evaluator;  // evaluator.hpp

/// [islands] One migrant (islands.hpp): a copy of population[from] (island from_island) replaced
/// population[to].
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
  bool valid = true;  ///< false if the swim broke an invariant (embedding, collisions); fitness 0
  /// Edge-component steps where drag_scheme "stable" scaled eq. 5 down (0 with every other scheme):
  /// the swim was not integrated as written there.
  long drag_limited = 0;
  /// Coarse class of the body plan (morphology_kind() in body.hpp; 0 if not viable or unknown):
  /// what the morphological innovation protection (evolution.protection_generations) compares.
  int morphology_kind = 0;
  // Measures of the swim (EvaluationResult's fields of the same names; 0 if not viable): what
  // MAP-Elites' descriptors and NSGA-II's criteria read (search.hpp, measures()), so that no
  // genome is developed or swum again to describe it.
  double actuation_work = 0.0;
  double actuation_work_positive = 0.0;
  double actuation_work_absolute = 0.0;
  double max_speed = 0.0;
  // Measures of the body at rest (shape.hpp) and of its oscillators; 0 if not viable.
  double elongation = 0.0;
  int protrusions = 0;
  int symmetric_pair = 0;
  double concavity = 0.0;
  double frequency = 0.0;
  /// Locomotion mode of the swim (EvaluationResult::locomotion: the index in
  /// animat.locomotion.MODES), classified only when the config's search reads it; -1: not measured.
  int locomotion = -1;
  friend bool operator==(const Fitness&, const Fitness&) = default;
};

/// Fitness's fields with their documentation, in one list: its order is that of the MPI wire
/// (wire.hpp) and of the Python pickle; the Python properties follow it too. A new field: one line.
template <class F, class V>
void visit_fields(F& f, V&& v)
  requires std::is_same_v<std::remove_const_t<F>, Fitness>
{
  v("fitness",
    "The objective's value (the paper's: distance travelled by the centre of mass); 0 if not "
    "viable.",
    f.fitness);
  v("viable", "Development verdict; non-viable genomes are never swum.", f.viable);
  v("stable", "False if the swim was flagged unstable.", f.stable);
  v("cell_count", "Cells of the embryo.", f.cell_count);
  v("valid", "False if the swim broke an invariant (embedding, collisions); its fitness is 0.",
    f.valid);
  v("drag_limited",
    "Edge-component steps where physics.drag_scheme = \"stable\" scaled eq. 5 down (0 with every "
    "other scheme).",
    f.drag_limited);
  v("morphology_kind",
    "Coarse class of the body plan: cell_count * 16 + elongation band (0 if not viable or not "
    "given); evolution.protection_generations protects an offspring whose class differs from its "
    "parents'.",
    f.morphology_kind);
  v("actuation_work", "Net mechanical work of actuation on the springs (0 if not viable).",
    f.actuation_work);
  v("actuation_work_positive",
    "Positive actuation work, per spring and Box2D step: what the actuators spend (0 if not "
    "viable).",
    f.actuation_work_positive);
  v("actuation_work_absolute",
    "Absolute actuation work, per spring and Box2D step (0 if not viable).",
    f.actuation_work_absolute);
  v("max_speed", "Largest cell speed seen in the swim (0 if not viable).", f.max_speed);
  v("elongation", "Elongation of the body at rest (animat.shape; 0 if not viable).", f.elongation);
  v("protrusions", "Protrusions of the body at rest (animat.shape; 0 if not viable).",
    f.protrusions);
  v("symmetric_pair",
    "1 when two protrusions mirror each other about a principal axis, else 0 (animat.shape).",
    f.symmetric_pair);
  v("concavity", "Concavity of the body at rest (animat.shape; 0 if not viable).", f.concavity);
  v("frequency", "Median oscillator frequency of the cells (0 if not viable).", f.frequency);
  v("locomotion",
    "Locomotion mode of the swim, the index in animat.locomotion.MODES (0 undulation ... 5 none), "
    "classified during the evaluation's own swim when the config's search reads it "
    "(search.descriptors or search.objectives name \"locomotion\"); -1 when not measured.",
    f.locomotion);
}

struct EvaluationResult;  // evaluate.hpp

/// What the searches know of an evaluation: its Fitness fields copied from the EvaluationResult
/// (the fitness, the verdicts, the cell count, the morphology kind and the swim's measures). The
/// one conversion: swim_fitness's and every other evaluator's.
[[nodiscard]] Fitness fitness_of(const EvaluationResult& result);

/// Deterministic, thread-safe fitness of a genome. The real one develops and swims (swim_fitness);
/// tests plug in cheap stubs.
using FitnessFunction = std::function<Fitness(const Genome&)>;

class Objective;

/// genome → development → body → swim, per `config` (see evaluate.hpp), scored by the config's
/// objective (evaluation.objective; objective.hpp).
[[nodiscard]] FitnessFunction swim_fitness(const Config& config);
/// The same chain scored by `objective` (e.g. a Python callable) instead of the config's.
[[nodiscard]] FitnessFunction objective_fitness(const Config& config,
                                                std::shared_ptr<const Objective> objective);

/// What a fitness function reads of a genome, as bytes: genomes with equal keys get equal Fitness
/// (and equal reference fitness), so the GA evaluates one of them and copies the result. Empty:
/// the whole genome (any deterministic fitness function).
using GenomeKey = std::function<std::string(const Genome&)>;

/// The key of swim_fitness and objective_fitness under `config`: the genome's network
/// (Grn::network_key) when development reads nothing else of the genome
/// (development.jitter_stream = "fixed"), else empty (the whole genome: under "genome" the
/// placement jitter is seeded by the genome's hash).
[[nodiscard]] GenomeKey evaluation_key(const Config& config);

/// No parent (an initial individual; the second parent of a mutant); Individual::parent_a, _b.
inline constexpr std::int64_t kNoParent = -1;

struct Individual {
  Genome genome;
  Fitness result;
  int tries = 0;  ///< random genomes drawn to find this one (initial population only)
  /// Who it is, for the genealogy: generation of birth × population + its index then (initial
  /// individuals 0 … population − 1). An elite or migrant copy keeps its id.
  std::int64_t id = 0;
  /// Its parents' ids: both for a crossover, parent_a only for a mutant of one parent, neither
  /// (kNoParent) for an initial individual or one restored from a checkpoint without ids.
  std::int64_t parent_a = kNoParent, parent_b = kNoParent;
  /// Fitness at the reference step (the exploit guard, evaluation.reference_check); NaN = not
  /// evaluated.
  double reference = std::numeric_limits<double>::quiet_NaN();
  /// Generations since its lineage's morphology kind (Fitness::morphology_kind) appeared: 0 for an
  /// initial individual and for an offspring of a kind neither parent had; else the age of the
  /// parent of its kind (the younger, if both are) + 1; an elite or unchanged copy ages by 1 per
  /// generation. Under evolution.protection_generations = P, an individual younger than P is
  /// protected from older individuals of other kinds in tournaments.
  int morphology_age = 0;
};

/// One row of history.csv.
struct GenerationStats {
  int generation = 0;
  double best = 0.0;  ///< best fitness in the population (all-time best, thanks to elitism)
  /// Over viable individuals; finite whenever their fitnesses are (no overflow: see finite_mean in
  /// evolution.cpp), so that a checkpoint always holds it.
  double mean = 0.0;
  double median = 0.0;  ///< over viable individuals (finite likewise)
  double viable_fraction = 0.0;
  int best_cells = 0;
  /// cumulative fitness evaluations (swims and non-viable developments)
  std::int64_t evaluations = 0;
  /// cumulative wall time of the run (the only machine-dependent column)
  double wall_seconds = 0.0;
  /// of this generation alone (its evaluations / its wall time)
  double evaluations_per_second = 0.0;
  /// Swims of this generation: its evaluations of viable genomes (a non-viable one is only
  /// developed, hundreds of times cheaper); generation 0: the initial population's.
  int swims = 0;
  /// of this generation alone (its swims / its wall time): the rate the progress line shows
  double swims_per_second = 0.0;
  bool best_changed = false;  ///< the best genome differs from the previous generation's
  int crossovers = 0;         ///< offspring made by crossover in this generation
  /// The best's fitness at the reference step (evaluation.reference_check); NaN when off.
  double best_reference = std::numeric_limits<double>::quiet_NaN();
  /// viable individuals whose swim was unstable or broke an invariant (fitness 0)
  int invalid = 0;
  /// Individuals whose swim the drag limiter altered (drag_scheme "stable" only;
  /// Fitness::drag_limited > 0).
  int drag_limited = 0;
  /// Viable individuals whose morphology is younger than evolution.protection_generations
  /// (Individual::morphology_age < P); 0 without protection.
  int protected_count = 0;
};

/// How a GenerationStats field is stored (its descriptor, visit_fields below).
struct StatsField {
  enum class Checkpoint : std::uint8_t {
    none,      ///< not in a checkpoint (a per-session figure)
    required,  ///< always written; a checkpoint without it is refused
    later,     ///< always written; absent from older checkpoints, where it reads as its default
    /// written only when it holds information (not NaN, not 0); absent reads as its default
    when_set,
  };
  const char* name;
  const char* doc;
  bool csv;  ///< a column of history.csv (columns in visiting order)
  Checkpoint checkpoint;
  /// history.csv: fixed decimals (-1: the shortest form that reads back exactly)
  int decimals = -1;
  /// A column of history.csv only in runs with morphological innovation protection
  /// (evolution.protection_generations > 0), so that every other run writes the file as before
  /// (and its Python history has the dtype it always had).
  bool protection_only = false;
};

/// GenerationStats' fields with their documentation, in history.csv's column order: the one list
/// from which history.csv, a checkpoint's history, the Python class (fields, to_dict, pickling) and
/// animat.HISTORY_DTYPE follow. A new field is one line here.
template <class S, class V>
void visit_fields(S& s, V&& v)
  requires std::is_same_v<std::remove_const_t<S>, GenerationStats>
{
  using C = StatsField::Checkpoint;
  v(StatsField{"generation", "Generation number (0 = the initial population).", true, C::required},
    s.generation);
  v(StatsField{"best", "Best fitness in the population.", true, C::required}, s.best);
  v(StatsField{"mean", "Mean fitness of the viable individuals.", true, C::required}, s.mean);
  v(StatsField{"median", "Median fitness of the viable individuals.", true, C::required}, s.median);
  v(StatsField{"viable_fraction", "Share of viable individuals.", true, C::required},
    s.viable_fraction);
  v(StatsField{"best_cells", "Cells of the best individual.", true, C::required}, s.best_cells);
  v(StatsField{"evaluations", "Cumulative fitness evaluations (swims and non-viable developments).",
               true, C::required},
    s.evaluations);
  v(StatsField{"swims",
               "Swims of this generation: evaluations of viable genomes (a non-viable genome is "
               "only developed); generation 0: the initial population. 0 in rows written before "
               "this column existed.",
               true, C::later},
    s.swims);
  v(
      StatsField{
          "best_reference",
          "The best's fitness at the reference step (evaluation.reference_check); NaN when off.",
          true, C::when_set},
      s.best_reference);
  v(StatsField{"invalid",
               "Viable individuals whose swim was unstable or broke an invariant (fitness 0).",
               true, C::later},
    s.invalid);
  v(StatsField{"drag_limited",
               "Individuals whose swim the drag limiter altered (physics.drag_scheme = \"stable\" "
               "only; 0 otherwise).",
               true, C::when_set},
    s.drag_limited);
  v(StatsField{"protected",
               "Viable individuals whose morphology is younger than "
               "evolution.protection_generations generations (a column only in runs with "
               "protection).",
               true, C::when_set, -1, true},
    s.protected_count);
  // Last column: the only machine-dependent one.
  v(StatsField{"wall_seconds", "Cumulative wall time of the run, seconds.", true, C::required, 3},
    s.wall_seconds);
  v(StatsField{"best_changed", "Whether the best genome changed in this generation.", false,
               C::required},
    s.best_changed);
  v(StatsField{"evaluations_per_second", "Evaluations per second of this generation alone.", false,
               C::none},
    s.evaluations_per_second);
  v(StatsField{"swims_per_second", "Swims per second of this generation alone.", false, C::none},
    s.swims_per_second);
  v(StatsField{"crossovers", "Offspring made by crossover in this generation.", false, C::none},
    s.crossovers);
}

/// Probability that the fitter of two wins a tournament at generation g (linear ramp, paper §5).
[[nodiscard]] double tournament_probability(const EvolutionParams& p, int generation);

/// Index of the tournament winner among two distinct random eligible individuals: the fitter wins
/// with probability p_fitter. With `protection` = P > 0 (evolution.protection_generations), two
/// individuals do not compete when the less fit is younger than P (Individual::morphology_age), of
/// another morphology kind than the fitter and younger than it: the winner is then either, with
/// probability 1/2. The same random numbers are drawn either way; P = 0 is the paper's tournament.
[[nodiscard]] std::size_t tournament(const std::vector<Individual>& population,
                                     const std::vector<std::size_t>& eligible, double p_fitter,
                                     Rng& rng, int protection = 0);

/// A run (or its initial population, or one generation) stopped by a StopRequest before it
/// finished; what was completed before it is kept (see Evolution::initialize and Evolution::step).
struct Interrupted : Error {
  using Error::Error;
};

/// Asks a running evolution to stop early. Checked between evaluations and between the random
/// genomes drawn for the initial population, so a stop is honoured within one evaluation (27 ms at
/// the paper's setting), not only between generations.
struct StopRequest {
  /// set asynchronously (a signal handler, another thread)
  const std::atomic<bool>* flag = nullptr;
  /// Called on the thread that runs the evolution only, about every 20 ms while it works (e.g.
  /// Python's PyErr_CheckSignals with the GIL briefly acquired); returning true stops the run. Must
  /// not throw.
  std::function<bool()> poll;

  [[nodiscard]] bool empty() const { return flag == nullptr && !poll; }
};

/// Calls once, before any parallel region: Box2D's lazily-initialised globals (docs/model.md §4,
/// "Evaluation, determinism, threads").
void prepare_parallel_evaluation();

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
  explicit Evolution(const Config& config, FitnessFunction fitness = {},
                     FitnessFunction reference = {},
                     std::shared_ptr<Evaluator> evaluator = nullptr);

  /// Draws the initial population: random genomes regenerated until viable (ask/evaluate/tell
  /// rounds with speculative draws; the result equals one-at-a-time drawing). Throws Interrupted
  /// (and stays uninitialised) if the stop request fires first.
  void initialize();
  /// Makes and evaluates the next generation; returns its statistics. Throws Interrupted if the
  /// stop request fires before the generation is complete: the state stays at the previous
  /// generation (resuming recomputes the same generation, every random number derives from (seed,
  /// g, i)). Throws Error if the fitness function returns a non-finite fitness, or a negative one
  /// under an objective that is never negative (ObjectiveSpec::nonnegative).
  GenerationStats step();
  /// Checked by initialize() and step() (see StopRequest); empty = never stop.
  void set_stop(StopRequest stop) { stop_ = std::move(stop); }
  /// What the fitness (and reference) function reads of a genome (GenomeKey, evaluation_key()):
  /// an offspring whose key equals that of an individual of the previous generation keeps its
  /// fitness instead of being evaluated, and an elite candidate takes a remembered reference
  /// fitness of an equal key. Empty (the default): only an offspring equal to an evaluated genome
  /// keeps its fitness. Results are the same either way; only the evaluations differ.
  void set_fitness_key(GenomeKey key) { key_ = std::move(key); }

  /// The genomes that need a fitness next, in order. Before generation 0: the next random draw of
  /// every initial slot not yet holding a viable individual (slot i draws from
  /// Rng::derive(seed, initial, i)); with `lookahead` > 1, that many consecutive draws per slot
  /// (speculative: those after a slot's first viable draw are discarded and not counted, so the run
  /// does not depend on it). After that: the offspring of the next generation that are not copies
  /// of an evaluated genome (elites and unchanged copies keep their fitness, as do offspring with
  /// an evaluated genome's key: set_fitness_key; the list may be empty). ask() again before tell()
  /// returns the same genomes.
  std::vector<Genome> ask(int lookahead = 1);
  /// The fitness of every genome of the last ask(), in order. Returns true when this completed a
  /// generation (history().back() holds its statistics). Throws Error for a count mismatch, a value
  /// that the engine's own evaluations refuse (naming its index: a fitness that is not finite, a
  /// negative one under a distance objective, a negative cell_count, drag_limited or
  /// morphology_kind), or an initial slot that used up evolution.max_init_tries. With a reference
  /// fitness function (the exploit guard), a tell that completes a generation with a new best
  /// evaluates its reference here, as step() does; if that throws, the engine is left as before the
  /// tell (the ask still pending).
  bool tell(const std::vector<Fitness>& fitness);
  /// Whether an ask() awaits its tell().
  [[nodiscard]] bool asked() const { return pending_; }
  /// Why the run should stop now ("" = keep going): stall, generation cap or wall-clock budget.
  [[nodiscard]] std::string stop_reason() const;

  [[nodiscard]] int generation() const { return generation_; }
  [[nodiscard]] const std::vector<Individual>& population() const { return population_; }
  /// The first of the fittest by nominal fitness; under evaluation.reference_check = "select", the
  /// first of the best reference fitness among the viable individuals that have one (what selection
  /// trusts).
  [[nodiscard]] const Individual& best() const;
  [[nodiscard]] const std::vector<GenerationStats>& history() const { return history_; }
  [[nodiscard]] int generations_without_improvement() const { return stall_; }
  [[nodiscard]] std::int64_t evaluations() const { return evaluations_; }
  /// Tries per initial individual (paper: "a few hundred").
  [[nodiscard]] std::vector<int> initial_tries() const;

  /// Whole state as JSON text with a checksum; restore() refuses a corrupt or mismatched one, and
  /// one whose content is inconsistent even with a valid checksum (hand-edited): a fitness that is
  /// not finite (and >= 0 under a distance objective), a genome that does not validate or is empty,
  /// a history that does not count 0, 1, ..., generation or whose last row disagrees with the
  /// population, a population of the wrong size, a best_ever or stall counter that the history
  /// contradicts.
  [[nodiscard]] std::string checkpoint() const;
  void restore(std::string_view checkpoint_text, std::string_view source = "checkpoint");

  /// Seconds of wall time consumed before this process (restored from a checkpoint).
  void set_wall_offset(double seconds) { wall_offset_ = seconds; }
  /// [islands] Migrants that arrived at the end of the last step (empty without islands).
  [[nodiscard]] const std::vector<Migration>& migrations() const { return migrations_; }

 private:
  GenerationStats statistics(bool best_changed, double wall_seconds, int swims) const;
  /// Exploit guard, after a generation is complete: the best's reference fitness (evaluated once
  /// per genome), recorded in the last history row.
  void check_reference();
  /// The evaluator's fitness of every genome, honouring the stop request (throws Interrupted), each
  /// checked by fitness_problem.
  std::vector<Fitness> evaluate_genomes(const std::vector<Genome>& genomes,
                                        const std::string& what);
  /// "select": reference fitness of the elite candidates, which are then ranked by it.
  std::vector<std::size_t> reference_ranked(const std::vector<std::size_t>& order,
                                            std::size_t elites);
  /// "select", when a generation is complete: the reference fitness of every island's elite
  /// candidates, so that best() can be the best by reference (the next ask() finds them known).
  void reference_elite_candidates();
  /// A reference fitness this engine computed for an equal genome (or one of equal key_) in the
  /// last completed generation (reference_memo_), or null.
  [[nodiscard]] const double* remembered_reference(const Genome& genome) const;
  /// Keep every reference fitness of the completed generation for the next one's lookups.
  void remember_references();

  std::vector<Genome> ask_initial(int lookahead);
  std::vector<Genome> ask_generation();
  bool tell_initial(const std::vector<Fitness>& fitness);
  bool tell_generation(const std::vector<Fitness>& fitness);

  /// One initial individual being drawn (before generation 0).
  struct InitialSlot {
    Rng rng;
    int tries = 0;
    bool filled = false;
    /// its first viable draw; the population exists only once every slot is filled
    Individual individual;
  };

  std::shared_ptr<const Config> config_;  ///< own copy: the engine outlives no caller state
  std::uint64_t identity_;
  FitnessFunction fitness_;
  FitnessFunction reference_;
  /// runs fitness_ (or the given evaluator); null: ask/tell only
  std::shared_ptr<Evaluator> evaluator_;
  std::shared_ptr<Evaluator> reference_evaluator_;  ///< runs reference_ on this process's threads
  std::vector<Migration> migrations_;               // [islands]
  std::vector<Individual> population_;
  std::vector<InitialSlot> slots_;        ///< before generation 0 only
  bool pending_ = false;                  ///< an ask() awaits its tell()
  std::vector<Genome> asked_;             ///< the genomes of that ask()
  std::vector<std::size_t> asked_index_;  ///< their initial slot, or their index in next_
  std::vector<Individual> next_;          ///< the generation being made
  /// Where each of next_ comes from in population_ (the morphology ages, computed by tell()):
  /// parents (Origin::none: none), and whether it is an elite copy.
  struct Origin {
    static constexpr std::size_t none = static_cast<std::size_t>(-1);
    std::size_t a = none, b = none;
    bool elite = false;
  };
  std::vector<Origin> next_origin_;
  int next_crossovers_ = 0;
  /// The genomes that had a reference fitness when the last generation completed, with it: a
  /// clone of an elite or of an elite candidate is not swum at the reference step again (the
  /// reference is a function of the genome, so the results are the same). Not checkpointed.
  std::vector<std::pair<Genome, double>> reference_memo_;
  GenomeKey key_;  ///< set_fitness_key(); empty: the whole genome
  /// key_ of each genome of reference_memo_ (empty without key_), in its order
  std::vector<std::string> reference_memo_keys_;
  std::vector<GenerationStats> history_;
  int generation_ = -1;  ///< -1 before initialize()
  int stall_ = 0;
  double best_ever_ = -1.0;
  std::int64_t evaluations_ = 0;
  double wall_offset_ = 0.0;
  double started_ = 0.0;
  StopRequest stop_;
};

}  // namespace animat
