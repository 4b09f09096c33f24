#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evolution.hpp"

namespace animat {
FitnessFunction swim_fitness(const Config&) { throw Error("swim_fitness: evaluate() is not available yet"); }
}  // namespace animat
