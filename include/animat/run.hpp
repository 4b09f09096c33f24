#pragma once
// A run on disk (the run layer): run_evolution() drives an Evolution and keeps its run directory:
// config.toml, history.csv, the best's lineage in best/, checkpoints, resume.log (islands.csv with
// islands), under the directory's lock; run_search() does the same for MAP-Elites and NSGA-II
// (search.hpp): config.toml, history.csv, checkpoints and resume.log.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/search.hpp"

namespace animat {

/// Options of a run on disk (animat_evolve and animat.evolve).
struct RunOptions {
  std::filesystem::path out;  ///< run directory ("" = write nothing)
  bool resume = false;        ///< continue the run in `out`
  /// Start afresh in `out` even when it holds a run: the run's files (run_file_names()) are removed
  /// once the directory is locked. Contradicts `resume`.
  bool overwrite = false;
  bool quiet = false;
  double progress_interval = 1.0;  ///< seconds between progress lines
  /// Prefix of every progress line, "[label] " (several runs in one process); "" = none.
  std::string label;
  const std::atomic<bool>* stop_flag = nullptr;  ///< set by a signal handler: checkpoint and stop
  /// Polled like StopRequest::poll (on the calling thread, about every 20 ms): true = checkpoint
  /// and stop.
  std::function<bool()> stop_poll;
  /// how to evaluate (evaluator.hpp); null = OpenMP threads
  std::shared_ptr<Evaluator> evaluator;
  /// run_evolution: what the given fitness function reads of a genome (Evolution::set_fitness_key;
  /// evaluation_key(config) for swim_fitness and objective_fitness). Ignored when run_evolution
  /// makes the fitness function itself: it then uses evaluation_key(config).
  GenomeKey fitness_key;
  /// Called after every generation, generation 0 of a new run included; return false to stop
  /// (checkpointed).
  std::function<bool(const GenerationStats&, const Evolution&)> callback;
  /// run_search's callback: called after every generation with the search; return false to stop
  /// (checkpointed).
  std::function<bool(const Search&)> search_callback;
  /// run_search: the names of the measures whose values `describe` gives (make_search's
  /// `supplied`: MAP-Elites' descriptors or NSGA-II's criteria).
  std::vector<std::string> supplied;
  /// run_search: evaluates every generation's genomes instead of the evaluator (Search::step's
  /// hook); null = the evaluator.
  Search::EvaluateHook evaluate;
  /// run_search: the supplied values of every genome of a generation (Search::step's hook).
  Search::DescribeHook describe;
  /// run_search: the caller's search, made from the same config (animat.MapElites and animat.Nsga2
  /// run theirs, with their own centroids, reference hook and reference point); null = make_search.
  Search* search = nullptr;
  /// Called once every check has passed and the run directory is locked, before the first write to
  /// it (animat_evolve shows and removes stopped.txt here, so that a refused command leaves it in
  /// place).
  std::function<void()> on_start;
};

/// Another process holds the run directory's lock (RUN/.lock): the message names its pid and host.
struct RunDirectoryBusy : IoError {
  using IoError::IoError;
};
/// The run directory holds a run (a checkpoint, or the files of a run without one) and neither
/// resume nor overwrite was asked for.
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
/// (path length, an existing run, a missing checkpoint), and on resume the checkpoint itself and
/// the settings, which may differ from the run's config.toml only in resumable_keys() (the others
/// are named in the ConfigError). Accepted changes are written to config.toml and noted in
/// resume.log. A resume that its settings stop at once (the generation cap already reached, the
/// stall or the wall budget already spent) writes nothing and returns the run as it is, its
/// stop_reason saying so. A stop (stop_flag, stop_poll, or the callback returning false) leaves a
/// checkpoint of the last complete generation; stop_reason is then "interrupted" (history empty if
/// it came before generation 0 was complete, and nothing to resume). `fitness` defaults to
/// swim_fitness(config), and then `reference` to the exploit guard's
/// swim_fitness(reference_config(config)) unless evaluation.reference_check is "off".
RunSummary run_evolution(const Config& config, const RunOptions& options,
                         FitnessFunction fitness = {}, FitnessFunction reference = {});

/// Throws ConfigError unless config.search.algorithm is "ga": run_evolution runs the GA, and a run
/// directory's config.toml must say which search made it (MAP-Elites and NSGA-II: run_search).
void require_ga(const Config& config);

/// What a run of run_search did.
struct SearchSummary {
  std::string algorithm;
  std::vector<HistoryColumn> columns;
  std::vector<std::vector<double>> history;  ///< one row per generation, in `columns` order
  std::string stop_reason;
  int generation = -1;
};

/// Runs (or resumes) the search of config.search.algorithm ("map_elites" or "nsga2"; search.hpp)
/// in options.out with run_evolution's guarantees: everything that can refuse the command is
/// checked before any file is written (the [search] settings and every size, the run directory,
/// on resume the checkpoint and the settings, [search] included, which may differ from the run's
/// config.toml only in resumable_keys()), the directory is locked for the run's life, and the
/// checkpoint is checksummed and checked on load. Writes config.toml, history.csv (the search's
/// history columns) and checkpoint.json (every evolution.checkpoint_every generations and at the
/// end). RunOptions::search_callback is called after every generation (not callback); on_start
/// before the first write; RunOptions::evaluate and describe evaluate and describe each
/// generation, and what they throw stops the run (propagated; the last checkpoint stays as it
/// was, and a resume continues from it). `fitness` and `reference` as for run_evolution.
SearchSummary run_search(const Config& config, const RunOptions& options,
                         FitnessFunction fitness = {}, FitnessFunction reference = {});

}  // namespace animat
