// Objectives, the evaluation record, the ask/tell engine and externally driven actuation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/external_actuation.hpp"
#include "animat/objective.hpp"
#include "animat/objective_table.hpp"
#include "animat/physics.hpp"
#include "animat/run.hpp"
#include "counting_allocator.hpp"
#include "physics_support.hpp"
#include "test_support.hpp"

using namespace animat;

namespace {

using animat::test::expect_same_history;
using animat::test::expect_same_population;
using animat::test::stub_fitness;

Config small_config(int population = 20, std::int64_t seed = 7) {
  Config c;
  c.evolution.population = population;
  c.evolution.elites = 2;
  c.evolution.seed = seed;
  c.evolution.threads = 1;
  c.evaluation.steps = 600;
  return c;
}

/// The first viable random genome of Rng(seed).
Genome viable_genome(const Config& c, std::uint64_t seed) {
  Rng rng(seed);
  for (int k = 0; k < 100000; ++k) {
    Genome g = random_genome(c.genome, rng);
    if (develop(g, c.genome, c.grn, c.development).viable) return g;
  }
  throw Error("no viable genome");
}

Body triangle_body() {
  Points p(3, 2);
  p << 0.0, 0.0, 3.0, 0.0, 0.0, 4.0;
  return build_body(p, Vector(), Vector(), Vector());
}

}  // namespace

// --- ask / tell ----------------------------------------------------------------------------------

TEST(AskTell, DrivenFromOutsideEqualsTheEngineRunningItself) {
  const Config c = small_config(24);
  Evolution itself(c, stub_fitness);
  itself.initialize();
  for (int g = 0; g < 15; ++g) itself.step();

  for (int lookahead : {1, 3, 50}) {
    Evolution driven(c);  // no fitness function: ask/tell only
    int rounds = 0;
    while (driven.generation() < 15) {
      const std::vector<Genome> genomes = driven.ask(lookahead);
      EXPECT_TRUE(driven.asked());
      std::vector<Fitness> f;
      for (const auto& g : genomes) f.push_back(stub_fitness(g));
      driven.tell(f);
      ++rounds;
    }
    EXPECT_GT(rounds,
              15);  // the initial slots needed more than one round (1 genome in 4 is non-viable)
    expect_same_history(itself.history(), driven.history());
    for (std::size_t g = 0; g < itself.history().size(); ++g)
      EXPECT_EQ(itself.history()[g].crossovers, driven.history()[g].crossovers)
          << "generation " << g;
    expect_same_population(itself.population(), driven.population());
  }
}

TEST(AskTell, InitialRoundsCountOnlyTheDrawsUpToEachSlotsFirstViable) {
  const Config c = small_config(12);
  Evolution evo(c);
  std::int64_t told = 0;
  while (evo.generation() < 0) {
    const auto genomes = evo.ask(4);
    std::vector<Fitness> f;
    for (const auto& g : genomes) f.push_back(stub_fitness(g));
    told += static_cast<std::int64_t>(f.size());
    evo.tell(f);
  }
  int tries = 0;
  for (const auto& ind : evo.population()) {
    EXPECT_TRUE(ind.result.viable);
    tries += ind.tries;
  }
  EXPECT_EQ(evo.evaluations(), tries);
  EXPECT_GE(told, tries);  // speculative draws after a slot's first viable one are discarded
}

TEST(AskTell, MisuseIsAClearError) {
  Evolution evo(small_config());
  EXPECT_THROW((void)evo.tell({}), Error);      // nothing asked
  EXPECT_THROW((void)evo.checkpoint(), Error);  // no generation yet
  EXPECT_THROW((void)evo.best(), Error);
  EXPECT_THROW(evo.initialize(), Error);  // no fitness function
  const auto first = evo.ask();
  const auto again = evo.ask();  // same genomes until tell()
  ASSERT_EQ(first.size(), again.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_TRUE(first[i] == again[i]);
  try {
    (void)evo.tell(std::vector<Fitness>(first.size() - 1));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("19 fitness values for the 20 genomes"), std::string::npos)
        << e.what();
  }
  std::vector<Fitness> nan(first.size(), Fitness{std::nan(""), true, true, 3});
  EXPECT_THROW((void)evo.tell(nan), Error);
  EXPECT_TRUE(evo.asked());  // a refused tell changes nothing
}

