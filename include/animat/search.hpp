#pragma once
// One search interface (ask / tell / checkpoint) and its algorithms: the paper's GA (evolution.hpp,
// adapted unchanged), MAP-Elites over a grid or CVT archive and NSGA-II, chosen by
// search.algorithm.
//
// Design:
// - Search: ask() gives the genomes to evaluate next, tell() takes their Fitness (evolution.hpp) in
//   order. tell() is atomic: it checks every value and evaluates the exploit guard's references
//   before it changes anything, so a refused or interrupted tell leaves the search as it was, its
//   ask still pending. step() is ask, evaluate, tell.
// - Every search evaluates through an Evaluator (evaluator.hpp: OpenMP threads or MPI ranks), and
//   every random number of generation g, offspring i derives from Rng::derive(seed, g, i): a run is
//   bit-identical for any thread or rank count and across checkpoint and resume.
// - Measures: what MAP-Elites' descriptors and NSGA-II's criteria read of an evaluation comes from
//   one table, measures(), of Fitness fields that the evaluation's own swim filled
//   (objective_fitness): no genome is developed or swum again to describe it.
// - Breeding: offspring() is the one variation step of MAP-Elites and NSGA-II (a parent, with
//   probability crossover_fraction a second one and crossover, then mutation), drawn as animat.qd
//   and animat.moo draw it. The GA keeps its own order of draws (tournaments first), which the
//   determinism gate pins.
// - Supplied measures: descriptors and criteria the caller computes (Python's own) are named
//   when the search is made and their values passed to tell(fitness, values), a row per genome.
// - Stopping: the generation cap, the wall-clock budget and the stall (evolution.stall_generations
//   generations without improvement: the GA's best, MAP-Elites' archive, NSGA-II's hypervolume).
// - Checkpoints: JSON text whose payload carries an FNV-1a checksum and the run identity; restore()
//   checks the checksum, format, version and identity, every field's type and range, and that the
//   content is what the engine would have computed (a hand edit with a valid checksum is refused).
// - Sizes: every count that sizes memory (archive cells, batch, population) is bounded, and a
//   bad one is a ConfigError naming the key and value, raised when the search is made, before a
//   run writes any file.
// - The exploit guard (evaluation.reference_check): "record" evaluates each new elite (MAP-Elites)
//   or front member (NSGA-II) again at the reference step; "select" evaluates every candidate
//   there first and compares the reference values, as animat.qd and animat.moo do.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/random.hpp"

namespace animat {

struct Config;
class Evaluator;

// ---------------------------------------------------------------------------------------------------
// Measures

/// A number read from one evaluation's Fitness: a descriptor of MAP-Elites or a criterion of
/// NSGA-II.
struct Measure {
  const char* name;
  const char* meaning;
  /// The range of a descriptor (a grid over [lo, hi)); lo == hi: a criterion only.
  double lo, hi;
  bool maximize;  ///< the criterion's default sense
  double (*of)(const Fitness&);
};

/// The measures, in table order. "fitness" is the config's evaluation.objective, which may also be
/// named by its own name (e.g. "distance" when evaluation.objective = "distance").
[[nodiscard]] std::span<const Measure> measures();
/// The measure `name` under `config`; ConfigError naming `key` (e.g. "search.descriptors") and the
/// name when there is none, listing the names there are.
[[nodiscard]] const Measure& find_measure(std::string_view name, const Config& config,
                                          std::string_view key);

/// Measures whose values the caller computes and passes to tell (MapElites' supplied descriptors,
/// Nsga2's supplied criteria): their names, and measures without a function (`of` is null) that
/// the archive or the criteria point to. Not copyable (the measures point into the names); a
/// search shares its one.
struct SuppliedMeasures {
  /// ConfigError unless every name is one of `allowed` (the entries of the config key `key`) and
  /// is listed once.
  /// A name of the measures table under `config` (find_measure) keeps its range and sense.
  SuppliedMeasures(std::vector<std::string> names, const std::vector<std::string>& allowed,
                   std::string_view key, const Config& config);
  SuppliedMeasures(const SuppliedMeasures&) = delete;
  SuppliedMeasures& operator=(const SuppliedMeasures&) = delete;
  /// The position of `m` in `names` (m one of `measures`).
  [[nodiscard]] std::size_t index_of(const Measure* m) const {
    return static_cast<std::size_t>(m - measures.data());
  }
  [[nodiscard]] const Measure* find(std::string_view name) const;
  /// Every supplied value computed by the measures table from a swim's Fitness, when every name is
  /// a table measure: a checkpoint of a search that measured them itself (animat_evolve's) holds
  /// no supplied values, and these are the ones its caller would have supplied.
  [[nodiscard]] std::optional<std::vector<double>> from_table(const Fitness& f) const;

