// The crawl world (issue 17, part 1): effects "gravity" and "ground" (a floor with Coulomb friction),
// the settling phase before the fitness clock, and the horizontal-distance objective. Values are
// asserted against the analytic solutions of the discrete scheme (symplectic Euler, as Box2D
// integrates) and of the continuous equations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/objective.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "physics_support.hpp"

namespace animat {
namespace {

/// A row of `n` cells on y = y0, spacing 1, neighbours linked by springs (a chain; skin = the chain).
Body row_block(int n, double y0 = 0.0) {
  std::vector<std::pair<double, double>> xy;
  std::vector<std::pair<int, int>> springs;
  for (int i = 0; i < n; ++i) xy.emplace_back(static_cast<double>(i), y0);
  for (int i = 0; i + 1 < n; ++i) springs.emplace_back(i, i + 1);
  return make_body(points(xy), springs, {}, springs);
}

/// Two rows of three cells (a 2 × 1 box split into four triangles), bottom row on y = 0.
Body two_row_block() {
  const Points p = points({{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}});
  return make_body(p, {{0, 1}, {1, 2}, {3, 4}, {4, 5}, {0, 3}, {1, 4}, {2, 5}, {0, 4}, {1, 5}},
                   {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}}, {{0, 1}, {1, 2}, {2, 5}, {5, 4}, {4, 3}, {3, 0}});
}

SceneParams floor_scene(std::vector<std::string> effects, double g = 2.0, double mu_s = 0.8, double mu_k = 0.5) {
  SceneParams s = scene_with(std::move(effects));
  s.gravity = g;
  s.ground_friction_static = mu_s;
  s.ground_friction_kinetic = mu_k;
  return s;
}

double min_y(const Simulation& sim) {
  const SwimState& s = sim.state();
  return *std::min_element(s.y.begin(), s.y.end());
}

/// Mechanical energy: kinetic + gravitational (above the floor) + elastic springs.
double mechanical_energy(const Simulation& sim, const Body& body, double g, double y0) {
  const SwimState& s = sim.state();
  double e = sim.kinetic_energy();
  for (int i = 0; i < s.n; ++i) e += s.mass * g * (s.y[static_cast<std::size_t>(i)] - y0);
  const double k = sim.scene().spring_stiffness;
  for (int sp = 0; sp < body.spring_count(); ++sp) {
    const auto i = static_cast<std::size_t>(body.springs(sp, 0)), j = static_cast<std::size_t>(body.springs(sp, 1));
    const double len = std::hypot(s.x[j] - s.x[i], s.y[j] - s.y[i]);
    e += 0.5 * k * (len - body.rest_lengths(sp)) * (len - body.rest_lengths(sp));
  }
  return e;
}

// Box2D keeps positions in float: near coordinates of size ~10 one rounding is ~1e-6, and a few
// hundred steps accumulate at most a few hundred of them.
constexpr double kFloatPosition = 1e-3;

TEST(Gravity, FreeFallIsAnalytic) {
  // One cell, gravity only, from rest at y = 30. Symplectic Euler: v_n = −g·n·h exactly, and
  // y_n = y_0 − g·h²·n(n+1)/2, which differs from the continuous ½·g·t² by ½·g·h·t.
  const double g = 2.0, y_start = 30.0;
  Simulation sim(make_body(points({{0.0, y_start}}), {}, {}, {}), floor_scene({"gravity"}, g));
  const double h = sim.physics().dt;
  const long n = 300;
  sim.step(n);
  const double t = static_cast<double>(n) * h;
  const Points v = sim.velocities(), p = sim.positions();
  EXPECT_NEAR(v(0, 1), -g * t, 1e-5 * g * t);
  EXPECT_EQ(v(0, 0), 0.0);
  const double discrete = y_start - g * h * h * static_cast<double>(n * (n + 1)) / 2.0;
  EXPECT_NEAR(p(0, 1), discrete, kFloatPosition);
  const double continuous = y_start - 0.5 * g * t * t;
  EXPECT_NEAR(p(0, 1), continuous, 0.5 * g * h * t + kFloatPosition);
  EXPECT_EQ(p(0, 0), 0.0);
  EXPECT_EQ(sim.counters().ground_contacts, 0);
}

TEST(Ground, AbsentEffectsAreNotInTheLoop) {
  Simulation sim(square(), SceneParams{});
  EXPECT_EQ(sim.effect("gravity"), nullptr);
  Simulation pair(two_nodes(1.0, 1.0), SceneParams{});
  EXPECT_EQ(pair.effect("ground"), nullptr);
  EXPECT_EQ(sim.effect("ground"), nullptr);
  Simulation crawl(square(), floor_scene({"springs", "gravity", "ground"}));
  ASSERT_NE(crawl.effect("ground"), nullptr);
  EXPECT_EQ(crawl.effect("ground")->stage(), Effect::Stage::constraint);
  EXPECT_EQ(crawl.effect("gravity")->stage(), Effect::Stage::force);
}

TEST(Ground, BlockBelowTheStaticLimitStaysAtRest) {
  // A row of cells on the floor, each pushed sideways by F = 0.99·μ_s·m·g: Coulomb's law says it
  // sticks; the impulse form sticks exactly (the cells never move).
  const double g = 2.0, mu_s = 0.8;
  Simulation sim(row_block(4), floor_scene({"springs", "gravity", "ground"}, g, mu_s));
  sim.add_effect(std::make_unique<ConstantForce>(0.99 * mu_s * g, 0.0));
  const Points p0 = sim.positions();
  for (int k = 0; k < 600; ++k) {
    sim.step();
    ASSERT_GE(min_y(sim), -1e-6);
  }
  const Points p1 = sim.positions();
  EXPECT_LT((p1 - p0).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(sim.velocities().cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(sim.counters().ground_contacts, 600L * 4);  // every cell, every step
  EXPECT_EQ(sim.counters().ground_slips, 0);
}

TEST(Ground, TwoRowBlockBelowTheStaticLimitDoesNotSlide) {
  // A block whose top row rests on the bottom row through springs: after settling, a sideways
  // force per cell F = μ_s·m·g/4 (total 6F, well below μ_s·N = μ_s·6·m·g even with the transient
  // overshoot of the springs and the tilting moment) shears the block elastically but its floor
  // cells never slip.
  const double g = 2.0, mu_s = 0.8;
  const Body b = two_row_block();
  Simulation sim(b, floor_scene({"springs", "pressure", "collisions", "gravity", "ground"}, g, mu_s));
  sim.step(600);  // settle
  const Points p0 = sim.positions();
  const long slips0 = sim.counters().ground_slips;
  sim.add_effect(std::make_unique<ConstantForce>(0.25 * mu_s * g, 0.0));
  for (int k = 0; k < 900; ++k) {
    sim.step();
    ASSERT_GE(min_y(sim), -1e-6);
  }
  const Points p1 = sim.positions();
  for (int i : {0, 1, 2}) EXPECT_LT(std::abs(p1(i, 0) - p0(i, 0)), 1e-6) << "floor cell " << i;
  EXPECT_EQ(sim.counters().ground_slips, slips0);
  EXPECT_GT(p1(4, 0) - p0(4, 0), 1e-4);  // the top row did shear
}

TEST(Ground, BlockAboveTheStaticLimitSlidesWithKineticFriction) {
  // F = 1.5·μ_s·m·g per cell: the block slides with a = F/m − μ_k·g. Discrete: v_n = a·n·h and
  // x_n − x_0 = a·h²·n(n+1)/2 (the first step already slides).
  const double g = 2.0, mu_s = 0.8, mu_k = 0.5;
  const double f = 1.5 * mu_s * g;
  Simulation sim(row_block(3), floor_scene({"springs", "gravity", "ground"}, g, mu_s, mu_k));
  sim.add_effect(std::make_unique<ConstantForce>(f, 0.0));
  const double h = sim.physics().dt;
  const Points p0 = sim.positions();
  const long n = 240;
  sim.step(n);
  const double a = f - mu_k * g;
  const double t = static_cast<double>(n) * h;
  const Points v = sim.velocities(), p = sim.positions();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(v(i, 0), a * t, 1e-5 * a * t) << i;
    EXPECT_NEAR(p(i, 0) - p0(i, 0), a * h * h * static_cast<double>(n * (n + 1)) / 2.0, kFloatPosition) << i;
    EXPECT_NEAR(p(i, 0) - p0(i, 0), 0.5 * a * t * t, 0.5 * a * h * t + kFloatPosition) << i;
    EXPECT_NEAR(v(i, 1), 0.0, 1e-6);
  }
  EXPECT_EQ(sim.counters().ground_slips, n * 3);
}

TEST(Ground, LaunchedBlockDeceleratesAtMuKGAndStops) {
  // A row launched at v0 with no applied force: v(t) = v0 − μ_k·g·t until it stops after
  // t* = v0/(μ_k·g), having slid v0²/(2·μ_k·g) (± one step of travel); then static friction holds it.
  const double g = 2.0, mu_s = 0.8, mu_k = 0.5, v0 = 3.0;
  Simulation sim(row_block(3), floor_scene({"springs", "gravity", "ground"}, g, mu_s, mu_k));
  sim.set_velocities(Points::Constant(3, 2, 0.0).rowwise() + Eigen::RowVector2d(v0, 0.0));
  const double h = sim.physics().dt;
  const Points p0 = sim.positions();
  sim.step(60);
  EXPECT_NEAR(sim.velocities()(1, 0), v0 - mu_k * g * 60 * h, 1e-5 * v0);
  sim.step(600);  // t* = 3 time units = 180 steps
  EXPECT_LT(sim.velocities().cwiseAbs().maxCoeff(), 1e-6);
  const double slid = sim.positions()(1, 0) - p0(1, 0);
  EXPECT_NEAR(slid, v0 * v0 / (2.0 * mu_k * g), v0 * h + kFloatPosition);
  const Points p_stop = sim.positions();
  sim.step(120);
  EXPECT_LT((sim.positions() - p_stop).cwiseAbs().maxCoeff(), 1e-6);  // stays stopped
}

TEST(Ground, DroppedBodyEnergyNeverGrowsAndNoCellGoesBelowTheFloor) {
  // A lattice body dropped from 3 length units above a floor at y0 = −2.5 (not 0, to test the
  // height key): mechanical energy (kinetic + gravitational + elastic) never exceeds its initial
  // value (the floor is inelastic, friction and spring damping dissipate, and symplectic Euler loses
  // ½·m·g²·h² per cell and free-fall step), and no cell centre is ever below the floor beyond float
  // rounding of the positions.
  const double g = 2.0, y0 = -2.5;
  Body b = swimmer(lattice_points(4, 3), Drive::none);
  b.positions.col(1).array() += y0 + 3.0;
  SceneParams scene = floor_scene({"springs", "collisions", "gravity", "ground"}, g);
  scene.ground_height = y0;
  Simulation sim(b, scene);
  const Body sb = swim_body(b);
  const double e0 = mechanical_energy(sim, sb, g, y0);
  double e_max = e0, lowest = 1e9;
  for (int k = 0; k < 1200; ++k) {
    sim.step();
    e_max = std::max(e_max, mechanical_energy(sim, sb, g, y0));
    lowest = std::min(lowest, min_y(sim));
  }
  EXPECT_LE(e_max, e0);
  EXPECT_GE(lowest, y0 - 1e-6);
  EXPECT_LT(lowest, y0 + 1e-3);  // it did land
  EXPECT_GT(sim.counters().ground_contacts, 0);
  EXPECT_LT(sim.kinetic_energy(), 1e-3 * e0);  // and came to rest
}

TEST(Ground, ActuatedBodyNeverGoesBelowTheFloor) {
  // A driven lattice on the floor, every Box2D step checked.
  SceneParams scene = floor_scene({"springs", "actuation", "pressure", "collisions", "gravity", "ground"}, 1.0);
  Body b = swimmer(lattice_points(5, 3, 0.05, 3), Drive::wave, 0.15, 4.0);
  b.positions.col(1).array() -= b.positions.col(1).minCoeff();
  Simulation sim(b, scene);
  double lowest = 1e9;
  for (int k = 0; k < 1500; ++k) {
    sim.step();
    lowest = std::min(lowest, min_y(sim));
  }
  EXPECT_GE(lowest, -1e-6);
  EXPECT_GT(sim.counters().ground_contacts, 0);
}

TEST(Ground, ConfigErrorsNameKeyAndValue) {
  SceneParams s;
  s.ground_friction_static = 0.3;
  s.ground_friction_kinetic = 0.5;
  try {
    validate(s);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.ground_friction_kinetic"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.5"), std::string::npos) << e.what();
  }
  SceneParams neg;
  neg.gravity = -1.0;
  try {
    validate(neg);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.gravity"), std::string::npos) << e.what();
  }
  Config c;
  c.evaluation.objective = "distance_per_energy";
  c.evaluation.energy_offset = 0.0;
  EXPECT_THROW((void)make_objective(c.evaluation), ConfigError);
}

