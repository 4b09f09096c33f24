// libFuzzer target: evaluate() (development, body, swim) on genomes built from the fuzz bytes.
//
// The first byte picks how the genome is made:
//   '{'   the input is genome JSON (genome_from_json; rejected inputs end there);
//   'R'   the next 8 bytes (little-endian) seed a random genome (as the GA seeds its population), the rest drive up to 8
//         rounds of the GA's mutation operators: the way to reach viable, swimming bodies;
//   else  raw: each element takes its type, sign, channel and coordinates from the bytes.
// The swim is shortened to evaluation.steps = 200 so each input takes milliseconds.
// Failure = a crash, a hang (-timeout), a sanitizer report, any exception (evaluate() of a valid
// genome under a valid config must not throw), or a broken oracle: a finite fitness in
// [0, v_max·T] (docs/reliability.md), 0 when not viable or unstable, at most max_cells cells.
#include <fmt/format.h>
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "fuzz_util.hpp"

namespace {

using namespace animat;

Config fuzz_config() {
  Config c;
  c.evaluation.steps = 200;
  return c;
}

double coordinate(FuzzedDataProvider& in) {
  // Mostly inside the random genomes' range [0, coord_range), sometimes anything finite.
  return in.ConsumeBool() ? in.ConsumeFloatingPointInRange<double>(-2.0, 12.0) : in.ConsumeFloatingPoint<double>();
}

Genome raw_genome(FuzzedDataProvider& in, const Config& c) {
  Genome g;
  g.dimensions = c.genome.dimensions;
  const int n = in.ConsumeIntegralInRange<int>(0, 64);
  for (int i = 0; i < n && in.remaining_bytes() > 0; ++i) {
    Element e;
    e.type = static_cast<ElementType>(in.ConsumeIntegralInRange<int>(0, kElementTypeCount - 1));
    e.sign = in.ConsumeBool() ? 1 : -1;
    e.channel = e.type == ElementType::input    ? in.ConsumeIntegralInRange<int>(0, kInputCount - 1)
                : e.type == ElementType::output ? in.ConsumeIntegralInRange<int>(0, kOutputCount - 1)
                                                : 0;
    for (int k = 0; k < g.dimensions; ++k) e.coords.push_back(coordinate(in));
    g.elements.push_back(std::move(e));
  }
  return g;
}

Genome mutated_genome(std::uint64_t seed, FuzzedDataProvider& in, const Config& c) {
  Rng rng(seed);
  Genome g = random_genome(c.genome, rng);
  const int rounds = in.ConsumeIntegralInRange<int>(0, 8);
  for (int r = 0; r < rounds; ++r) {
    Rng m(in.ConsumeIntegral<std::uint64_t>());
    mutate(g, c.mutation, c.genome, m);
  }
  return g;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const Config config = fuzz_config();
  Genome g;
  if (data[0] == '{') {
    try {
      g = genome_from_json(std::string_view(reinterpret_cast<const char*>(data), size), config.genome, "fuzz");
    } catch (const Error&) {
      return 0;
    }
  } else if (data[0] == 'R') {
    // The seed is read from the front, so a corpus file is 'R' + the seed's 8 little-endian bytes.
    std::uint64_t seed = 0;
    std::memcpy(&seed, data + 1, std::min<std::size_t>(size - 1, 8));
    FuzzedDataProvider in(data + std::min<std::size_t>(size, 9), size - std::min<std::size_t>(size, 9));
    g = mutated_genome(seed, in, config);
  } else {
    FuzzedDataProvider in(data + 1, size - 1);
    g = raw_genome(in, config);
  }
  validate(g, config.genome, "fuzz genome");  // the builders make valid genomes only

  const EvaluationResult r = evaluate(g, config);
  const double h = config.physics.dt / config.physics.substeps;
  const double bound = config.physics.max_step_displacement / h * config.evaluation.steps * config.physics.dt;
  if (!std::isfinite(r.fitness) || r.fitness < 0.0 || r.fitness > bound)
    fuzz::fail(fmt::format("fitness {} outside [0, {}]", r.fitness, bound));
  if (!r.viable && r.fitness != 0.0) fuzz::fail(fmt::format("non-viable genome with fitness {}", r.fitness));
  if (!r.stable && r.fitness != 0.0) fuzz::fail(fmt::format("unstable swim with fitness {}", r.fitness));
  if (r.cell_count > config.development.max_cells) fuzz::fail(fmt::format("{} cells", r.cell_count));
  return 0;
}