  std::vector<std::string> names;
  std::vector<Measure> measures;
  std::vector<const Measure*> table;  ///< each name's table measure, or null
};

/// The exactly rounded sum of `values` (Python's math.fsum): the QD-score and the hypervolume do
/// not depend on the order of their terms.
[[nodiscard]] double exact_sum(std::span<const double> values);

// ---------------------------------------------------------------------------------------------------
// NSGA-II's pieces, on plain values (every objective minimised: negate the maximised ones)

/// Whether a is no worse than b in every objective and better in one.
[[nodiscard]] bool dominates(std::span<const double> a, std::span<const double> b);
/// The fronts of `points` (rows of equal length), best first, each listing row indices in
/// increasing order (Deb et al.'s fast non-dominated sort; equal points share a front).
[[nodiscard]] std::vector<std::vector<std::size_t>> non_dominated_sort(
    const std::vector<std::vector<double>>& points);
/// Deb et al.'s crowding distance of the points of one front: per objective, a stable sort by
/// value; both ends get infinity and every other point adds (next - previous) / (max - min)
/// (nothing when max = min). One or two points: all infinity.
[[nodiscard]] std::vector<double> crowding_distance(const std::vector<std::vector<double>>& points);
/// The hypervolume that `points` dominate, bounded by `reference` (one or two objectives; points
/// not better than the reference in every objective add nothing). Error for three or more.
[[nodiscard]] double hypervolume(const std::vector<std::vector<double>>& points,
                                 std::span<const double> reference);

// ---------------------------------------------------------------------------------------------------
// The interface

/// One column of a search's history (history.csv): integers are written without a fraction.
struct HistoryColumn {
  std::string name;
  bool integer = false;
};

/// The history columns of a search (history.csv, in order): "map_elites" (no criteria) or
/// "nsga2" (a best_<name> column per criterion, as search.objectives names them); the last is
/// wall_seconds. Error for another algorithm.
[[nodiscard]] std::vector<HistoryColumn> search_history_columns(
    std::string_view algorithm, const std::vector<std::string>& criteria = {});

/// What every search algorithm is (see the design above).
class Search {
 public:
  virtual ~Search() = default;
  /// "ga", "map_elites" or "nsga2" (search.algorithm).
  [[nodiscard]] virtual std::string_view algorithm() const = 0;
  /// The genomes that need a fitness next, in order; again before tell(): the same genomes.
  virtual std::vector<Genome> ask() = 0;
  /// The fitness of every genome of the last ask(), in order; true when a generation completed
  /// (history() has its row). Atomic: throws Error, and changes nothing, for a count mismatch or a
  /// value the search refuses (naming the value's index and what is wrong).
  virtual bool tell(const std::vector<Fitness>& fitness) = 0;
  /// tell() with the values of the measures the caller supplies (supplied()): one row per genome,
  /// in supplied() order, read only for the genomes the search keeps (viable, stable and valid),
  /// whose values must be finite; refused, changing nothing, by the value's index and the
  /// measure's name. A search that supplies none takes no rows.
  virtual bool tell(const std::vector<Fitness>& fitness,
                    const std::vector<std::vector<double>>& supplied);
  /// The names of the measures whose values the caller passes to tell (none by default).
  [[nodiscard]] virtual const std::vector<std::string>& supplied() const;
  /// A generation's evaluation by the caller: the Fitness of every genome, in order.
  using EvaluateHook = std::function<std::vector<Fitness>(const std::vector<Genome>&)>;
  /// The values of the supplied measures of every genome (a row each, in supplied() order).
  using DescribeHook = std::function<std::vector<std::vector<double>>(const std::vector<Genome>&,
                                                                      const std::vector<Fitness>&)>;
  /// ask(), evaluate with the search's evaluator (honouring the stop request: Interrupted), tell(),
  /// until a generation completes.
  void step() { step({}, {}); }
  /// step() with the caller's hooks: `evaluate` replaces the search's evaluator (null: the
  /// evaluator), `describe` gives the supplied values (null: none). What a hook throws stops the
  /// step and leaves the search as it was before its ask.
  void step(const EvaluateHook& evaluate, const DescribeHook& describe);
  /// -1 before the first generation is complete.
  [[nodiscard]] virtual int generation() const = 0;
  [[nodiscard]] virtual std::int64_t evaluations() const = 0;
  /// Why the run should stop now ("" = keep going): the generation cap, the wall-clock budget or
  /// the stall (evolution.stall_generations generations without improvement).
  [[nodiscard]] virtual std::string stop_reason() const = 0;
  [[nodiscard]] virtual std::vector<HistoryColumn> history_columns() const = 0;
  /// One row per generation, in history_columns() order.
  [[nodiscard]] virtual std::vector<std::vector<double>> history() const = 0;
  /// The whole state (no pending ask) as checksummed JSON text; restore() refuses a corrupt,
  /// foreign or inconsistent one (CheckpointError naming `source`).
  [[nodiscard]] virtual std::string checkpoint() const = 0;
  virtual void restore(std::string_view text, std::string_view source) = 0;
  /// Checked between evaluations by step().
  void set_stop(StopRequest stop) { stop_ = std::move(stop); }
  /// The exploit guard's reference swims, computed by the caller: the Fitness of every genome at
  /// the reference step and the supplied measures' values there (a row each, supplied() order;
  /// no rows: the values told at the run's step stand).
  struct ReferenceSwims {
    std::vector<Fitness> fitness;
    std::vector<std::vector<double>> supplied;
  };
  using ReferenceHook = std::function<ReferenceSwims(const std::vector<Genome>&)>;
  /// Replaces the reference swims of the exploit guard (MapElites, Nsga2; the GA: Error) by the
  /// caller's, e.g. criteria that only the caller computes; the guard still runs only where it
  /// did (evaluation.reference_check, and a reference function given: make_search gives one).
  /// What the hook throws leaves the tell changing nothing.
  void set_reference_hook(ReferenceHook hook);

