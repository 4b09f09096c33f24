// Evaluation benchmarks (docs/performance.md): the cost of one fitness evaluation at the paper
// setting (the embedded default config: 400 development steps, up to 32 cells, 4000 swim steps),
// split into its stages, on random viable genomes drawn at fixed seeds; and the cost of a random
// try (development of a random genome, viable or not), which is what seeding generation 0 costs.
//
//   build/bench_evaluation --benchmark_out=bench_evaluation.csv --benchmark_out_format=csv
//
// bench/run_benchmarks.sh runs it with the other benchmarks and writes docs/performance tables.
// Instruction counts (reproducible on a shared machine):
//   valgrind --tool=callgrind --toggle-collect='benchmark::RunSpecifiedBenchmarks*'
//            build/bench_evaluation --benchmark_filter='^BM_Evaluate$' --benchmark_min_time=0.01
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "bench_context.hpp"

namespace {

using namespace animat;

constexpr int kGenomes = 8;  // viable genomes each benchmark cycles through

struct Sample {
  Config config;
  std::vector<Genome> genomes;
  std::vector<Embryo> embryos;
  std::vector<Body> bodies;
  long tries = 0;  // random genomes developed to find kGenomes viable ones
};

/// The first kGenomes viable random genomes of seeds 0, 1, 2, ... (Rng(seed), default config).
const Sample& sample() {
  static const Sample s = [] {
    Sample out;
    warm_up_box2d();
    for (std::uint64_t seed = 0; static_cast<int>(out.genomes.size()) < kGenomes; ++seed) {
      if (seed > 1000000) throw std::runtime_error("bench_evaluation: no viable random genomes");
      Rng rng(seed);
      Genome g = random_genome(out.config.genome, rng);
      ++out.tries;
      Embryo e = develop(g, out.config.genome, out.config.grn, out.config.development);
      if (!e.viable) continue;
      Body b;
      try {
        b = build_body(e, out.config.body);
      } catch (const std::exception&) {
        continue;
      }
      out.genomes.push_back(std::move(g));
      out.embryos.push_back(std::move(e));
      out.bodies.push_back(std::move(b));
    }
    return out;
  }();
  return s;
}

void set_counters(benchmark::State& state, const char* rate_name) {
  state.counters[rate_name] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["tries_per_viable"] = static_cast<double>(sample().tries) / kGenomes;
}

/// The whole evaluation: develop + build_body + swim(4000) + fitness.
void BM_Evaluate(benchmark::State& state) {
  const Sample& s = sample();
  std::size_t k = 0;
  for (auto _ : state) {
    EvaluationResult r = evaluate(s.genomes[k++ % kGenomes], s.config);
    benchmark::DoNotOptimize(r.fitness);
  }
  set_counters(state, "per_s");
}
BENCHMARK(BM_Evaluate)->Unit(benchmark::kMillisecond);

/// Development of a viable genome (400 steps, up to 32 cells).
void BM_Develop(benchmark::State& state) {
  const Sample& s = sample();
  std::size_t k = 0;
  for (auto _ : state) {
    Embryo e =
        develop(s.genomes[k++ % kGenomes], s.config.genome, s.config.grn, s.config.development);
    benchmark::DoNotOptimize(e.viable);
  }
  set_counters(state, "per_s");
}
BENCHMARK(BM_Develop)->Unit(benchmark::kMillisecond);

/// Body construction: Delaunay → Gabriel graph → regions → skin → oscillators.
void BM_BuildBody(benchmark::State& state) {
  const Sample& s = sample();
  std::size_t k = 0;
  for (auto _ : state) {
    Body b = build_body(s.embryos[k++ % kGenomes], s.config.body);
    benchmark::DoNotOptimize(b.positions.data());
  }
  set_counters(state, "per_s");
}
BENCHMARK(BM_BuildBody)->Unit(benchmark::kMillisecond);

/// The swim of an evaluation: 4000 control steps and the fitness measurement.
void BM_Swim(benchmark::State& state) {
  const Sample& s = sample();
  std::size_t k = 0;
  for (auto _ : state) {
    SwimResult r =
        swim(s.bodies[k++ % kGenomes], s.config.scene, s.config.physics, s.config.evaluation.steps);
    benchmark::DoNotOptimize(r.distance);
  }
  set_counters(state, "per_s");
}
BENCHMARK(BM_Swim)->Unit(benchmark::kMillisecond);

/// One random try while seeding generation 0: a random genome developed (most are not viable and
/// stop early); viable ones are not swum here.
void BM_RandomTry(benchmark::State& state) {
  const Sample& s = sample();
  std::uint64_t seed = 0;
  long viable = 0;
  for (auto _ : state) {
    Rng rng(seed++);
    Genome g = random_genome(s.config.genome, rng);
    Embryo e = develop(g, s.config.genome, s.config.grn, s.config.development);
    viable += e.viable ? 1 : 0;
  }
  set_counters(state, "per_s");
  // A label, not a counter: the CSV reporter wants the same counters in every benchmark.
  state.SetLabel("viable_fraction=" + std::to_string(static_cast<double>(viable) /
                                                     static_cast<double>(state.iterations())));
}
BENCHMARK(BM_RandomTry)->Unit(benchmark::kMicrosecond);

/// One development step with n cells (the size exponent of docs/performance.md): the GRN of the
/// first sample genome that has morphogen products, n cells placed on a triangular lattice of
/// spacing 1 (as grown cells pack), max_cells = n so that none divides; stepped 50 times before
/// timing. Second argument: development.morphogen_cutoff in tenths (0 = none, the paper's
/// every-pair field).
void BM_DevelopStep(benchmark::State& state) {
  const Sample& s = sample();
  const int n = static_cast<int>(state.range(0));
  std::size_t pick = 0;
  for (std::size_t k = 0; k < s.genomes.size(); ++k)
    if (!Grn(s.genomes[k], s.config.genome).morphogen_units().empty()) {
      pick = k;
      break;
    }
  DevelopmentParams params = s.config.development;
  params.max_cells = n;
  params.morphogen_cutoff = 0.1 * static_cast<double>(state.range(1));
  DevelopmentWorld world(Grn(s.genomes[pick], s.config.genome), s.config.grn, params);
  world.set_symmetry_seed(genome_hash(s.genomes[pick]));
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  for (int i = 0; i < n; ++i) {
    const int row = i / side, col = i % side;
    world.add_cell(DevelopmentWorld::Vec2(col + 0.5 * (row % 2), row * 0.8660254037844386),
                   params.cell_radius, DevelopmentWorld::Vec2(1.0, 0.0));
  }
  for (int k = 0; k < 50; ++k) world.step();
  for (auto _ : state) benchmark::DoNotOptimize(world.step());
  state.counters["cells"] = n;
  state.counters["cutoff"] = params.morphogen_cutoff;
  state.counters["morphogens"] = static_cast<double>(world.grn().morphogen_units().size());
}
BENCHMARK(BM_DevelopStep)
    ->ArgsProduct({{32, 64, 128, 256, 512, 1024}, {0, 40, 80}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  animat::bench::add_context();
  // draw the genomes before any benchmark (and outside callgrind's --toggle-collect window)
  sample();
  benchmark::AddCustomContext("genomes",
                              std::to_string(kGenomes) + " viable random genomes, seeds from 0");
  benchmark::AddCustomContext("tries_per_viable",
                              std::to_string(static_cast<double>(sample().tries) / kGenomes));
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
