// Fitness evaluation: genome -> development -> body -> swim -> distance of the centre of mass.
#include "animat/evaluate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/development.hpp"
#include "animat/embedding.hpp"
#include "animat/errors.hpp"
#include "animat/locomotion.hpp"
#include "animat/objective_table.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "animat/shape.hpp"

namespace animat {

void copy_counters(const SwimCounters& from, SwimResult& to) {
  visit_fields(from, [&](std::string_view name, const char*, const auto& value) {
    visit_fields(to, [&](std::string_view field, const char*, auto& target) {
      if constexpr (std::is_same_v<std::decay_t<decltype(target)>, std::decay_t<decltype(value)>>)
        if (field == name) target = value;
    });
  });
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The median of the cells' oscillator frequencies (numpy's: the mean of the two middle values for
/// an even count); 0 for no cell.
double median_frequency(const Body& body) {
  std::vector<double> f(body.frequency.data(), body.frequency.data() + body.frequency.size());
  if (f.empty()) return 0.0;
  std::sort(f.begin(), f.end());
  const std::size_t n = f.size();
  return n % 2 ? f[n / 2] : (f[n / 2 - 1] + f[n / 2]) / 2.0;
}

/// Half the median rest length: the floor of the stretch denominators.
double stretch_floor(const Body& body) {
  if (body.spring_count() == 0) return 0.0;
  std::vector<double> l(body.rest_lengths.data(),
                        body.rest_lengths.data() + body.rest_lengths.size());
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
    const auto i = static_cast<std::size_t>(body.springs(s, 0)),
               j = static_cast<std::size_t>(body.springs(s, 1));
    const double len = std::hypot(st.x[j] - st.x[i], st.y[j] - st.y[i]);
    r.max_stretch = std::max(r.max_stretch, len / std::max(l0, floor));
    if (l0 >= floor && l0 > 0.0) r.min_stretch = std::min(r.min_stretch, len / l0);
  }
  r.max_kinetic_energy = std::max(r.max_kinetic_energy, sim.kinetic_energy());
}

}  // namespace

GrnControlStart grn_control_start(const Genome& genome, const Embryo& embryo,
                                  const Config& config) {
  GrnControlStart start;
  start.grn = Grn(genome, config.genome);
  start.grn_params = config.grn;
  start.amplitude_max = config.development.amplitude_max;
  const int n = embryo.cell_count();
  if (embryo.grn_levels.rows() == n && embryo.grn_levels.cols() == start.grn.node_count()) {
    start.levels.assign(embryo.grn_levels.data(),
                        embryo.grn_levels.data() + embryo.grn_levels.size());
  } else {
    start.levels.assign(
        static_cast<std::size_t>(n) * static_cast<std::size_t>(start.grn.node_count()), 0.0);
  }
  if (embryo.grn_maternal.rows() == n && embryo.grn_maternal.cols() == 3)
    start.maternal.assign(embryo.grn_maternal.data(),
                          embryo.grn_maternal.data() + embryo.grn_maternal.size());
  const auto morph = static_cast<Eigen::Index>(start.grn.morphogen_units().size());
  if (morph > 0 && embryo.grn_sensed.rows() == n && embryo.grn_sensed.cols() == morph)
    start.sensed.assign(embryo.grn_sensed.data(),
                        embryo.grn_sensed.data() + embryo.grn_sensed.size());
  return start;
}

std::vector<double> source_direction(const Config& config, int trial) {
  // T = source_directions evenly spaced directions turned by one random offset, uniform in [0, 2π)
  // from evaluation.source_seed: every genome of a run meets the same directions, and a body that
  // swims straight, whatever its heading, gains nothing on average (Σ_t cos(θ_t − heading) = 0 for
  // T >= 2), so only sensing and turning pays.
  Rng rng(static_cast<std::uint64_t>(config.evaluation.source_seed));
  const double offset = rng.uniform(0.0, 2.0 * 3.14159265358979323846);
  const int count = std::max(1, config.evaluation.source_directions);
  const double angle = offset + 2.0 * 3.14159265358979323846 * static_cast<double>(trial) / count;
  const double x = config.scene.chemical_source[0], y = config.scene.chemical_source[1];
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * x - s * y, s * x + c * y};
}