 protected:
  StopRequest stop_;
  std::shared_ptr<Evaluator> evaluator_;
  ReferenceHook reference_hook_;
};

/// The search of config.search.algorithm: `fitness` (default swim_fitness(config)) evaluates on
/// `evaluator` (default: this process's OpenMP threads); `reference` is the exploit guard's
/// (default swim_fitness(reference_config(config)) unless evaluation.reference_check is "off").
/// `supplied`: MAP-Elites' descriptors or NSGA-II's criteria whose values the caller passes to
/// tell (MapElites, Nsga2). `centroids`: a CVT archive's, the caller's (MapElites).
/// Throws ConfigError for [search] settings that cannot run (naming the key and value).
[[nodiscard]] std::unique_ptr<Search> make_search(
    const Config& config, FitnessFunction fitness = {}, FitnessFunction reference = {},
    std::shared_ptr<Evaluator> evaluator = nullptr, const std::vector<std::string>& supplied = {},
    const std::vector<std::vector<double>>& centroids = {});

/// The GA (Evolution) behind the Search interface: the same engine, the same results.
class GaSearch final : public Search {
 public:
  /// `key`: what `fitness` reads of a genome (Evolution::set_fitness_key; empty: the genome).
  GaSearch(const Config& config, FitnessFunction fitness, FitnessFunction reference,
           std::shared_ptr<Evaluator> evaluator, GenomeKey key = {});
  [[nodiscard]] std::string_view algorithm() const override { return "ga"; }
  std::vector<Genome> ask() override;
  bool tell(const std::vector<Fitness>& fitness) override;
  using Search::tell;
  [[nodiscard]] int generation() const override { return evo_.generation(); }
  [[nodiscard]] std::int64_t evaluations() const override { return evo_.evaluations(); }
  [[nodiscard]] std::string stop_reason() const override { return evo_.stop_reason(); }
  [[nodiscard]] std::vector<HistoryColumn> history_columns() const override;
  [[nodiscard]] std::vector<std::vector<double>> history() const override;
  [[nodiscard]] std::string checkpoint() const override { return evo_.checkpoint(); }
  void restore(std::string_view text, std::string_view source) override {
    evo_.restore(text, source);
  }
  [[nodiscard]] const Evolution& evolution() const { return evo_; }

