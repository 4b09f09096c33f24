#pragma once
// Objectives: what an evaluation is worth to the GA (like pagmo's "problem": a name plus a function
// of the evaluation record to a float). The paper's objective is `distance`; the config selects one
// by name (evaluation.objective) and Python can bring its own callable (named "python:NAME").
//
// The built-ins are the rows of kObjectives (objective_table.hpp); make_objective() wraps one. The
// energy objectives (distance_minus_energy, distance_per_energy) read the positive actuation work
// of the swim (docs/worlds.md).
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "animat/body.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/objective_table.hpp"

namespace animat {

struct Config;
struct EvaluationParams;

/// Everything an objective may look at: the evaluation result (fitness = the paper's distance, and
/// every diagnostic), the body that swam, and its trajectory sampled every `every` control steps
/// (frame 0 is the start; empty when the objective asked for no samples or the genome was not
/// viable). With evaluation.repeats > 1 the objective sees one record per repeat: that repeat's
/// result and trajectory (frame 0 is its displaced start) and the body as built (its rest
/// geometry, the same for every repeat).
struct EvaluationRecord {
  EvaluationResult result;
  Body body;                       ///< empty (0 nodes) when the genome was not viable
  long every = 0;                  ///< sampling of the trajectory, control steps (0 = none)
  std::vector<long> steps;         ///< F control steps of the frames
  std::vector<double> times;       ///< F simulated times
  std::vector<double> positions;   ///< F × n × 2, row-major
  std::vector<double> velocities;  ///< F × n × 2, row-major
  [[nodiscard]] std::size_t frame_count() const { return times.size(); }
};

/// A pluggable objective. value() is only called for viable genomes (a non-viable one scores 0 and
/// is never selected before a viable one); it must be deterministic and thread-safe.
class Objective {
 public:
  virtual ~Objective() = default;
  /// The name evaluation.objective holds for it.
  [[nodiscard]] virtual std::string name() const = 0;
  /// Whether value() reads record.body (otherwise the record's body may stay empty).
  [[nodiscard]] virtual bool needs_body() const { return false; }
  /// Control steps between trajectory frames it needs; 0 = no trajectory.
  [[nodiscard]] virtual long sample_every() const { return 0; }
  /// The objective of one evaluation: larger is better; must be finite.
  [[nodiscard]] virtual double value(const EvaluationRecord& record) const = 0;
};

/// The built-in objective named by params.objective (throws ConfigError for an unknown name, and
/// for a "python:..." name: such a run needs its callable, which only Python can supply).
[[nodiscard]] std::shared_ptr<const Objective> make_objective(const EvaluationParams& params);

/// Checks evaluation.objective (a built-in name or "python:NAME") and evaluation.direction (2
/// finite numbers, not both 0); throws ConfigError naming the key.
void validate(const EvaluationParams& params);

/// Length of a body along its longest axis: the largest distance between two cell centres at rest
/// plus one cell diameter (1 length unit), so a 1-cell body is 1 long. 0 for an empty body.
[[nodiscard]] double body_length(const Body& body);

/// genome -> development -> body -> swim (exactly evaluate()), keeping the body when `keep_body`
/// and the trajectory every `every` control steps (0 = none). The result's fitness is still the
/// paper's distance (with evaluation.repeats > 1 its mean over the repeats, and the trajectory is
/// repeat 0's).
[[nodiscard]] EvaluationRecord record_evaluation(const Genome& genome, const Config& config,
                                                 bool keep_body, long every);

/// evaluate() scored by `objective`: result.fitness = objective.value(record) for a viable genome
/// (0 otherwise). With evaluation.repeats > 1 the objective scores each repeat's record and the
/// fitness is their mean (evaluate_repeats()). For the `distance` objective this is evaluate()
/// itself, bit for bit. Throws Error if the objective returns a non-finite value.
[[nodiscard]] EvaluationResult evaluate(const Genome& genome, const Config& config,
                                        const Objective& objective);

}  // namespace animat
