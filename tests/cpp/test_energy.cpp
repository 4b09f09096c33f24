// Energy accounting (include/animat/energy.hpp): the books of a swim close, on analytic cases (a
// free edge in the fluid, a damped spring, a compressed pressurised region, a body dropped on the
// floor, a push) and on the evolved swimmers of tests/data/evolved; keeping them changes no result.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/energy.hpp"
#include "animat/evaluate.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "evolved_support.hpp"
#include "physics_support.hpp"

namespace animat {
namespace {

/// The energy that flowed through the books: what came in plus what left, the scale against which
/// the residual is judged.
double throughput(const EnergyAccount& a) {
  return std::abs(a.actuation) + std::abs(a.external) + std::abs(a.dissipated()) +
         std::abs(a.kinetic_start - a.kinetic_end) + std::abs(a.elastic_start - a.elastic_end) +
         std::abs(a.pressure_start - a.pressure_end) + std::abs(a.gravity_start - a.gravity_end);
}

TEST(EnergyAccount, OffUntilAskedAndKeepingTheBooksChangesNoResult) {
  for (const Evolved& e : evolved_genomes()) {
    const Body body = body_of(e);
    SwimOptions plain, booked;
    booked.account_energy = true;
    const SwimResult a = swim(body, e.config.scene, e.config.physics, 1500, plain);
    const SwimResult b = swim(body, e.config.scene, e.config.physics, 1500, booked);
    EXPECT_FALSE(a.energy.measured) << e.name;
    EXPECT_TRUE(b.energy.measured) << e.name;
    // Bit for bit: the books read the forces, they never change them.
    EXPECT_EQ(a.distance, b.distance) << e.name;
    EXPECT_EQ(a.displacement, b.displacement) << e.name;
    EXPECT_EQ(a.final_kinetic_energy, b.final_kinetic_energy) << e.name;
    EXPECT_EQ(a.collisions, b.collisions) << e.name;
    EXPECT_EQ(a.actuation_work, b.actuation_work) << e.name;
    EXPECT_EQ(b.energy.actuation, b.actuation_work) << e.name;
  }
}

TEST(EnergyAccount, FreeEdgeLosesExactlyTheAnalyticKineticEnergyToDrag) {
  // One skin edge of length L = 1 between two cells of mass m, moving rigidly with speed u0 normal
  // (then tangential) to itself, drag only. The edge force −d·L·u|u| acts on mass 2m, so
  // du/dt = −c·u|u| with c = d·L/(2m), u(t) = u0/(1 + c·u0·t); the semi-implicit scheme is exact
  // for a free edge. The fluid takes m·(u0² − u(T)²), all of it through the part the edge moves in.
  SceneParams scene = scene_with({"drag"});
  scene.drag_normal = 2.0;
  scene.drag_tangential = 0.3;
  const double u0 = 1.5, m = scene.cell_mass;
  for (const bool normal : {true, false}) {
    Simulation sim(two_nodes(1.0, 1.0), scene);
    const double vx = normal ? 0.0 : u0, vy = normal ? u0 : 0.0;
    sim.set_velocities(points({{vx, vy}, {vx, vy}}));
    sim.account_energy();
    sim.step(600);
    const EnergyAccount a = sim.energy_account();
    const double d = normal ? scene.drag_normal : scene.drag_tangential;
    const double c = d * 1.0 / (2.0 * m);
    const double uT = u0 / (1.0 + c * u0 * sim.time());
    const double expected = m * (u0 * u0 - uT * uT);
    const double moving = normal ? a.drag_normal : a.drag_tangential;
    const double other = normal ? a.drag_tangential : a.drag_normal;
    // Float velocities (relative rounding 6e-8 per step) bound the agreement, not the scheme.
    EXPECT_NEAR(moving, expected, 1e-5 * expected) << (normal ? "normal" : "tangential");
    EXPECT_EQ(other, 0.0);
    EXPECT_NEAR(a.kinetic_start - a.kinetic_end, expected, 1e-5 * expected);
    EXPECT_LT(std::abs(a.residual()), 1e-6 * expected);
    EXPECT_DOUBLE_EQ(a.fluid_share(), 1.0);
  }
}

TEST(EnergyAccount, DampedSpringDissipatesTheElasticEnergyItStartedWith) {
  // Two cells joined by a spring stretched from 1 to 1.2, no fluid: the damper takes ½k·0.2² as the
  // oscillation dies out (reduced mass ½, decay rate c/(2μ) = 4 per time unit: e^−80 after t = 20).
  SceneParams scene = scene_with({"springs"});
  scene.spring_damping = 4.0;
  Simulation sim(two_nodes(1.2, 1.0), scene);
  sim.account_energy();
  const EnergyAccount start = sim.energy_account();
  // Positions are Box2D's floats: 1.2 is 1.2 ± 5e-8.
  EXPECT_NEAR(start.elastic_start, 0.5 * scene.spring_stiffness * 0.2 * 0.2,
              scene.spring_stiffness * 0.2 * 1e-7);
  sim.step(1200);
  const EnergyAccount a = sim.energy_account();
  const double e0 = 0.5 * scene.spring_stiffness * 0.04;
  EXPECT_LT(a.elastic_end + a.kinetic_end, 1e-12 * e0);  // at rest
  // The books close within 1 % of the energy that flowed (the criterion for every case here).
  EXPECT_LT(std::abs(a.residual()), 0.01 * throughput(a));
  EXPECT_NEAR(a.spring_damping, e0, 0.01 * e0);
  EXPECT_EQ(a.fluid(), 0.0);
}

TEST(EnergyAccount, CompressedRegionReturnsItsPressureEnergyToTheDampers) {
  // A unit square scaled by 0.8 about its centre (rest values from the unscaled square): springs
  // and pressure push it back, the dampers take the potential it started with.
  Body b = square();
  for (int i = 0; i < 4; ++i) b.positions.row(i) = 0.5 + 0.8 * (b.positions.row(i).array() - 0.5);
  SceneParams scene = scene_with({"springs", "pressure"});
  Simulation sim(b, scene);
  sim.account_energy();
  sim.step(1200);
  const EnergyAccount a = sim.energy_account();
  EXPECT_GT(a.pressure_start, 0.0);
  EXPECT_GT(a.elastic_start, 0.0);
  EXPECT_LT(a.pressure_end + a.elastic_end + a.kinetic_end,
            1e-9 * (a.pressure_start + a.elastic_start));
  EXPECT_LT(std::abs(a.residual()), 0.01 * throughput(a));
  EXPECT_NEAR(a.spring_damping, a.pressure_start + a.elastic_start,
              0.01 * (a.pressure_start + a.elastic_start));
}

TEST(EnergyAccount, BodyDroppedOnTheFloorBooksTheGroundAndGravity) {
  // A pressurised square dropped from y = 2 onto the floor at y = 0, under gravity: it lands,
  // bounces in its springs and comes to rest. The floor's impulses (inelastic in the normal
  // direction) and the dampers take the potential energy it lost.
  Body b = square();
  for (int i = 0; i < 4; ++i) b.positions(i, 1) += 2.0;
  SceneParams scene = scene_with({"springs", "pressure", "gravity", "ground"});
  scene.gravity = 1.0;
  Simulation sim(b, scene);
  sim.account_energy();
  sim.step(3000);
  const EnergyAccount a = sim.energy_account();
  EXPECT_GT(sim.counters().ground_contacts, 0);
  const double lost = a.gravity_start - a.gravity_end;
  // fell about 2 (sags a bit)
  EXPECT_NEAR(lost, 4.0 * scene.cell_mass * scene.gravity * 2.0, 0.05 * lost);
  EXPECT_GT(a.ground, 0.0);
  EXPECT_GT(a.spring_damping, 0.0);
  EXPECT_LT(std::abs(a.residual()), 0.01 * throughput(a));
}

TEST(EnergyAccount, CompliantFloorIsBookedAsTheGroundAndTheBooksClose) {
  // The same drop onto the compliant floor: its forces act in the velocity pass and are booked as
  // the floor's (what it still stores at the end, m·g·d/2 per resting cell, counts there too).
  Body b = square();
  for (int i = 0; i < 4; ++i) b.positions(i, 1) += 2.0;
  SceneParams scene = scene_with({"springs", "pressure", "gravity", "ground"});
  scene.gravity = 1.0;
  scene.ground_contact = "compliant";
  Simulation sim(b, scene);
  sim.account_energy();
  sim.step(3000);
  const EnergyAccount a = sim.energy_account();
  EXPECT_GT(sim.counters().ground_contacts, 0);
  const double lost = a.gravity_start - a.gravity_end;
  EXPECT_NEAR(lost, 4.0 * scene.cell_mass * scene.gravity * 2.0, 0.05 * lost);
  EXPECT_GT(a.ground, 0.0);
  EXPECT_EQ(a.other, 0.0);
  EXPECT_LT(std::abs(a.residual()), 0.01 * throughput(a));
}

TEST(EnergyAccount, FloorEventsInTheCollisionLoopAreBookedAsTheGround) {
  // A lattice dropped hard (g = 20, from 4 up) with collisions and ground: the floor contacts are
  // events of the collision loop, their impulses are still booked as the floor's, and the books
  // close up to the position corrections of the landings (a cell that lands at τ·h moved down for
  // τ·h only, the books assume the whole step), which are O(h): the residual shrinks with the step.
  double previous = 1.0;
  for (int refine : {1, 4, 16}) {
    Body b = swimmer(lattice_points(5, 3, 0.05, 11), Drive::none);
    b.positions.col(1).array() += 4.0 - b.positions.col(1).minCoeff();
    SceneParams scene = scene_with({"springs", "pressure", "collisions", "gravity", "ground"});
    scene.gravity = 20.0;
    PhysicsParams physics;
    physics.dt /= refine;
    Simulation sim(b, scene, physics);
    sim.account_energy();
    sim.step(1200L * refine);
    const EnergyAccount a = sim.energy_account();
    EXPECT_GT(sim.counters().ground_contacts, 0);
    EXPECT_GT(a.ground, 0.0);
    // fell about 4 (sags a bit)
    EXPECT_GT(a.gravity_start - a.gravity_end, 0.9 * 15.0 * 20.0 * 4.0);
    const double relative = std::abs(a.residual()) / throughput(a);
    std::printf("dt/%d: residual %.6g of throughput %.6g (%.4g)\n", refine, a.residual(),
                throughput(a), relative);
    EXPECT_LT(relative, 0.02) << refine;
    EXPECT_LT(relative, previous) << refine;
    previous = relative;
  }
}

TEST(EnergyAccount, PushIsBookedAsExternalEnergy) {
  Simulation sim(two_nodes(1.0, 1.0), scene_with({"springs", "drag"}));
  sim.account_energy();
  const std::vector<int> cells = {0, 1};
  sim.push(cells, Eigen::Vector2d(0.0, 2.0));  // each cell gets velocity 2: kinetic energy 2·½·m·4
  EXPECT_NEAR(sim.energy_account().external, 4.0, 1e-6);
  sim.step(600);
  const EnergyAccount a = sim.energy_account();
  EXPECT_NEAR(a.drag_normal, a.external - a.kinetic_end, 1e-5 * a.external);
  EXPECT_LT(std::abs(a.residual()), 1e-5 * a.external);
}

TEST(EnergyAccount, ElasticCollisionsDissipateNothingAndTheBooksClose) {
  // An evolved swimmer that collides hundreds of times per swim, without drag (as in the momentum
  // test of test_collisions.cpp): collisions are elastic, so they remove no energy beyond rounding.
  const auto genomes = evolved_genomes();
  const Evolved& e = named(genomes, "colliding_f12_dn0.5.json");
  SceneParams scene = e.config.scene;
  scene.effects = {"springs", "actuation", "pressure", "collisions"};
  Simulation sim(body_of(e), scene);
  sim.account_energy();
  sim.step(2000);
  const EnergyAccount a = sim.energy_account();
  EXPECT_GT(sim.counters().collisions, 50);
  EXPECT_LT(std::abs(a.collisions), 1e-3 * a.actuation);
  EXPECT_LT(std::abs(a.residual()), 0.01 * throughput(a));
}

TEST(EnergyAccount, EvolvedSwimmersBooksCloseWithinOnePercent) {
  // The hard cases selection found, in the environments they evolved in, over the paper's 4000
  // steps.
  for (const Evolved& e : evolved_genomes()) {
    SwimOptions options;
    options.account_energy = true;
    const SwimResult r = swim(body_of(e), e.config.scene, e.config.physics, 4000, options);
    const EnergyAccount& a = r.energy;
    SCOPED_TRACE(e.name);
    ASSERT_TRUE(r.valid);
    EXPECT_GT(a.actuation, 0.0);
    EXPECT_LT(std::abs(a.residual()), 0.01 * a.actuation);
    EXPECT_GT(a.drag_normal, 0.0);
    EXPECT_GE(a.drag_tangential, 0.0);
    EXPECT_GT(a.spring_damping, 0.0);
    EXPECT_GT(a.fluid_share(), 0.0);
    EXPECT_LT(a.fluid_share(), 1.0);
  }
}

}  // namespace
}  // namespace animat