TEST(AskTell, ExhaustedInitialSlotNamesMaxInitTries) {
  Config c = small_config(4);
  c.evolution.max_init_tries = 3;
  Evolution evo(c);
  try {
    for (int r = 0; r < 10; ++r) {
      const auto genomes = evo.ask(2);
      (void)evo.tell(std::vector<Fitness>(genomes.size(), Fitness{0.0, false, true, 1}));
    }
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("evolution.max_init_tries = 3"), std::string::npos)
        << e.what();
  }
}

TEST(AskTell, CheckpointBetweenAskAndTellResumesIdentically) {
  const Config c = small_config(16);
  Evolution a(c, stub_fitness);
  a.initialize();
  for (int g = 0; g < 5; ++g) a.step();
  const auto pending = a.ask();
  Evolution b(c);
  b.restore(a.checkpoint());
  const auto again = b.ask();
  ASSERT_EQ(pending.size(), again.size());
  for (std::size_t i = 0; i < pending.size(); ++i) EXPECT_TRUE(pending[i] == again[i]);
}

TEST(RunEvolution, CallbackSeesGenerationZeroAndTheResultHoldsThePopulation) {
  Config c = small_config(10);
  c.evolution.generations = 3;
  RunOptions opt;
  opt.quiet = true;
  std::vector<int> seen;
  opt.callback = [&](const GenerationStats& s, const Evolution&) {
    seen.push_back(s.generation);
    return true;
  };
  const RunSummary r = run_evolution(c, opt, stub_fitness);
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3}));
  ASSERT_EQ(r.population.size(), 10u);
  int holds_best = 0;
  for (const auto& ind : r.population) {
    EXPECT_LE(ind.result.fitness, r.best.result.fitness);
    holds_best += ind.genome == r.best.genome;
  }
  EXPECT_GE(holds_best, 1);
  opt.callback = [&](const GenerationStats&, const Evolution&) { return false; };
  EXPECT_EQ(run_evolution(c, opt, stub_fitness).stop_reason, "stopped by callback");
}

TEST(RunEvolution, EvaluationsPerSecondIsThatOfTheGenerationAlone) {
  Config c = small_config(10);
  Evolution evo(c, stub_fitness);
  evo.initialize();
  for (int g = 0; g < 3; ++g) evo.step();
  const auto& h = evo.history();
  for (std::size_t i = 1; i < h.size(); ++i) {
    const double seconds = h[i].wall_seconds - h[i - 1].wall_seconds;
    if (seconds > 0) {
      EXPECT_DOUBLE_EQ(h[i].evaluations_per_second,
                       static_cast<double>(h[i].evaluations - h[i - 1].evaluations) / seconds);
    }
  }
}

// --- objectives ----------------------------------------------------------------------------------

