// Fitness evaluation: genome -> development -> body -> swim -> distance of the centre of mass.
#include "animat/evaluate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>
#include <string>
#include <utility>

#include "animat/body.hpp"
#include "animat/development.hpp"
#include "animat/embedding.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"

namespace animat {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Half the median rest length: the floor of the stretch denominators.
double stretch_floor(const Body& body) {
  if (body.spring_count() == 0) return 0.0;
  std::vector<double> l(body.rest_lengths.data(), body.rest_lengths.data() + body.rest_lengths.size());
  std::nth_element(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(l.size() / 2), l.end());
  return 0.5 * l[l.size() / 2];
}

/// Spring stretch extremes and kinetic energy: sampled diagnostics of a swim. Stretch is
/// length / max(L0, floor), compression is length / L0 over springs with L0 >= floor, so that
/// near-zero rest lengths (slivers, near-coincident cells) do not make the ratios meaningless.
void sample(const Simulation& sim, const Body& body, double floor, SwimResult& r) {
  const SwimState& st = sim.state();
  for (int s = 0; s < body.spring_count(); ++s) {
    const double l0 = body.rest_lengths(s);
    const auto i = static_cast<std::size_t>(body.springs(s, 0)), j = static_cast<std::size_t>(body.springs(s, 1));
    const double len = std::hypot(st.x[j] - st.x[i], st.y[j] - st.y[i]);
    r.max_stretch = std::max(r.max_stretch, len / std::max(l0, floor));
    if (l0 >= floor && l0 > 0.0) r.min_stretch = std::min(r.min_stretch, len / l0);
  }
  r.max_kinetic_energy = std::max(r.max_kinetic_energy, sim.kinetic_energy());
}

}  // namespace

StartState start_state(const Body& body, const SceneParams& scene, const PhysicsParams& physics, long settle_steps) {
  if (settle_steps < 0)
    throw ConfigError(fmt::format("evaluation.settle_steps: {} is out of range (expected >= 0)", settle_steps));
  StartState out;
  out.body = body;
  if (has_effect(scene.effects, "ground") && body.node_count() > 0)
    out.body.positions.col(1).array() += scene.ground_height - body.positions.col(1).minCoeff();
  out.velocities = Points::Zero(body.node_count(), 2);
  if (settle_steps > 0) {
    SceneParams quiet = scene;
    std::erase(quiet.effects, std::string("actuation"));
    Simulation settle(out.body, quiet, physics);
    settle.step(settle_steps);
    out.body.positions = settle.positions();
    out.velocities = settle.velocities();
    out.settled = settle_steps;
  }
  return out;
}

SwimResult swim(const Body& body_in, const SceneParams& scene, const PhysicsParams& physics, long steps,
                const SwimOptions& options) {
  constexpr long kSampleEvery = 16;
  SwimResult r;
  StartState begin;
  try {
    begin = start_state(body_in, scene, physics, options.settle_steps);
  } catch (const SimulationError& e) {
    r.stable = false;
    r.valid = false;
    r.failure = fmt::format("while settling: {}", e.what());
    r.min_stretch = 0.0;
    return r;
  }
  r.settle_steps = begin.settled;
  const Body& body = begin.body;
  Simulation sim(body, scene, physics);
  if (begin.settled > 0) sim.set_velocities(begin.velocities);
  if (options.check_embedding) sim.monitor_embedding(body);
  r.min_stretch = body.spring_count() > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  const Eigen::Vector2d start = sim.center_of_mass();
  const double floor = stretch_floor(body);
  sample(sim, body, floor, r);
  EvaluationObserver* observer = options.observer;
  const long every = observer ? observer->sample_every() : 0;
  if (every > 0) observer->on_sample(sim);
  const bool stop_early = options.stop_when_invalid && options.check_embedding;
  auto broken = [&] {
    return sim.first_broken_step() >= 0 || sim.counters().collisions_unresolved > 0;
  };
  try {
    for (long done = 0; done < steps;) {
      // Stops at the diagnostic samples (every 16 steps and the end) and the observer's frames;
      // splitting step() changes nothing in the motion. When an invalid swim ends early, it goes
      // one step at a time so that it stops at the first broken invariant.
      long next = std::min(steps, (done / kSampleEvery + 1) * kSampleEvery);
      if (every > 0) next = std::min(next, (done / every + 1) * every);
      if (stop_early) {
        for (; done < next && !broken(); ++done) sim.step(1);
      } else {
        sim.step(next - done);
        done = next;
      }
      if (done % kSampleEvery == 0 || done == steps) sample(sim, body, floor, r);
      if (every > 0 && done % every == 0) observer->on_sample(sim);
      if (stop_early && broken()) {
        sample(sim, body, floor, r);
        break;
      }
    }
  } catch (const SimulationError& e) {
    r.stable = false;
    r.failure = e.what();
  }
  r.steps = sim.steps_done();
  r.simulated_time = sim.time();
  r.max_speed = sim.max_speed_seen();
  r.max_step_displacement = sim.max_step_displacement_seen();
  r.final_kinetic_energy = sim.kinetic_energy();
  r.displacement = sim.center_of_mass() - start;
  if (r.stable && !r.displacement.allFinite()) {
    r.stable = false;
    r.failure = "unstable swim: non-finite centre of mass";
  }
  r.max_kinetic_energy_per_cell = body.node_count() > 0 ? r.max_kinetic_energy / body.node_count() : 0.0;
  const SwimCounters& c = sim.counters();
  r.collisions = c.collisions;
  r.collisions_inelastic = c.collisions_inelastic;
  r.collisions_unresolved = c.collisions_unresolved;
  r.drag_limited = c.drag_limited;
  r.ground_contacts = c.ground_contacts;
  r.ground_slips = c.ground_slips;
  r.actuation_work = c.actuation_work;
  r.actuation_work_positive = c.actuation_work_positive;
  r.actuation_work_absolute = c.actuation_work_absolute;
  if (const Effect* springs = sim.effect("springs")) {
    std::vector<double> pos, abs;
    if (actuation_work_per_cell(*springs, pos, abs)) {
      r.cell_work_positive = Eigen::Map<const Eigen::VectorXd>(pos.data(), static_cast<Eigen::Index>(pos.size()));
      r.cell_work_absolute = Eigen::Map<const Eigen::VectorXd>(abs.data(), static_cast<Eigen::Index>(abs.size()));
    }
  }
  if (r.cell_work_positive.size() == 0) {
    r.cell_work_positive = Eigen::VectorXd::Zero(body.node_count());
    r.cell_work_absolute = Eigen::VectorXd::Zero(body.node_count());
  }
  if (const EmbeddingMonitor* m = sim.embedding_monitor()) {
    r.embedding_checked = true;
    r.min_area_ratio = m->min_area_ratio();
    r.inverted_region_steps = m->inverted_region_frames();
    r.skin_crossing_steps = m->skin_crossing_frames();
    r.first_invalid_step = sim.first_broken_step();
  }
  r.valid = r.stable && r.inverted_region_steps == 0 && r.skin_crossing_steps == 0 && r.collisions_unresolved == 0;
  if (r.stable && !r.valid) {
    std::vector<std::string> what;
    if (r.inverted_region_steps > 0)
      what.push_back(fmt::format("a region turned inside out (smallest S/S0 {:.3g})", r.min_area_ratio));
    if (r.skin_crossing_steps > 0) what.push_back("the skin crossed itself");
    if (r.collisions_unresolved > 0)
      what.push_back(fmt::format("{} steps with an unresolved cell-edge collision", r.collisions_unresolved));
    r.failure = fmt::format("invalid swim: {} (first at step {})", fmt::join(what, "; "),
                            r.first_invalid_step >= 0 ? r.first_invalid_step : r.steps);
  }
  r.distance = r.valid ? r.displacement.norm() : 0.0;
  if (body.spring_count() > 0 && !std::isfinite(r.min_stretch)) r.min_stretch = 0.0;
  return r;
}

