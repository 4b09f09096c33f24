// Evolvable stiffness (docs/model.md): a per-cell stiffness factor f sets each spring's stiffness
// k·2·f_i·f_j/(f_i + f_j) (src/effects/springs.cpp, Body::stiffness). Uniform factors reproduce the
// paper's uniform body bit for bit; a two-cell body oscillates at ω = sqrt(k_eff/μ).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
// physics_support.hpp: helpers this file does not use
#pragma GCC diagnostic ignored "-Wunused-function"
#include "physics_support.hpp"

namespace animat {
namespace {

std::vector<double> run_positions(const Body& body, const SceneParams& scene, int steps) {
  PhysicsParams physics;
  Simulation sim(body, scene, physics);
  sim.step(steps);
  std::vector<double> out(sim.state().x.begin(), sim.state().x.end());
  out.insert(out.end(), sim.state().y.begin(), sim.state().y.end());
  return out;
}

TEST(EvolvedStiffness, HarmonicMeanRule) {
  EXPECT_EQ(spring_stiffness_factor(1.0, 1.0), 1.0);
  EXPECT_EQ(spring_stiffness_factor(2.0, 2.0), 2.0);
  EXPECT_DOUBLE_EQ(spring_stiffness_factor(1.0, 3.0), 1.5);  // 2·3/4
  EXPECT_DOUBLE_EQ(spring_stiffness_factor(0.5, 2.0), 0.8);  // 2·1/2.5
  EXPECT_EQ(spring_stiffness_factor(0.7, 1.9), spring_stiffness_factor(1.9, 0.7));
}

TEST(EvolvedStiffness, UniformFactorsReproduceTheDefaultBodyBitwise) {
  const Body plain = swimmer(lattice_points(6, 5, 0.1), Drive::wave);
  const SceneParams scene;  // the paper's scene: springs, actuation, pressure, drag, collisions
  const int steps = 600;
  const std::vector<double> reference = run_positions(plain, scene, steps);

  Body ones = plain;
  ones.stiffness = Vector::Ones(plain.node_count());
  EXPECT_EQ(run_positions(ones, scene, steps), reference)
      << "factors 1 must be the uniform body, bit for bit";

  // Factors 2 with half the scene stiffness: k/2 · 2 = k exactly (powers of two).
  Body twos = plain;
  twos.stiffness = Vector::Constant(plain.node_count(), 2.0);
  SceneParams half = scene;
  half.spring_stiffness = 0.5 * scene.spring_stiffness;
  EXPECT_EQ(run_positions(twos, half, steps), reference);

  // Not vacuous: other factors change the motion.
  Body soft = plain;
  soft.stiffness = Vector::Constant(plain.node_count(), 0.5);
  EXPECT_NE(run_positions(soft, scene, steps), reference);
}

/// Period of the two-cell oscillation from the upward zero crossings of (length − rest).
double measured_period(const Body& body, const SceneParams& scene, int steps) {
  PhysicsParams physics;
  Simulation sim(body, scene, physics);
  const double rest = body.rest_lengths(0);
  std::vector<double> crossings;
  double prev =
      std::hypot(sim.state().x[1] - sim.state().x[0], sim.state().y[1] - sim.state().y[0]) - rest;
  for (int k = 1; k <= steps; ++k) {
    sim.step(1);
    const double u =
        std::hypot(sim.state().x[1] - sim.state().x[0], sim.state().y[1] - sim.state().y[0]) - rest;
    // linear interpolation
    if (prev < 0.0 && u >= 0.0) crossings.push_back((k - 1 + prev / (prev - u)) * physics.dt);
    prev = u;
  }
  EXPECT_GE(crossings.size(), 5U);
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(EvolvedStiffness, TwoCellPeriodFollowsTheEvolvedStiffness) {
  // Two cells of mass m joined by one undamped spring of stiffness k_eff = k·2 f0 f1/(f0 + f1):
  // the relative coordinate oscillates with ω = sqrt(k_eff/μ), μ = m/2 the reduced mass.
  SceneParams scene = scene_with({"springs"});
  scene.spring_damping = 0.0;
  const double k = scene.spring_stiffness, m = scene.cell_mass;
  const PhysicsParams physics;
  for (const auto& [f0, f1] : std::vector<std::pair<double, double>>{
           {1.0, 1.0}, {0.3, 0.3}, {0.5, 2.0}, {1.0, 4.0}, {0.2, 3.0}}) {
    Body b = two_nodes(1.05, 1.0);  // stretched by 5 %
    b.stiffness = (Vector(2) << f0, f1).finished();
    const double k_eff = k * 2.0 * f0 * f1 / (f0 + f1);
    const double omega = std::sqrt(k_eff / (0.5 * m));
    const double period = 2.0 * std::numbers::pi / omega;
    const int steps = static_cast<int>(8.0 * period / physics.dt);
    const double measured = measured_period(b, scene, steps);
    // A second-order integrator at ω·dt <= 0.4 is within ~(ω dt)²/24 < 1 % of the continuous
    // period.
    EXPECT_NEAR(measured, period, 0.01 * period)
        << "f0=" << f0 << " f1=" << f1 << " omega*dt=" << omega * physics.dt;
  }
}

TEST(EvolvedStiffness, BadFactorsAreRejected) {
  Body b = two_nodes(1.0, 1.0);
  SceneParams scene = scene_with({"springs"});
  PhysicsParams physics;
  b.stiffness = Vector::Ones(3);
  EXPECT_THROW(Simulation(b, scene, physics), GeometryError);
  b.stiffness = (Vector(2) << 1.0, 0.0).finished();
  EXPECT_THROW(Simulation(b, scene, physics), GeometryError);
  b.stiffness = (Vector(2) << 1.0, NAN).finished();
  EXPECT_THROW(Simulation(b, scene, physics), GeometryError);
}

}  // namespace
}  // namespace animat
