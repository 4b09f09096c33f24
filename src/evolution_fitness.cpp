// The GA's real fitness: the whole chain of evaluate.hpp, scored by the config's objective.
#include <memory>
#include <string>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/grn.hpp"
#include "animat/objective.hpp"

namespace animat {

Fitness fitness_of(const EvaluationResult& r) {
  Fitness f{r.fitness, r.viable, r.stable, r.cell_count, r.valid, r.drag_limited};
  f.morphology_kind = r.morphology_kind;
  f.actuation_work = r.actuation_work;
  f.actuation_work_positive = r.actuation_work_positive;
  f.actuation_work_absolute = r.actuation_work_absolute;
  f.max_speed = r.max_speed;
  f.elongation = r.elongation;
  f.protrusions = r.protrusions;
  f.symmetric_pair = r.symmetric_pair;
  f.concavity = r.concavity;
  f.frequency = r.frequency;
  f.locomotion = r.locomotion;
  return f;
}

FitnessFunction swim_fitness(const Config& config) {
  return objective_fitness(config, make_objective(config.evaluation));
}

FitnessFunction objective_fitness(const Config& config,
                                  std::shared_ptr<const Objective> objective) {
  validate(config);
  if (!objective) throw Error("objective_fitness: no objective");
  auto shared = std::make_shared<const Config>(config);
  return [shared, objective = std::move(objective)](const Genome& genome) {
    return fitness_of(evaluate(genome, *shared, *objective));
  };
}

GenomeKey evaluation_key(const Config& config) {
  if (config.development.jitter_stream != "fixed") return {};
  return
      [params = config.genome](const Genome& genome) { return Grn(genome, params).network_key(); };
}

Config reference_config(const Config& config) {
  Config c = config;
  c.physics.substeps = config.physics.substeps * config.evaluation.reference_substeps;
  // The reference swim is not itself guarded: left on, validating it would ask for a reference of
  // the reference (substeps x reference_substeps squared) and refuse every physics.substeps > 3.
  c.evaluation.reference_check = "off";
  return c;
}

}  // namespace animat
