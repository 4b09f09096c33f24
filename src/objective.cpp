// The built-in objectives and the evaluation record they read (objective.hpp).
#include "animat/objective.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"

namespace animat {

namespace objective_values {
// The paper's objective; evaluate() has computed it (0 for an unstable or invalid swim).
double distance(const SwimOutcome& o, const EvaluationParams&) { return o.distance; }

// Distance in body lengths: favours fast small bodies over merely big ones.
double distance_per_size(const SwimOutcome& o, const EvaluationParams&) {
  return o.body_length > 0.0 ? o.distance / o.body_length : 0.0;
}

// Displacement · d / time: a body swimming backwards scores below one that stays put.
double speed_toward(const SwimOutcome& o, const EvaluationParams& p) {
  if (!(o.duration > 0.0)) return 0.0;
  const double norm = std::hypot(p.direction[0], p.direction[1]);
  return (o.dx * (p.direction[0] / norm) + o.dy * (p.direction[1] / norm)) / o.duration;
}

// Either direction, like the paper's distance; vertical motion (falling) does not count.
double distance_x(const SwimOutcome& o, const EvaluationParams&) { return std::abs(o.dx); }

double distance_minus_energy(const SwimOutcome& o, const EvaluationParams& p) {
  return o.distance - p.energy_weight * o.actuation_work_positive;
}

// The offset W0 > 0 keeps a body that barely works from scoring a ratio of round-off.
double distance_per_energy(const SwimOutcome& o, const EvaluationParams& p) {
  return o.distance / (o.actuation_work_positive + p.energy_offset);
}

// evaluate() swims once per source direction and leaves the mean progress in source_progress.
double chemotaxis(const SwimOutcome& o, const EvaluationParams&) { return o.source_progress; }
}  // namespace objective_values

namespace {

std::vector<std::string_view> objective_names() {
  std::vector<std::string_view> out;
  for (const auto& spec : kObjectives) out.push_back(spec.name);
  return out;
}

/// A built-in objective: a row of kObjectives with the evaluation parameters it reads.
class Builtin final : public Objective {
 public:
  Builtin(const ObjectiveSpec& spec, const EvaluationParams& params)
      : spec_(spec), params_(params) {}
  std::string name() const override { return std::string(spec_.name); }
  bool needs_body() const override { return spec_.needs_body; }
  double value(const EvaluationRecord& r) const override {
    SwimOutcome o;
    o.distance = r.result.fitness;  // evaluate() leaves the paper's distance there
    o.dx = r.result.displacement.x();
    o.dy = r.result.displacement.y();
    o.duration = r.result.simulated_time;
    o.body_length = spec_.needs_body ? body_length(r.body) : 0.0;
    o.actuation_work_positive = r.result.actuation_work_positive;
    o.source_progress = r.result.source_progress;
    return spec_.value(o, params_);
  }

 private:
  const ObjectiveSpec& spec_;
  EvaluationParams params_;
};

/// Copies the body and the sampled frames an objective asked for.
class Recorder final : public EvaluationObserver {
 public:
  Recorder(EvaluationRecord& record, bool keep_body) : record_(record), keep_body_(keep_body) {}
  long sample_every() const override { return record_.every; }
  void on_body(const Body& body) override {
    if (keep_body_) record_.body = body;
  }
  void on_sample(const Simulation& sim) override {
    const SwimState& s = sim.state();
    record_.steps.push_back(sim.steps_done());
    record_.times.push_back(sim.time());
    for (int i = 0; i < s.n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      record_.positions.push_back(s.x[u]);
      record_.positions.push_back(s.y[u]);
      record_.velocities.push_back(s.vx[u]);
      record_.velocities.push_back(s.vy[u]);
    }
  }