// --- settling and the crawl swim ------------------------------------------------------------------

TEST(Settle, BodyIsPlacedOnTheFloorAndFallingIsNotCounted) {
  // A still body (no actuation amplitude) high above the floor: swim() places its lowest cell on
  // the floor, settles it, and the measured swim then barely moves (the settling sag is not counted).
  SceneParams scene = floor_scene({"springs", "actuation", "pressure", "collisions", "gravity", "ground"}, 1.0);
  Body b = swimmer(lattice_points(5, 3), Drive::none);
  b.positions.col(1).array() += 7.0;
  PhysicsParams physics;
  SwimOptions settled;
  settled.settle_steps = 600;
  const SwimResult r = swim(b, scene, physics, 300, settled);
  ASSERT_TRUE(r.valid) << r.failure;
  EXPECT_EQ(r.settle_steps, 600);
  EXPECT_LT(r.distance, 1e-3);
  EXPECT_GT(r.ground_contacts, 0);
  // Without settling the sag onto the floor is part of the displacement (still no fall of 7 units).
  const SwimResult raw = swim(b, scene, physics, 300);
  ASSERT_TRUE(raw.valid) << raw.failure;
  EXPECT_EQ(raw.settle_steps, 0);
  EXPECT_GT(raw.distance, 10.0 * r.distance);
  EXPECT_LT(raw.distance, 0.5);
}

