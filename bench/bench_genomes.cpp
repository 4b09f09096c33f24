// Evaluation cost of given genomes (the speed budget of docs/performance.md): develop + build_body
// + swim at the build's default config (plus --set overrides), as animat_evolve evaluates them.
//
//   build/bench_genomes [--set section.key=value]... [--repeat N] GENOME.json...
//
// A genome file is a genome JSON, or any JSON object with a "genome" member (a lineage file or a
// tests/data/evolved file). Prints one line per genome (median wall ms of N evaluations, fitness)
// and the median over all genomes. The file compiles against older builds of the library too, so
// bench/speed_budget.py can time the previous release on the same genomes in the same run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animat/config.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/physics.hpp"

int main(int argc, char** argv) {
  using namespace animat;
  Config config;
  int repeat = 5;
  std::vector<std::string> files;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--set" && k + 1 < argc) {
      apply_override(config, argv[++k]);
    } else if (a == "--repeat" && k + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++k]));
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr,
                 "usage: bench_genomes [--set section.key=value]... [--repeat N] GENOME.json...\n");
    return 2;
  }
  warm_up_box2d();
  std::vector<double> medians;
  for (const auto& f : files) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    auto j = nlohmann::json::parse(ss.str());
    if (j.contains("genome")) j = j["genome"];
    const Genome g = genome_from_json(j.dump(), config.genome, f);
    std::vector<double> ms;
    double fitness = 0.0;
    for (int r = 0; r < repeat; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const EvaluationResult e = evaluate(g, config);
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      fitness = e.fitness;
    }
    std::sort(ms.begin(), ms.end());
    medians.push_back(ms[ms.size() / 2]);
    std::printf("%s\t%.3f ms\tfitness %.6f\n", f.c_str(), ms[ms.size() / 2], fitness);
  }
  std::sort(medians.begin(), medians.end());
  std::printf("median over %zu genomes: %.3f ms per evaluation\n", medians.size(),
              medians[medians.size() / 2]);
  return 0;
}