 private:
  EvaluationRecord& record_;
  bool keep_body_;
};

}  // namespace

std::shared_ptr<const Objective> make_objective(const EvaluationParams& p) {
  if (const ObjectiveSpec* spec = find_objective(p.objective)) {
    validate(p);
    return std::make_shared<Builtin>(*spec, p);
  }
  if (std::string_view(p.objective).starts_with(kPythonObjectivePrefix))
    throw ConfigError(
        fmt::format("evaluation.objective = \"{}\" is a Python objective: run it from Python with "
                    "animat.evolve(config, objective=...) (the C++ engine cannot call it)",
                    p.objective));
  throw ConfigError(fmt::format(
      "evaluation.objective: unknown objective \"{}\" (expected one of {}, or python:NAME)",
      p.objective, fmt::join(objective_names(), ", ")));
}

void validate(const EvaluationParams& p) {
  const std::string_view name = p.objective;
  const bool builtin = find_objective(name) != nullptr;
  if (name.starts_with(kPythonObjectivePrefix)) {
    if (name.size() == kPythonObjectivePrefix.size())
      throw ConfigError(
          "evaluation.objective = \"python:\": a Python objective needs a name (python:NAME)");
  } else if (!builtin) {
    throw ConfigError(fmt::format(
        "evaluation.objective: unknown objective \"{}\" (expected one of {}, or python:NAME)",
        p.objective, fmt::join(objective_names(), ", ")));
  }
  if (p.direction.size() != 2)
    throw ConfigError(
        fmt::format("evaluation.direction: expected 2 numbers [x, y], got {}", p.direction.size()));
  if (!std::isfinite(p.direction[0]) || !std::isfinite(p.direction[1]) ||
      (p.direction[0] == 0.0 && p.direction[1] == 0.0))
    throw ConfigError(fmt::format("evaluation.direction = [{}, {}]: must be finite and not both 0",
                                  p.direction[0], p.direction[1]));
  if (!(p.energy_weight >= 0.0) || !std::isfinite(p.energy_weight))
    throw ConfigError(
        fmt::format("evaluation.energy_weight = {}: must be finite and >= 0", p.energy_weight));
  if (!(p.energy_offset > 0.0) || !std::isfinite(p.energy_offset))
    throw ConfigError(
        fmt::format("evaluation.energy_offset = {}: must be finite and > 0", p.energy_offset));
  if (p.push_impulse.size() != 2)
    throw ConfigError(fmt::format("evaluation.push_impulse: expected 2 numbers [Jx, Jy], got {}",
                                  p.push_impulse.size()));
}

double body_length(const Body& body) {
  const int n = body.node_count();
  if (n == 0) return 0.0;
  double longest = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      longest = std::max(longest, std::hypot(body.positions(j, 0) - body.positions(i, 0),
                                             body.positions(j, 1) - body.positions(i, 1)));
  return longest + 1.0;
}

EvaluationRecord record_evaluation(const Genome& genome, const Config& config, bool keep_body,
                                   long every) {
  if (every < 0)
    throw ConfigError(fmt::format("record_evaluation: every must be >= 0, got {}", every));
  EvaluationRecord record;
  record.every = every;
  if (!keep_body && every == 0) {
    record.result = evaluate(genome, config);
    return record;
  }
  Recorder recorder(record, keep_body);
  record.result = evaluate(genome, config, &recorder);
  return record;
}

namespace {

/// The value of one viable, stable and valid evaluation record; throws Error if not finite.
double finite_value(const Objective& objective, const EvaluationRecord& record) {
  const double v = objective.value(record);
  if (!std::isfinite(v))
    throw Error(fmt::format("objective \"{}\" returned {} (objectives must be finite)",
                            objective.name(), v));
  return v;
}

/// evaluation.repeats > 1: each repeat recorded (its own body copy and trajectory) and scored.
class ObjectiveScorer final : public RepeatScorer {
 public:
  explicit ObjectiveScorer(const Objective& objective)
      : objective_(objective), keep_body_(objective.needs_body()) {}
  EvaluationObserver* observer(int) override {
    record_ = EvaluationRecord{};
    record_.every = objective_.sample_every();
    if (!keep_body_ && record_.every == 0) return nullptr;
    recorder_.emplace(record_, keep_body_);
    return &*recorder_;
  }
  double value(int, const EvaluationResult& result) override {
    record_.result = result;
    return finite_value(objective_, record_);
  }

 private:
  const Objective& objective_;
  bool keep_body_;
  EvaluationRecord record_;
  std::optional<Recorder> recorder_;
};

}  // namespace

EvaluationResult evaluate(const Genome& genome, const Config& config, const Objective& objective) {
  if (config.evaluation.repeats > 1) {
    // Each repeat scored on its own record, the fitness their mean (evaluate_repeats()); a repeat
    // that is unstable or invalid makes the evaluation so, and no objective scores it.
    ObjectiveScorer scorer(objective);
    return evaluate_repeats(genome, config, scorer);
  }
  EvaluationRecord record =
      record_evaluation(genome, config, objective.needs_body(), objective.sample_every());
  // Non-viable genomes are never swum, and an unstable or invalid swim (one that broke the planar
  // embedding or an invariant) is worth nothing whatever the objective: no objective scores them.
  if (!record.result.viable || !record.result.stable || !record.result.valid) {
    record.result.fitness = 0.0;
    return std::move(record.result);
  }
  record.result.fitness = finite_value(objective, record);
  return std::move(record.result);
}

}  // namespace animat
