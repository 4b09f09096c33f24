// libFuzzer target: the checkpoint loader (Evolution::restore).
//
// The first byte picks how the rest reaches restore():
//   0 (mod 3)  as is: the whole checkpoint file (checksum and all);
//   1          as the payload, wrapped with its correct checksum (reaches the content checks);
//   2          as a payload JSON object whose identity (scheme 2), format and version are set to this config's,
//              then wrapped with its checksum (reaches population, genomes and history).
// Failure = a crash, a sanitizer report, an exception other than animat::Error, or a broken oracle:
// an accepted checkpoint is one run_evolution can continue (a non-empty history ending at the
// restored generation >= 0, the configured population), it round-trips through checkpoint(), and the
// engine can step from it.
#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/run.hpp"
#include "animat/run_identity.hpp"
#include "fuzz_util.hpp"

namespace {

using namespace animat;
using nlohmann::json;

Config fuzz_config() {
  Config c;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.seed = 7;
  c.evolution.threads = 1;
  return c;
}

// Cheap and deterministic, like the stub of tests/cpp/test_evolution.cpp.
Fitness stub(const Genome& g) {
  Fitness f;
  f.viable = genome_hash(g) % 4 != 0 && !g.elements.empty();
  if (!f.viable) return f;
  double s = 0.0;  // a mean that cannot overflow: a fitness must be finite and >= 0 (the engine checks)
  for (const auto& e : g.elements) s += e.coords[0] / static_cast<double>(g.size());
  f.fitness = std::abs(s);
  f.cell_count = static_cast<int>(g.size());
  return f;
}

std::string fnv_hex(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return fmt::format("{:016x}", h);
}

/// {"checksum": FNV-1a of body, "payload": body}. Invalid UTF-8 in body is replaced first (JSON
/// strings hold UTF-8 only, and the checksum must be of what restore() will read back).
std::string wrap(std::string body) {
  body = json::parse(json(body).dump(-1, ' ', false, json::error_handler_t::replace)).get<std::string>();
  return json{{"checksum", fnv_hex(body)}, {"payload", body}}.dump();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const Config config = fuzz_config();
  const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::string text;
  switch (data[0] % 3) {
    case 0: text = rest; break;
    case 1: text = wrap(rest); break;
    default: {
      json p = json::parse(rest, nullptr, false);
      if (p.is_discarded() || !p.is_object()) return 0;
      p["identity"] = fmt::format("{:016x}", run_identity(config));
      p["identity_scheme"] = kRunIdentityScheme;
      p["format"] = "animat.checkpoint";
      p["version"] = 1;
      text = wrap(p.dump(-1, ' ', false, json::error_handler_t::replace));
    }
  }
  Evolution evo(config, stub);
  try {
    evo.restore(text, "fuzz");
  } catch (const Error&) {
    return 0;
  }
  if (evo.generation() < 0) fuzz::fail(fmt::format("accepted generation {}", evo.generation()));
  if (evo.history().empty()) fuzz::fail("accepted an empty history");
  if (evo.history().back().generation != evo.generation())
    fuzz::fail(fmt::format("accepted generation {} with a history ending at {}", evo.generation(),
                           evo.history().back().generation));
  if (evo.population().size() != static_cast<std::size_t>(config.evolution.population))
    fuzz::fail("accepted a population of the wrong size");
  for (const auto& ind : evo.population())
    if (!std::isfinite(ind.result.fitness) || ind.result.fitness < 0.0)
      fuzz::fail(fmt::format("accepted a fitness of {}", ind.result.fitness));
  for (std::size_t k = 0; k < evo.history().size(); ++k)
    if (evo.history()[k].generation != static_cast<int>(k)) fuzz::fail("accepted a history that does not count 0, 1, 2, ...");
  const std::string again = evo.checkpoint();
  Evolution copy(config, stub);
  try {
    copy.restore(again, "round trip");
  } catch (const Error& e) {
    fuzz::fail(std::string("checkpoint() of a restored run does not restore: ") + e.what());
  }
  if (copy.checkpoint() != again) fuzz::fail("checkpoint round trip changed the state");
  const GenerationStats s = evo.step();
  if (!std::isfinite(s.best) || !std::isfinite(s.mean) || !std::isfinite(s.median))
    fuzz::fail("non-finite statistics after a step from a restored checkpoint");
  return 0;
}
