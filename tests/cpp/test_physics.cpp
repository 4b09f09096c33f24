// Swimming physics (paper §4, docs/model.md §4): analytic checks of every effect, conservation
// laws, "off means off", the stable drag scheme, error detection, and the named stability cases. No
// timing assertions anywhere.
#include <box2d/box2d.h>
#include <gtest/gtest.h>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <numbers>
#include <string>
#include <vector>

#include "../../src/box2d_island.hpp"
#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "animat/scene.hpp"
#include "physics_support.hpp"

// Counting allocator: proves the swim loop allocates nothing.
#include "counting_allocator.hpp"

namespace animat {
namespace {

double signed_area(const Points& p, const std::vector<int>& loop) { return polygon_area(p, loop); }

// --- world setup
// -------------------------------------------------------------------------------------

TEST(SwimWorld, OneFixturelessBodyPerCellEqualMassesNoSleepNoGravity) {
  const Body b = swimmer(lattice_points(8, 4), Drive::wave);
  SceneParams scene;  // every built-in effect, skin collision included
  scene.cell_mass = 2.5;
  PhysicsParams physics;
  physics.integrator = "box2d";  // a real world to inspect (the native integrator has none)
  Simulation sim(b, scene, physics);
  b2World& w = sim.world();
  EXPECT_EQ(w.GetBodyCount(), b.node_count());
  EXPECT_EQ(w.GetContactCount(), 0);
  EXPECT_FALSE(w.GetAllowSleeping());
  EXPECT_FALSE(w.GetContinuousPhysics());
  EXPECT_EQ(w.GetGravity().x, 0.0f);
  EXPECT_EQ(w.GetGravity().y, 0.0f);
  for (b2Body* body = w.GetBodyList(); body; body = body->GetNext()) {
    EXPECT_EQ(body->GetType(), b2_dynamicBody);
    EXPECT_EQ(body->GetFixtureList(), nullptr)
        << "no effect needs Box2D collisions, so no fixtures";
    EXPECT_FLOAT_EQ(body->GetMass(), 2.5f);
    EXPECT_FALSE(body->IsSleepingAllowed());
  }
  sim.step(200);
  EXPECT_EQ(w.GetContactCount(), 0);
  for (b2Body* body = w.GetBodyList(); body; body = body->GetNext()) EXPECT_TRUE(body->IsAwake());
}

TEST(SwimWorld, RejectsInvalidParamsAndBodies) {
  const Body b = two_nodes(1.0, 1.0);
  EXPECT_THROW(Simulation(b, scene_with({"springs", "buoyancy"})), ConfigError);
  EXPECT_THROW(Simulation(b, scene_with({"springs", "springs"})), ConfigError);
  PhysicsParams p;
  p.drag_scheme = "magic";
  EXPECT_THROW(Simulation(b, SceneParams{}, p), ConfigError);
  p = PhysicsParams{};
  p.dt = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Simulation(b, SceneParams{}, p), ConfigError);
  p = PhysicsParams{};
  p.substeps = 0;
  EXPECT_THROW(Simulation(b, SceneParams{}, p), ConfigError);
  SceneParams s;
  s.drag_normal = -1.0;
  EXPECT_THROW(Simulation(b, s), ConfigError);
  Body bad = b;
  bad.springs(0, 1) = 5;
  EXPECT_THROW(Simulation(bad, SceneParams{}), GeometryError);
  try {
    Simulation(b, scene_with({"springs", "buoyancy"}));
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("buoyancy"), std::string::npos) << e.what();
  }
}

TEST(SwimWorld, DefaultTangentialDragIsNormalOver200) {
  SceneParams s;
  s.drag_normal = 10.0;
  EXPECT_DOUBLE_EQ(tangential_drag(s), 0.05);
  s.drag_tangential = 0.3;
  EXPECT_DOUBLE_EQ(tangential_drag(s), 0.3);
}

// --- springs
// --------------------------------------------------------------------------------------

/// Zero crossings of len − L0 (linear interpolation) give the period.
double measured_period(Simulation& sim, double l0, int steps) {
  std::vector<double> crossings;
  double prev = sim.positions()(1, 0) - sim.positions()(0, 0) - l0;
  for (int k = 1; k <= steps; ++k) {
    sim.step();
    const double cur = sim.positions()(1, 0) - sim.positions()(0, 0) - l0;
    if ((prev < 0.0) != (cur < 0.0))
      crossings.push_back(sim.time() - sim.physics().dt * cur / (cur - prev));
    prev = cur;
  }
  EXPECT_GE(crossings.size(), 20u);
  return 2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(Springs, TwoNodePeriodMatchesAnalyticAtDefaultDt) {
  SceneParams scene = scene_with({"springs"});
  scene.spring_damping = 0.0;
  for (double k : {10.0, 30.0, 100.0}) {
    scene.spring_stiffness = k;
    Simulation sim(two_nodes(1.2, 1.0), scene);
    const double mu = scene.cell_mass / 2.0;
    const double expected = 2.0 * kPi * std::sqrt(mu / k);
    const double got = measured_period(sim, 1.0, 3000);
    EXPECT_NEAR(got / expected, 1.0, 0.01) << "k = " << k;
  }
}

/// The linear map (x, v) -> (x', v') of one Box2D step for a damped oscillator x'' = −ω²x − γv,
/// with the damping evaluated at the start velocity or at the predicted midpoint velocity.
Eigen::Matrix2d oscillator_step(double w2, double g, double h, bool midpoint) {
  Eigen::Matrix2d a;
  for (int c = 0; c < 2; ++c) {
    double x = c == 0 ? 1.0 : 0.0, v = c == 1 ? 1.0 : 0.0;
    double u = v;
    if (midpoint) u = v + 0.5 * h * (-w2 * x - g * v);
    v += h * (-w2 * x - g * u);
    x += h * v;
    a(0, c) = x;
    a(1, c) = v;
  }
  return a;
}

/// Solves AᵀQA − Q = −e₂e₂ᵀ (Q symmetric): then V(z) = zᵀQz falls by exactly v² at every step.
Eigen::Matrix2d lyapunov(const Eigen::Matrix2d& a) {
  Eigen::Matrix4d k;  // vec(AᵀQA) = (Aᵀ ⊗ Aᵀ) vec(Q), column-major vec
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q) k(i + 2 * j, p + 2 * q) = a(p, i) * a(q, j);
  const Eigen::Vector4d r(0.0, 0.0, 0.0, 1.0);
  const Eigen::Vector4d q = (Eigen::Matrix4d::Identity() - k).inverse() * r;
  Eigen::Matrix2d out;
  out << q(0), q(2), q(1), q(3);
  return 0.5 * (out + out.transpose());
}

TEST(Springs, DampingMakesEnergyDecayMonotonically) {
  // Box2D integrates with symplectic Euler (v += h·a; x += h·v); spring damping is evaluated at the
  // start velocity or at the predicted midpoint velocity (physics.velocity_forces). For the stretch
  // x and stretching speed v of a damped two-node spring (ω² = k/μ, γ = c/μ) a step is a linear map
  // A. Its discrete energy V = zᵀQz (AᵀQA − Q = −e₂e₂ᵀ, Q positive definite) falls by exactly v²
  // per step: V must fall at every single step. (For γ = 0 it is the conserved "shadow" energy; the
  // textbook energy ½μv² + ½kx² wobbles by O(ωh) within a period, so it must fall period by
  // period.)
  for (const std::string mode : {"midpoint", "start"}) {
    SceneParams scene = scene_with({"springs"});
    PhysicsParams physics;
    physics.velocity_forces = mode;
    Simulation sim(two_nodes(1.3, 1.0), scene, physics);
    const double mu = 0.5, k = scene.spring_stiffness, h = sim.physics().dt;
    const double w2 = k / mu, g = scene.spring_damping / mu;
    const Eigen::Matrix2d q = lyapunov(oscillator_step(w2, g, h, mode == "midpoint"));
    ASSERT_GT(q(0, 0), 0.0) << mode;
    ASSERT_GT(q.determinant(), 0.0) << mode;
    auto energy = [&](double& x, double& v) {
      const Points pos = sim.positions(), u = sim.velocities();
      x = pos(1, 0) - pos(0, 0) - 1.0;
      v = u(1, 0) - u(0, 0);
      return q(0, 0) * x * x + 2.0 * q(0, 1) * x * v + q(1, 1) * v * v;
    };
    double x, v;
    double prev = energy(x, v);
    const double v0 = prev, e0 = 0.5 * k * x * x;
    std::vector<double> per_period;
    const int period_steps = static_cast<int>(std::round(2.0 * kPi / std::sqrt(w2) / h));
    for (int s = 1; s <= 600; ++s) {
      sim.step();
      const double now = energy(x, v);
      // float state: round-off allowance
      EXPECT_LE(now, prev + 1e-6 * v0) << mode << " step " << s;
      prev = now;
      if (s % period_steps == 0) per_period.push_back(0.5 * mu * v * v + 0.5 * k * x * x);
    }
    ASSERT_GE(per_period.size(), 5u);
    for (std::size_t i = 1; i < per_period.size() && per_period[i - 1] > 1e-9 * e0; ++i)
      EXPECT_LT(per_period[i], per_period[i - 1]) << mode << " period " << i;
    EXPECT_LT(prev, 1e-4 * v0) << mode;
  }
}

