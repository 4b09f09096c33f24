#pragma once
// Islands (evolution.islands = K > 1): the population is cut into K contiguous sub-populations
// that select, keep elites and breed apart; every evolution.migration_interval generations each
// island sends copies of its evolution.migrants best individuals to the next island of a ring
// (k -> k+1 mod K), where they replace the worst. Not in the paper (its future work: protect new
// morphologies from the established ones); off by default (K = 1 is the paper's single population).
//
// Islands are a structure of the GA on rank 0, not of the machines: all islands' offspring are
// evaluated together by whatever evaluator runs the job, so the results never depend on the layout
// (ranks x threads). Every random number still derives from (seed, generation, global index).
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "animat/evolution.hpp"

namespace animat {

struct Config;

/// Island k holds the individuals [offsets[k], offsets[k+1]); sizes differ by at most one (the
/// first population % K islands are one larger).
struct IslandLayout {
  std::vector<std::size_t> offsets;

  [[nodiscard]] std::size_t count() const { return offsets.size() - 1; }
  [[nodiscard]] std::size_t begin(std::size_t k) const { return offsets[k]; }
  [[nodiscard]] std::size_t end(std::size_t k) const { return offsets[k + 1]; }
  [[nodiscard]] std::size_t size(std::size_t k) const { return offsets[k + 1] - offsets[k]; }
  [[nodiscard]] std::size_t island_of(std::size_t index) const;
};

[[nodiscard]] IslandLayout island_layout(std::size_t population, int islands);

/// Cross-field rules of the island keys (sizes, elites and migrants that fit); "" when valid.
[[nodiscard]] std::string island_config_error(const EvolutionParams& p);

/// True when migrants arrive at the end of `generation` (a positive multiple of the interval, K >
/// 1, migrants > 0).
[[nodiscard]] bool is_migration_generation(const EvolutionParams& p, int generation);

/// Indices of island k from the fittest to the least fit (viable first, then fitness; ties by
/// index).
[[nodiscard]] std::vector<std::size_t> island_ranking(const std::vector<Individual>& population,
                                                      const IslandLayout& layout, std::size_t k);

/// Ring migration: every island's `migrants` best (chosen before any replacement) replace the
/// `migrants` worst of the next island. Deterministic; returns what moved, by destination island.
std::vector<Migration> migrate(std::vector<Individual>& population, const IslandLayout& layout,
                               int migrants, int generation);

/// Per-island statistics of one generation, written to RUN_DIR/islands.csv.
struct IslandStats {
  int generation = 0;
  std::size_t island = 0;
  double best = 0.0;
  double mean = 0.0;  ///< over viable individuals
  double viable_fraction = 0.0;
  int best_cells = 0;
  int immigrants = 0;  ///< individuals that arrived at the end of this generation
};

[[nodiscard]] std::vector<IslandStats> island_statistics(const std::vector<Individual>& population,
                                                         const IslandLayout& layout, int generation,
                                                         int immigrants);

/// RUN_DIR/islands.csv: one row per island and generation; written only when evolution.islands > 1
/// and the run has a directory.
class IslandLog {
 public:
  IslandLog(const std::filesystem::path& run_dir, const EvolutionParams& params);
  /// A fresh run: the header and the rows of generation 0.
  void start(const Evolution& evolution);
  /// A resumed run: keeps the rows up to the checkpoint's generation and drops later ones.
  void resume(int generation);
  void append(const Evolution& evolution);
  [[nodiscard]] bool enabled() const { return enabled_; }

 private:
  std::filesystem::path path_;
  EvolutionParams params_;
  bool enabled_ = false;
};

}  // namespace animat
