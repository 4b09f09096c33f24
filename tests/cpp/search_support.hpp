#pragma once
// What the search tests share (search.hpp): a cheap deterministic stub fitness with the measures
// the descriptors and criteria read, histories without their wall-clock column, and checkpoints
// edited by hand (resealed with a valid checksum) or by one digit.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"

namespace animat::test {

/// Deterministic and non-negative; a quarter of the genomes are not viable; distance and work pull
/// apart, so that NSGA-II's front has several members.
inline Fitness search_stub(const Genome& g) {
  Fitness f;
  const std::uint64_t h = genome_hash(g);
  f.viable = h % 4 != 0 && !g.elements.empty();
  if (!f.viable) return f;
  double s = 0.0;
  for (const auto& e : g.elements) s += std::abs(e.coords[0]);
  f.fitness = 10.0 * s / static_cast<double>(g.size());
  f.cell_count = 1 + static_cast<int>(g.size() % 64);
  f.actuation_work_positive = f.fitness * (1.0 + static_cast<double>((h >> 8) % 100) / 50.0);
  f.max_speed = static_cast<double>((h >> 20) % 100) / 10.0;
  return f;
}

// Expects `run` to throw an E whose message holds every one of `parts`.
template <class E = ConfigError>
inline void expect_error(const std::function<void()>& run,
                         std::initializer_list<std::string> parts) {
  try {
    run();
    ADD_FAILURE() << "no error";
  } catch (const E& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

/// History rows without their last column (wall_seconds, the only machine-dependent one).
inline std::vector<std::vector<double>> without_wall(std::vector<std::vector<double>> rows) {
  for (auto& r : rows) r.pop_back();
  return rows;
}

/// history.csv without its last column (wall_seconds).
inline std::string csv_without_wall(const std::string& csv) {
  std::string out, line;
  std::istringstream in(csv);
  while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

/// A checkpoint whose payload `edit` changed, sealed again with a valid checksum.
inline std::string reseal(const std::string& checkpoint,
                          const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json outer = nlohmann::json::parse(checkpoint);
  nlohmann::json payload = nlohmann::json::parse(outer["payload"].get<std::string>());
  edit(payload);
  const std::string body = payload.dump();
  return nlohmann::json{{"checksum", fmt::format("{:016x}", fnv1a(body))}, {"payload", body}}
      .dump();
}

/// Changes one digit of `text` at every `stride`-th character that is one, and counts the changed
/// texts `restore` refuses with a CheckpointError; returns {refused, changed}.
inline std::pair<int, int> refused_digit_changes(
    const std::string& text, std::size_t stride,
    const std::function<void(const std::string&)>& restore) {
  int refused = 0, changed = 0;
  for (std::size_t i = 0; i < text.size(); i += stride) {
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) continue;
    ++changed;
    std::string bad = text;
    bad[i] = bad[i] == '9' ? '0' : static_cast<char>(bad[i] + 1);
    try {
      restore(bad);
    } catch (const CheckpointError&) {
      ++refused;
    }
  }
  return {refused, changed};
}

}  // namespace animat::test
