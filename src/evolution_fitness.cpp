// The GA's real fitness: the whole chain of evaluate.hpp.
#include <memory>

#include "animat/config.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"

namespace animat {

FitnessFunction swim_fitness(const Config& config) {
  validate(config);
  auto shared = std::make_shared<const Config>(config);
  return [shared](const Genome& genome) {
    const EvaluationResult r = evaluate(genome, *shared);
    return Fitness{r.fitness, r.viable, r.stable, r.cell_count, r.valid};
  };
}

Config reference_config(const Config& config) {
  Config c = config;
  c.physics.substeps = config.physics.substeps * config.evaluation.reference_substeps;
  return c;
}

}  // namespace animat