 private:
  Evolution evo_;
};

// ---------------------------------------------------------------------------------------------------
// MAP-Elites

/// An archive holds at most this many cells (search.bins' product, or search.cells).
inline constexpr std::int64_t kMaxArchiveCells = 1000000;
/// The most sample-centroid distances of one Lloyd iteration of cvt_centroids (samples x cells),
/// which keeps its k-means to seconds (animat.qd's MAX_CVT_WORK).
inline constexpr std::int64_t kMaxCvtWork = 2000000000;
/// The key of the random stream of cvt_centroids' samples: Rng::derive(seed, kCvtSamplesKey, 0),
/// with seed = evolution.seed for a search's archive; far above any generation number, so it is
/// no generation's stream.
inline constexpr std::uint64_t kCvtSamplesKey = 0x4356540000000000ULL;  // "CVT"

/// The sample count of a CVT archive: `samples`, or 0 = max(1000, 20 cells) (search.samples).
[[nodiscard]] std::size_t cvt_samples(std::size_t cells, std::size_t samples);
/// ConfigError naming `cells_key` unless 1 <= cells <= kMaxArchiveCells and samples x cells <=
/// kMaxCvtWork (checked in floating point), or naming `samples_key` for fewer samples than cells.
void check_cvt_size(std::size_t dims, std::size_t cells, std::size_t samples,
                    std::string_view cells_key, std::string_view samples_key);
/// The centroids of a CVT archive in the unit cube, as animat.qd.CVTArchive computes them from its
/// samples: cvt_samples(cells, samples) points of [0, 1)^dims drawn from Rng::derive(seed,
/// kCvtSamplesKey, 0) (uniform(), row by row); the first `cells` start Lloyd's k-means; each
/// iteration assigns every sample to its nearest centroid (nearest_centroid) and moves each
/// centroid to the mean of its samples (summed in sample order; a centroid without samples stays),
/// until the assignment is unchanged or after `iterations`. Sizes as check_cvt_size.
[[nodiscard]] std::vector<std::vector<double>> cvt_centroids(std::size_t dims, std::size_t cells,
                                                             std::uint64_t seed,
                                                             std::size_t samples = 0,
                                                             int iterations = 100);
/// The centroid nearest to `point` (squared Euclidean distance, summed over the dimensions in
/// order); the lowest index among equals.
[[nodiscard]] std::size_t nearest_centroid(std::span<const double> point,
                                           const std::vector<std::vector<double>>& centroids);

/// One elite of an archive.
struct Elite {
  Genome genome;
  Fitness result;
  std::vector<double> descriptors;
  /// What the archive compares: the fitness, or under evaluation.reference_check = "select" the
  /// reference fitness.
  double objective = 0.0;
  /// Fitness at the exploit guard's reference step; NaN = not evaluated.
  double reference = std::numeric_limits<double>::quiet_NaN();
  int generation = 0;  ///< the generation that made it
};

/// The range [lo, hi) of an archive's descriptor.
struct Range {
  double lo, hi;
};

/// MAP-Elites' archive over the descriptors, a grid or a centroidal Voronoi tessellation (CVT).
///
/// A grid (search.archive = "grid"): descriptor j is divided into bins[j] equal bins over [lo, hi)
/// (edges lo + k (hi - lo) / bins, the last one hi); a value below lo goes to the first bin, one
/// at or above hi to the last. The cell index is the row-major index of the bins (animat.qd's
/// GridArchive, pyribs's order).
///
/// A CVT (search.archive = "cvt"): a cell per centroid of the unit cube (cvt_centroids); a value is
/// scaled to the unit cube by each descriptor's range ((x - lo) / (hi - lo)), clipped to [0, 1],
/// and belongs to the cell of its nearest centroid (animat.qd's CVTArchive).
class Archive {
 public:
  /// A grid. `ranges`: one per descriptor (search.ranges); empty: each measure's own range.
  /// ConfigError naming search.bins for a count < 1 or a grid of more than kMaxArchiveCells cells,
  /// and naming search.ranges for a count other than one per descriptor or a range that is not
  /// finite lo < hi.
  Archive(std::vector<const Measure*> descriptors, std::vector<int> bins,
          std::vector<Range> ranges = {});
  /// A CVT of `centroids` (rows of the unit cube, one per cell); `ranges` as for a grid.
  /// ConfigError naming `centroids` for a count outside 1..kMaxArchiveCells, a row of another
  /// length than the descriptors' count, or a coordinate that is not a finite number in [0, 1].
  [[nodiscard]] static Archive cvt(std::vector<const Measure*> descriptors,
                                   std::vector<Range> ranges,
                                   std::vector<std::vector<double>> centroids);
  /// "grid" or "cvt".
  [[nodiscard]] std::string_view kind() const { return centroids_.empty() ? "grid" : "cvt"; }
  [[nodiscard]] std::size_t cells() const { return cells_; }
  [[nodiscard]] std::size_t dims() const { return descriptors_.size(); }
  [[nodiscard]] const std::vector<const Measure*>& descriptors() const { return descriptors_; }
  /// A grid's bins per descriptor (empty for a CVT).
  [[nodiscard]] const std::vector<int>& bins() const { return bins_; }
  /// A CVT's centroids in the unit cube, one row per cell (empty for a grid).
  [[nodiscard]] const std::vector<std::vector<double>>& centroids() const { return centroids_; }
  /// The range of every descriptor, in descriptor order.
  [[nodiscard]] const std::vector<Range>& ranges() const { return ranges_; }
  /// The cell of finite descriptor values.
  [[nodiscard]] std::size_t index_of(std::span<const double> values) const;
  /// Offers a candidate: enters when its cell is empty or its objective is strictly greater than
  /// the elite's. Returns whether it entered.
  bool add(Elite elite);
  [[nodiscard]] const std::map<std::size_t, Elite>& elites() const { return elites_; }
  std::map<std::size_t, Elite>& elites() { return elites_; }
  /// Σ objective over the elites (exact_sum).
  [[nodiscard]] double qd_score() const;
  [[nodiscard]] double coverage() const;
  /// The elite of the greatest objective (the lowest cell among equals); null when empty.
  [[nodiscard]] const Elite* best() const;

