#pragma once
// [evaluation] section of the config: how an evaluation is run and scored. Data only (no code), so
// that the evaluation layer and the config see it without the GA (evolution.hpp).
#include <string>
#include <string_view>
#include <vector>

#include "animat/objective_table.hpp"
#include "animat/params.hpp"

namespace animat {

inline constexpr std::string_view kReferenceCheckNames[] = {"record", "select", "off"};
inline constexpr std::string_view kPushCellNames[] = {"all", "front"};
inline constexpr std::string_view kRepeatStatisticNames[] = {"mean", "min"};

/// How an evaluation is run and scored: the swim horizon, the objective (objective.hpp), the
/// invariants checked, and the exploit guard.
struct EvaluationParams {
  int steps = 4000;  ///< swim steps at physics.dt [paper: 4000 or 8000]
  /// A built-in objective (kObjectives) or "python:NAME" (a Python callable).
  std::string objective = "distance";
  std::vector<double> direction = {1.0, 0.0};  ///< speed_toward's direction (normalised when used)
  /// Check the body's planar embedding after every step (no region inverted, the skin simple); a
  /// swim that breaks it is invalid and gets fitness 0, like an unstable one.
  bool check_embedding = true;
  /// "record": each time the GA's best changes, re-evaluate it with physics.substeps multiplied by
  /// reference_substeps (the same horizon at a finer step) and record both fitnesses; "select": the
  /// same, and elites are ranked by the reference fitness; "off".
  std::string reference_check = "record";
  int reference_substeps = 16;            ///< refinement factor of the reference evaluation
  double reference_tolerance = 0.01;      ///< relative fitness difference that is warned about...
  double reference_abs_tolerance = 0.05;  ///< ...when it also exceeds this many length units
  /// Control steps simulated before the fitness clock starts, with actuation off (the crawl world:
  /// the body settles onto the ground); 0 = none, today's swims bit for bit (docs/worlds.md).
  int settle_steps = 0;
  /// λ of distance_minus_energy: distance − λ·(positive actuation work) [choose: docs/worlds.md; a
  /// 20-generation d_N = 2 best swims 12.8 for W⁺ = 6.5e4, so λ = 1e-4 weighs both alike]
  double energy_weight = 1e-4;
  /// W₀ of distance_per_energy: distance / (positive actuation work + W₀) [choose: docs/worlds.md;
  /// of the order of a swimmer's W⁺, so that barely moving bodies do not win on the ratio]
  double energy_offset = 1e4;
  // Directional tasks and disruption (docs/control.md).
  /// objective chemotaxis: swims per evaluation, one per source direction [choose]
  int source_directions = 4;
  /// objective chemotaxis: seed of the source directions (the same for every genome) [choose]
  int source_seed = 1;
  /// control step (from the fitness clock's start) of a push; -1 = none
  int push_step = -1;
  std::vector<double> push_impulse = {0.0, 0.0};  ///< impulse [Jx, Jy] given to every pushed cell
  std::string push_cells = "all";  ///< pushed cells: all, or front (x >= the centre of mass's x)
  /// Keep the energy books of every swim (EvaluationResult::energy): slower, results unchanged.
  bool energy_accounting = false;
  /// Swims per evaluation of the one developed body (1 = the paper's one swim, bit for bit): repeat
  /// 0 from the unperturbed start, repeat j >= 1 with every cell's start displaced by
  /// repeat_perturbation (start_perturbation() in evaluate.hpp); the fitness is repeat_statistic of
  /// the objective over the repeats [not in the paper: chaotic bodies, docs/regime.md]
  int repeats = 1;
  /// Length of every cell's start displacement in repeats j >= 1, length units (a cell diameter is
  /// 1) [not in the paper]
  double repeat_perturbation = 1e-6;
  /// How the K repeats' values make the fitness: "mean", or "min" (the worst repeat, which ranks a
  /// chaotic gait by its bad case, so that selection prefers gaits that do not depend on chance)
  /// [not in the paper]
  std::string repeat_statistic = "mean";
};

template <class V>
void visit_fields(EvaluationParams& p, V&& v) {
  v(FieldInfo{"steps", "swim steps per evaluation [paper: 4000, or 8000]",
              Bounds::closed(0, 10000000)},
    p.steps);
  v(FieldInfo{"objective", objective_field_doc(), Bounds::any(), kObjectiveChoices, Identity::late},
    p.objective);
  v(FieldInfo{"direction",
              "direction [x, y] of speed_toward (normalised; not both 0)",
              Bounds::closed(-kMaxLength, kMaxLength),
              {},
              Identity::late},
    p.direction);
  v(FieldInfo{"check_embedding",
              "check after every step that no region is inverted and the skin is a simple polygon; "
              "a swim that breaks it gets fitness 0",
              Bounds::any()},
    p.check_embedding);
  v(FieldInfo{"reference_check",
              "exploit guard: re-evaluate each new best at a finer step and record both fitnesses "
              "(record), also rank elites by it (select), or off",
              Bounds::any(), kReferenceCheckNames},
    p.reference_check);
  v(FieldInfo{"reference_substeps",
              "the reference evaluation uses physics.substeps times this (dt/16 by default)",
              Bounds::closed(1, 1024)},
    p.reference_substeps);
  v(FieldInfo{"reference_tolerance",
              "warn when the best's fitness and its reference differ by more than this fraction...",
              Bounds::upto(1e6)},
    p.reference_tolerance);
  v(FieldInfo{"reference_abs_tolerance", "...and by more than this many length units",
              Bounds::upto(kMaxLength)},
    p.reference_abs_tolerance);
  v(FieldInfo{"settle_steps",
              "control steps simulated with actuation off before the fitness clock starts (crawl "
              "world: the body settles onto the ground; docs/worlds.md); 0 = none",
              Bounds::closed(0, 10000000),
              {},
              Identity::late},
    p.settle_steps);
  v(FieldInfo{"energy_weight",
              "lambda of objective distance_minus_energy: distance - lambda * positive actuation "
              "work, length per energy unit [choose]",
              Bounds::upto(1e6),
              {},
              Identity::late},
    p.energy_weight);
  v(FieldInfo{"energy_offset",
              "W0 of objective distance_per_energy: distance / (positive actuation work + W0), "
              "energy units, > 0 [choose]",
              Bounds::positive_upto(1e12),
              {},
              Identity::late},
    p.energy_offset);
  v(FieldInfo{"source_directions",
              "objective chemotaxis: swims per evaluation, each with scene.chemical_source rotated "
              "to a random direction; fitness = mean progress toward the source (docs/control.md) "
              "[choose]",
              Bounds::closed(1, 64),
              {},
              Identity::late},
    p.source_directions);
  v(
      FieldInfo{
          "source_seed",
          "objective chemotaxis: seed of the source directions, the same for every genome [choose]",
          Bounds::closed(0, 2147483647),
          {},
          Identity::late},
      p.source_seed);
  v(FieldInfo{"push_step",
              "disruption: control step (from the fitness clock's start) at which the pushed cells "
              "get push_impulse; -1 = never (docs/control.md)",
              Bounds::closed(-1, 10000000),
              {},
              Identity::late},
    p.push_step);
  v(FieldInfo{"push_impulse",
              "disruption: impulse [Jx, Jy] given to every pushed cell (velocity change impulse / "
              "cell_mass), mass * length / time",
              Bounds::closed(-kMaxCoefficient, kMaxCoefficient),
              {},
              Identity::late},
    p.push_impulse);
  v(FieldInfo{"push_cells",
              "disruption: which cells are pushed: all, or front (x >= the centre of mass's x, a "
              "push that also turns the body)",
              Bounds::any(), kPushCellNames, Identity::late},
    p.push_cells);
  v(FieldInfo{"energy_accounting",
              "keep the energy books of every swim: actuation work in; fluid drag (normal, "
              "tangential), spring damping, collisions and ground out; kinetic and potential "
              "energies stored (include/animat/energy.hpp). Slower; fitness unchanged",
              Bounds::any(),
              {},
              Identity::resumable},
    p.energy_accounting);
  v(FieldInfo{"repeats",
              "swims per evaluation of the one developed body, each scored by the objective; "
              "fitness = their repeat_statistic. Repeat 0 starts unperturbed, repeat j >= 1 with "
              "every cell's "
              "start displaced by repeat_perturbation (docs/model.md, section 5); 1 = the paper's "
              "one swim [not in the paper]",
              Bounds::closed(1, 64),
              {},
              Identity::late},
    p.repeats);
  v(FieldInfo{"repeat_perturbation",
              "repeats > 1: length of every cell's start displacement in repeats j >= 1, in length "
              "units (a cell diameter is 1), (0, 0.1] [not in the paper]",
              Bounds::positive_upto(0.1),
              {},
              Identity::late},
    p.repeat_perturbation);
  v(FieldInfo{"repeat_statistic",
              "repeats > 1: the fitness is the repeats' mean, or their min (the worst repeat: "
              "selection then prefers gaits whose distance does not depend on chance) [not in the "
              "paper]",
              Bounds::any(), kRepeatStatisticNames, Identity::late},
    p.repeat_statistic);
}

}  // namespace animat
