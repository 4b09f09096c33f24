// The cost of actuation (docs/worlds.md): the mechanical work that the changing rest lengths put
// into the springs, ΔW = k·(r − r₀)·((r + r₀)/2 − (ℓ + ℓ₀)/2) per spring and Box2D step
// (src/effects/springs.cpp), checked on a single driven spring against the analytic energy balance.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "animat/body.hpp"
#include "animat/evaluate.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "physics_support.hpp"

namespace animat {
namespace {

/// One spring of rest length 1 between two cells, both driven with amplitude c/2, frequency w and
/// phase 0, so r(t) = 1 + c·sin(w·t) from t = 0.
Body driven_spring(double c, double w) {
  Body b = two_nodes(1.0, 1.0);
  b.amplitude = Vector::Constant(2, 0.5 * c);
  b.frequency = Vector::Constant(2, w);
  b.phase = Vector::Zero(2);
  return b;
}

double spring_length(const Simulation& sim) {
  const SwimState& s = sim.state();
  return std::hypot(s.x[1] - s.x[0], s.y[1] - s.y[0]);
}

TEST(ActuationWork, UndampedPeriodicResponseDoesNoNetWorkPerPeriod) {
  // Undamped, in vacuum, started on the periodic solution of the discrete equations of motion
  // (symplectic Euler, as Box2D integrates): with ω0² = 2k/m, θ = w·h, the relative coordinate
  // ℓ_k = 1 + A·sin(θ·k), A = c·h²ω0²/(h²ω0² − 4 sin²(θ/2)), solves
  // ℓ_{k+1} − 2ℓ_k + ℓ_{k−1} = −h²ω0²·(ℓ_k − r_k) exactly, with initial relative velocity
  // A·sin(θ)/h. ℓ is then an affine function of r, and the midpoint-rule work telescopes to exactly
  // zero over every period of N steps. What remains is float rounding of Box2D's positions: each
  // length carries an error of a few float ulps (ε ~ 1e-6 at coordinates ~1), so the net work per
  // period is bounded by k·Σ|Δr|·ε, while the absolute work per period is k·Σ|Δr|·|r̄ − ℓ̄| with
  // |r − ℓ| ~ 0.01 here: the tolerance is 1e-6·k·Σ|Δr|, about 1e-4 of the absolute work.
  SceneParams scene = scene_with({"springs", "actuation"});
  scene.spring_damping = 0.0;
  PhysicsParams physics;
  const double h = physics.dt, k = scene.spring_stiffness, m = scene.cell_mass;
  const int N = 120;  // steps per period
  const double w = 2.0 * std::numbers::pi / (N * h), c = 0.2;
  const double theta = w * h, hw0 = h * h * 2.0 * k / m;
  const double A = c * hw0 / (hw0 - 4.0 * std::sin(0.5 * theta) * std::sin(0.5 * theta));
  Simulation sim(driven_spring(c, w), scene, physics);
  const double u0 = A * std::sin(theta) / h;
  sim.set_velocities(points({{-0.5 * u0, 0.0}, {0.5 * u0, 0.0}}));
  const double sum_abs_dr = 4.0 * c;  // Σ|Δr| over one period of r = 1 + c·sin
  // The work of step k covers [t_{k−1}, t_k] (it needs r_k, known when step k starts), so after
  // 1 + p·N steps the counters cover exactly p periods.
  sim.step(1);
  for (int period = 0; period < 10; ++period) {
    const SwimCounters before = sim.counters();
    sim.step(N);
    const SwimCounters& after = sim.counters();
    const double net = after.actuation_work - before.actuation_work;
    const double abs = after.actuation_work_absolute - before.actuation_work_absolute;
    const double pos = after.actuation_work_positive - before.actuation_work_positive;
    EXPECT_LT(std::abs(net), 1e-6 * k * sum_abs_dr)
        << "period " << period << " net " << net << " abs " << abs;
    EXPECT_GT(abs, 0.1 * k * c * std::abs(c - A));  // the test is not vacuous: work flows both ways
    EXPECT_NEAR(pos, 0.5 * abs, 1e-6 * k * sum_abs_dr);
  }
  // The motion is the predicted one (so the zero is not an accident of a different motion).
  EXPECT_NEAR(spring_length(sim), 1.0 + A * std::sin(theta), 1e-5);  // ℓ_{1+10N} = ℓ_1
  EXPECT_NEAR(sim.velocities()(1, 0) - sim.velocities()(0, 0), u0, 1e-3 * std::abs(u0));
}

TEST(ActuationWork, DampedSteadyStateWorkEqualsDissipation) {
  // With spring damping c_d, in the periodic steady state the actuation work over whole periods
  // equals the energy the damper dissipated, ∫ c_d·(dℓ/dt)² dt, here summed per step from the
  // relative velocity Box2D integrates (ℓ_{k+1} − ℓ_k = h·u_{k+1}); within 1 %.
  SceneParams scene = scene_with({"springs", "actuation"});
  scene.spring_damping = 4.0;
  PhysicsParams physics;
  const double h = physics.dt;
  const int N = 120;
  const double w = 2.0 * std::numbers::pi / (N * h), c = 0.2;
  Simulation sim(driven_spring(c, w), scene, physics);
  sim.step(20 * N);  // the transient decays as exp(−c_d/m · t): e^−160 after 40 time units
  const SwimCounters before = sim.counters();
  double dissipated = 0.0;
  double len = spring_length(sim);
  const int periods = 5;
  for (int k = 0; k < periods * N; ++k) {
    sim.step();
    const double next = spring_length(sim);
    const double u = (next - len) / h;
    dissipated += scene.spring_damping * u * u * h;
    len = next;
  }
  const double work = sim.counters().actuation_work - before.actuation_work;
  ASSERT_GT(dissipated, 0.0);
  EXPECT_NEAR(work, dissipated, 0.01 * dissipated)
      << "work " << work << " dissipated " << dissipated;
}

TEST(ActuationWork, NoActuationNoWorkAndPerCellSplitSumsToTotals) {
  const Body still = swimmer(lattice_points(5, 3, 0.05, 3), Drive::none);
  const SwimResult r0 = swim(still, SceneParams{}, PhysicsParams{}, 200);
  EXPECT_EQ(r0.actuation_work, 0.0);
  EXPECT_EQ(r0.actuation_work_absolute, 0.0);
  ASSERT_EQ(r0.cell_work_positive.size(), still.node_count());
  EXPECT_EQ(r0.cell_work_positive.sum(), 0.0);

  const Body b = swimmer(lattice_points(5, 3, 0.05, 3), Drive::wave, 0.15, 4.0);
  const SwimResult r = swim(b, SceneParams{}, PhysicsParams{}, 600);
  ASSERT_TRUE(r.valid) << r.failure;
  EXPECT_GT(r.actuation_work_positive, 0.0);
  EXPECT_GE(r.actuation_work_absolute, r.actuation_work_positive);
  EXPECT_LE(std::abs(r.actuation_work), r.actuation_work_absolute);
  // Net work = 2·positive − absolute (each step's ΔW is either positive or not).
  EXPECT_NEAR(r.actuation_work, 2.0 * r.actuation_work_positive - r.actuation_work_absolute,
              1e-9 * r.actuation_work_absolute);
  ASSERT_EQ(r.cell_work_positive.size(), b.node_count());
  EXPECT_NEAR(r.cell_work_positive.sum(), r.actuation_work_positive,
              1e-9 * r.actuation_work_positive);
  EXPECT_NEAR(r.cell_work_absolute.sum(), r.actuation_work_absolute,
              1e-9 * r.actuation_work_absolute);
  EXPECT_GE(r.cell_work_positive.minCoeff(), 0.0);
  // Without actuation rest lengths never change: a still square does no work at all.
  Simulation sq(square(), scene_with({"springs", "pressure"}));
  sq.step(10);
  EXPECT_EQ(sq.counters().actuation_work_absolute, 0.0);
}

}  // namespace
}  // namespace animat