TEST(Objective, ConfigSelectsABuiltInByNameAndRefusesUnknownOnes) {
  Config c;
  EXPECT_EQ(make_objective(c.evaluation)->name(), "distance");
  apply_override(c, "evaluation.objective=speed_toward");
  apply_override(c, "evaluation.direction=[0.0, -2.0]");
  EXPECT_EQ(make_objective(c.evaluation)->name(), "speed_toward");
  EXPECT_EQ(config_from_toml(to_toml(c)), c);
  try {
    apply_override(c, "evaluation.objective=distnce");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "evaluation.objective = \"distnce\": expected one of distance, "
                  "distance_per_size, speed_toward, distance_x, distance_minus_energy, "
                  "distance_per_energy, chemotaxis, python:*"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(apply_override(c, "evaluation.direction=[0.0, 0.0]"), ConfigError);
  EXPECT_THROW(apply_override(c, "evaluation.direction=[1.0]"), ConfigError);
  EXPECT_THROW(apply_override(c, "evaluation.objective=python:"), ConfigError);  // needs a name
  c.evaluation.objective = "python:mine";
  validate(c);                                                    // a valid config...
  EXPECT_THROW((void)make_objective(c.evaluation), ConfigError);  // ...that only Python can run
  EXPECT_THROW((void)swim_fitness(c), ConfigError);
}

TEST(Objective, DistanceIsEvaluateBitForBitAndObservingChangesNothing) {
  const Config c = small_config();
  const Genome g = viable_genome(c, 3);
  const EvaluationResult plain = evaluate(g, c);
  ASSERT_TRUE(plain.viable);
  ASSERT_GT(plain.fitness, 0.0);
  const EvaluationResult scored = evaluate(g, c, *make_objective(c.evaluation));
  EXPECT_EQ(scored.fitness, plain.fitness);
  const EvaluationRecord rec = record_evaluation(g, c, true, 7);
  EXPECT_EQ(rec.result.fitness, plain.fitness);
  EXPECT_EQ(rec.result.max_stretch, plain.max_stretch);
  EXPECT_EQ(rec.result.max_kinetic_energy, plain.max_kinetic_energy);
  EXPECT_EQ(rec.body.node_count(), plain.cell_count);
  ASSERT_EQ(rec.frame_count(), static_cast<std::size_t>(600 / 7 + 1));
  EXPECT_EQ(rec.steps[1], 7);
  const std::size_t n = static_cast<std::size_t>(plain.cell_count), last = rec.frame_count() - 1;
  // The last frame is step 595; its centre of mass is close to (not exactly) the final one.
  double cx0 = 0, cy0 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cx0 += rec.positions[2 * i] / static_cast<double>(n);
    cy0 += rec.positions[2 * i + 1] / static_cast<double>(n);
  }
  double cx = 0, cy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cx += rec.positions[(last * n + i) * 2] / static_cast<double>(n);
    cy += rec.positions[(last * n + i) * 2 + 1] / static_cast<double>(n);
  }
  EXPECT_NEAR(std::hypot(cx - cx0, cy - cy0), plain.fitness, 0.05 * plain.fitness);
}

TEST(Objective, DistancePerSizeAndSpeedTowardFollowTheirFormulas) {
  EXPECT_DOUBLE_EQ(body_length(triangle_body()),
                   5.0 + 1.0);  // the 3-4-5 triangle's hypotenuse + a cell
  Config c = small_config();
  const Genome g = viable_genome(c, 5);
  const EvaluationRecord rec = record_evaluation(g, c, true, 0);
  ASSERT_TRUE(rec.result.viable && rec.result.stable);
  c.evaluation.objective = "distance_per_size";
  EXPECT_DOUBLE_EQ(evaluate(g, c, *make_objective(c.evaluation)).fitness,
                   rec.result.fitness / body_length(rec.body));
  c.evaluation.objective = "speed_toward";
  c.evaluation.direction = {3.0, 4.0};
  const double toward = (0.6 * rec.result.displacement.x() + 0.8 * rec.result.displacement.y()) /
                        rec.result.simulated_time;
  EXPECT_DOUBLE_EQ(evaluate(g, c, *make_objective(c.evaluation)).fitness, toward);
  c.evaluation.direction = {-3.0, -4.0};
  EXPECT_DOUBLE_EQ(evaluate(g, c, *make_objective(c.evaluation)).fitness, -toward);
}