 private:
  std::vector<const Measure*> descriptors_;
  std::vector<int> bins_;
  std::vector<Range> ranges_;
  std::vector<std::vector<double>> centroids_;
  std::size_t cells_ = 1;
  /// ConfigError naming `centroids` unless they are a CVT's (Archive::cvt).
  void check_centroids() const;
  std::map<std::size_t, Elite> elites_;
};

/// MAP-Elites (Mouret & Clune 2015) over an Archive of search.descriptors (search.archive: a grid
/// of search.bins, or a CVT of search.cells centroids; ranges search.ranges), as
/// animat.qd.MapElites: generation 0 (and any generation while the archive is empty) asks
/// search.batch random viable genomes (genome i: the first viable draw of
/// Rng::derive(seed, g, i)); later ones search.batch offspring() of elites picked uniformly in cell
/// order. A candidate enters when it is viable, stable and valid and beats its cell's elite.
///
/// Descriptors the caller computes (animat.qd's Python descriptors): the names of
/// search.descriptors listed in `supplied` are not read from the measures table (search.ranges
/// gives their ranges); tell(fitness, supplied) takes their values, one row per genome in
/// `supplied`'s order, and the checkpoint keeps each elite's.
///
/// A CVT archive's centroids are `centroids` when given (the caller's: unit cube, a row per cell),
/// else cvt_centroids(descriptors, search.cells, evolution.seed, search.samples); the checkpoint
/// keeps them and restore() refuses other ones.
class MapElites final : public Search {
 public:
  MapElites(const Config& config, FitnessFunction fitness, FitnessFunction reference,
            std::shared_ptr<Evaluator> evaluator, const std::vector<std::string>& supplied = {},
            const std::vector<std::vector<double>>& centroids = {});
  [[nodiscard]] std::string_view algorithm() const override { return "map_elites"; }
  std::vector<Genome> ask() override;
  bool tell(const std::vector<Fitness>& fitness) override { return tell(fitness, {}); }
  bool tell(const std::vector<Fitness>& fitness,
            const std::vector<std::vector<double>>& supplied) override;
  /// The names of the descriptors the caller supplies, in their rows' order.
  [[nodiscard]] const std::vector<std::string>& supplied() const override {
    return supplied_->names;
  }
  [[nodiscard]] int generation() const override { return generation_; }
  [[nodiscard]] std::int64_t evaluations() const override { return evaluations_; }
  [[nodiscard]] std::string stop_reason() const override;
  [[nodiscard]] std::vector<HistoryColumn> history_columns() const override;
  [[nodiscard]] std::vector<std::vector<double>> history() const override { return history_; }
  [[nodiscard]] std::string checkpoint() const override;
  void restore(std::string_view text, std::string_view source) override;
  [[nodiscard]] const Archive& archive() const { return archive_; }
  [[nodiscard]] int batch() const { return batch_; }