TEST(Springs, MatchTrajectoryOfIndependentIntegrator) {
  // A trajectory computed without any of the simulation's effect code: symplectic Euler in double
  // for a damped two-node spring, damping at the start or the predicted midpoint velocity. Box2D
  // stores float, so they agree to float round-off.
  for (const std::string mode : {"midpoint", "start"}) {
    SceneParams scene = scene_with({"springs"});
    PhysicsParams physics;
    physics.velocity_forces = mode;
    Simulation sim(two_nodes(1.25, 1.0), scene, physics);
    const double k = scene.spring_stiffness, c = scene.spring_damping, h = sim.physics().dt;
    double x0 = 0.0, x1 = 1.25, v0 = 0.0, v1 = 0.0;
    for (int s = 0; s < 600; ++s) {
      const double elastic = k * ((x1 - x0) - 1.0);
      double u0 = v0, u1 = v1;
      if (mode == "midpoint") {
        const double f = elastic + c * (v1 - v0);
        u0 = v0 + 0.5 * h * f;
        u1 = v1 - 0.5 * h * f;
      }
      const double f = elastic + c * (u1 - u0);
      v0 += h * f;
      v1 -= h * f;
      x0 += h * v0;
      x1 += h * v1;
      sim.step();
      ASSERT_NEAR(sim.positions()(0, 0), x0, 2e-5) << mode << " " << s;
      ASSERT_NEAR(sim.positions()(1, 0), x1, 2e-5) << mode << " " << s;
    }
  }
}

// --- rest and conservation
// ---------------------------------------------------------------------------

TEST(Conservation, BodyAtRestStaysExactlyAtRest) {
  // All effects on, no actuation, no velocity: every force is exactly zero (the simulation measures
  // rest lengths and areas on the float positions Box2D holds), so nothing moves at all.
  Points p = lattice_points(6, 5, 0.15, 3);
  p(0, 0) = p(1, 0) - 1e-3;  // a near-coincident pair, too
  p(0, 1) = p(1, 1);
  const Body b = swimmer(p, Drive::none);
  Simulation sim(b, SceneParams{});
  const Points start = sim.positions();
  sim.step(1000);
  EXPECT_EQ(sim.positions(), start);
  EXPECT_EQ(sim.kinetic_energy(), 0.0);
}

TEST(Conservation, CentreOfMassFixedWithoutDrag) {
  // Springs, actuation, pressure and skin collision are internal, equal-and-opposite forces (and
  // pressure and collision are exact gradients), so with drag off the centre of mass must stay put.
  // Round-off bound: Box2D keeps positions and velocities in float (ε = 2^-24 ≈ 6e-8). Each step
  // rounds every velocity (a momentum random walk of ~ε·|v|·√n per step) and every position
  // (~ε·|x|); integrated over N = 4000 steps the COM random walk is ~h·N^1.5·ε·|v|/√n ≈ 1e-4 for
  // the most violent of these bodies (|v| ~ 10). We allow 1e-3 length units: 1/1000 of a cell
  // spacing, and thousands of times less than the same bodies swim with drag on.
  const SceneParams scene = scene_with({"springs", "actuation", "pressure", "skin_collision"});
  std::vector<Body> bodies = {swimmer(lattice_points(8, 4), Drive::wave, 0.2, 12.0),
                              swimmer(lattice_points(8, 4, 0.1, 5), Drive::random),
                              swimmer(lattice_points(8, 8, 0.2, 6), Drive::random, 0.2, 4.0, 11),
                              swimmer(lattice_points(4, 3), Drive::wave, 0.2, 1.0)};
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    Simulation sim(bodies[k], scene);
    const Eigen::Vector2d c0 = sim.center_of_mass();
    sim.step(4000);
    const double moved = (sim.center_of_mass() - c0).norm();
    EXPECT_LE(moved, 1e-3) << "body " << k;
    EXPECT_GT(sim.kinetic_energy(), 0.1) << "body " << k << " must actually move internally";
    Simulation with_drag(bodies[k], SceneParams{});
    const Eigen::Vector2d d0 = with_drag.center_of_mass();
    with_drag.step(4000);
    EXPECT_GT((with_drag.center_of_mass() - d0).norm(), 100.0 * std::max(moved, 1e-4))
        << "body " << k;
  }
}

// --- pressure -----------------------------------------------------------------------------------

Eigen::Vector2d total(const Simulation& sim) {
  Eigen::Vector2d s(0, 0);
  for (int i = 0; i < sim.node_count(); ++i)
    s += Eigen::Vector2d(sim.forces_x()[i], sim.forces_y()[i]);
  return s;
}

/// Forces of the pressure effect alone on `b` with its nodes moved to `p`.
Simulation pressure_at(Body b, const Points& p, double floor = 0.1) {
  SceneParams scene = scene_with({"pressure"});
  scene.pressure_area_floor = floor;
  b.rest_areas.resize(b.region_count());
  for (int r = 0; r < b.region_count(); ++r)
    b.rest_areas(r) = polygon_area(b.positions, b.regions[r]);
  const Points rest = b.positions;
  b.positions = p;  // rest areas stay those of the rest shape
  Simulation sim(b, scene);
  sim.compute_forces();
  return sim;
}

TEST(Pressure, ForcesOnAClosedRegionSumToZeroWithoutTorque) {
  const Body pentagon = make_body(points({{0, 0}, {2, -0.3}, {2.6, 1.2}, {1.1, 2.4}, {-0.4, 1.3}}),
                                  {}, {{0, 1, 2, 3, 4}}, {});
  Rng rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    Points p = pentagon.positions;
    for (int i = 0; i < p.rows(); ++i)
      p.row(i) += Eigen::RowVector2d(rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6));
    const Simulation sim = pressure_at(pentagon, p);
    double scale = 0.0, torque = 0.0;
    const Points q = sim.positions();
    for (int i = 0; i < sim.node_count(); ++i) {
      scale = std::max(scale, std::hypot(sim.forces_x()[i], sim.forces_y()[i]));
      torque += q(i, 0) * sim.forces_y()[i] - q(i, 1) * sim.forces_x()[i];
    }
    EXPECT_LE(total(sim).norm(), 1e-12 * std::max(scale, 1.0)) << trial;
    EXPECT_LE(std::abs(torque), 1e-11 * std::max(scale, 1.0)) << trial;
  }
}

TEST(Pressure, CompressedPushesOutStretchedPullsIn) {
  const Body sq = square();
  const Eigen::RowVector2d centre(0.5, 0.5);
  for (double scale : {0.8, 0.95, 1.05, 1.25}) {
    Points p = sq.positions;
    for (int i = 0; i < 4; ++i) p.row(i) = centre + scale * (sq.positions.row(i) - centre);
    const Simulation sim = pressure_at(sq, p);
    const double area = scale * scale;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d f(sim.forces_x()[i], sim.forces_y()[i]);
      const Eigen::Vector2d out = (p.row(i) - centre).transpose();
      if (scale < 1.0)
        EXPECT_GT(f.dot(out), 0.0) << "compressed region must push out, scale " << scale;
      else
        EXPECT_LT(f.dot(out), 0.0) << "stretched region must pull in, scale " << scale;
      // Eq. 3 per edge: c_p·L·(1 − S/S0) along each of the two adjacent normals, half to each end:
      // at a square corner that is c_p·L·(1 − S)/2 along each axis.
      // (The simulation sees Box2D's float positions: 1e-6 relative.)
      const double expected = SceneParams{}.pressure * scale * (1.0 - area) / 2.0;
      EXPECT_NEAR(std::abs(f.x()), std::abs(expected), 1e-6 * SceneParams{}.pressure);
      EXPECT_NEAR(std::abs(f.y()), std::abs(expected), 1e-6 * SceneParams{}.pressure);
    }
  }
}