TEST(ObjectiveTable, EveryRowIsSelectableAndItsSignRuleHoldsOnExtremeOutcomes) {
  // The config's choices are the table's names (and python:*), in its order; every row is what
  // make_objective() builds for its name.
  ASSERT_EQ(std::size(kObjectiveChoices), std::size(kObjectives) + 1);
  EXPECT_EQ(kObjectiveChoices.back(), "python:*");
  EvaluationParams p;
  p.direction = {3.0, -4.0};
  p.energy_weight = 2.0;
  p.energy_offset = 0.5;
  for (std::size_t i = 0; i < std::size(kObjectives); ++i) {
    const ObjectiveSpec& spec = kObjectives[i];
    EXPECT_EQ(kObjectiveChoices[i], spec.name);
    EXPECT_EQ(find_objective(spec.name), &spec);
    for (std::size_t j = 0; j < i; ++j) EXPECT_NE(kObjectives[j].name, spec.name);
    p.objective = std::string(spec.name);
    const auto built = make_objective(p);
    EXPECT_EQ(built->name(), spec.name);
    EXPECT_EQ(built->needs_body(), spec.needs_body);
    EXPECT_FALSE(spec.meaning.empty());
    // A nonnegative objective is >= 0 for any outcome a swim can have (distance, length, work >= 0;
    // displacements and progress of either sign).
    if (!spec.nonnegative) continue;
    for (double d : {-7.0, -1e-300, 0.0, 3.0})
      for (double work : {0.0, 1e-9, 4.0}) {
        SwimOutcome o;
        o.distance = std::hypot(d, 2.0 * d);
        o.dx = d;
        o.dy = 2.0 * d;
        o.duration = 10.0;
        o.body_length = 3.0;
        o.actuation_work_positive = work;
        o.source_progress = d;
        EXPECT_GE(spec.value(o, p), 0.0) << spec.name << " d " << d << " work " << work;
      }
  }
  EXPECT_EQ(find_objective("python:mine"), nullptr);
  EXPECT_EQ(find_objective("fastest"), nullptr);
  // Each formula, on one outcome.
  SwimOutcome o;
  o.distance = 5.0;
  o.dx = -3.0;
  o.dy = 4.0;
  o.duration = 2.0;
  o.body_length = 2.5;
  o.actuation_work_positive = 1.5;
  o.source_progress = -0.25;
  auto value = [&](std::string_view name) { return find_objective(name)->value(o, p); };
  EXPECT_EQ(value("distance"), 5.0);
  EXPECT_EQ(value("distance_per_size"), 2.0);
  EXPECT_DOUBLE_EQ(value("speed_toward"), (-3.0 * 0.6 + 4.0 * -0.8) / 2.0);
  EXPECT_EQ(value("distance_x"), 3.0);
  EXPECT_EQ(value("distance_minus_energy"), 5.0 - 2.0 * 1.5);
  EXPECT_EQ(value("distance_per_energy"), 5.0 / (1.5 + 0.5));
  EXPECT_EQ(value("chemotaxis"), -0.25);
  EXPECT_FALSE(find_objective("chemotaxis")->one_swim);
}

TEST(Objective, CustomObjectiveDrivesTheGAAndStaysThreadCountIndependent) {
  // A C++ objective: speed of the centre of mass over the last half of the swim, from the frames.
  class LateSpeed final : public Objective {
   public:
    std::string name() const override { return "late_speed"; }
    long sample_every() const override { return 50; }
    double value(const EvaluationRecord& r) const override {
      const std::size_t f = r.frame_count(), n = r.positions.size() / (2 * f), half = f / 2;
      double dx = 0, dy = 0;
      for (std::size_t i = 0; i < n; ++i) {
        dx += (r.positions[((f - 1) * n + i) * 2] - r.positions[(half * n + i) * 2]) /
              static_cast<double>(n);
        dy += (r.positions[((f - 1) * n + i) * 2 + 1] - r.positions[(half * n + i) * 2 + 1]) /
              static_cast<double>(n);
      }
      return std::hypot(dx, dy) / (r.times[f - 1] - r.times[half]);
    }
  };
  Config c = small_config(10, 2);
  c.evaluation.steps = 400;
  c.evolution.generations = 2;
  auto run = [&](int threads) {
    Config t = c;
    t.evolution.threads = threads;
    RunOptions opt;
    opt.quiet = true;
    return run_evolution(t, opt, objective_fitness(t, std::make_shared<LateSpeed>()));
  };
  const RunSummary one = run(1), two = run(2);
  ASSERT_EQ(one.history.size(), 3u);
  for (std::size_t i = 0; i < one.history.size(); ++i)
    EXPECT_EQ(one.history[i].best, two.history[i].best);
  EXPECT_GT(one.history.back().best, 0.0);
  EXPECT_LT(one.history.back().best, 5.0);  // a speed (length per time unit), not a distance
}