 private:
  [[nodiscard]] std::vector<double> row(int added, int discarded) const;
  [[nodiscard]] int disagreements(const Archive& archive) const;

  std::shared_ptr<const Config> config_;
  std::uint64_t identity_;
  FitnessFunction reference_;
  bool select_ = false;  ///< the exploit guard "select": the archive compares reference fitness
  std::shared_ptr<const SuppliedMeasures> supplied_;  ///< shared by copies
  Archive archive_;
  int batch_;
  int generation_ = -1;
  std::int64_t evaluations_ = 0, reference_evaluations_ = 0;
  double wall_offset_ = 0.0, started_ = 0.0;
  std::vector<std::vector<double>> history_;
  std::optional<std::vector<Genome>> asked_;
};

// ---------------------------------------------------------------------------------------------------
// NSGA-II

/// One member of NSGA-II's population.
struct Solution {
  Genome genome;
  Fitness result;
  /// What the selection compares, one value per criterion (NaN when infeasible), in the
  /// criteria's own units and senses: the measured values (criteria of `result`), or under
  /// evaluation.reference_check = "select" the reference ones.
  std::vector<double> objectives;
  /// The criteria at the exploit guard's reference step (NaN where that swim was not valid); empty
  /// when not evaluated there.
  std::vector<double> reference;
  /// The values of the criteria the caller supplies (Nsga2::supplied() order); empty when none
  /// are supplied or the member is not feasible.
  std::vector<double> supplied;
  int generation = 0;
  bool feasible = false;  ///< viable, stable and valid
  int rank = 0;           ///< its front in the selection (infeasible or a copy: past the last)
  double crowding = 0.0;  ///< its crowding distance there (0 when infeasible or a copy)
};

/// NSGA-II (Deb et al. 2002) over the criteria of search.objectives ("NAME", "NAME:max",
/// "NAME:min"), as animat.moo.Nsga2: generation 0 asks evolution.population random viable genomes;
/// later ones as many offspring() of parents chosen by binary tournament (lower rank, then larger
/// crowding distance, then the first drawn); the next population is Deb's (mu + lambda) selection
/// of parents and candidates, copies and infeasible candidates last.
///
/// Criteria the caller computes (animat.moo's Python criteria): the names of search.objectives
/// listed in `supplied` are not read from the measures table, and their entries must give the
/// sense ("NAME:max" or "NAME:min"); tell(fitness, supplied) takes their values, one row per
/// genome in `supplied`'s order, and the checkpoint keeps each member's. At the exploit guard's
/// reference step a supplied criterion keeps its supplied value (the caller describes the genome;
/// the engine cannot measure it again).
class Nsga2 final : public Search {
 public:
  Nsga2(const Config& config, FitnessFunction fitness, FitnessFunction reference,
        std::shared_ptr<Evaluator> evaluator, const std::vector<std::string>& supplied = {});
  [[nodiscard]] std::string_view algorithm() const override { return "nsga2"; }
  std::vector<Genome> ask() override;
  bool tell(const std::vector<Fitness>& fitness) override { return tell(fitness, {}); }
  bool tell(const std::vector<Fitness>& fitness,
            const std::vector<std::vector<double>>& supplied) override;
  /// The names of the criteria the caller supplies, in their rows' order.
  [[nodiscard]] const std::vector<std::string>& supplied() const override {
    return supplied_->names;
  }
  [[nodiscard]] int generation() const override { return generation_; }
  [[nodiscard]] std::int64_t evaluations() const override { return evaluations_; }
  [[nodiscard]] std::string stop_reason() const override;
  [[nodiscard]] std::vector<HistoryColumn> history_columns() const override;
  [[nodiscard]] std::vector<std::vector<double>> history() const override { return history_; }
  [[nodiscard]] std::string checkpoint() const override;
  void restore(std::string_view text, std::string_view source) override;
  [[nodiscard]] const std::vector<Solution>& population() const { return population_; }
  /// The feasible members of rank 0, ordered by the first criterion, best first (then the next
  /// ..., then population order).
  [[nodiscard]] std::vector<const Solution*> front() const;
  /// The hypervolume's reference point: the worst value of every criterion over the feasible
  /// candidates of the first generation that had any (empty until then).
  [[nodiscard]] const std::vector<double>& reference_point() const { return reference_point_; }
  /// Fixes the reference point instead (one finite value per criterion), before the first
  /// generation; the checkpoint keeps it. Error otherwise.
  void set_reference_point(std::vector<double> point);
  /// The criteria of a member's own swim (the step's, before any reference), NaN when not
  /// feasible.
  [[nodiscard]] std::vector<double> measured(const Solution& s) const {
    return criteria_of(s.result, s.supplied);
  }
  /// The criteria's names, as search.objectives names them, in order.
  [[nodiscard]] const std::vector<std::string>& criteria() const { return names_; }
  /// Whether each criterion is maximised (else minimised), in criteria() order.
  [[nodiscard]] const std::vector<bool>& maximized() const { return maximize_; }

