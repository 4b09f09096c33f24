#pragma once
// Private helpers of the searches (search.hpp): the checkpoint envelope (checksum, format, version,
// identity), type- and range-checked fields, Fitness and history rows as JSON, the run's stop rule.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/search.hpp"

namespace animat::search_state {

using nlohmann::json;

inline double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// {"checksum", "payload"}: the payload's JSON text and its FNV-1a hash.
std::string seal(const json& payload);
/// The payload of a sealed checkpoint after checking its checksum, format, version and identity
/// (CheckpointError naming `source`).
json unseal(std::string_view text, std::string_view source, std::string_view format, int version,
            std::uint64_t identity);

/// What every search's checkpoint counts: the generation, the evaluations, the exploit guard's
/// evaluations and the wall-clock seconds of the run so far.
struct Counters {
  int generation = -1;
  std::int64_t evaluations = 0, reference_evaluations = 0;
  double wall_seconds = 0.0;
};
/// The payload's head: format, version, identity and the counters.
json payload_head(std::string_view format, int version, std::uint64_t identity, const Counters& c);
/// The counters of a payload, type- and range-checked.
Counters read_counters(const json& payload);

long long int_field(const json& j, const char* key, long long lo, long long hi);
double number_field(const json& j, const char* key);
bool bool_field(const json& j, const char* key);
/// A float that may be NaN (null in JSON).
json nan_or(double x);
double nan_or_number(const json& j, const char* key);

json fitness_to_json(const Fitness& f);
Fitness fitness_from_json(const json& j);

json history_to_json(const std::vector<std::vector<double>>& rows,
                     const std::vector<HistoryColumn>& columns);
std::vector<std::vector<double>> history_from_json(const json& j,
                                                   const std::vector<HistoryColumn>& columns);

[[noreturn]] void inconsistent(std::string_view source, const std::string& what);
/// Refuses a history that does not count 0, 1, ..., generation, or whose last row differs from
/// `expected` (what the engine computes from the restored state, `state` saying what that is; NaN
/// equals NaN).
void check_history(const std::vector<std::vector<double>>& rows, int generation,
                   std::string_view source);
void check_last_row(const std::vector<double>& last, const std::vector<double>& expected,
                    const std::vector<HistoryColumn>& columns, std::string_view state,
                    std::string_view source);

/// Runs `read` (a restore) and turns what it throws for a malformed checkpoint into a
/// CheckpointError naming `source`.
template <class Read>
void reading_checkpoint(std::string_view source, Read&& read) {
  try {
    read();
  } catch (const CheckpointError& e) {
    if (std::string_view(e.what()).starts_with(source)) throw;
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  } catch (const GenomeError& e) {
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  } catch (const json::exception& e) {
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  }
}

/// Why a run of `config` stops at generation g after `wall` seconds ("" = it does not): the
/// generation cap evolution.generations, the wall-clock budget evolution.wall_seconds, or the
/// stall: `stalled` generations without improvement (`improvement` says what that is) reaching
/// evolution.stall_generations.
std::string stop_rule(const Config& config, int generation, double wall, int stalled,
                      std::string_view improvement);

/// Refuses supplied values where the search has no supplied measure (own = 0), and a row count
/// other than one per genome of the last ask().
void check_supplied_rows(std::string_view who, std::size_t own, std::size_t rows,
                         std::size_t genomes);

/// Error of a tell(): "WHO.tell: value K (genome K of the last ask()) is refused: WHAT".
[[noreturn]] void refuse(std::string_view who, std::size_t k, const std::string& what);

/// The reference swims of `genomes` (the exploit guard): the caller's `hook` where it is set
/// (its rows, if any, checked against the `supplied` measures' count), else `reference` on the
/// config's threads (no rows); each fitness checked finite.
Search::ReferenceSwims evaluate_references(const FitnessFunction& reference,
                                           const Search::ReferenceHook& hook, const Config& config,
                                           const std::vector<const Genome*>& genomes,
                                           std::size_t supplied, std::string_view who);

}  // namespace animat::search_state
