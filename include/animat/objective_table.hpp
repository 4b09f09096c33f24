#pragma once
// The built-in objectives, one row each: the only list of their names, what each means, its sign
// and how it scores a swim. Config validation (evaluation.objective's choices and doc),
// make_objective(), the sign rule of a fitness (fitness_problem), the CLI's summary, the Python
// bindings (animat.objectives()) and SwimEnv's rewards are all read from this table.
//
// Adding a built-in objective: one row in kObjectives and its value function in src/objective.cpp.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace animat {

struct EvaluationParams;

/// What a built-in objective reads of a swim (evaluate() fills it from the evaluation result;
/// SwimEnv from its episode so far).
struct SwimOutcome {
  /// straight-line distance of the centre of mass, start to end
  double distance = 0.0;
  double dx = 0.0, dy = 0.0;  ///< displacement of the centre of mass
  /// simulated time of the swim (SwimEnv: the episode's horizon)
  double duration = 0.0;
  double body_length = 0.0;              ///< body_length() of the body (read only when needs_body)
  double actuation_work_positive = 0.0;  ///< positive mechanical work of the actuation
  double source_progress = 0.0;          ///< mean progress toward the chemical source (chemotaxis)
};

/// One built-in objective.
struct ObjectiveSpec {
  std::string_view name;     ///< its value of evaluation.objective
  std::string_view meaning;  ///< what it measures, one phrase (docs, the config's comment, the CLI)
  /// every value is >= 0 by construction, so a negative fitness is refused
  bool nonnegative;
  bool needs_body;  ///< reads SwimOutcome::body_length
  /// one swim decides it (else one swim per source direction): SwimEnv can reward it
  bool one_swim;
  /// The objective of a viable, stable and valid swim; larger is better.
  double (*value)(const SwimOutcome&, const EvaluationParams&);
};

namespace objective_values {
double distance(const SwimOutcome&, const EvaluationParams&);
double distance_per_size(const SwimOutcome&, const EvaluationParams&);
double speed_toward(const SwimOutcome&, const EvaluationParams&);
double distance_x(const SwimOutcome&, const EvaluationParams&);
double distance_minus_energy(const SwimOutcome&, const EvaluationParams&);
double distance_per_energy(const SwimOutcome&, const EvaluationParams&);
double chemotaxis(const SwimOutcome&, const EvaluationParams&);
}  // namespace objective_values

inline constexpr ObjectiveSpec kObjectives[] = {
    {"distance", "the paper's: straight-line distance of the centre of mass, start to end", true,
     false, true, objective_values::distance},
    {"distance_per_size", "distance / body length", true, true, true,
     objective_values::distance_per_size},
    {"speed_toward", "signed centre-of-mass speed along evaluation.direction", false, false, true,
     objective_values::speed_toward},
    {"distance_x", "the crawl world's: |horizontal displacement| of the centre of mass", true,
     false, true, objective_values::distance_x},
    {"distance_minus_energy", "distance - energy_weight * positive actuation work", false, false,
     true, objective_values::distance_minus_energy},
    {"distance_per_energy", "distance / (positive actuation work + energy_offset)", true, false,
     true, objective_values::distance_per_energy},
    {"chemotaxis",
     "mean progress toward the chemical source over evaluation.source_directions swims", false,
     false, false, objective_values::chemotaxis},
};

/// evaluation.objective of a run whose objective is a Python callable: "python:" + its name.
inline constexpr std::string_view kPythonObjectivePrefix = "python:";

/// The allowed values of evaluation.objective: every built-in name and "python:*" (a wildcard).
inline constexpr auto kObjectiveChoices = [] {
  std::array<std::string_view, std::size(kObjectives) + 1> out{};
  for (std::size_t i = 0; i < std::size(kObjectives); ++i) out[i] = kObjectives[i].name;
  out.back() = "python:*";
  return out;
}();

/// evaluation.objective's documentation, written from the table.
inline std::string_view objective_field_doc() {
  static const std::string doc = [] {
    std::string out = "what the GA maximises: ";
    for (const auto& spec : kObjectives)
      out.append(spec.name).append(" (").append(spec.meaning).append("); ");
    return out + "python:NAME (a Python callable, set by animat.evolve)";
  }();
  return doc;
}

/// The row of a built-in objective, or nullptr (a "python:" name or an unknown one).
[[nodiscard]] constexpr const ObjectiveSpec* find_objective(std::string_view name) {
  for (const auto& spec : kObjectives)
    if (spec.name == name) return &spec;
  return nullptr;
}

}  // namespace animat
