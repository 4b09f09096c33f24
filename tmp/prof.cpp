#include <cstdio>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include "animat/config.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
using namespace animat;
int main(int argc, char** argv) {
  std::ifstream in(argv[1]); std::stringstream ss; ss << in.rdbuf();
  auto j = nlohmann::json::parse(ss.str());
  Config c = load_config(argv[2]);
  for (int k = 3; k < argc; ++k) apply_override(c, argv[k]);
  Genome g = genome_from_json(j["genome"].dump(), c.genome, "x");
  EvaluationResult r = evaluate(g, c);
  std::printf("fitness %.6f valid %d coll %ld dev %.1f ms swim %.1f ms\n", r.fitness, r.valid, r.collisions, r.seconds_development*1e3, r.seconds_swim*1e3);
}