EvaluationResult evaluate(const Genome& genome, const Config& config, EvaluationObserver* observer) {
  EvaluationResult out;
  validate(genome, config.genome, "evaluate");  // a genome no loader would accept is an error, not UB
  validate(config.scene);
  validate(config.physics);
  auto t0 = Clock::now();
  Embryo embryo;
  try {
    embryo = develop(genome, config.genome, config.grn, config.development);
  } catch (const SimulationError& e) {
    out.seconds_development = seconds_since(t0);
    out.viable = false;
    out.stable = false;
    out.valid = false;
    out.reasons.push_back(fmt::format("development: {}", e.what()));
    return out;
  }
  out.seconds_development = seconds_since(t0);
  out.cell_count = embryo.cell_count();
  out.development_steps = embryo.steps_run;
  out.viable = embryo.viable;
  if (!embryo.viable) {
    out.reasons = embryo.reasons;
    return out;
  }

  t0 = Clock::now();
  Body body;
  try {
    body = build_body(embryo, config.body);
  } catch (const GeometryError& e) {
    out.seconds_body = seconds_since(t0);
    out.viable = false;
    out.reasons.push_back(fmt::format("body: {}", e.what()));
    return out;
  }
  out.seconds_body = seconds_since(t0);
  out.spring_count = body.spring_count();
  out.region_count = body.region_count();
  out.skin_edge_count = static_cast<int>(body.skin.rows());

  t0 = Clock::now();
  SwimOptions options;
  options.check_embedding = config.evaluation.check_embedding;
  options.observer = observer;
  options.settle_steps = config.evaluation.settle_steps;
  if (observer) observer->on_body(body);
  const SwimResult s = swim(body, config.scene, config.physics, config.evaluation.steps, options);
  out.seconds_swim = seconds_since(t0);
  out.stable = s.stable;
  out.valid = s.valid;
  if (!s.valid) out.reasons.push_back(s.failure);
  out.fitness = s.distance;
  out.displacement = s.displacement;
  out.swim_steps = s.steps;
  out.simulated_time = s.simulated_time;
  out.max_speed = s.max_speed;
  out.max_step_displacement = s.max_step_displacement;
  out.max_stretch = s.max_stretch;
  out.min_stretch = s.min_stretch;
  out.max_kinetic_energy = s.max_kinetic_energy;
  out.final_kinetic_energy = s.final_kinetic_energy;
  out.max_kinetic_energy_per_cell = s.max_kinetic_energy_per_cell;
  out.min_area_ratio = s.min_area_ratio;
  out.inverted_region_steps = s.inverted_region_steps;
  out.skin_crossing_steps = s.skin_crossing_steps;
  out.first_invalid_step = s.first_invalid_step;
  out.collisions = s.collisions;
  out.collisions_inelastic = s.collisions_inelastic;
  out.collisions_unresolved = s.collisions_unresolved;
  out.drag_limited = s.drag_limited;
  out.settle_steps = s.settle_steps;
  out.ground_contacts = s.ground_contacts;
  out.ground_slips = s.ground_slips;
  out.actuation_work = s.actuation_work;
  out.actuation_work_positive = s.actuation_work_positive;
  out.actuation_work_absolute = s.actuation_work_absolute;
  out.cell_work_positive = s.cell_work_positive;
  out.cell_work_absolute = s.cell_work_absolute;
  return out;
}

}  // namespace animat