TEST(Pressure, IsMinusTheGradientOfItsPotential) {
  // F = −∇[c_p·(S − S0)² / (2A)], A = max(S0, floor·Lmax²): checked by central differences.
  const Body pentagon = make_body(points({{0, 0}, {2, -0.3}, {2.6, 1.2}, {1.1, 2.4}, {-0.4, 1.3}}),
                                  {}, {{0, 1, 2, 3, 4}}, {});
  const double s0 = polygon_area(pentagon.positions, pentagon.regions[0]);
  Points p = pentagon.positions;
  p(2, 0) += 0.3;
  p(4, 1) -= 0.2;
  const Simulation sim = pressure_at(pentagon, p);
  const double cp = SceneParams{}.pressure;
  auto energy = [&](const Points& q) {
    const double s = polygon_area(q, pentagon.regions[0]);
    return cp * (s - s0) * (s - s0) / (2.0 * s0);
  };
  const double eps = 1e-6;
  for (int i = 0; i < 5; ++i)
    for (int c = 0; c < 2; ++c) {
      Points a = sim.positions(), b = sim.positions();
      a(i, c) += eps;
      b(i, c) -= eps;
      const double grad = (energy(a) - energy(b)) / (2.0 * eps);
      const double f = c == 0 ? sim.forces_x()[i] : sim.forces_y()[i];
      EXPECT_NEAR(f, -grad, 1e-6) << i << "," << c;
    }
}

TEST(Pressure, InvertedRegionIsPushedBackAndRecovers) {
  // A triangle whose apex is pushed through its base: signed area −S0/2.
  const Body tri = make_body(points({{0, 0}, {1, 0}, {0.5, 0.8}}), {{0, 1}, {1, 2}, {0, 2}},
                             {{0, 1, 2}}, {{0, 1}, {1, 2}, {0, 2}});
  Points inverted = tri.positions;
  inverted(2, 1) = -0.4;
  {
    const Simulation sim = pressure_at(tri, inverted);
    EXPECT_GT(sim.forces_y()[2], 0.0) << "the apex is pushed back up through the base";
    EXPECT_LT(sim.forces_y()[0], 0.0);
    EXPECT_LT(sim.forces_y()[1], 0.0);
  }
  // Pressure alone turns it the right way out.
  {
    Body b = tri;
    b.positions = inverted;
    Simulation sim(b, scene_with({"pressure"}));
    bool recovered = false;
    for (int s = 0; s < 600 && !recovered; ++s) {
      sim.step();
      recovered = signed_area(sim.positions(), tri.regions[0]) > 0.0;
    }
    EXPECT_TRUE(recovered);
  }
  // With damped springs it settles back to its rest shape, the right way out.
  {
    Body b = tri;
    b.positions = inverted;
    Simulation sim(b, scene_with({"springs", "pressure"}));
    sim.step(3000);
    EXPECT_NEAR(signed_area(sim.positions(), tri.regions[0]), 0.4, 0.01);
  }
}

TEST(Pressure, SliverRegionStiffnessIsBounded) {
  // A 1 × 0.01 rectangle: eq. 3 with S0 = 0.01 would be stiffness ~c_p/S0; the floor makes it
  // ~c_p/(floor·1). The force on a corner moved by δ is bounded accordingly.
  const Body sliver =
      make_body(points({{0, 0}, {1, 0}, {1, 0.01}, {0, 0.01}}), {}, {{0, 1, 2, 3}}, {});
  Points p = sliver.positions;
  p(2, 1) += 0.01;
  const Simulation floored = pressure_at(sliver, p, 0.1);
  const Simulation raw = pressure_at(sliver, p, 0.0);
  // (Lmax is measured on the given positions, here the 1.0001-long deformed top edge.)
  EXPECT_NEAR(std::abs(floored.forces_y()[2]) * 10.0 / std::abs(raw.forces_y()[2]), 1.0, 2e-4);
  EXPECT_LT(std::abs(floored.forces_y()[2]), SceneParams{}.pressure * 0.01 / 0.1);
}

// --- drag
// ---------------------------------------------------------------------------------------------

/// Steady velocity of `b` pushed by a total force (fx, fy), split over its cells in proportion to
/// their share of the skin length (half of each adjacent skin edge), i.e. in proportion to the drag
/// they feel: a chain of springs has no bending stiffness, and any other split would bend it.
double terminal_speed(const Body& b, double fx, double fy, const SceneParams& scene,
                      const std::string& scheme, int steps, int substeps = 1) {
  PhysicsParams physics;
  physics.drag_scheme = scheme;
  physics.substeps = substeps;
  Simulation sim(b, scene, physics);
  std::vector<double> share(static_cast<std::size_t>(b.node_count()), 0.0);
  double total_length = 0.0;
  for (int e = 0; e < b.skin.rows(); ++e) {
    const double l = dist(b.positions, b.skin(e, 0), b.skin(e, 1));
    share[static_cast<std::size_t>(b.skin(e, 0))] += 0.5 * l;
    share[static_cast<std::size_t>(b.skin(e, 1))] += 0.5 * l;
    total_length += l;
  }
  for (double& w : share) w /= total_length;
  sim.add_effect(std::make_unique<ConstantForce>(fx, fy, share));
  sim.step(steps);
  const Eigen::Vector2d c0 = sim.center_of_mass();
  const double t0 = sim.time();
  sim.step(600);
  return (sim.center_of_mass() - c0).norm() / (sim.time() - t0);
}

TEST(Drag, QuadraticTerminalVelocityNormalToARod) {
  // v = sqrt(F / (d_N·L)) for a straight rod (one skin edge of length L = 4) pulled normal to
  // itself. (A chain of several springs has no bending stiffness and buckles when dragged, so the
  // rod is one edge; the closed square below covers skin nodes shared by two edges.) All schemes,
  // at the default dt, wherever one explicit step removes at most half the velocity (x = h·d·L·v/M
  // <= 1/2, M = 2m here); beyond that the stable scheme's limiter is active and it needs a smaller
  // step, which substeps give.
  const Body rod = two_nodes(4.0, 4.0);
  for (const std::string scheme : {"stable", "explicit", "implicit"}) {
    for (double dn : {0.2, 0.5, 2.0, 10.0}) {
      for (double v : {0.5, 1.0, 3.0}) {
        SceneParams scene = scene_with({"springs", "drag"});
        scene.drag_normal = dn;
        const double force = dn * 4.0 * v * v;
        const double x = PhysicsParams{}.dt * dn * 4.0 * v / 2.0;
        const int substeps = x <= 0.5 ? 1 : static_cast<int>(std::ceil(2.0 * x));
        EXPECT_NEAR(terminal_speed(rod, 0.0, force, scene, scheme, 2400, substeps) / v, 1.0, 0.01)
            << scheme << " d_N=" << dn << " v=" << v << " substeps " << substeps;
      }
    }
  }
}

TEST(Drag, QuadraticTerminalVelocityAlongARod) {
  // v = sqrt(F / (d_T·L)) pulled along its axis.
  SceneParams scene = scene_with({"springs", "drag"});
  scene.drag_normal = 2.0;
  scene.drag_tangential = 0.5;  // explicit d_T so the test settles in a few thousand steps
  for (const std::string scheme : {"stable", "explicit", "implicit"}) {
    for (double v : {0.5, 2.0}) {
      const double force = 0.5 * 4.0 * v * v;
      EXPECT_NEAR(terminal_speed(two_nodes(4.0, 4.0), force, 0.0, scene, scheme, 3000) / v, 1.0,
                  0.01)
          << scheme;
    }
  }
}

TEST(Drag, QuadraticTerminalVelocityOfAClosedSquare) {
  // A 2 × 2 square pulled along x: two skin edges move normal to themselves, two tangentially, and
  // every skin node is shared by two edges. F = 2·2·(d_N + d_T)·v². (The implicit scheme is biased
  // here by design, see src/effects.cpp; it is not the default.)
  Body sq = square();
  sq.positions *= 2.0;
  sq.rest_lengths *= 2.0;
  sq.rest_areas *= 4.0;
  for (const std::string scheme : {"stable", "explicit"}) {
    for (double v : {0.5, 1.0, 2.0}) {
      SceneParams scene = scene_with({"springs", "pressure", "drag"});
      const double force = 4.0 * (scene.drag_normal + tangential_drag(scene)) * v * v;
      EXPECT_NEAR(terminal_speed(sq, force, 0.0, scene, scheme, 2400) / v, 1.0, 0.01)
          << scheme << " v=" << v;
    }
  }
}