TEST(Settle, ZeroSettleStepsWithoutGroundIsTheOldSwimBitForBit) {
  const Body b = swimmer(lattice_points(5, 3, 0.05, 3), Drive::wave, 0.15, 4.0);
  SwimOptions zero;
  zero.settle_steps = 0;
  const SwimResult a = swim(b, SceneParams{}, PhysicsParams{}, 400, zero);
  const SwimResult c = swim(b, SceneParams{}, PhysicsParams{}, 400);
  EXPECT_EQ(a.displacement.x(), c.displacement.x());
  EXPECT_EQ(a.displacement.y(), c.displacement.y());
  EXPECT_EQ(a.ground_contacts, 0);
}

TEST(Settle, ShippedCrawlPresetLoadsAndCrawls) {
  const Config c = load_config(std::string(ANIMAT_SOURCE_DIR) + "/configs/crawl.toml");
  EXPECT_TRUE(has_effect(c.scene.effects, "gravity"));
  EXPECT_TRUE(has_effect(c.scene.effects, "ground"));
  EXPECT_FALSE(has_effect(c.scene.effects, "drag"));
  EXPECT_GT(c.evaluation.settle_steps, 0);
  EXPECT_EQ(c.evaluation.objective, "distance_x");
  // A driven body crawls: it moves horizontally, its cells touch the floor, and it stays valid.
  Body b = swimmer(lattice_points(5, 3, 0.05, 3), Drive::wave, 0.15, 4.0);
  SwimOptions options;
  options.settle_steps = c.evaluation.settle_steps;
  const SwimResult r = swim(b, c.scene, c.physics, 1200, options);
  ASSERT_TRUE(r.valid) << r.failure;
  EXPECT_GT(r.ground_contacts, 0);
  EXPECT_GT(std::abs(r.displacement.x()), 1e-3);
}

TEST(Objective, DistanceXAndEnergyObjectives) {
  EvaluationRecord rec;
  rec.result.viable = true;
  rec.result.fitness = 5.0;
  rec.result.displacement = Eigen::Vector2d(-3.0, 4.0);
  rec.result.actuation_work_positive = 200.0;
  EvaluationParams p;
  p.objective = "distance_x";
  EXPECT_DOUBLE_EQ(make_objective(p)->value(rec), 3.0);
  p.objective = "distance_minus_energy";
  p.energy_weight = 0.01;
  EXPECT_DOUBLE_EQ(make_objective(p)->value(rec), 5.0 - 2.0);
  p.objective = "distance_per_energy";
  p.energy_offset = 50.0;
  EXPECT_DOUBLE_EQ(make_objective(p)->value(rec), 5.0 / 250.0);
}

}  // namespace
}  // namespace animat
