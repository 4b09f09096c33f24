#pragma once
// [evolution] section of the config: the GA's parameters (evolution.hpp, islands.hpp). Data only
// (no code), so that the config (config.hpp) holds it without the GA itself.
#include <cstdint>

#include "animat/params.hpp"

namespace animat {

struct EvolutionParams {
  std::int64_t seed = 1;                   ///< run seed; every random number derives from it
  int population = 100;                    ///< [paper: 100]
  int elites = 2;                          ///< best individuals copied unchanged [choose]
  double crossover_fraction = 0.2;         ///< share of offspring made by crossover [paper: 0.2]
  double tournament_p_start = 0.8;         ///< p(fitter wins) at generation 0 [paper: 0.8]
  double tournament_p_end = 1.0;           ///< p(fitter wins) after the ramp [paper: 1]
  int tournament_ramp_generations = 1000;  ///< [paper: 1000]
  /// Morphological innovation protection: an individual whose morphology kind is younger than this
  /// many generations is not beaten in a tournament by an older individual of another kind with
  /// probability p, only 1/2 (evolution.hpp, tournament()) [not in the paper; 0 = off]
  int protection_generations = 0;
  int generations = 0;  ///< generation cap; 0 = none
  /// stop after this many generations without improvement [paper: 500]
  int stall_generations = 500;
  double wall_seconds = 0.0;  ///< wall-clock budget; 0 = none
  int threads = 0;            ///< OpenMP threads; 0 = all cores
  int checkpoint_every = 1;   ///< write a checkpoint every k generations
  /// give up seeding one viable individual after this many tries
  int max_init_tries = 1000000;
  // [islands] islands.hpp; 1 = the paper's single population
  /// sub-populations evolving apart [not in the paper; 1 = off]
  int islands = 1;
  int migration_interval = 10;  ///< generations between ring migrations
  int migrants = 1;             ///< best individuals each island sends to the next one
};

template <class V>
void visit_fields(EvolutionParams& p, V&& v) {
  v(FieldInfo{"seed", "run seed", Bounds::non_negative()}, p.seed);
  v(FieldInfo{"population", "population size [paper: 100]", Bounds::closed(2, 100000)},
    p.population);
  v(FieldInfo{"elites", "best individuals copied unchanged into the next generation [choose]",
              Bounds::closed(0, 100000)},
    p.elites);
  v(FieldInfo{"crossover_fraction", "share of each generation made by crossover [paper: 0.2]",
              Bounds::unit()},
    p.crossover_fraction);
  v(FieldInfo{"tournament_p_start",
              "probability that the fitter of 2 wins, at generation 0 [paper: 0.8]",
              Bounds::unit()},
    p.tournament_p_start);
  v(FieldInfo{"tournament_p_end", "probability that the fitter wins after the ramp [paper: 1.0]",
              Bounds::unit()},
    p.tournament_p_end);
  v(FieldInfo{"tournament_ramp_generations", "generations of the linear ramp [paper: 1000]",
              Bounds::closed(0, 100000000)},
    p.tournament_ramp_generations);
  v(FieldInfo{"protection_generations",
              "generations a new morphology (another cell count or elongation band than its "
              "parents') is protected: against a fitter, older individual of another morphology it "
              "wins a tournament with probability 1/2 [not in the paper: 0 = off]",
              Bounds::closed(0, 100000000),
              {},
              Identity::late},
    p.protection_generations);
  v(FieldInfo{"generations",
              "generation cap; 0 = no cap",
              Bounds::closed(0, 100000000),
              {},
              Identity::resumable},
    p.generations);
  v(FieldInfo{"stall_generations",
              "stop after this many generations without improvement [paper: 500]; 0 = never",
              Bounds::closed(0, 100000000),
              {},
              Identity::resumable},
    p.stall_generations);
  v(FieldInfo{"wall_seconds",
              "wall-clock budget in seconds; 0 = none",
              Bounds::upto(1e10),
              {},
              Identity::resumable},
    p.wall_seconds);
  v(FieldInfo{"threads",
              "OpenMP threads; 0 = all cores",
              Bounds::closed(0, 1024),
              {},
              Identity::resumable},
    p.threads);
  v(FieldInfo{"checkpoint_every",
              "write a checkpoint every k generations",
              Bounds::closed(1, 1000000),
              {},
              Identity::resumable},
    p.checkpoint_every);
  v(FieldInfo{"max_init_tries", "tries to find one viable random individual before giving up",
              Bounds::closed(1, 1000000000)},
    p.max_init_tries);
  // [islands] last in the section: run_identity() of a run without islands ignores these lines
  v(FieldInfo{"islands",
              "sub-populations evolving apart with ring migration [not in the paper: 1 = off]",
              Bounds::closed(1, 10000)},
    p.islands);
  v(FieldInfo{"migration_interval", "generations between migrations (islands > 1)",
              Bounds::closed(1, 100000000)},
    p.migration_interval);
  v(FieldInfo{"migrants",
              "best individuals each island copies to the next island of the ring (islands > 1)",
              Bounds::closed(0, 100000)},
    p.migrants);
}

}  // namespace animat