// --- external actuation --------------------------------------------------------------------------

TEST(ExternalActuation, RestLengthsFollowTheTermsSetFromOutside) {
  Points p(4, 2);
  p << 0, 0, 1, 0, 0.5, 0.9, 1.5, 0.9;
  const Body b = build_body(p, Vector(), Vector(), Vector());
  SceneParams scene;
  scene.effects = {"springs", "pressure", "drag"};
  Simulation sim(b, scene);
  auto effect = std::make_unique<ExternalActuation>(b, ExternalActuation::Mode::rest_length);
  ExternalActuation* act = effect.get();
  sim.add_effect(std::move(effect));
  const std::vector<double> l0(sim.rest_lengths_now().begin(), sim.rest_lengths_now().end());
  sim.step(10);  // all terms 0: a body at rest stays exactly at rest
  EXPECT_EQ(sim.kinetic_energy(), 0.0);
  const std::vector<double> u = {0.1, -0.2, 0.05, 0.0};
  act->set_terms(u);
  sim.step();
  for (int s = 0; s < b.spring_count(); ++s)
    EXPECT_DOUBLE_EQ(sim.rest_lengths_now()[static_cast<std::size_t>(s)],
                     (1.0 + u[static_cast<std::size_t>(b.springs(s, 0))] +
                      u[static_cast<std::size_t>(b.springs(s, 1))]) *
                         l0[static_cast<std::size_t>(s)]);
  EXPECT_GT(sim.kinetic_energy(), 0.0);
  EXPECT_THROW(act->set_terms(std::vector<double>{0.1, 0.2}), GeometryError);
  EXPECT_THROW(act->set_terms(std::vector<double>{0.5, 0, 0, 0}), GeometryError);
  EXPECT_THROW(act->set_oscillators(u, u), ConfigError);
}

TEST(ExternalActuation, OscillatorModeIsEq2WithoutTheDelayedStart) {
  Points p(3, 2);
  p << 0, 0, 1, 0, 0.5, 0.9;
  Vector f(3);
  f << 2.0, 3.0, 4.0;
  const Body b = build_body(p, Vector::Zero(3), f, Vector::Zero(3));
  SceneParams scene;
  scene.effects = {"springs"};
  Simulation sim(b, scene);
  auto effect = std::make_unique<ExternalActuation>(b, ExternalActuation::Mode::oscillator);
  ExternalActuation* act = effect.get();
  sim.add_effect(std::move(effect));
  const std::vector<double> l0(sim.rest_lengths_now().begin(), sim.rest_lengths_now().end());
  const std::vector<double> a = {0.1, 0.2, 0.15}, phase = {0.3, 1.0, 2.0};
  act->set_oscillators(a, phase);
  const double h = PhysicsParams{}.dt;
  for (int k = 0; k < 50; ++k) {
    sim.step();
    const double t = k * h;  // the rest lengths used by step k
    for (int s = 0; s < b.spring_count(); ++s) {
      const auto i = static_cast<std::size_t>(b.springs(s, 0)),
                 j = static_cast<std::size_t>(b.springs(s, 1));
      const double expected =
          (1.0 + a[i] * std::sin(f(static_cast<Eigen::Index>(i)) * t + phase[i]) +
           a[j] * std::sin(f(static_cast<Eigen::Index>(j)) * t + phase[j])) *
          l0[static_cast<std::size_t>(s)];
      ASSERT_NEAR(sim.rest_lengths_now()[static_cast<std::size_t>(s)], expected, 1e-12)
          << "step " << k;
    }
  }
}

namespace {

std::vector<double> values(const Vector& v) { return {v.data(), v.data() + v.size()}; }

}  // namespace

