#pragma once
// Helpers shared by the C++ test files: a cheap GA fitness stub, comparisons of GA runs and small
// file utilities.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "animat/evolution.hpp"

namespace animat::test {

/// Viable for 3 genomes in 4; fitness = mean first coordinate, which mutation can improve.
/// Cheap and deterministic: GA logic is checked in milliseconds.
inline Fitness stub_fitness(const Genome& g) {
  Fitness f;
  f.viable = genome_hash(g) % 4 != 0 && !g.elements.empty();
  if (!f.viable) return f;
  double s = 0.0;
  for (const auto& e : g.elements) s += e.coords[0];
  f.fitness = s / static_cast<double>(g.size());
  f.cell_count = static_cast<int>(g.size());
  return f;
}

/// Every column of two histories that is a result, bit for bit: not the counters of work done
/// (evaluations, swims, their rates, the wall time), which a fitness key (set_fitness_key) lowers,
/// nor the crossovers, which a checkpoint does not keep.
inline void expect_same_results(const std::vector<GenerationStats>& a,
                                const std::vector<GenerationStats>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].generation, b[i].generation);
    EXPECT_EQ(a[i].best, b[i].best) << "generation " << i;
    EXPECT_EQ(a[i].mean, b[i].mean) << "generation " << i;
    EXPECT_EQ(a[i].median, b[i].median) << "generation " << i;
    EXPECT_EQ(a[i].viable_fraction, b[i].viable_fraction) << "generation " << i;
    EXPECT_EQ(a[i].best_cells, b[i].best_cells) << "generation " << i;
    EXPECT_EQ(a[i].best_changed, b[i].best_changed) << "generation " << i;
    EXPECT_EQ(std::isnan(a[i].best_reference), std::isnan(b[i].best_reference));
    if (!std::isnan(a[i].best_reference)) {
      EXPECT_EQ(a[i].best_reference, b[i].best_reference) << "generation " << i;
    }
    EXPECT_EQ(a[i].invalid, b[i].invalid) << "generation " << i;
    EXPECT_EQ(a[i].drag_limited, b[i].drag_limited) << "generation " << i;
    EXPECT_EQ(a[i].protected_count, b[i].protected_count) << "generation " << i;
  }
}

/// The results and the evaluations: the same run.
inline void expect_same_history(const std::vector<GenerationStats>& a,
                                const std::vector<GenerationStats>& b) {
  expect_same_results(a, b);
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    EXPECT_EQ(a[i].evaluations, b[i].evaluations) << "generation " << i;
}

/// Genomes, results and initial tries, individual by individual.
inline void expect_same_population(const std::vector<Individual>& a,
                                   const std::vector<Individual>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].genome == b[i].genome) << "individual " << i;
    EXPECT_EQ(a[i].result, b[i].result) << "individual " << i;
    EXPECT_EQ(a[i].tries, b[i].tries) << "individual " << i;
  }
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void spit(const std::filesystem::path& p, std::string_view text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

/// An empty (removed) path under the temp directory, unique per process and prefix.
inline std::filesystem::path fresh_dir(const std::string& prefix, const std::string& name) {
  auto p =
      std::filesystem::temp_directory_path() / (prefix + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(p);
  return p;
}

}  // namespace animat::test