StartState start_state(const Body& body, const SceneParams& scene, const PhysicsParams& physics,
                       long settle_steps) {
  if (settle_steps < 0)
    throw ConfigError(
        fmt::format("evaluation.settle_steps: {} is out of range (expected >= 0)", settle_steps));
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

SwimResult swim(const Body& body_in, const SceneParams& scene, const PhysicsParams& physics,
                long steps, const SwimOptions& options) {
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
  if (options.start_offset) {  // a perturbed repeat (evaluation.repeats): the start, not the rest
    if (options.start_offset->rows() != begin.body.node_count() ||
        !options.start_offset->allFinite())
      throw ConfigError(fmt::format(
          "swim: SwimOptions::start_offset must hold {} finite rows (one per cell), got {}",
          begin.body.node_count(), options.start_offset->rows()));
    begin.body.positions += *options.start_offset;
  }
  const Body& body = begin.body;
  // control.mode = "grn": the GRN drives eq. 2 instead of the scene's oscillators.
  SceneParams swim_scene = scene;
  if (options.control_start) std::erase(swim_scene.effects, std::string("actuation"));
  Simulation sim(body, swim_scene, physics);
  const GrnControl* controller = nullptr;
  if (options.control_start) {
    if (!options.control)
      throw ConfigError("swim: SwimOptions::control_start needs SwimOptions::control");
    auto effect = std::make_unique<GrnControl>(body, *options.control_start, *options.control,
                                               scene, physics);
    controller = effect.get();
    sim.add_effect(std::move(effect));
  }
  if (begin.settled > 0) sim.set_velocities(begin.velocities);
  std::vector<int> pushed;  // sized before the loop: pushing allocates nothing there
  pushed.reserve(static_cast<std::size_t>(body.node_count()));
  MotionRecording* motion = options.motion;
  // Append the frame of the current step (capacity reserved below: no allocation in the loop).
  auto record = [&] {
    const SwimState& st = sim.state();
    for (int i = 0; i < st.n; ++i) {
      motion->frames.xy.push_back(st.x[static_cast<std::size_t>(i)]);
      motion->frames.xy.push_back(st.y[static_cast<std::size_t>(i)]);
    }
    motion->frames.times.push_back(sim.time());
  };
  if (motion) {
    const auto count = static_cast<std::size_t>(std::max(0L, steps - motion->first_step + 1));
    motion->start_positions = body.positions;
    motion->frames.cells = body.node_count();
    motion->frames.swim_start = 0.0;
    motion->frames.xy.clear();
    motion->frames.times.clear();
    motion->frames.xy.reserve(count * 2 * static_cast<std::size_t>(body.node_count()));
    motion->frames.times.reserve(count);
    if (motion->first_step <= 0) record();
  }
  if (options.check_embedding) sim.monitor_embedding(body);
  if (options.account_energy) sim.account_energy();
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
      if (options.push_step >= 0 && done < options.push_step)
        next = std::min(next, options.push_step);
      if (motion) next = std::min(next, std::max(done + 1, motion->first_step));
      if (options.push_step >= 0 && done == options.push_step &&
          sim.steps_done() == options.push_step) {
        const SwimState& st = sim.state();
        const Eigen::Vector2d com = sim.center_of_mass();
        r.displacement_at_push = com - start;
        pushed.clear();
        for (int i = 0; i < st.n; ++i)
          if (!options.push_front_only || st.x[static_cast<std::size_t>(i)] >= com.x())
            pushed.push_back(i);
        sim.push(pushed, options.push_impulse);
      }
      if (stop_early) {
        for (; done < next && !broken(); ++done) sim.step(1);
      } else {
        sim.step(next - done);
        done = next;
      }
      if (done % kSampleEvery == 0 || done == steps) sample(sim, body, floor, r);
      if (every > 0 && done % every == 0) observer->on_sample(sim);
      if (motion && done >= motion->first_step) record();
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
  if (controller) r.grn_updates = controller->updates();
  r.simulated_time = sim.time();
  r.max_speed = sim.max_speed_seen();
  r.max_step_displacement = sim.max_step_displacement_seen();
  r.final_kinetic_energy = sim.kinetic_energy();
  r.displacement = sim.center_of_mass() - start;
  if (r.stable && !r.displacement.allFinite()) {
    r.stable = false;
    r.failure = "unstable swim: non-finite centre of mass";
  }
  r.max_kinetic_energy_per_cell =
      body.node_count() > 0 ? r.max_kinetic_energy / body.node_count() : 0.0;
  copy_counters(sim.counters(), r);
  r.energy = sim.energy_account();
  if (const Effect* springs = sim.effect("springs")) {
    std::vector<double> pos, abs;
    if (actuation_work_per_cell(*springs, pos, abs)) {
      r.cell_work_positive =
          Eigen::Map<const Eigen::VectorXd>(pos.data(), static_cast<Eigen::Index>(pos.size()));
      r.cell_work_absolute =
          Eigen::Map<const Eigen::VectorXd>(abs.data(), static_cast<Eigen::Index>(abs.size()));
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
  r.valid = r.stable && r.inverted_region_steps == 0 && r.skin_crossing_steps == 0 &&
            r.collisions_unresolved == 0;
  if (r.stable && !r.valid) {
    std::vector<std::string> what;
    if (r.inverted_region_steps > 0)
      what.push_back(
          fmt::format("a region turned inside out (smallest S/S0 {:.3g})", r.min_area_ratio));
    if (r.skin_crossing_steps > 0) what.push_back("the skin crossed itself");
    if (r.collisions_unresolved > 0)
      what.push_back(
          fmt::format("{} steps with an unresolved cell-edge collision", r.collisions_unresolved));
    r.failure = fmt::format("invalid swim: {} (first at step {})", fmt::join(what, "; "),
                            r.first_invalid_step >= 0 ? r.first_invalid_step : r.steps);
  }
  r.distance = r.valid ? r.displacement.norm() : 0.0;
  if (body.spring_count() > 0 && !std::isfinite(r.min_stretch)) r.min_stretch = 0.0;
  return r;
}

namespace {

/// evaluation.repeats, repeat_perturbation and repeat_statistic valid (the config's bounds, for a
/// config that did not pass validate()).
void check_repeats(const EvaluationParams& p) {
  if (p.repeats < 1 || p.repeats > 64)
    throw ConfigError(fmt::format(
        "evaluation.repeats = {} is out of range (expected an integer in [1, 64])", p.repeats));
  if (!(p.repeat_perturbation > 0.0 && p.repeat_perturbation <= 0.1))
    throw ConfigError(
        fmt::format("evaluation.repeat_perturbation = {} is out of range (expected a length in "
                    "(0, 0.1], length units)",
                    p.repeat_perturbation));
  if (p.repeat_statistic != "mean" && p.repeat_statistic != "min")
    throw ConfigError(fmt::format(
        "evaluation.repeat_statistic = \"{}\" is not known (expected \"mean\" or \"min\")",
        p.repeat_statistic));
}

/// What every swim of one evaluation shares: the developed body and the swim options.
struct Developed {
  Body body;
  GrnControlStart control_start;
  SwimOptions options;
};

/// Develops the genome and builds its body into `d`, filling the development and body fields of
/// `out`; false when there is nothing to swim (not viable, or development left the valid domain:
/// `out` says why).
bool develop_body(const Genome& genome, const Config& config, EvaluationResult& out, Developed& d) {
  // a genome no loader would accept is an error, not UB
  validate(genome, config.genome, "evaluate");
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
    return false;
  }
  out.seconds_development = seconds_since(t0);
  out.cell_count = embryo.cell_count();
  out.development_steps = embryo.steps_run;
  out.viable = embryo.viable;
  if (!embryo.viable) {
    out.reasons = embryo.reasons;
    return false;
  }

  t0 = Clock::now();
  Body& body = d.body;
  try {
    body = build_body(embryo, config.body);
  } catch (const GeometryError& e) {
    out.seconds_body = seconds_since(t0);
    out.viable = false;
    out.reasons.push_back(fmt::format("body: {}", e.what()));
    return false;
  }
  out.seconds_body = seconds_since(t0);
  out.spring_count = body.spring_count();
  out.region_count = body.region_count();
  out.skin_edge_count = static_cast<int>(body.skin.rows());
  out.morphology_kind = morphology_kind(body.positions);
  const Shape shape = body_shape(body);
  out.elongation = shape.elongation;
  out.protrusions = static_cast<int>(shape.protrusions.size());
  out.symmetric_pair = shape.symmetric_pairs.empty() ? 0 : 1;
  out.concavity = shape.concavity;
  out.frequency = median_frequency(body);

  SwimOptions& options = d.options;
  options.check_embedding = config.evaluation.check_embedding;
  options.account_energy = config.evaluation.energy_accounting;
  options.settle_steps = config.evaluation.settle_steps;
  options.push_step = config.evaluation.push_step;
  if (config.evaluation.push_impulse.size() != 2)
    throw ConfigError(fmt::format("evaluation.push_impulse: expected 2 numbers [Jx, Jy], got {}",
                                  config.evaluation.push_impulse.size()));
  options.push_impulse =
      Eigen::Vector2d(config.evaluation.push_impulse[0], config.evaluation.push_impulse[1]);
  options.push_front_only = config.evaluation.push_cells == "front";
  if (config.control.mode == "grn") {
    d.control_start = grn_control_start(genome, embryo, config);
    options.control_start = &d.control_start;
    options.control = &config.control;
  }
  return true;
}

/// The swims of one start (one per source direction for objective chemotaxis; the first is
/// observed and gives the diagnostics) into the swim fields of `out`: fitness = the paper's
/// distance, source_progress their mean progress toward the source. Returns the failure ('' when
/// valid).
std::string swim_start(const Developed& d, const Config& config, SwimOptions options,
                       EvaluationObserver* observer, EvaluationResult& out) {
  const Clock::time_point t0 = Clock::now();
  options.observer = observer;
  if (observer) observer->on_body(d.body);
  // An objective that one swim does not decide (chemotaxis): one swim per source direction, the
  // fitness their mean progress toward the source.
  const ObjectiveSpec* spec = find_objective(config.evaluation.objective);
  const bool chemotaxis = spec != nullptr && !spec->one_swim;
  const int trials = chemotaxis ? config.evaluation.source_directions : 1;
  SwimResult s;
  double progress = 0.0;
  // The locomotion measure (needs_locomotion): the first swim's window, recorded as it swims;
  // with evaluation.repeats only repeat 0's (the unperturbed start), whose fields the result keeps.
  const bool classify = needs_locomotion(config) && options.start_offset == nullptr;
  MotionRecording motion;
  const double omega = classify ? dominant_frequency(d.body.amplitude, d.body.frequency) : 0.0;
  if (classify) {
    motion.first_step =
        window_start_step(static_cast<int>(config.evaluation.steps), config.physics.dt, omega);
    options.motion = &motion;
  }
  for (int t = 0; t < trials; ++t) {
    SceneParams scene = config.scene;
    if (chemotaxis) scene.chemical_source = source_direction(config, t);
    const SwimResult st = swim(d.body, scene, config.physics, config.evaluation.steps, options);
    if (chemotaxis) {
      const Eigen::Vector2d src(scene.chemical_source[0], scene.chemical_source[1]);
      progress += st.valid ? src.norm() - (src - st.displacement).norm() : 0.0;
    }
    if (t == 0) {
      s = st;
      options.observer = nullptr;
      options.motion = nullptr;
    } else if (!st.valid) {
      s.valid = false;
      s.stable = s.stable && st.stable;
      s.failure = fmt::format("source direction {}: {}", t, st.failure);
    }
  }
  out.source_progress = chemotaxis && s.valid ? progress / trials : 0.0;
  if (classify && s.stable && s.steps == config.evaluation.steps &&
      motion.frames.frame_count() >= 8)
    out.locomotion = static_cast<int>(
        classify_body_motion(motion.frames, d.body, 4.0, &motion.start_positions).mode);
  out.seconds_swim = seconds_since(t0);
  out.stable = s.stable;
  out.fitness = s.distance;
  out.swim_steps = s.steps;
  // Every field both records have (valid, the counters, the work, ...): visit_swim_fields.
  visit_swim_fields([](const char*, const char*, const auto& from, auto& to) { to = from; }, s,
                    out);
  return s.valid ? std::string() : s.failure;
}

/// evaluate()'s scorer with repeats: the paper's distance, the observer on repeat 0.
class DistanceScorer final : public RepeatScorer {
 public:
  explicit DistanceScorer(EvaluationObserver* observer) : observer_(observer) {}
  EvaluationObserver* observer(int repeat) override { return repeat == 0 ? observer_ : nullptr; }
  double value(int, const EvaluationResult& result) override { return result.fitness; }

 private:
  EvaluationObserver* observer_;
};

}  // namespace

bool needs_locomotion(const Config& config) {
  const SearchParams& p = config.search;
  if (p.algorithm == "map_elites")
    return std::find(p.descriptors.begin(), p.descriptors.end(), "locomotion") !=
           p.descriptors.end();
  if (p.algorithm == "nsga2")
    return std::any_of(p.objectives.begin(), p.objectives.end(), [](const std::string& o) {
      return std::string_view(o).substr(0, o.find(':')) == "locomotion";
    });
  return false;
}

Points start_perturbation(int repeat, int cells, double magnitude) {
  Points d = Points::Zero(std::max(cells, 0), 2);
  if (repeat == 0) return d;
  for (int i = 0; i < cells; ++i) {
    // A uniform direction without trigonometry (the same bits with every libm): a point uniform in
    // the unit disc, by rejection, scaled to length 1.
    Rng rng = Rng::derive(static_cast<std::uint64_t>(repeat), static_cast<std::uint64_t>(i));
    double u = 0.0, v = 0.0, r2 = 0.0;
    do {
      u = rng.uniform(-1.0, 1.0);
      v = rng.uniform(-1.0, 1.0);
      r2 = u * u + v * v;
    } while (r2 > 1.0 || r2 < 1e-6);
    const double r = std::sqrt(r2);
    d(i, 0) = magnitude * (u / r);
    d(i, 1) = magnitude * (v / r);
  }
  return d;
}

EvaluationResult evaluate(const Genome& genome, const Config& config,
                          EvaluationObserver* observer) {
  check_repeats(config.evaluation);
  if (config.evaluation.repeats > 1) {
    DistanceScorer scorer(observer);
    return evaluate_repeats(genome, config, scorer);
  }
  EvaluationResult out;
  Developed d;
  if (!develop_body(genome, config, out, d)) return out;
  if (std::string failure = swim_start(d, config, d.options, observer, out); !out.valid)
    out.reasons.push_back(std::move(failure));
  return out;
}

EvaluationResult evaluate_repeats(const Genome& genome, const Config& config,
                                  RepeatScorer& scorer) {
  check_repeats(config.evaluation);
  const int repeats = config.evaluation.repeats;
  EvaluationResult developed;
  Developed d;
  if (!develop_body(genome, config, developed, d)) return developed;
  EvaluationResult out;
  std::vector<double> values(static_cast<std::size_t>(repeats), 0.0);
  double seconds_swim = 0.0;
  for (int j = 0; j < repeats; ++j) {
    EvaluationResult r = developed;
    SwimOptions options = d.options;
    Points offset;
    if (j > 0) {
      offset = start_perturbation(j, d.body.node_count(), config.evaluation.repeat_perturbation);
      options.start_offset = &offset;
    }
    const std::string failure = swim_start(d, config, options, scorer.observer(j), r);
    seconds_swim += r.seconds_swim;
    if (j == 0) out = r;
    if (!r.valid || !r.stable) {
      // The evaluation is invalid, as one invalid swim makes it; the diagnostics stay repeat 0's.
      out.valid = false;
      out.stable = out.stable && r.stable;
      out.fitness = 0.0;
      out.fitness_spread = 0.0;
      out.reasons.push_back(fmt::format(
          "repeat {} of {}{}: {}", j, repeats,
          j > 0 && r.first_invalid_step == 0
              ? fmt::format(" (its start, displaced by {:g}, already broke the embedding)",
                            config.evaluation.repeat_perturbation)
              : std::string(),
          failure));
      out.seconds_swim = seconds_swim;
      return out;
    }
    values[static_cast<std::size_t>(j)] = scorer.value(j, r);
  }
  double sum = 0.0;
  for (double v : values) sum += v;
  const double mean = sum / repeats;
  double squares = 0.0;
  for (double v : values) squares += (v - mean) * (v - mean);
  const double sd = repeats > 1 ? std::sqrt(squares / (repeats - 1)) : 0.0;
  // Summed and compared in repeat order: the same bits for any thread count or rank.
  out.fitness = config.evaluation.repeat_statistic == "min"
                    ? *std::min_element(values.begin(), values.end())
                    : mean;
  out.fitness_spread = sd == 0.0     ? 0.0
                       : mean != 0.0 ? sd / std::abs(mean)
                                     : std::numeric_limits<double>::infinity();
  out.seconds_swim = seconds_swim;
  return out;
}

}  // namespace animat
