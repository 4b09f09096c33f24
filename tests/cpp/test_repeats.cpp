// evaluation.repeats: one developed body swum K times from slightly perturbed starts, the fitness
// the mean of the K objective values (docs/notes/evolution.md, "Repeated swims").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/objective.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "evolved_support.hpp"

namespace animat {
namespace {

/// An evolved swimmer in its own environment, over a short swim.
Evolved swimmer(long steps = 600) {
  Evolved e = evolved_genomes().at(0);
  e.config.evaluation.steps = static_cast<int>(steps);
  return e;
}

/// Keeps every repeat's result and scores it by a chosen field.
struct Capture final : RepeatScorer {
  std::vector<EvaluationResult> results;
  double (*score)(const EvaluationResult&) = [](const EvaluationResult& r) { return r.fitness; };
  EvaluationObserver* observer(int) override { return nullptr; }
  double value(int repeat, const EvaluationResult& r) override {
    EXPECT_EQ(repeat, static_cast<int>(results.size()));
    results.push_back(r);
    return score(r);
  }
};

/// The swim options evaluate() uses with the default evaluation keys.
SwimOptions options_with(const Points* offset) {
  SwimOptions o;
  o.start_offset = offset;
  return o;
}

/// An objective that keeps frame 0 (the start positions) and the body of every record it scores.
struct StartRecorder final : Objective {
  mutable std::vector<std::vector<double>> starts;
  mutable std::vector<Points> bodies;
  std::string name() const override { return "starts"; }
  bool needs_body() const override { return true; }
  long sample_every() const override { return 50; }
  double value(const EvaluationRecord& r) const override {
    const std::size_t n = static_cast<std::size_t>(r.body.node_count());
    starts.emplace_back(r.positions.begin(),
                        r.positions.begin() + static_cast<std::ptrdiff_t>(2 * n));
    bodies.push_back(r.body.positions);
    return r.result.fitness;
  }
};

}  // namespace

TEST(Repeats, OneRepeatIsTheOneSwimBitForBit) {
  const Evolved e = swimmer();
  const Config& c = e.config;
  ASSERT_EQ(c.evaluation.repeats, 1);
  const EvaluationResult r = evaluate(e.genome, c);
  const SwimResult s = swim(body_of(e), c.scene, c.physics, c.evaluation.steps);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.fitness, s.distance);
  EXPECT_EQ(r.displacement, s.displacement);
  EXPECT_EQ(r.max_speed, s.max_speed);
  EXPECT_EQ(r.fitness_spread, 0.0);
  // The objective layer and evaluate_repeats() with K = 1 are the same evaluation.
  const EvaluationResult o = evaluate(e.genome, c, *make_objective(c.evaluation));
  EXPECT_EQ(o.fitness, r.fitness);
  EXPECT_EQ(o.fitness_spread, 0.0);
  Capture capture;
  const EvaluationResult k = evaluate_repeats(e.genome, c, capture);
  EXPECT_EQ(k.fitness, r.fitness);
  EXPECT_EQ(k.displacement, r.displacement);
  ASSERT_EQ(capture.results.size(), 1u);
}

