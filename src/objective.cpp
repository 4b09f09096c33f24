// The built-in objectives and the evaluation record they read (objective.hpp).
#include "animat/objective.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"

namespace animat {
namespace {

/// The paper's objective: straight-line distance of the centre of mass, start to end (0 if unstable).
class Distance final : public Objective {
 public:
  std::string name() const override { return "distance"; }
  double value(const EvaluationRecord& r) const override { return r.result.fitness; }
};

/// Distance in body lengths (body_length()): favours fast small bodies over merely big ones.
class DistancePerSize final : public Objective {
 public:
  std::string name() const override { return "distance_per_size"; }
  bool needs_body() const override { return true; }
  double value(const EvaluationRecord& r) const override {
    const double length = body_length(r.body);
    return length > 0.0 ? r.result.fitness / length : 0.0;
  }
};

/// Mean speed of the centre of mass along a direction: displacement · d / simulated time. Signed: a
/// body swimming backwards scores below one that stays put; an unstable or invalid swim scores 0
/// (evaluate() does not ask the objective then).
class SpeedToward final : public Objective {
 public:
  explicit SpeedToward(const std::vector<double>& direction) {
    const double norm = std::hypot(direction[0], direction[1]);
    dx_ = direction[0] / norm;
    dy_ = direction[1] / norm;
  }
  std::string name() const override { return "speed_toward"; }
  double value(const EvaluationRecord& r) const override {
    if (!r.result.stable || !(r.result.simulated_time > 0.0)) return 0.0;
    return (r.result.displacement.x() * dx_ + r.result.displacement.y() * dy_) / r.result.simulated_time;
  }

 private:
  double dx_ = 1.0, dy_ = 0.0;
};

/// Issue 18: the mean progress toward the chemical source over evaluation.source_directions swims
/// (EvaluationResult::source_progress, computed by evaluate()).
class Chemotaxis final : public Objective {
 public:
  std::string name() const override { return "chemotaxis"; }
  double value(const EvaluationRecord& r) const override { return r.result.source_progress; }
};

/// The crawl world's objective: |horizontal displacement| of the centre of mass, start to end
/// (either direction, like the paper's distance; vertical motion, e.g. falling, does not count).
class DistanceX final : public Objective {
 public:
  std::string name() const override { return "distance_x"; }
  double value(const EvaluationRecord& r) const override { return std::abs(r.result.displacement.x()); }
};

/// The paper's distance minus λ times the positive mechanical work of actuation (evaluation.energy_weight).
class DistanceMinusEnergy final : public Objective {
 public:
  explicit DistanceMinusEnergy(double weight) : weight_(weight) {}
  std::string name() const override { return "distance_minus_energy"; }
  double value(const EvaluationRecord& r) const override {
    return r.result.fitness - weight_ * r.result.actuation_work_positive;
  }

 private:
  double weight_;
};

/// The paper's distance per unit of positive actuation work, distance / (W+ + W0) (W0 =
/// evaluation.energy_offset > 0 keeps a body that barely works from scoring a ratio of round-off).
class DistancePerEnergy final : public Objective {
 public:
  explicit DistancePerEnergy(double offset) : offset_(offset) {}
  std::string name() const override { return "distance_per_energy"; }
  double value(const EvaluationRecord& r) const override {
    return r.result.fitness / (r.result.actuation_work_positive + offset_);
  }

 private:
  double offset_;
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
  if (p.objective == "distance") return std::make_shared<Distance>();
  if (p.objective == "distance_per_size") return std::make_shared<DistancePerSize>();
  if (p.objective == "speed_toward") {
    validate(p);
    return std::make_shared<SpeedToward>(p.direction);
  }
  if (p.objective == "distance_x") return std::make_shared<DistanceX>();
  if (p.objective == "chemotaxis") return std::make_shared<Chemotaxis>();
  if (p.objective == "distance_minus_energy") {
    validate(p);
    return std::make_shared<DistanceMinusEnergy>(p.energy_weight);
  }
  if (p.objective == "distance_per_energy") {
    validate(p);
    return std::make_shared<DistancePerEnergy>(p.energy_offset);
  }
  // Register new built-ins here.
  if (std::string_view(p.objective).starts_with(kPythonObjectivePrefix))
    throw ConfigError(fmt::format("evaluation.objective = \"{}\" is a Python objective: run it from Python with "
                                  "animat.evolve(config, objective=...) (the C++ engine cannot call it)",
                                  p.objective));
  throw ConfigError(fmt::format("evaluation.objective: unknown objective \"{}\" (expected one of {}, or python:NAME)",
                                p.objective, fmt::join(kObjectiveNames, ", ")));
}

void validate(const EvaluationParams& p) {
  const std::string_view name = p.objective;
  const bool builtin = std::find(std::begin(kObjectiveNames), std::end(kObjectiveNames), name) != std::end(kObjectiveNames);
  if (name.starts_with(kPythonObjectivePrefix)) {
    if (name.size() == kPythonObjectivePrefix.size())
      throw ConfigError("evaluation.objective = \"python:\": a Python objective needs a name (python:NAME)");
  } else if (!builtin) {
    throw ConfigError(fmt::format("evaluation.objective: unknown objective \"{}\" (expected one of {}, or python:NAME)",
                                  p.objective, fmt::join(kObjectiveNames, ", ")));
  }
  if (p.direction.size() != 2)
    throw ConfigError(fmt::format("evaluation.direction: expected 2 numbers [x, y], got {}", p.direction.size()));
  if (!std::isfinite(p.direction[0]) || !std::isfinite(p.direction[1]) || (p.direction[0] == 0.0 && p.direction[1] == 0.0))
    throw ConfigError(fmt::format("evaluation.direction = [{}, {}]: must be finite and not both 0", p.direction[0],
                                  p.direction[1]));
  if (!(p.energy_weight >= 0.0) || !std::isfinite(p.energy_weight))
    throw ConfigError(fmt::format("evaluation.energy_weight = {}: must be finite and >= 0", p.energy_weight));
  if (!(p.energy_offset > 0.0) || !std::isfinite(p.energy_offset))
    throw ConfigError(fmt::format("evaluation.energy_offset = {}: must be finite and > 0", p.energy_offset));
  if (p.push_impulse.size() != 2)
    throw ConfigError(fmt::format("evaluation.push_impulse: expected 2 numbers [Jx, Jy], got {}", p.push_impulse.size()));
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

EvaluationRecord record_evaluation(const Genome& genome, const Config& config, bool keep_body, long every) {
  if (every < 0) throw ConfigError(fmt::format("record_evaluation: every must be >= 0, got {}", every));
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

EvaluationResult evaluate(const Genome& genome, const Config& config, const Objective& objective) {
  EvaluationRecord record = record_evaluation(genome, config, objective.needs_body(), objective.sample_every());
  // Non-viable genomes are never swum, and an unstable or invalid swim (one that broke the planar
  // embedding or an invariant) is worth nothing whatever the objective: no objective scores them.
  if (!record.result.viable || !record.result.stable || !record.result.valid) {
    record.result.fitness = 0.0;
    return std::move(record.result);
  }
  const double v = objective.value(record);
  if (!std::isfinite(v))
    throw Error(fmt::format("objective \"{}\" returned {} (objectives must be finite)", objective.name(), v));
  record.result.fitness = v;
  return std::move(record.result);
}

}  // namespace animat
