// The native integrator (src/cell_integrator.hpp) against Box2D itself: it must move the cells
// bit for bit as b2World::Step does, so that physics.integrator = "native" (the default) and
// "box2d" give the same swims, developments and fitnesses.
#include <box2d/box2d.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>
#include "../../src/box2d_island.hpp"
#include "../../src/cell_integrator.hpp"

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
// physics_support.hpp's helpers this file does not need
#pragma GCC diagnostic ignored "-Wunused-function"
#include "physics_support.hpp"

namespace animat {
namespace {

std::uint32_t bits(float x) { return std::bit_cast<std::uint32_t>(x); }

/// Cells as the swim and development worlds made them before the native integrator: fixture-less,
/// fixed-rotation dynamic bodies with SetMassData, sleeping, continuous physics and warm starting
/// off, optionally linked into one island by zero-force friction joints.
struct Box2DCells {
  b2World world{b2Vec2(0.0f, 0.0f)};
  std::vector<b2Body*> bodies;
  Box2DCells(const CellIntegrator& init, float damping, bool linked) {
    world.SetAllowSleeping(false);
    world.SetContinuousPhysics(false);
    world.SetWarmStarting(false);
    b2MassData mass;
    mass.mass = init.mass;
    mass.center.SetZero();
    mass.I = 0.0f;
    for (std::size_t i = 0; i < init.size(); ++i) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.position.Set(init.px[i], init.py[i]);
      def.linearVelocity.Set(init.vx[i], init.vy[i]);
      def.linearDamping = damping;
      def.fixedRotation = true;
      def.allowSleep = false;
      b2Body* b = world.CreateBody(&def);
      b->SetMassData(&mass);
      bodies.push_back(b);
    }
    if (linked) link_into_one_island(world, bodies);
  }
  void step(float h, const std::vector<double>& fx, const std::vector<double>& fy) {
    for (std::size_t i = 0; i < bodies.size(); ++i)
      bodies[i]->ApplyForceToCenter(b2Vec2(static_cast<float>(fx[i]), static_cast<float>(fy[i])),
                                    true);
    world.Step(h, 1, 1);
  }
};

struct Case {
  double mass;
  float damping;
  float h;
  bool linked;
};

class IntegratorVersusBox2D : public ::testing::TestWithParam<Case> {};

TEST_P(IntegratorVersusBox2D, SamePositionsAndVelocitiesBitForBit) {
  const Case c = GetParam();
  constexpr int n = 32;
  Rng rng(11);
  CellIntegrator cells;
  cells.set_mass(c.mass);
  cells.damping = c.damping;
  for (int i = 0; i < n; ++i)
    cells.add(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0), rng.uniform(-1.0, 1.0), 0.0);
  Box2DCells box2d(cells, c.damping, c.linked);
  std::vector<double> fx(n), fy(n);
  long clamped = 0;
  for (int step = 0; step < 3000; ++step) {
    for (int i = 0; i < n; ++i) {
      const double r = rng.uniform(0.0, 1.0);
      // Every kind of force: none (never applied, or +-0), ordinary, tiny, and huge (Box2D's
      // translation cap then scales the velocity down: that branch must match as well).
      const double scale = r < 0.1 ? 0.0 : r < 0.15 ? 1e-30 : r < 0.2 ? 1e6 : 50.0;
      fx[i] = scale * rng.uniform(-1.0, 1.0);
      fy[i] = r < 0.05 ? -0.0 : scale * rng.uniform(-1.0, 1.0);
    }
    for (int i = 0; i < n; ++i) {
      const float tx = c.h * (cells.vx[i] + c.h * cells.inv_mass * static_cast<float>(fx[i]));
      if (std::abs(tx) > b2_maxTranslation) ++clamped;
    }
    cells.step(c.h, fx.data(), fy.data());
    box2d.step(c.h, fx, fy);
    for (int i = 0; i < n; ++i) {
      const b2Body* b = box2d.bodies[static_cast<std::size_t>(i)];
      ASSERT_EQ(bits(cells.px[i]), bits(b->GetPosition().x)) << "step " << step << " cell " << i;
      ASSERT_EQ(bits(cells.py[i]), bits(b->GetPosition().y)) << "step " << step << " cell " << i;
      // The linking joints may turn a -0 velocity into +0 (their zero impulse is subtracted);
      // values are the same, and positions (above) are bitwise equal either way.
      if (c.linked) {
        ASSERT_EQ(cells.vx[i], b->GetLinearVelocity().x) << "step " << step << " cell " << i;
        ASSERT_EQ(cells.vy[i], b->GetLinearVelocity().y) << "step " << step << " cell " << i;
      } else {
        ASSERT_EQ(bits(cells.vx[i]), bits(b->GetLinearVelocity().x))
            << "step " << step << " cell " << i;
        ASSERT_EQ(bits(cells.vy[i]), bits(b->GetLinearVelocity().y))
            << "step " << step << " cell " << i;
      }
    }
    // Keep the cells within a box (as a body holds together) by resetting the far ones, both ways.
    for (int i = 0; i < n; ++i) {
      if (std::abs(cells.px[i]) < 1e4f && std::abs(cells.py[i]) < 1e4f) continue;
      cells.px[i] = cells.py[i] = cells.vx[i] = cells.vy[i] = 0.0f;
      b2Body* b = box2d.bodies[static_cast<std::size_t>(i)];
      b->SetTransform(b2Vec2(0.0f, 0.0f), 0.0f);
      b->SetLinearVelocity(b2Vec2(0.0f, 0.0f));
    }
  }
  EXPECT_GT(clamped, 0) << "the translation cap must have been exercised";
}