TEST(Repeats, ThreeRepeatsAreTheMeanOfThreeSwimsWhoseFirstIsUnperturbed) {
  Evolved e = swimmer();
  const EvaluationResult one = evaluate(e.genome, e.config);
  e.config.evaluation.repeats = 3;
  const Config& c = e.config;
  const EvaluationResult r = evaluate(e.genome, c);
  ASSERT_TRUE(r.valid) << (r.reasons.empty() ? "" : r.reasons.front());

  const Body body = body_of(e);
  std::vector<double> d;
  for (int j = 0; j < 3; ++j) {
    const Points offset = start_perturbation(j, body.node_count(), 1e-6);
    const SwimResult s =
        swim(body, c.scene, c.physics, c.evaluation.steps, options_with(j > 0 ? &offset : nullptr));
    ASSERT_TRUE(s.valid);
    d.push_back(s.distance);
  }
  EXPECT_EQ(d[0], one.fitness);  // repeat 0 is the unperturbed swim
  for (int j = 1; j < 3; ++j) {  // the others differ, slightly
    EXPECT_NE(d[static_cast<std::size_t>(j)], d[0]) << j;
    EXPECT_LT(std::abs(d[static_cast<std::size_t>(j)] - d[0]), 0.2 * d[0]) << j;
  }
  EXPECT_EQ(r.fitness, (d[0] + d[1] + d[2]) / 3.0);
  const double mean = r.fitness;
  const double sd = std::sqrt(((d[0] - mean) * (d[0] - mean) + (d[1] - mean) * (d[1] - mean) +
                               (d[2] - mean) * (d[2] - mean)) /
                              2.0);
  EXPECT_DOUBLE_EQ(r.fitness_spread, sd / mean);
  EXPECT_GT(r.fitness_spread, 0.0);
  // The diagnostics are repeat 0's.
  EXPECT_EQ(r.displacement, one.displacement);
  EXPECT_EQ(r.max_speed, one.max_speed);
  EXPECT_EQ(r.collisions, one.collisions);
  EXPECT_EQ(r.swim_steps, one.swim_steps);
  // The objective layer scores each repeat and averages: for distance, the same bits.
  const EvaluationResult o = evaluate(e.genome, c, *make_objective(c.evaluation));
  EXPECT_EQ(o.fitness, r.fitness);
  EXPECT_EQ(o.fitness_spread, r.fitness_spread);
}

TEST(Repeats, TheMinStatisticIsTheWorstRepeatAndKeepsTheSpreadAboutTheMean) {
  Evolved e = swimmer();
  e.config.evaluation.repeats = 3;
  const EvaluationResult mean = evaluate(e.genome, e.config);
  e.config.evaluation.repeat_statistic = "min";
  const EvaluationResult worst = evaluate(e.genome, e.config);
  ASSERT_TRUE(worst.valid) << (worst.reasons.empty() ? "" : worst.reasons.front());

  const Body body = body_of(e);
  const Config& c = e.config;
  double smallest = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j) {
    const Points offset = start_perturbation(j, body.node_count(), 1e-6);
    const SwimResult s =
        swim(body, c.scene, c.physics, c.evaluation.steps, options_with(j > 0 ? &offset : nullptr));
    ASSERT_TRUE(s.valid);
    smallest = std::min(smallest, s.distance);
  }
  EXPECT_EQ(worst.fitness, smallest);
  EXPECT_LT(worst.fitness, mean.fitness);  // the three repeats differ (the test above)
  EXPECT_EQ(worst.fitness_spread, mean.fitness_spread);
  EXPECT_EQ(worst.displacement, mean.displacement);
  // Through the objective layer too, and the guard's reference keeps the statistic.
  EXPECT_EQ(evaluate(e.genome, c, *make_objective(c.evaluation)).fitness, worst.fitness);
  EXPECT_EQ(reference_config(c).evaluation.repeat_statistic, "min");
}

TEST(Repeats, AnUnknownStatisticIsRefusedNamingKeyAndValue) {
  Evolved e = swimmer();
  e.config.evaluation.repeats = 2;
  e.config.evaluation.repeat_statistic = "median";
  try {
    (void)evaluate(e.genome, e.config);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("evaluation.repeat_statistic"), std::string::npos);
    EXPECT_NE(std::string(err.what()).find("median"), std::string::npos);
  }
}

TEST(Repeats, DeterministicForAnyThreadCount) {
  Evolved e = swimmer(400);
  e.config.evaluation.repeats = 3;
  const Config& c = e.config;
  const EvaluationResult a = evaluate(e.genome, c), b = evaluate(e.genome, c);
  EXPECT_EQ(a.fitness, b.fitness);
  EXPECT_EQ(a.fitness_spread, b.fitness_spread);
  std::vector<Genome> genomes;
  for (const Evolved& x : evolved_genomes()) genomes.push_back(x.genome);
  const FitnessFunction f = swim_fitness(c);
  const std::vector<Fitness> one = evaluate_all(genomes, f, 1);
  const std::vector<Fitness> two = evaluate_all(genomes, f, 2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].fitness, two[i].fitness) << i;
  EXPECT_EQ(one[0].fitness, a.fitness);
}