TEST(Drag, OnlySkinEdgesFeelDrag) {
  // A square with a centre node: the centre is on no skin edge, so it feels no drag.
  Body b =
      make_body(points({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}}),
                {{0, 1}, {1, 2}, {2, 3}, {0, 3}, {0, 4}, {1, 4}, {2, 4}, {3, 4}},
                {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {0, 4, 3}}, {{0, 1}, {1, 2}, {2, 3}, {0, 3}});
  for (const std::string scheme : {"stable", "explicit", "implicit"}) {
    PhysicsParams physics;
    physics.drag_scheme = scheme;
    physics.velocity_forces = "start";  // forces at the given velocities
    Simulation sim(b, scene_with({"drag"}), physics);
    sim.set_velocities(Points::Constant(5, 2, 0.7));
    sim.compute_forces();
    EXPECT_EQ(sim.forces_x()[4], 0.0);
    EXPECT_EQ(sim.forces_y()[4], 0.0);
    // Skin nodes: each gets half of each of its two edges' drag: d_N·L·v_N²/2 from the edge normal
    // to the motion component, d_T·L·v_T²/2 from the other.
    const double vn = 0.7, dn = 2.0, dt = 0.01, L = 2.0;
    const double expected = 0.5 * dn * L * vn * vn + 0.5 * dt * L * vn * vn;
    if (scheme == "explicit") {
      EXPECT_NEAR(sim.forces_x()[0], -expected, 1e-6);
    }
    EXPECT_LT(sim.forces_x()[0], 0.0);
    EXPECT_LT(sim.forces_y()[0], 0.0);
  }
}

TEST(Drag, ImplicitQuadraticNeverReverses) {
  for (double w : {-50.0, -1.0, -1e-9, 0.0, 1e-9, 0.3, 7.0, 1e6}) {
    for (double c : {0.0, 1e-6, 0.1, 1.0, 10.0, 1e6}) {
      const double u = implicit_quadratic_drag(w, c);
      EXPECT_TRUE(u == 0.0 ? w == 0.0 : (u > 0.0) == (w > 0.0)) << w << " " << c;
      EXPECT_LE(std::abs(u), std::abs(w));
      EXPECT_NEAR(u + c * u * std::abs(u), w, 1e-9 * std::max(1.0, std::abs(w))) << w << " " << c;
    }
  }
  EXPECT_EQ(implicit_quadratic_drag(3.0, 0.0), 3.0);
}

/// A free dimer (two nodes, one skin edge, no spring) launched normal to itself at speed v0.
std::vector<double> launched_dimer_speeds(const std::string& scheme, double dn, double v0,
                                          int steps,
                                          const std::string& velocity_forces = "midpoint") {
  SceneParams scene = scene_with({"drag"});
  scene.drag_normal = dn;
  PhysicsParams physics;
  physics.drag_scheme = scheme;
  physics.velocity_forces = velocity_forces;
  Simulation sim(two_nodes(1.0, 1.0), scene, physics);
  sim.set_velocities(Points::Constant(2, 2, 0.0).rowwise() + Eigen::RowVector2d(0.0, v0));
  std::vector<double> v = {v0};
  for (int s = 0; s < steps; ++s) {
    sim.step();
    v.push_back(sim.velocities()(0, 1));
  }
  return v;
}

TEST(Drag, StableSchemeNeverReversesWhereExplicitDoesAndBlowsUp) {
  // c·h·|v| = d·L·h·|v|/M with M = 2m for a free edge: d = 50, v0 = 10 gives 4.2, far beyond the
  // explicit scheme's limit of 1 (reversal) and 2 (growth).
  for (const std::string mode : {"midpoint", "start"}) {
    const auto stable = launched_dimer_speeds("stable", 50.0, 10.0, 200, mode);
    const auto implicit = launched_dimer_speeds("implicit", 50.0, 10.0, 200, mode);
    for (std::size_t k = 1; k < stable.size(); ++k) {
      EXPECT_GT(stable[k], 0.0) << mode << " " << k;
      EXPECT_LE(stable[k], stable[k - 1]) << mode << " " << k;
      EXPECT_GT(implicit[k], 0.0) << mode << " " << k;
      EXPECT_LE(implicit[k], implicit[k - 1]) << mode << " " << k;
    }
  }
  // Explicit: the first step reverses the velocity (drag at the start velocity) or makes it grow
  // (at the predicted midpoint velocity, whose predictor has reversed); either way it then grows
  // until the step is rejected.
  for (const std::string mode : {"start", "midpoint"}) {
    SceneParams scene = scene_with({"drag"});
    scene.drag_normal = 50.0;
    PhysicsParams physics;
    physics.drag_scheme = "explicit";
    physics.velocity_forces = mode;
    Simulation sim(two_nodes(1.0, 1.0), scene, physics);
    sim.set_velocities(Points::Constant(2, 2, 0.0).rowwise() + Eigen::RowVector2d(0.0, 10.0));
    sim.step();
    const double v1 = sim.velocities()(0, 1);
    EXPECT_TRUE(v1 < 0.0 || v1 > 10.0)
        << mode << ": explicit drag reverses or amplifies, got " << v1;
    EXPECT_THROW(sim.step(10), SimulationError) << mode;
    EXPECT_TRUE(sim.failed());
    EXPECT_THROW(sim.step(), SimulationError) << "a failed simulation stays failed";
  }
}

TEST(Drag, StableSchemeFollowsTheExactDecayOfAFreeEdge) {
  // v' = −c·v|v| with c = d·L/(2m): v(t) = v0 / (1 + c·v0·t). First-order schemes, within 1% at the
  // default dt while c·v·h is small.
  const double dn = 2.0, v0 = 1.0, c = dn * 1.0 / 2.0;
  const double h = PhysicsParams{}.dt;
  for (const std::string scheme : {"stable", "explicit", "implicit"}) {
    const auto v = launched_dimer_speeds(scheme, dn, v0, 600);
    for (std::size_t k = 60; k < v.size(); k += 60) {
      const double exact = v0 / (1.0 + c * v0 * h * static_cast<double>(k));
      EXPECT_NEAR(v[k] / exact, 1.0, 0.01) << scheme << " step " << k;
    }
  }
}

TEST(Drag, ExplicitSchemeBlowsUpOnASwimmerWhereStableDoesNot) {
  // A 32-cell swimmer thrown at speed 8 in the d_N = 50 fluid: the explicit drag overshoots
  // (c·h·|v| ≈ 50·8/60 > 2) and the swim is rejected; the stable scheme slows it down smoothly.
  const Body b = swimmer(lattice_points(8, 4), Drive::wave, 0.2, 12.0);
  SceneParams scene;
  scene.drag_normal = 50.0;
  const Points launch =
      Points::Constant(b.node_count(), 2, 0.0).rowwise() + Eigen::RowVector2d(8.0, 0.0);
  PhysicsParams physics;
  physics.drag_scheme = "explicit";
  Simulation bad(b, scene, physics);
  bad.set_velocities(launch);
  EXPECT_THROW(bad.step(4000), SimulationError);
  for (const std::string scheme : {"stable", "implicit"}) {
    physics.drag_scheme = scheme;
    Simulation good(b, scene, physics);
    good.set_velocities(launch);
    const double e0 = good.kinetic_energy();
    good.step(4000);
    EXPECT_TRUE(good.positions().allFinite());
    EXPECT_LT(good.kinetic_energy(), e0);
    EXPECT_LT(good.max_step_displacement_seen(), 0.5 * physics.max_step_displacement);
  }
}

// --- actuation
// --------------------------------------------------------------------------------------