INSTANTIATE_TEST_SUITE_P(Cases, IntegratorVersusBox2D,
                         ::testing::Values(Case{1.0, 0.0f, 1.0f / 60.0f, true},  // the swim world
                                           Case{1.0, 0.0f, 1.0f / 60.0f, false},
                                           // another mass, dt/16
                                           Case{2.5, 0.0f, 1.0f / 960.0f, true},
                                           // the development world
                                           Case{1.0, 10.0f, 0.1f, true},
                                           Case{0.7, 3.0f, 0.05f, false}));

/// A whole swim, every built-in effect, with collisions (position corrections) and drag: the two
/// integrators give bitwise the same state after every control step.
TEST(IntegratorVersusBox2D, SwimsAreBitwiseTheSame) {
  for (const Drive drive : {Drive::wave, Drive::random}) {
    const Body body = swimmer(lattice_points(8, 4, 0.05), drive, 0.2, 6.0);
    SceneParams scene;
    scene.drag_normal = 0.5;
    PhysicsParams native, box2d;
    box2d.integrator = "box2d";
    Simulation a(body, scene, native), b(body, scene, box2d);
    for (int step = 0; step < 3000; ++step) {
      a.step();
      b.step();
      const SwimState& sa = a.state();
      const SwimState& sb = b.state();
      for (int i = 0; i < sa.n; ++i) {
        const auto u = static_cast<std::size_t>(i);
        ASSERT_EQ(sa.x[u], sb.x[u]) << "step " << step << " cell " << i;
        ASSERT_EQ(sa.y[u], sb.y[u]) << "step " << step << " cell " << i;
        ASSERT_EQ(sa.vx[u], sb.vx[u]) << "step " << step << " cell " << i;
        ASSERT_EQ(sa.vy[u], sb.vy[u]) << "step " << step << " cell " << i;
      }
    }
    EXPECT_EQ(a.counters().collisions, b.counters().collisions);
    EXPECT_EQ(a.center_of_mass(), b.center_of_mass());
    EXPECT_EQ(a.momentum(), b.momentum());
    EXPECT_EQ(a.kinetic_energy(), b.kinetic_energy());
    EXPECT_EQ(a.positions(), b.positions());
    EXPECT_EQ(a.velocities(), b.velocities());
  }
}

/// Whole evaluations (development + swim) of random viable genomes and of the shipped evolved
/// genomes: the same fitness, bit for bit, with either integrator.
TEST(IntegratorVersusBox2D, EvaluationsAreBitwiseTheSame) {
  Config native;
  Config box2d;
  box2d.physics.integrator = "box2d";
  Rng rng(5);
  int viable = 0;
  long collisions = 0;
  for (int tries = 0; tries < 3000 && viable < 4; ++tries) {
    const Genome g = random_genome(native.genome, rng);
    const EvaluationResult a = evaluate(g, native);
    if (!a.viable) continue;
    ++viable;
    const EvaluationResult b = evaluate(g, box2d);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.fitness), std::bit_cast<std::uint64_t>(b.fitness));
    EXPECT_EQ(a.collisions, b.collisions);
    collisions += a.collisions;
  }
  EXPECT_EQ(viable, 4);
  const auto dir = std::filesystem::path(ANIMAT_SOURCE_DIR) / "tests" / "data" / "evolved";
  int evolved = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path());
    std::stringstream text;
    text << in.rdbuf();
    const auto j = nlohmann::json::parse(text.str());
    // Each in the environment it evolved in (tests/cpp/test_collisions.cpp reads them the same
    // way).
    Config a_config;
    a_config.scene.drag_normal = j.at("drag_normal").get<double>();
    a_config.development.max_cells = j.at("max_cells").get<int>();
    a_config.development.frequency_max = j.at("frequency_max").get<double>();
    a_config.scene.pressure = j.at("pressure").get<double>();
    a_config.scene.pressure_area_floor = j.at("pressure_area_floor").get<double>();
    Config b_config = a_config;
    b_config.physics.integrator = "box2d";
    const Genome g =
        genome_from_json(j.at("genome").dump(), a_config.genome, entry.path().string());
    const EvaluationResult a = evaluate(g, a_config);
    const EvaluationResult b = evaluate(g, b_config);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.fitness), std::bit_cast<std::uint64_t>(b.fitness))
        << entry.path();
    EXPECT_EQ(a.collisions, b.collisions) << entry.path();
    collisions += a.collisions;
    ++evolved;
  }
  EXPECT_GE(evolved, 5);
  EXPECT_GT(collisions, 0) << "collisions (position corrections) must have been exercised";
}

}  // namespace
}  // namespace animat