TEST(Repeats, ThePerturbationDisplacesEveryCellsStartByAFixedVector) {
  // Unit directions from Rng::derive(repeat, cell): the same for every call, none for repeat 0.
  const Points p1 = start_perturbation(1, 5, 1e-3), q1 = start_perturbation(1, 5, 1e-3);
  EXPECT_EQ(p1, q1);
  EXPECT_TRUE(start_perturbation(0, 5, 1e-3).isZero(0.0));
  EXPECT_NE(start_perturbation(2, 5, 1e-3), p1);
  EXPECT_EQ(start_perturbation(1, 3, 1e-3), p1.topRows(3));  // cell i's does not depend on n
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(p1.row(i).norm(), 1e-3, 1e-18) << i;

  // Every repeat's record starts at the built positions plus its displacement (as the swim's float
  // state holds them), and the body it sees is the body as built.
  Evolved e = swimmer(100);
  e.config.evaluation.repeats = 3;
  e.config.evaluation.repeat_perturbation = 0.01;
  const Body body = body_of(e);
  const int n = body.node_count();
  StartRecorder objective;
  const EvaluationResult r = evaluate(e.genome, e.config, objective);
  ASSERT_TRUE(r.valid);
  ASSERT_EQ(objective.starts.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    const Points d = start_perturbation(j, n, 0.01);
    EXPECT_EQ(objective.bodies[static_cast<std::size_t>(j)], body.positions) << j;
    const std::vector<double>& x = objective.starts[static_cast<std::size_t>(j)];
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 2; ++k)
        EXPECT_EQ(x[static_cast<std::size_t>(2 * i + k)],
                  static_cast<double>(static_cast<float>(body.positions(i, k) + d(i, k))))
            << "repeat " << j << " cell " << i;
  }
}

TEST(Repeats, BadValuesAreRefusedNamingKeyAndValue) {
  for (const char* o : {"evaluation.repeats=0", "evaluation.repeats=65", "evaluation.repeats=-1",
                        "evaluation.repeat_perturbation=0", "evaluation.repeat_perturbation=0.2",
                        "evaluation.repeat_perturbation=-1e-6"}) {
    Config c;
    try {
      apply_override(c, o);
      ADD_FAILURE() << o << " was accepted";
    } catch (const ConfigError& err) {
      const std::string key = std::string(o).substr(0, std::string(o).find('='));
      EXPECT_NE(std::string(err.what()).find(key), std::string::npos) << err.what();
    }
  }
  // A config that skipped validation is refused by the evaluation itself.
  const Evolved e = swimmer(10);
  Config c = e.config;
  c.evaluation.repeats = 0;
  try {
    (void)evaluate(e.genome, c);
    ADD_FAILURE() << "repeats = 0 was evaluated";
  } catch (const ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("evaluation.repeats = 0"), std::string::npos)
        << err.what();
  }
  c = e.config;
  c.evaluation.repeat_perturbation = std::nan("");
  EXPECT_THROW((void)evaluate(e.genome, c), ConfigError);
  c.evaluation.repeat_perturbation = 0.5;
  try {
    (void)evaluate(e.genome, c);
    ADD_FAILURE() << "repeat_perturbation = 0.5 was evaluated";
  } catch (const ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("evaluation.repeat_perturbation = 0.5"),
              std::string::npos)
        << err.what();
  }
}

TEST(Repeats, EveryRepeatKeepsTheEmbeddingAndItsEnergyBooksClose) {
  for (Evolved e : evolved_genomes()) {
    SCOPED_TRACE(e.name);
    e.config.evaluation.steps = 1500;
    e.config.evaluation.repeats = 3;
    e.config.evaluation.energy_accounting = true;
    Capture capture;
    const EvaluationResult r = evaluate_repeats(e.genome, e.config, capture);
    ASSERT_TRUE(r.valid) << (r.reasons.empty() ? "" : r.reasons.front());
    ASSERT_EQ(capture.results.size(), 3u);
    for (const EvaluationResult& x : capture.results) {
      EXPECT_TRUE(x.valid);
      EXPECT_GT(x.min_area_ratio, 0.0);
      EXPECT_EQ(x.inverted_region_steps, 0);
      EXPECT_EQ(x.skin_crossing_steps, 0);
      EXPECT_EQ(x.collisions_unresolved, 0);
      ASSERT_TRUE(x.energy.measured);
      EXPECT_GT(x.energy.actuation, 0.0);
      EXPECT_LT(std::abs(x.energy.residual()), 0.01 * x.energy.actuation);
    }
  }
}