TEST(ExternalActuation, DelayedStartReplaysTheBodysOwnActuationBitForBit) {
  // Random amplitudes, frequencies and phases: every cell has its own start step. The same values,
  // set again every 7 steps (a controller holding its action), write the rest lengths the effect
  // "actuation" writes, bit for bit, across a resynchronisation of the oscillators (step 1024).
  const Body b = swimmer(lattice_points(5, 4, 0.1, 3), Drive::random, 0.2, 4.0, 11);
  const std::vector<double> a = values(b.amplitude), phase = values(b.phase);
  Simulation own(b, scene_with({"springs", "actuation", "pressure", "drag"}));
  Simulation driven(b, scene_with({"springs", "pressure", "drag"}));
  auto effect = std::make_unique<ExternalActuation>(b, ExternalActuation::Mode::oscillator, true);
  ExternalActuation* act = effect.get();
  driven.add_effect(std::move(effect));
  EXPECT_TRUE(act->delayed_start());
  const double h = PhysicsParams{}.dt;
  long latest = 0;
  for (long k = 0; k < 1300; ++k) {
    if (k % 7 == 0) act->set_oscillators(a, phase);
    own.step();
    driven.step();
    ASSERT_EQ(
        std::vector<double>(driven.rest_lengths_now().begin(), driven.rest_lengths_now().end()),
        std::vector<double>(own.rest_lengths_now().begin(), own.rest_lengths_now().end()))
        << "step " << k;
    if (k == 0) {
      const std::vector<long> start = act->start_steps();
      for (int i = 0; i < b.node_count(); ++i) {
        const auto u = static_cast<std::size_t>(i);
        EXPECT_EQ(start[u], static_cast<long>(
                                std::ceil(actuation_start_time(b.frequency(i), b.phase(i)) / h)))
            << i;
        latest = std::max(latest, start[u]);
      }
    }
  }
  EXPECT_GT(latest, 10);  // the starts really are delayed
  EXPECT_EQ(driven.positions(), own.positions());
  EXPECT_EQ(driven.velocities(), own.velocities());
}

TEST(ExternalActuation, EvaluateEqualsTheBodysOscillatorsDrivenFromOutside) {
  // evaluate()'s distance is the distance of a swim whose actuation is external, set once to the
  // body's amplitudes and phases with delayed_start: the same number, not just a close one.
  Config c = small_config();
  c.evaluation.steps = 1100;
  // The first viable genome (from seed 5 on) with a cell whose start is delayed by 10 steps or more
  // (a saturated phase output, φ = 0 or 2π, starts at once).
  Genome g;
  Body body;
  for (std::uint64_t seed = 5;; ++seed) {
    ASSERT_LT(seed, 100u);
    g = viable_genome(c, seed);
    body = build_body(develop(g, c.genome, c.grn, c.development), c.body);
    double latest = 0.0;
    for (int i = 0; i < body.node_count(); ++i)
      latest = std::max(latest, actuation_start_time(body.frequency(i), body.phase(i)));
    if (latest >= 10 * c.physics.dt) break;
  }
  const EvaluationResult r = evaluate(g, c);
  ASSERT_TRUE(r.valid);
  ASSERT_GT(r.fitness, 0.0);
  SceneParams scene = c.scene;
  std::erase(scene.effects, std::string("actuation"));
  auto distance = [&](bool delayed_start) {
    Simulation sim(body, scene, c.physics);
    auto effect = std::make_unique<ExternalActuation>(body, ExternalActuation::Mode::oscillator,
                                                      delayed_start);
    effect->set_oscillators(values(body.amplitude), values(body.phase));
    sim.add_effect(std::move(effect));
    const Eigen::Vector2d start = sim.center_of_mass();
    sim.step(c.evaluation.steps);
    return (sim.center_of_mass() - start).norm();
  };
  EXPECT_EQ(distance(true), r.fitness);
  EXPECT_GT(std::abs(distance(false) - r.fitness),
            1e-6 * r.fitness);  // every cell started at once: another swim
}

