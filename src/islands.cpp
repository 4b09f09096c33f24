#include "animat/islands.hpp"
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>

#include "animat/errors.hpp"

namespace animat {

namespace {

// The GA's order (evolution.cpp): viable before non-viable, then higher fitness.
bool fitter(const Individual& a, const Individual& b) {
  if (a.result.viable != b.result.viable) return a.result.viable;
  return a.result.fitness > b.result.fitness;
}

constexpr std::string_view kHeader =
    "generation,island,best,mean,viable_fraction,best_cells,immigrants\n";

std::string row(const IslandStats& s) {
  return fmt::format("{},{},{},{},{},{},{}\n", s.generation, s.island, s.best, s.mean,
                     s.viable_fraction, s.best_cells, s.immigrants);
}

void write_replacing(const std::filesystem::path& path, const std::string& text) {
  // one per process
  const std::filesystem::path tmp = path.string() + "." + std::to_string(::getpid()) + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !(out << text) || !out.flush())
      throw IoError(fmt::format("{}: cannot write", tmp.string()));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw IoError(fmt::format("{}: rename failed: {}", path.string(), ec.message()));
}

}  // namespace

std::size_t IslandLayout::island_of(std::size_t index) const {
  const auto it = std::upper_bound(offsets.begin(), offsets.end(), index);
  return static_cast<std::size_t>(it - offsets.begin()) - 1;
}

IslandLayout island_layout(std::size_t population, int islands) {
  const std::size_t k = static_cast<std::size_t>(std::max(1, islands));
  IslandLayout layout;
  layout.offsets.resize(k + 1, 0);
  for (std::size_t i = 0; i < k; ++i)
    layout.offsets[i + 1] = layout.offsets[i] + population / k + (i < population % k ? 1 : 0);
  return layout;
}

std::string island_config_error(const EvolutionParams& p) {
  if (p.islands <= 1) return {};
  const int smallest = p.population / p.islands;
  if (smallest < 2)
    return fmt::format(
        "evolution.islands = {} leaves fewer than 2 individuals per island (evolution.population = "
        "{})",
        p.islands, p.population);
  if (p.elites >= smallest)
    return fmt::format(
        "evolution.elites = {} (per island) must be smaller than the smallest island ({} of "
        "evolution.population = {} in evolution.islands = {})",
        p.elites, smallest, p.population, p.islands);
  if (2 * p.migrants > smallest || p.elites + p.migrants > smallest)
    return fmt::format(
        "evolution.migrants = {} is too many for the smallest island ({} individuals, "
        "evolution.elites = {}): "
        "at most {} (half an island, and never an elite)",
        p.migrants, smallest, p.elites, std::min(smallest / 2, smallest - p.elites));
  return {};
}

bool is_migration_generation(const EvolutionParams& p, int generation) {
  return p.islands > 1 && p.migrants > 0 && generation > 0 &&
         generation % p.migration_interval == 0;
}

std::vector<std::size_t> island_ranking(const std::vector<Individual>& population,
                                        const IslandLayout& layout, std::size_t k) {
  std::vector<std::size_t> order(layout.size(k));
  std::iota(order.begin(), order.end(), layout.begin(k));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return fitter(population[a], population[b]);
  });
  return order;
}

std::vector<Migration> migrate(std::vector<Individual>& population, const IslandLayout& layout,
                               int migrants, int generation) {
  const std::size_t K = layout.count();
  std::vector<Migration> moves;
  if (K < 2 || migrants <= 0) return moves;
  const auto m = static_cast<std::size_t>(migrants);
  std::vector<std::vector<std::size_t>> ranking(K);
  for (std::size_t k = 0; k < K; ++k) {
    ranking[k] = island_ranking(population, layout, k);
    if (2 * m > ranking[k].size())
      throw Error(
          fmt::format("migrate: {} migrants do not fit island {} of {}", m, k, ranking[k].size()));
  }
  // Every emigrant is copied before any replacement: the best and the worst halves never overlap.
  std::vector<Individual> copies;
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t j = 0; j < m; ++j) copies.push_back(population[ranking[k][j]]);
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t dest = (k + 1) % K;
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t to = ranking[dest][ranking[dest].size() - 1 - j];  // the worst first
      population[to] = copies[k * m + j];
      population[to].tries = 0;
      moves.push_back(Migration{generation, k, dest, ranking[k][j], to});
    }
  }
  return moves;
}

std::vector<IslandStats> island_statistics(const std::vector<Individual>& population,
                                           const IslandLayout& layout, int generation,
                                           int immigrants) {
  std::vector<IslandStats> out;
  for (std::size_t k = 0; k < layout.count(); ++k) {
    IslandStats s;
    s.generation = generation;
    s.island = k;
    s.immigrants = immigrants;
    const auto ranking = island_ranking(population, layout, k);
    const Individual& best = population[ranking.front()];
    s.best = best.result.fitness;
    s.best_cells = best.result.cell_count;
    std::size_t viable = 0;
    double sum = 0.0;
    for (std::size_t i = layout.begin(k); i < layout.end(k); ++i)
      if (population[i].result.viable) {
        ++viable;
        sum += population[i].result.fitness;
      }
    s.viable_fraction = static_cast<double>(viable) / static_cast<double>(layout.size(k));
    s.mean = viable ? sum / static_cast<double>(viable) : 0.0;
    out.push_back(s);
  }
  return out;
}

IslandLog::IslandLog(const std::filesystem::path& run_dir, const EvolutionParams& params)
    : path_(run_dir / "islands.csv"),
      params_(params),
      enabled_(!run_dir.empty() && params.islands > 1) {}

void IslandLog::start(const Evolution& evolution) {
  if (!enabled_) return;
  write_replacing(path_, std::string(kHeader));
  append(evolution);
}

void IslandLog::resume(int generation) {
  if (!enabled_) return;
  std::string kept(kHeader);  // rows written after the checkpoint belong to the lost future
  std::ifstream in(path_, std::ios::binary);
  std::string line;
  for (bool header = true; std::getline(in, line); header = false) {
    int g = -1;
    if (!header && std::sscanf(line.c_str(), "%d,", &g) == 1 && g <= generation)
      kept += line + "\n";
  }
  in.close();
  write_replacing(path_, kept);
}

void IslandLog::append(const Evolution& evolution) {
  if (!enabled_) return;
  const int g = evolution.generation();
  const IslandLayout layout = island_layout(evolution.population().size(), params_.islands);
  std::string text;
  for (const auto& s :
       island_statistics(evolution.population(), layout, g,
                         is_migration_generation(params_, g) ? params_.migrants : 0))
    text += row(s);
  std::ofstream out(path_, std::ios::app | std::ios::binary);
  if (!out || !(out << text) || !out.flush())
    throw IoError(fmt::format("{}: cannot append", path_.string()));
}

}  // namespace animat