TEST(Repeats, ChemotaxisSwimsEveryDirectionInEveryRepeat) {
  Evolved e = swimmer(300);
  e.config.evaluation.objective = "chemotaxis";
  e.config.evaluation.source_directions = 2;
  e.config.evaluation.repeats = 2;
  e.config.evaluation.repeat_perturbation = 1e-4;
  const Config& c = e.config;
  const Body body = body_of(e);
  double sum = 0.0;
  for (int j = 0; j < 2; ++j) {
    const Points offset = start_perturbation(j, body.node_count(), 1e-4);
    double progress = 0.0;
    for (int t = 0; t < 2; ++t) {
      SceneParams scene = c.scene;
      scene.chemical_source = source_direction(c, t);
      const SwimResult s =
          swim(body, scene, c.physics, c.evaluation.steps, options_with(j > 0 ? &offset : nullptr));
      ASSERT_TRUE(s.valid);
      const Eigen::Vector2d src(scene.chemical_source[0], scene.chemical_source[1]);
      progress += src.norm() - (src - s.displacement).norm();
    }
    sum += progress / 2;
  }
  const EvaluationResult r = evaluate(e.genome, c, *make_objective(c.evaluation));
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.fitness, sum / 2);
}

TEST(Repeats, TheExploitGuardsReferenceSwimsTheSameRepeats) {
  Evolved e = swimmer(200);
  e.config.evaluation.repeats = 2;
  e.config.evaluation.repeat_perturbation = 1e-5;
  const Config ref = reference_config(e.config);
  EXPECT_EQ(ref.evaluation.repeats, 2);
  EXPECT_EQ(ref.evaluation.repeat_perturbation, 1e-5);
  Capture capture;
  const EvaluationResult r = evaluate_repeats(e.genome, ref, capture);
  ASSERT_EQ(capture.results.size(), 2u);
  EXPECT_EQ(r.fitness, (capture.results[0].fitness + capture.results[1].fitness) / 2);
  EXPECT_EQ(swim_fitness(ref)(e.genome).fitness, r.fitness);
}

TEST(Repeats, ARepeatThatFailsMakesTheEvaluationInvalidAndSaysWhich) {
  // physics.max_step_displacement set to the largest step of the unperturbed swim (a check, not a
  // change of the motion): repeat 0 passes, and a perturbed repeat that steps farther is unstable.
  int failed = 0;
  for (Evolved e : evolved_genomes()) {
    SCOPED_TRACE(e.name);
    e.config.evaluation.steps = 600;
    const EvaluationResult one = evaluate(e.genome, e.config);
    ASSERT_TRUE(one.valid);
    e.config.physics.max_step_displacement = one.max_step_displacement;
    EXPECT_EQ(evaluate(e.genome, e.config).fitness, one.fitness);
    e.config.evaluation.repeats = 8;
    e.config.evaluation.repeat_perturbation = 1e-3;
    const EvaluationResult r = evaluate(e.genome, e.config);
    if (r.valid) continue;
    ++failed;
    EXPECT_FALSE(r.stable);
    EXPECT_EQ(r.fitness, 0.0);
    EXPECT_EQ(r.fitness_spread, 0.0);
    ASSERT_FALSE(r.reasons.empty());
    const std::string& why = r.reasons.back();
    EXPECT_EQ(why.rfind("repeat ", 0), 0u) << why;
    EXPECT_EQ(why.find("repeat 0 "), std::string::npos) << why;
    EXPECT_NE(why.find(" of 8: unstable swim"), std::string::npos) << why;
    EXPECT_EQ(r.displacement, one.displacement);  // the diagnostics stay repeat 0's
    EXPECT_EQ(evaluate(e.genome, e.config, *make_objective(e.config.evaluation)).fitness, 0.0);
  }
  EXPECT_GT(failed, 0);
}

}  // namespace animat
