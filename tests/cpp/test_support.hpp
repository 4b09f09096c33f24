#pragma once
// Helpers shared by the C++ test files: a cheap GA fitness stub and small file utilities.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

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