namespace animat {

TEST(SwimCounters, EveryCounterThatSwimResultReportsIsCopiedByName) {
  // Distinct values in every counter; each SwimResult field of the same name and type gets its
  // counter's value, every other field keeps its default.
  SwimCounters c;
  double next = 1.0;
  visit_fields(c, [&](const char*, const char*, auto& value) {
    value = static_cast<std::decay_t<decltype(value)>>(next);
    next += 1.0;
  });
  SwimResult r;
  copy_counters(c, r);
  std::vector<std::string> copied, not_reported;
  visit_fields(c, [&](const char* name, const char*, const auto& value) {
    bool found = false;
    visit_fields(r, [&](const char* field, const char*, const auto& target) {
      if constexpr (std::is_same_v<std::decay_t<decltype(target)>, std::decay_t<decltype(value)>>) {
        if (std::string_view(field) == name) {
          EXPECT_EQ(target, value) << name;
          found = true;
        }
      }
    });
    (found ? copied : not_reported).push_back(name);
  });
  EXPECT_EQ(copied, (std::vector<std::string>{
                        "collisions", "collisions_inelastic", "collisions_unresolved",
                        "drag_limited", "ground_contacts", "ground_slips", "airborne_steps",
                        "actuation_work", "actuation_work_positive", "actuation_work_absolute"}));
  // The counters a swim's record does not report (Simulation.counters has them).
  EXPECT_EQ(not_reported, (std::vector<std::string>{"collision_max_passes"}));
  EXPECT_EQ(r.distance, SwimResult{}.distance);
}

}  // namespace animat