TEST(ExternalActuation, ANewPhaseRestartsTheOscillatorAndRecountsAPendingStart) {
  Points p(3, 2);
  p << 0, 0, 1, 0, 0.5, 0.9;
  Vector f(3);
  f << 2.0, 0.1, 4.0;
  const Body b = build_body(p, Vector::Zero(3), f, Vector::Zero(3));
  const double h = PhysicsParams{}.dt;
  Simulation sim(b, scene_with({"springs"}));
  auto effect = std::make_unique<ExternalActuation>(b, ExternalActuation::Mode::oscillator, true);
  ExternalActuation* act = effect.get();
  sim.add_effect(std::move(effect));
  std::vector<double> a = {0.1, 0.2, 0.15}, phase = {0.3, 1.0, 2.0};
  act->set_oscillators(a, phase);
  sim.step(40);
  // cell 0 starts at (π − 0.3)/2 = 1.42 (step 86), cell 1 at (π − 1)/0.1 = 21.4, cell 2 at
  // (π − 2)/4 = 0.29 (step 18)
  const std::vector<long> start = act->start_steps();
  EXPECT_EQ(start[0], static_cast<long>(std::ceil((kPi - 0.3) / 2.0 / h)));
  EXPECT_EQ(start[2], static_cast<long>(std::ceil((kPi - 2.0) / 4.0 / h)));
  EXPECT_EQ(act->terms()[0], 0.0);
  EXPECT_NE(act->terms()[2], 0.0);
  // New phases at step 40 (t = 40 h): cell 1 has not started, so its start is recounted from now;
  // cell 2 has, and its oscillator is recomputed from its formula at once.
  phase = {0.3, 3.0, 0.5};
  act->set_oscillators(a, phase);
  sim.step();
  const double t = 40 * h;
  const std::vector<long> restart = act->start_steps();
  EXPECT_EQ(restart[0], start[0]);
  EXPECT_EQ(restart[1],
            40 + static_cast<long>(std::ceil(actuation_start_time(0.1, 0.1 * t + 3.0) / h)));
  EXPECT_EQ(restart[2], start[2]);
  EXPECT_EQ(act->terms()[2], 0.15 * std::sin(4.0 * t + 0.5));
  EXPECT_EQ(act->terms()[1], 0.0);
  sim.step(restart[1] - 41);
  EXPECT_EQ(act->terms()[1], 0.0);  // the step before its start
  sim.step();
  EXPECT_NEAR(act->terms()[1], 0.2 * std::sin(0.1 * static_cast<double>(restart[1]) * h + 3.0),
              1e-15);
  EXPECT_LT(std::abs(act->terms()[1]), 0.2 * 0.1 * h);  // it starts at a zero of its sine
  // Without delayed_start every cell oscillates from the first step on.
  ExternalActuation plain(b, ExternalActuation::Mode::oscillator);
  EXPECT_FALSE(plain.delayed_start());
  EXPECT_EQ(plain.start_steps(), (std::vector<long>{-1, -1, -1}));  // not decided before a step
  EXPECT_THROW(ExternalActuation(b, ExternalActuation::Mode::rest_length, true), ConfigError);
}

TEST(ExternalActuation, ControlLoopAllocatesNothing) {
  const Body b = swimmer(lattice_points(6, 4, 0.1, 2), Drive::random, 0.2, 4.0, 5);
  for (const bool delayed : {false, true}) {
    Simulation sim(b, scene_with({"springs", "pressure", "drag", "collisions"}));
    auto effect =
        std::make_unique<ExternalActuation>(b, ExternalActuation::Mode::oscillator, delayed);
    ExternalActuation* act = effect.get();
    sim.add_effect(std::move(effect));
    const std::vector<double> a = values(b.amplitude), phase = values(b.phase);
    std::vector<double> shifted = phase;
    for (double& v : shifted) v += 0.5;
    act->set_oscillators(a, phase);
    sim.step(10);
    g_allocations = 0;
    g_counting = true;
    for (int k = 0; k < 200; ++k) {
      act->set_oscillators(a, k % 50 < 25 ? phase : shifted);
      sim.step(4);
    }
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << "delayed_start " << delayed;
  }
}