 private:
  /// The criteria of `f` with the supplied values `own` (NaN when `f` is not feasible).
  [[nodiscard]] std::vector<double> criteria_of(const Fitness& f,
                                                std::span<const double> own) const;
  [[nodiscard]] std::vector<double> minimised(const std::vector<double>& values) const;
  /// Under "select": the objectives become the reference criteria (feasible only if finite).
  void compare_reference(Solution& s) const;
  [[nodiscard]] std::vector<Solution> select(std::vector<Solution> pool,
                                             const std::vector<bool>& copy) const;
  [[nodiscard]] std::vector<double> row(const std::vector<Solution>& population,
                                        const std::vector<double>& reference_point, int discarded,
                                        int copies) const;

  std::shared_ptr<const Config> config_;
  std::uint64_t identity_;
  FitnessFunction reference_;
  bool select_ = false;  ///< the exploit guard "select": the selection compares reference criteria
  std::shared_ptr<const SuppliedMeasures> supplied_;  ///< shared by copies
  std::vector<const Measure*> criteria_;
  std::vector<std::string> names_;  ///< as search.objectives names them
  std::vector<bool> maximize_;
  int size_;
  int generation_ = -1;
  std::int64_t evaluations_ = 0, reference_evaluations_ = 0;
  double wall_offset_ = 0.0, started_ = 0.0;
  std::vector<double> reference_point_;  ///< empty until set
  std::vector<Solution> population_;
  std::vector<std::vector<double>> history_;
  std::optional<std::vector<Genome>> asked_;
};

/// The variation step of MAP-Elites and NSGA-II for offspring i of generation g: rng =
/// Rng::derive(seed, g, i); a parent pick(rng); with probability crossover_fraction (rng.uniform()
/// < crossover_fraction) a second pick(rng) and crossover; then mutation, all from rng.
[[nodiscard]] Genome offspring(const Config& config, std::uint64_t seed, int g, std::size_t i,
                               double crossover_fraction,
                               const std::function<const Genome&(Rng&)>& pick);

/// The first viable genome drawn from `rng` (Genome.random_viable): developed only; Error after
/// evolution.max_init_tries draws.
[[nodiscard]] Genome random_viable_genome(const Config& config, Rng& rng);

}  // namespace animat