TEST(Actuation, StartTimeIsTheNextZeroOfTheSineWithinHalfAPeriod) {
  for (double f : {0.5, 1.0, 3.7, 12.0}) {
    for (int k = 0; k <= 64; ++k) {
      const double phi = 2.0 * kPi * k / 64.0;
      const double t0 = actuation_start_time(f, phi);
      EXPECT_GE(t0, 0.0);
      EXPECT_LT(t0, kPi / f + 1e-12) << "at most half a period";
      EXPECT_NEAR(std::sin(f * t0 + phi), 0.0, 1e-12);
      if (std::abs(std::sin(phi)) < 1e-15) {
        EXPECT_EQ(t0, 0.0) << "phase 0 or π starts at once";
      }
      // No earlier zero: sin(f·t + φ) keeps its sign on (0, t0).
      for (int q = 1; q < 20 && t0 > 0.0; ++q) {
        const double t = t0 * q / 20.0;
        EXPECT_GT(std::sin(f * t + phi) * std::sin(phi), 0.0);
      }
    }
  }
  EXPECT_EQ(actuation_start_time(0.0, 1.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(actuation_start_time(0.0, 0.0), 0.0);
}

TEST(Actuation, TermStartsAtZeroAndIsContinuous) {
  for (double phi : {0.0, 0.4, 1.9, 3.3, 5.9}) {
    const double a = 0.2, f = 6.0;
    const double t0 = actuation_start_time(f, phi);
    EXPECT_EQ(actuation_term(a, f, phi, 0.0), phi == 0.0 ? 0.0 : 0.0);
    EXPECT_EQ(actuation_term(a, f, phi, 0.999 * t0), 0.0);
    EXPECT_NEAR(actuation_term(a, f, phi, t0), 0.0, 1e-12);
    // Lipschitz continuity with constant a·f on a fine grid through the start.
    const double dt = 1e-4;
    double prev = actuation_term(a, f, phi, 0.0);
    for (double t = dt; t < t0 + 2.0; t += dt) {
      const double cur = actuation_term(a, f, phi, t);
      ASSERT_LE(std::abs(cur - prev), a * f * dt * (1.0 + 1e-9) + 1e-15)
          << "phi " << phi << " t " << t;
      prev = cur;
    }
  }
}

TEST(Actuation, RestLengthsFollowEq2FromEquilibrium) {
  // Rest lengths start at L0, leave it smoothly (per-step change ≤ (a1·f1 + a2·f2)·h·L0), and equal
  // (1 + term_i + term_j)·L0 with term from actuation_term at t = step·h (the recurrence the
  // effect uses stays within 1e-12 over 10,000 steps).
  Body b = swimmer(lattice_points(4, 3), Drive::random, 0.2, 4.0, 21);
  const double h = PhysicsParams{}.dt;
  Simulation sim(b, scene_with({"actuation"}));
  const Vector l0 = Eigen::Map<const Vector>(sim.rest_lengths_now().data(), b.spring_count());
  for (int s = 0; s < b.spring_count(); ++s) EXPECT_NEAR(l0(s), b.rest_lengths(s), 1e-6);
  std::vector<double> prev(l0.data(), l0.data() + l0.size());
  double worst = 0.0;
  for (int k = 0; k < 10000; ++k) {
    sim.step();
    const double t = static_cast<double>(k) * h;  // the rest lengths used by step k
    const auto rest = sim.rest_lengths_now();
    for (int s = 0; s < b.spring_count(); ++s) {
      const int i = b.springs(s, 0), j = b.springs(s, 1);
      const double ti = actuation_term(b.amplitude(i), b.frequency(i), b.phase(i), t);
      const double tj = actuation_term(b.amplitude(j), b.frequency(j), b.phase(j), t);
      worst = std::max(worst, std::abs(rest[s] - (1.0 + ti + tj) * l0(s)));
      const double bound =
          (b.amplitude(i) * b.frequency(i) + b.amplitude(j) * b.frequency(j)) * h * l0(s);
      ASSERT_LE(std::abs(rest[s] - prev[s]), bound * (1.0 + 1e-6) + 1e-12)
          << "spring " << s << " step " << k;
      prev[s] = rest[s];
    }
  }
  EXPECT_LT(worst, 1e-12);
}

// --- effects are really off when off
// -------------------------------------------------------------------

TEST(Effects, DisabledEffectIsNotInTheLoop) {
  const Body b = swimmer(lattice_points(6, 4), Drive::wave);
  for (const auto name : kSceneEffectNames) {
    std::vector<std::string> effects;
    for (const auto other : kSceneEffectNames)
      if (other != name) effects.emplace_back(other);
    PhysicsParams physics;
    physics.integrator = "box2d";  // to look at Box2D's bodies
    Simulation sim(b, scene_with(effects), physics);
    EXPECT_EQ(sim.effect(name), nullptr) << name;
    EXPECT_EQ(sim.effects().size(), effects.size());
    sim.step(50);
    for (const Effect* e : sim.effects()) EXPECT_EQ(e->calls(), 50) << e->name();
    EXPECT_EQ(sim.world().GetBodyList()->GetFixtureList(), nullptr);
  }
  Simulation sim(b, SceneParams{});
  sim.add_effect(std::make_unique<ConstantForce>(0.0, 0.0));
  std::vector<std::string> order;
  for (const Effect* e : sim.effects()) order.emplace_back(e->name());
  // Stage order: modifiers (actuation), force effects in canonical order and custom force effects
  // after them, then constraints (collisions), which need every force.
  EXPECT_EQ(order, (std::vector<std::string>{"actuation", "springs", "pressure", "drag",
                                             "constant_force", "collisions"}));
}

TEST(Effects, ZeroCoefficientTrajectoryEqualsEffectAbsent) {
  // Each effect, when present with a zero coefficient, adds exactly nothing: its trajectory is
  // bit-identical to the one computed without that effect's code at all.
  const Body moving = swimmer(lattice_points(6, 4, 0.1, 9), Drive::wave, 0.2, 6.0);
  Body still = moving;
  still.amplitude.setZero();
  struct Case {
    const char* name;
    void (*zero)(SceneParams&);
    bool still_body;
  };
  const Case cases[] = {
      {"springs",
       [](SceneParams& s) {
         s.spring_stiffness = 0.0;
         s.spring_damping = 0.0;
       },
       false},
      {"actuation", [](SceneParams&) {}, true},
      {"pressure", [](SceneParams& s) { s.pressure = 0.0; }, false},
      {"drag",
       [](SceneParams& s) {
         s.drag_normal = 0.0;
         s.drag_tangential = 0.0;
       },
       false},
      {"skin_collision", [](SceneParams& s) { s.collision_stiffness = 0.0; }, false},
      // Collisions have no coefficient to zero; on a body that never collides they add nothing.
      {"collisions", [](SceneParams&) {}, false},
      {"gravity", [](SceneParams& s) { s.gravity = 0.0; }, false},
      // The floor far below a body that never reaches it adds nothing.
      {"ground", [](SceneParams& s) { s.ground_height = -1000.0; }, false},
  };
  for (const Case& c : cases) {
    const Body& b = c.still_body ? still : moving;
    SceneParams with;
    if (!has_effect(with.effects, c.name)) with.effects.emplace_back(c.name);
    c.zero(with);
    SceneParams without = with;
    without.effects.erase(std::find(without.effects.begin(), without.effects.end(), c.name));
    Simulation a(b, with), z(b, without);
    if (!c.still_body) {  // give the body something to do when actuation stays on
      a.step(800);
      z.step(800);
    } else {
      const Points kick = Points::Constant(b.node_count(), 2, 0.3);
      a.set_velocities(kick);
      z.set_velocities(kick);
      a.step(800);
      z.step(800);
    }
    EXPECT_EQ(a.positions(), z.positions()) << c.name;
    EXPECT_EQ(a.velocities(), z.velocities()) << c.name;
  }
}

// --- skin collision
// -------------------------------------------------------------------------------

TEST(SkinCollision, CellBouncesElasticallyOffAForeignSkinEdge) {
  // Edge (0, 1) of a free dimer, and a lone cell 2 flying at its middle.
  Body b = make_body(points({{0, 0}, {1, 0}, {0.5, 0.6}}), {{0, 1}}, {}, {{0, 1}});
  Simulation sim(b, scene_with({"springs", "skin_collision"}));
  Points v = Points::Zero(3, 2);
  v(2, 1) = -1.5;
  sim.set_velocities(v);
  const double e0 = sim.kinetic_energy();
  const Eigen::Vector2d p0 = sim.momentum();
  double closest = 1.0;
  for (int s = 0; s < 600; ++s) {
    sim.step();
    const Points p = sim.positions();
    const double edge_y = 0.5 * (p(0, 1) + p(1, 1));
    closest = std::min(closest, p(2, 1) - edge_y);
    ASSERT_GT(p(2, 1), edge_y) << "the cell passed through the edge at step " << s;
  }
  EXPECT_LT(closest, SceneParams{}.collision_radius) << "they did touch";
  EXPECT_GT(sim.velocities()(2, 1), 0.0) << "the cell bounced back";
  // Elastic up to the time discretisation of a stiff penalty (and the dimer's own damped wobble).
  EXPECT_NEAR(sim.kinetic_energy() / e0, 1.0, 0.05);
  EXPECT_LT((sim.momentum() - p0).norm(), 1e-5);
}

TEST(SkinCollision, ForcesEqualTheAllPairsComputation) {
  // The Verlet list never misses a pair: feed the effect every state of a violent swim and compare
  // its forces with a brute-force all-pairs penalty (radius min(r, half the rest distance)).
  Body b = swimmer(lattice_points(8, 4, 0.05, 8), Drive::wave, 0.2, 12.0);
  b.phase.setZero();  // the whole body breathes at f = 12: violent, with many skin contacts
  SceneParams scene;
  scene.drag_normal = 0.2;
  // the first release's pressure, with which this swim squeezes cells against edges
  scene.pressure = 100.0;
  scene.pressure_area_floor = 0.1;
  Simulation sim(b, scene);
  const auto effect = make_effect("skin_collision", b, scene, PhysicsParams{});
  SwimState st;
  st.n = b.node_count();
  st.h = PhysicsParams{}.dt;
  for (auto* v : {&st.x, &st.y, &st.vx, &st.vy, &st.fx, &st.fy})
    v->assign(static_cast<std::size_t>(st.n), 0.0);
  int touching_states = 0;
  for (int step = 0; step < 3000; ++step) {
    sim.step();
    const Points p = sim.positions();
    for (int i = 0; i < st.n; ++i) {
      st.x[static_cast<std::size_t>(i)] = p(i, 0);
      st.y[static_cast<std::size_t>(i)] = p(i, 1);
      st.fx[static_cast<std::size_t>(i)] = 0.0;
      st.fy[static_cast<std::size_t>(i)] = 0.0;
    }
    st.step = step;
    effect->apply(st);
    Points brute = Points::Zero(st.n, 2);
    for (int i = 0; i < st.n; ++i) {
      for (int e = 0; e < b.skin.rows(); ++e) {
        const int a = b.skin(e, 0), c = b.skin(e, 1);
        if (a == i || c == i) continue;
        const Eigen::Vector2d pa = b.positions.row(a), pc = b.positions.row(c),
                              pi = b.positions.row(i);
        const Eigen::Vector2d ed = pc - pa;
        const double tr = std::clamp((pi - pa).dot(ed) / ed.squaredNorm(), 0.0, 1.0);
        const double r = std::min(scene.collision_radius, 0.5 * (pi - (pa + tr * ed)).norm());
        const Eigen::Vector2d qa = p.row(a), qc = p.row(c), qi = p.row(i);
        const Eigen::Vector2d eq = qc - qa;
        const double t = std::clamp((qi - qa).dot(eq) / eq.squaredNorm(), 0.0, 1.0);
        const Eigen::Vector2d d = qi - (qa + t * eq);
        if (d.norm() >= r) continue;
        const Eigen::Vector2d f = scene.collision_stiffness * (r - d.norm()) * d / d.norm();
        brute.row(i) += f.transpose();
        brute.row(a) -= (1.0 - t) * f.transpose();
        brute.row(c) -= t * f.transpose();
      }
    }
    double diff = 0.0, mag = 0.0;
    for (int i = 0; i < st.n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      diff = std::max(diff, std::hypot(st.fx[u] - brute(i, 0), st.fy[u] - brute(i, 1)));
      mag = std::max(mag, brute.row(i).norm());
    }
    if (mag > 0.0) ++touching_states;
    ASSERT_LE(diff, 1e-9 * std::max(1.0, mag)) << "step " << step;
  }
  EXPECT_GT(touching_states, 10) << "the swim must produce contacts for this test to mean anything";
}

// --- error detection
// ---------------------------------------------------------------------------------

TEST(Errors, SpeedCapIsDetectedNotClamped) {
  SceneParams scene = scene_with({"springs"});
  scene.spring_stiffness = 1e5;
  Simulation sim(two_nodes(3.0, 1.0), scene);  // stretched by 2 with k = 1e5: |v|·h ≫ 1
  const Points before = sim.positions();
  try {
    sim.step();
    FAIL() << "expected SimulationError";
  } catch (const SimulationError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("max_step_displacement"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cell"), std::string::npos) << msg;
  }
  EXPECT_EQ(sim.positions(), before) << "the rejected step is not taken";
  const SwimResult r = swim(two_nodes(3.0, 1.0), scene, PhysicsParams{}, 100);
  EXPECT_FALSE(r.stable);
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_FALSE(r.failure.empty());
}

TEST(Errors, NonFiniteStateIsDetected) {
  // Config bounds keep the built-in effects finite (a stiffness of 1e308 is refused), so a custom
  // effect plants the non-finite force.
  struct NanForce : Effect {
    std::string_view name() const override { return "nan_force"; }
    void apply(SwimState& s) override { s.fx[0] = std::numeric_limits<double>::quiet_NaN(); }
  };
  Simulation sim(two_nodes(3.0, 1.0), scene_with({"springs"}));
  sim.add_effect(std::make_unique<NanForce>());
  try {
    sim.step();
    FAIL() << "expected SimulationError";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
}

// --- allocation-free loop
// ------------------------------------------------------------------------------

TEST(Performance, SwimLoopAllocatesNothing) {
  for (const std::string scheme : {"stable", "explicit", "implicit"}) {
    PhysicsParams physics;
    physics.drag_scheme = scheme;
    physics.substeps = 2;
    Simulation sim(swimmer(lattice_points(8, 4, 0.1, 2), Drive::random), SceneParams{}, physics);
    sim.step(10);
    g_allocations = 0;
    g_counting = true;
    sim.step(2000);
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << scheme;
  }
}

/// Develops the first three viable random genomes of seed 3 cell by cell and checks that no step
/// without a division allocates; returns the number of such steps.
long development_steps_without_allocation(const Config& config, std::size_t grid_from) {
  Rng rng(3);
  int developed = 0;
  long quiet_steps = 0;
  for (int tries = 0; tries < 5000 && developed < 3; ++tries) {
    const Genome g = random_genome(config.genome, rng);
    if (!develop(g, config.genome, config.grn, config.development).viable) continue;
    ++developed;
    DevelopmentWorld world(Grn(g, config.genome), config.grn, config.development);
    world.set_symmetry_seed(genome_hash(g));
    world.set_pair_grid_from(grid_from);
    world.add_cell(DevelopmentWorld::Vec2::Zero(), config.development.cell_radius,
                   DevelopmentWorld::Vec2(1.0, 0.0));
    for (int step = 0; step < config.development.steps; ++step) {
      g_allocations = 0;
      g_counting = true;
      const int divisions = world.step();
      g_counting = false;
      if (divisions > 0) continue;
      ++quiet_steps;
      EXPECT_EQ(g_allocations.load(), 0) << "step " << step << " of viable genome " << developed;
      if (g_allocations.load() != 0) return quiet_steps;
    }
  }
  EXPECT_EQ(developed, 3);
  return quiet_steps;
}

/// Development allocates only when a cell is born (its GRN state, history rows and
/// slots); a step without a division allocates nothing, whatever the genome.
TEST(Performance, DevelopmentAllocatesOnlyWhenACellIsBorn) {
  EXPECT_GT(development_steps_without_allocation(Config{}, 64), 900);
}

/// The same with the pair grid in both pair loops (contacts, and a morphogen cut-off) from 2 cells
/// on.
TEST(Performance, DevelopmentWithThePairGridAllocatesOnlyWhenACellIsBorn) {
  Config config;
  config.development.morphogen_cutoff = 3.0;
  EXPECT_GT(development_steps_without_allocation(config, 2), 900);
}

TEST(Performance, CrawlLoopAllocatesNothing) {
  // The crawl world's effects (gravity, ground with contacts every step, on either floor) and the
  // actuation work metering allocate nothing either.
  for (const char* contact : {"impulse", "compliant"}) {
    SceneParams scene;
    scene.effects = {"springs", "actuation", "pressure", "collisions", "gravity", "ground"};
    scene.ground_contact = contact;
    Body b = swimmer(lattice_points(8, 4, 0.1, 2), Drive::random);
    b.positions.col(1).array() -= b.positions.col(1).minCoeff();
    Simulation sim(b, scene);
    sim.step(10);
    g_allocations = 0;
    g_counting = true;
    sim.step(2000);
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << contact;
    EXPECT_GT(sim.counters().ground_contacts, 0) << contact;
    EXPECT_GT(sim.counters().actuation_work_absolute, 0.0) << contact;
  }
}

// --- one Box2D island
// --------------------------------------------------------------------------------

/// The island-linking joints (src/box2d_island.hpp) must not change the motion: two worlds with the
/// same cells and the same random forces, one linked and one not, stay bitwise equal.
TEST(Performance, IslandLinkingJointsLeaveTheMotionBitwiseUnchanged) {
  for (const bool warm_starting : {false, true}) {
    std::vector<b2Body*> linked, free;
    b2World w_linked(b2Vec2(0.0f, 0.0f)), w_free(b2Vec2(0.0f, 0.0f));
    for (b2World* w : {&w_linked, &w_free}) {
      w->SetAllowSleeping(false);
      w->SetContinuousPhysics(false);
      w->SetWarmStarting(warm_starting);
    }
    Rng rng(11);
    b2MassData md;
    md.mass = 1.0f;
    md.center.SetZero();
    md.I = 0.0f;
    for (int i = 0; i < 24; ++i) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.fixedRotation = true;
      def.allowSleep = false;
      // the development world damps, the swim world does not
      def.linearDamping = warm_starting ? 10.0f : 0.0f;
      def.position.Set(static_cast<float>(rng.uniform(-3.0, 3.0)),
                       static_cast<float>(rng.uniform(-3.0, 3.0)));
      def.linearVelocity.Set(static_cast<float>(rng.uniform(-1.0, 1.0)),
                             static_cast<float>(rng.uniform(-1.0, 1.0)));
      linked.push_back(w_linked.CreateBody(&def));
      free.push_back(w_free.CreateBody(&def));
      linked.back()->SetMassData(&md);
      free.back()->SetMassData(&md);
    }
    link_into_one_island(w_linked, linked);
    EXPECT_EQ(w_linked.GetJointCount(), 23);
    for (int step = 0; step < 500; ++step) {
      for (std::size_t i = 0; i < linked.size(); ++i) {
        const b2Vec2 f(static_cast<float>(rng.uniform(-50.0, 50.0)),
                       static_cast<float>(rng.uniform(-50.0, 50.0)));
        linked[i]->ApplyForceToCenter(f, true);
        free[i]->ApplyForceToCenter(f, true);
      }
      w_linked.Step(1.0f / 60.0f, 1, 1);
      w_free.Step(1.0f / 60.0f, 1, 1);
    }
    for (std::size_t i = 0; i < linked.size(); ++i) {
      EXPECT_EQ(linked[i]->GetPosition().x, free[i]->GetPosition().x) << i;
      EXPECT_EQ(linked[i]->GetPosition().y, free[i]->GetPosition().y) << i;
      EXPECT_EQ(linked[i]->GetLinearVelocity().x, free[i]->GetLinearVelocity().x) << i;
      EXPECT_EQ(linked[i]->GetLinearVelocity().y, free[i]->GetLinearVelocity().y) << i;
    }
  }
}

TEST(Performance, SwimWorldIsOneIslandWithoutFixturesOrContacts) {
  PhysicsParams physics;
  physics.integrator = "box2d";
  Simulation sim(swimmer(lattice_points(8, 4), Drive::wave), SceneParams{}, physics);
  sim.step(10);
  const b2World& w = sim.world();
  EXPECT_EQ(w.GetBodyCount(), 32);
  EXPECT_EQ(w.GetJointCount(), 31);
  EXPECT_EQ(w.GetContactCount(), 0);
  for (const b2Body* b = w.GetBodyList(); b; b = b->GetNext())
    EXPECT_EQ(b->GetFixtureList(), nullptr);
}

TEST(Performance, TheNativeIntegratorHasNoBox2DWorld) {
  // physics.integrator = "native" by default
  Simulation sim(swimmer(lattice_points(8, 4), Drive::wave));
  try {
    (void)sim.world();
    FAIL() << "world() must refuse without a Box2D world";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("physics.integrator"), std::string::npos) << e.what();
  }
}

// --- stability suite
// -----------------------------------------------------------------------------------

/// Response of one spring of the body driven through its rest length at frequency ω (the building
/// block of every swimmer): stiffness k, damping c, the reduced mass m/2 of its two cells, so
/// ω0 = sqrt(2k/m) (14.1 rad/time at the defaults) and ζ = c/sqrt(2km) (0.28), and the
/// amplification of the drive M(ω) = 1/sqrt((1 − r²)² + (2ζr)²), r = ω/ω0 (1.17 at ω = 6, 1.80 at
/// 12).
double amplification(const SceneParams& scene, double omega) {
  const double w0 = std::sqrt(2.0 * scene.spring_stiffness / scene.cell_mass);
  const double zeta =
      scene.spring_damping / std::sqrt(2.0 * scene.spring_stiffness * scene.cell_mass);
  const double r = omega / w0;
  return 1.0 / std::sqrt((1.0 - r * r) * (1.0 - r * r) + 4.0 * zeta * zeta * r * r);
}

/// Runs `steps` and checks the named-case invariants, with bounds derived from the driven spring
/// (amplification above) for drives up to frequency `omega` and amplitude a = 0.2:
///  - stable (finite, never faster than max_step_displacement per step) and valid (the planar
///    embedding intact at every step, every collision resolved);
///  - spring lengths: the two ends' actuation moves a rest length by up to 2a·L0, so a spring
///    answering as a driven oscillator stays within 1 ± 2a·M(ω)·1.25 of L0; the 1.25 covers the
///    coupling of a cell's springs (the worst case seen, the f = 12 travelling wave, needs 1.09).
///    This holds for swims without collisions; a bounce is an impulse outside the linear response
///    (it lets a spring shrink further while the region it closes is squeezed flat), so swims that
///    collide are held to the embedding and energy bounds only;
///  - kinetic energy per cell at most the elastic energy the drive can give the ~3 springs per
///    cell at the amplified amplitude, 3·½k·(2a·M(ω)·L0)² (33 at ω = 6, 78 at ω = 12).
/// swim() measures stretch against max(L0, median L0 / 2), so near-zero rest lengths stay
/// meaningful.
void expect_sane_swim(const Body& b, const SceneParams& scene, const PhysicsParams& physics,
                      long steps, const std::string& label, double omega = 12.0) {
  const SwimResult r = swim(b, scene, physics, steps);
  EXPECT_TRUE(r.stable) << label << ": " << r.failure;
  EXPECT_TRUE(r.valid) << label << ": " << r.failure;
  EXPECT_EQ(r.steps, steps) << label;
  EXPECT_TRUE(std::isfinite(r.distance)) << label;
  const double swing = 2.0 * 0.2 * amplification(scene, omega);
  EXPECT_LT(r.max_kinetic_energy_per_cell, 3.0 * 0.5 * scene.spring_stiffness * swing * swing)
      << label;
  if (r.collisions == 0) {
    EXPECT_LT(r.max_stretch, 1.0 + 1.25 * swing) << label;
    EXPECT_GT(r.min_stretch, 1.0 - 1.25 * swing) << label;
  }
  EXPECT_GT(r.min_area_ratio, 0.0) << label;
  EXPECT_LE(r.max_step_displacement, physics.max_step_displacement) << label;
}

TEST(Stability, HighDrag) {
  for (double dn : {10.0, 50.0}) {
    SceneParams scene;
    scene.drag_normal = dn;
    expect_sane_swim(swimmer(lattice_points(8, 4), Drive::wave, 0.2, 12.0), scene, PhysicsParams{},
                     4000, "d_N=" + std::to_string(dn) + " wave f=12");
    expect_sane_swim(swimmer(lattice_points(8, 4, 0.15, 4), Drive::random), scene, PhysicsParams{},
                     4000, "d_N=" + std::to_string(dn) + " random");
  }
}

TEST(Stability, SixtyFourCells) {
  for (double dn : {0.2, 2.0, 10.0}) {
    SceneParams scene;
    scene.drag_normal = dn;
    expect_sane_swim(swimmer(lattice_points(8, 8, 0.15, 5), Drive::random, 0.2, 4.0, 5), scene,
                     PhysicsParams{}, 4000, "64 cells d_N=" + std::to_string(dn));
  }
}

TEST(Stability, MaximalAmplitudeAtHighestFrequency) {
  for (const Drive drive : {Drive::wave, Drive::none}) {
    Body b = swimmer(lattice_points(8, 4, 0.05, 8), Drive::wave, 0.2, 12.0);
    if (drive == Drive::none) b.phase.setZero();  // all in phase: the whole body breathes
    for (double dn : {0.2, 2.0, 10.0}) {
      SceneParams scene;
      scene.drag_normal = dn;
      expect_sane_swim(b, scene, PhysicsParams{}, 4000, "a=0.2 f=12 d_N=" + std::to_string(dn));
    }
  }
}

TEST(Stability, SliverRegions) {
  // Rows 1e-3 apart: thin rectangles (S0 ~ 1e-3) between them.
  Points p(24, 2);
  for (int i = 0; i < 8; ++i) {
    p(i, 0) = i;
    p(i, 1) = 0.0;
    p(8 + i, 0) = i;
    p(8 + i, 1) = 1e-3;
    p(16 + i, 0) = i + 0.5;
    p(16 + i, 1) = 0.9;
  }
  const Body b = swimmer(p, Drive::wave, 0.2, 12.0);
  double smallest = 1.0;
  for (int r = 0; r < b.region_count(); ++r) smallest = std::min(smallest, b.rest_areas(r));
  ASSERT_LT(smallest, 2e-3) << "the body must contain sliver regions";
  expect_sane_swim(b, SceneParams{}, PhysicsParams{}, 4000, "slivers");
}

TEST(Stability, NearCoincidentCells) {
  for (double gap : {1e-2, 1e-4, 1e-5}) {
    Points p = lattice_points(6, 4, 0.05, 10);
    p(7, 0) = p(8, 0) + gap;  // cells 7 and 8 nearly on top of each other
    p(7, 1) = p(8, 1);
    p(20, 0) = p(21, 0) - gap;
    p(20, 1) = p(21, 1) + gap;
    const Body b = swimmer(p, Drive::random, 0.2, 4.0, 3);
    const SwimResult r = swim(b, SceneParams{}, PhysicsParams{}, 4000);
    EXPECT_TRUE(r.stable) << gap << ": " << r.failure;
    EXPECT_LT(r.max_kinetic_energy, 50.0 * b.node_count()) << gap;
    EXPECT_LT(r.max_step_displacement, 0.5) << gap;
  }
}

TEST(Stability, TwentyThousandSteps) {
  expect_sane_swim(swimmer(lattice_points(8, 4, 0.1, 12), Drive::random), SceneParams{},
                   PhysicsParams{}, 20000, "20000 steps");
}

TEST(Stability, LargestDefaultSafeDt) {
  // docs/notes/physics.md: the default scene is safe up to dt = 1/30 (twice the default) with one
  // substep; the stiffest default mode (skin-collision penalty, ω ≈ 32) has ω·dt ≈ 1.05 < 2 there.
  PhysicsParams physics;
  physics.dt = 1.0 / 30.0;
  for (double dn : {0.2, 2.0, 10.0, 50.0}) {
    SceneParams scene;
    scene.drag_normal = dn;
    expect_sane_swim(swimmer(lattice_points(8, 4), Drive::wave, 0.2, 12.0), scene, physics, 2000,
                     "dt=1/30 d_N=" + std::to_string(dn));
    expect_sane_swim(swimmer(lattice_points(8, 8, 0.15, 5), Drive::random, 0.2, 4.0, 5), scene,
                     physics, 2000, "dt=1/30 64 cells d_N=" + std::to_string(dn));
  }
}

// --- evaluation
// -----------------------------------------------------------------------------------------

/// The first `count` viable genomes of the random stream seeded by `seed` (bounded tries).
std::vector<Genome> viable_genomes(const Config& config, int count, std::uint64_t seed,
                                   int max_tries) {
  std::vector<Genome> out;
  for (int i = 0; i < max_tries && static_cast<int>(out.size()) < count; ++i) {
    Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(i));
    Genome g = random_genome(config.genome, rng);
    if (develop(g, config.genome, config.grn, config.development).viable)
      out.push_back(std::move(g));
  }
  return out;
}

TEST(Evaluate, NonViableGenomeIsNeverSwum) {
  const Config config;
  const Genome empty;
  const EvaluationResult r = evaluate(empty, config);
  EXPECT_FALSE(r.viable);
  EXPECT_EQ(r.fitness, 0.0);
  EXPECT_EQ(r.swim_steps, 0);
  EXPECT_FALSE(r.reasons.empty());
}

TEST(Evaluate, DeterministicAndThreadSafe) {
  warm_up_box2d();
  const Config config;
  const auto genomes = viable_genomes(config, 8, 99, 20000);
  ASSERT_FALSE(genomes.empty());
  std::vector<double> serial(genomes.size()), parallel(genomes.size());
  for (std::size_t k = 0; k < genomes.size(); ++k) serial[k] = evaluate(genomes[k], config).fitness;
#pragma omp parallel for num_threads(2) schedule(dynamic)
  for (int k = 0; k < static_cast<int>(genomes.size()); ++k)
    parallel[static_cast<std::size_t>(k)] =
        evaluate(genomes[static_cast<std::size_t>(k)], config).fitness;
  for (std::size_t k = 0; k < genomes.size(); ++k) {
    EXPECT_EQ(serial[k], parallel[k]) << k;  // bit-identical
    const EvaluationResult again = evaluate(genomes[k], config);
    EXPECT_EQ(again.fitness, serial[k]) << k;
    EXPECT_TRUE(again.viable);
    EXPECT_TRUE(again.stable) << (again.reasons.empty() ? "" : again.reasons.front());
    EXPECT_EQ(again.swim_steps, config.evaluation.steps);
  }
}

TEST(Stability, ThousandRandomViableGenomesEndToEndAndForcedToMaximalActuation) {
  // 1,000 random viable genomes through the whole chain. To keep the suite within its time budget
  // on 2 busy cores, each swims 1,000 steps (a quarter of the paper's horizon); the named cases
  // above cover long runs. Every swim must be stable and sane.
  warm_up_box2d();
  Config config;
  config.evaluation.steps = 1000;
  const int wanted = 1000;
  std::vector<EvaluationResult> results;
  std::vector<int> seeds;
  const int batch = 2000;
  for (int start = 0; static_cast<int>(results.size()) < wanted && start < 2000000;
       start += batch) {
    std::vector<EvaluationResult> r(batch);
#pragma omp parallel for num_threads(2) schedule(dynamic, 16)
    for (int i = 0; i < batch; ++i) {
      Rng rng = Rng::derive(20120707, static_cast<std::uint64_t>(start + i));
      r[static_cast<std::size_t>(i)] = evaluate(random_genome(config.genome, rng), config);
    }
    for (int i = 0; i < batch && static_cast<int>(results.size()) < wanted; ++i)
      if (r[static_cast<std::size_t>(i)].viable) {
        results.push_back(r[static_cast<std::size_t>(i)]);
        seeds.push_back(start + i);
      }
  }
  ASSERT_EQ(static_cast<int>(results.size()), wanted);
  double swim_seconds = 0.0, dev_seconds = 0.0;
  for (const auto& r : results) {
    swim_seconds += r.seconds_swim;
    dev_seconds += r.seconds_development;
  }
  std::printf(
      "viable genomes: %d of the first %d seeds; swim %.1f s, development of the viable %.1f s\n",
      wanted, seeds.back() + 1, swim_seconds, dev_seconds);
  int moved = 0;
  for (std::size_t k = 0; k < results.size(); ++k) {
    const EvaluationResult& r = results[k];
    const std::string label = "seed " + std::to_string(seeds[k]);
    EXPECT_TRUE(r.stable) << label << ": " << (r.reasons.empty() ? "" : r.reasons.front());
    EXPECT_TRUE(std::isfinite(r.fitness)) << label;
    EXPECT_EQ(r.swim_steps, 1000) << label;
    EXPECT_LT(r.max_kinetic_energy, 50.0 * r.cell_count) << label;
    if (r.spring_count > 0) {
      EXPECT_LT(r.max_stretch, 3.0) << label;
      EXPECT_GT(r.min_stretch, 0.05) << label;
    }
    if (r.fitness > 1e-3) ++moved;
  }
  EXPECT_GT(moved, 0);

  // The same 1,000 bodies forced to the largest amplitude and the highest default frequency (with
  // their own phases) for the paper's 4,000 steps: the planar embedding holds at every step.
  std::vector<SwimResult> forced(seeds.size());
#pragma omp parallel for num_threads(2) schedule(dynamic, 8)
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    Rng rng = Rng::derive(20120707, static_cast<std::uint64_t>(seeds[k]));
    const Genome g = random_genome(config.genome, rng);
    Body b = build_body(develop(g, config.genome, config.grn, config.development));
    b.amplitude.setConstant(config.development.amplitude_max);
    b.frequency.setConstant(config.development.frequency_max);
    SceneParams scene;
    scene.drag_normal = std::array<double, 4>{0.2, 0.5, 2.0, 10.0}[k % 4];
    SwimOptions options;
    options.stop_when_invalid = false;
    forced[k] = swim(b, scene, PhysicsParams{}, 4000, options);
  }
  long collisions = 0;
  for (std::size_t k = 0; k < forced.size(); ++k) {
    const SwimResult& r = forced[k];
    const std::string label = "forced seed " + std::to_string(seeds[k]);
    EXPECT_TRUE(r.stable) << label << ": " << r.failure;
    EXPECT_EQ(r.inverted_region_steps, 0) << label;
    EXPECT_EQ(r.skin_crossing_steps, 0) << label;
    EXPECT_EQ(r.collisions_unresolved, 0) << label;
    collisions += r.collisions;
  }
  std::printf("forced to maximal actuation: %ld collisions resolved over %zu bodies\n", collisions,
              forced.size());
}

}  // namespace
}  // namespace animat

namespace animat {
namespace {

std::vector<int>* volatile g_escape = nullptr;  // keeps the allocation below from being elided

// The allocation tests pass vacuously if the counter never counts: a control.
TEST(Performance, TheAllocationCounterCountsAnAllocation) {
  g_allocations = 0;
  g_counting = true;
  g_escape = new std::vector<int>(100);
  g_counting = false;
  EXPECT_GE(g_allocations.load(), 2);  // the vector object and its buffer
  delete g_escape;
  g_escape = nullptr;
}

}  // namespace
}  // namespace animat
