// Active control (include/animat/control.hpp, docs/control.md): the GRN keeps running
// while the animat swims. Analytic checks of the sensors, of eq. 1 driving the actuation, of
// signalling (the discrete heat equation on a chain), the push, the config keys, and that open loop
// is the paper's engine.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/control.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "animat/objective.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "physics_support.hpp"

using namespace animat;

#include "counting_allocator.hpp"  // the grn-mode loop allocates nothing

namespace {

Element special(ElementType t, int channel, double x, double y, int sign = 1) {
  return Element{t, sign, channel, {x, y}};
}
Element el(ElementType t, double x, double y) { return Element{t, 1, 0, {x, y}}; }

/// input `channel` -> actuation output at distance 0: weight 10, so L -> tanh(5·input).
Genome follower(InputChannel channel) {
  return Genome{2,
                {special(ElementType::input, static_cast<int>(channel), 0, 0),
                 special(ElementType::output, static_cast<int>(OutputChannel::actuation), 0, 0)}};
}

GrnControlStart start_for(const Genome& g, int cells, double amplitude_max = 0.2) {
  GrnControlStart s;
  s.grn = Grn(g, GenomeParams{});
  s.levels.assign(static_cast<std::size_t>(cells * s.grn.node_count()), 0.0);
  s.maternal.assign(static_cast<std::size_t>(cells) * 3, 0.0);
  s.amplitude_max = amplitude_max;
  return s;
}

/// A SwimState for `body` at its rest positions, step `step` of length h.
SwimState state_of(const Body& body, long step, double h) {
  SwimState s;
  s.n = body.node_count();
  s.step = step;
  s.h = h;
  s.time = step * h;
  for (int i = 0; i < s.n; ++i) {
    s.x.push_back(body.positions(i, 0));
    s.y.push_back(body.positions(i, 1));
  }
  s.rest.assign(static_cast<std::size_t>(body.spring_count()), 0.0);
  return s;
}

// Float-exact coordinates: swim_body() rounds positions to float, so the analytic values are exact.
Body triangle() {
  return build_body(points({{0.0, 0.0}, {1.0, 0.0}, {0.5, 0.75}}), Vector(), Vector(), Vector());
}

}  // namespace

TEST(ControlChemical, FieldHasItsAnalyticForm) {
  EXPECT_DOUBLE_EQ(chemical_field("point", 3, 4, 1, 0, 2.0, 0, 0), std::exp(-5.0 / 2.0));
  EXPECT_DOUBLE_EQ(chemical_field("plane", 10, 0, 1, 0, 4.0, 2, 7), std::exp(-8.0 / 4.0));
  EXPECT_DOUBLE_EQ(chemical_field("plane", 10, 0, 1, 0, 4.0, 12, 7), 1.0);  // beyond the plane
  EXPECT_EQ(chemical_field("none", 10, 0, 1, 0, 4.0, 2, 7), 0.0);
}

TEST(ControlChemical, CellSensorReadsTheFieldAtTheCell) {
  const Body body = triangle();
  for (const std::string kind : {"point", "plane"}) {
    SceneParams scene;
    scene.chemical = kind;
    scene.chemical_source = {6.0, 8.0};  // relative to the start centre
    scene.chemical_decay_length = 3.0;
    ControlParams control;
    control.mode = "grn";
    control.start_ramp = 0.0;
    GrnControl c(body, start_for(follower(InputChannel::chemical), 3), control, scene,
                 PhysicsParams{});
    SwimState s = state_of(body, 0, 1.0 / 60.0);
    c.apply(s);
    const double cx = 0.5, cy = 0.25;  // centre of the triangle
    const double sx = cx + 6.0, sy = cy + 8.0;
    for (int i = 0; i < 3; ++i) {
      const double x = body.positions(i, 0), y = body.positions(i, 1);
      const double expected = kind == "point" ? std::exp(-std::hypot(x - sx, y - sy) / 3.0)
                                              : std::exp(-((sx - x) * 0.6 + (sy - y) * 0.8) / 3.0);
      EXPECT_NEAR(c.sensors()[3 * static_cast<std::size_t>(i) + 2], expected, 1e-12)
          << kind << " cell " << i;
    }
  }
}

TEST(ControlSensors, StrainAndPressureOfAUniformStretch) {
  const Body body = triangle();
  ControlParams control;
  control.mode = "grn";
  GrnControl c(body, start_for(follower(InputChannel::strain), 3), control, SceneParams{},
               PhysicsParams{});
  SwimState s = state_of(body, 0, 1.0 / 60.0);
  for (int i = 0; i < 3; ++i) {  // every length × 1.1 about cell 0: strain 0.1, S/S0 = 1.21
    s.x[static_cast<std::size_t>(i)] *= 1.1;
    s.y[static_cast<std::size_t>(i)] *= 1.1;
  }
  c.apply(s);
  for (std::size_t i = 0; i < 3; ++i) {
    // rest lengths are re-measured in float (swim_body)
    EXPECT_NEAR(c.sensors()[3 * i], 0.1, 1e-6) << i;
    EXPECT_NEAR(c.sensors()[3 * i + 1], 1.21, 1e-6) << i;
  }
}

TEST(ControlGrn, ActuationFollowsTheInputThroughEq1) {
  // A chemical field that changes as the cells move: the actuation level obeys the eq. 1
  // recurrence L' = L + (tanh(10·c/2) − L)·Δ with Δ = grn_rate·k·h, and u = a_max·(2L − 1).
  const Body body = triangle();
  SceneParams scene;
  scene.chemical = "point";
  scene.chemical_source = {2.0, 0.0};
  scene.chemical_decay_length = 1.5;
  ControlParams control;
  control.mode = "grn";
  control.update_interval = 4;
  control.grn_rate = 3.0;
  control.start_ramp = 0.0;
  PhysicsParams physics;
  const double h = physics.dt;
  const double delta = 3.0 * 4 * h;
  GrnControl c(body, start_for(follower(InputChannel::chemical), 3, 0.25), control, scene, physics);
  const Body swum = swim_body(body);
  const double sx = 0.5 + 2.0, sy = 0.25;
  std::vector<double> level(3, 0.0);
  SwimState s = state_of(body, 0, h);
  for (long step = 0; step < 200; ++step) {
    s.step = step;
    s.time = step * h;
    // the body slides along x
    const double shift = 0.5 * std::sin(0.05 * static_cast<double>(step / 4));
    for (std::size_t i = 0; i < 3; ++i) s.x[i] = body.positions(static_cast<int>(i), 0) + shift;
    c.apply(s);
    if (step % 4 == 0)
      for (std::size_t i = 0; i < 3; ++i) {
        const double cval = std::exp(-std::hypot(s.x[i] - sx, s.y[i] - sy) / 1.5);
        level[i] += (std::tanh(10.0 * cval / 2.0) - level[i]) * delta;
      }
    for (std::size_t i = 0; i < 3; ++i)
      ASSERT_NEAR(c.terms()[i], 0.25 * (2.0 * level[i] - 1.0), 1e-13)
          << "step " << step << " cell " << i;
    for (int e = 0; e < swum.spring_count(); ++e) {
      const auto a = static_cast<std::size_t>(swum.springs(e, 0)),
                 b = static_cast<std::size_t>(swum.springs(e, 1));
      ASSERT_NEAR(s.rest[static_cast<std::size_t>(e)],
                  (1.0 + c.terms()[a] + c.terms()[b]) * swum.rest_lengths(e), 1e-13);
    }
  }
  EXPECT_EQ(c.updates(), 50);
}

TEST(ControlGrn, StartRampScalesTheTermsFromZero) {
  const Body body = triangle();
  ControlParams control;
  control.mode = "grn";
  control.update_interval = 1;
  control.start_ramp = 0.5;
  GrnControl c(body, start_for(follower(InputChannel::bias), 3), control, SceneParams{},
               PhysicsParams{});
  SwimState s = state_of(body, 0, 1.0 / 60.0);
  c.apply(s);
  EXPECT_EQ(c.terms()[0], 0.0);  // t = 0
  s.step = 15;
  s.time = 0.25;
  c.apply(s);
  const double level = c.grn().output(c.state(0), OutputChannel::actuation);
  EXPECT_NEAR(c.terms()[0], 0.5 * 0.2 * (2.0 * level - 1.0), 1e-15);
}

TEST(ControlSignalling, ChainMatchesTheDiscreteHeatEquation) {
  // Five cells on a line: the Gabriel graph is the chain 0-1-2-3-4. One diffusible product, λ = 0:
  // f' = f + Δ·D·(f_{i-1} − 2 f_i + f_{i+1}) with the chain's ends reflecting (no flux).
  const Body chain =
      build_body(points({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}}), Vector(), Vector(), Vector());
  ASSERT_EQ(chain.spring_count(), 4);
  const Genome g{2, {el(ElementType::promoter, 0, 0), el(ElementType::morphogen_gene, 9, 9)}};
  GrnControlStart start = start_for(g, 5);
  ASSERT_EQ(start.grn.morphogen_units().size(), 1u);
  start.sensed = {1.0, 0.0, 0.0, 0.0, 0.5};
  ControlParams control;
  control.mode = "grn";
  control.update_interval = 2;
  control.signal_rate = 4.0;
  control.signal_decay = 0.0;
  PhysicsParams physics;
  GrnControl c(chain, start, control, SceneParams{}, physics);
  const double r = 2 * physics.dt * 4.0;  // Δ·D
  std::vector<double> f = {1.0, 0.0, 0.0, 0.0, 0.5};
  SwimState s = state_of(chain, 0, physics.dt);
  for (long step = 0; step < 40; ++step) {
    s.step = step;
    c.apply(s);
    if (step % 2 != 0) continue;
    std::vector<double> next(5);
    for (std::size_t i = 0; i < 5; ++i) {
      const double left = i > 0 ? f[i - 1] - f[i] : 0.0;
      const double right = i < 4 ? f[i + 1] - f[i] : 0.0;
      next[i] = f[i] + r * (left + right);
    }
    f = next;
    for (std::size_t i = 0; i < 5; ++i)
      ASSERT_NEAR(c.signals()[i], f[i], 1e-15) << "step " << step << " cell " << i;
  }
  double total = 0.0;
  for (double v : c.signals()) total += v;
  EXPECT_NEAR(total, 1.5, 1e-14);  // the Laplacian conserves the total
}

TEST(ControlSignalling, FastDiffusionTakesSubstepsAndStaysBounded) {
  // D = 100 with k·h = 5/60: Δ·(D·2 + λ) = 16.75 -> 17 substeps of Δ/17; the field stays in [0, 1]
  // and conserves its total (λ = 0) on the way to the uniform mean.
  const Body chain = build_body(points({{0, 0}, {1, 0}, {2, 0}}), Vector(), Vector(), Vector());
  const Genome g{2, {el(ElementType::promoter, 0, 0), el(ElementType::morphogen_gene, 9, 9)}};
  GrnControlStart start = start_for(g, 3);
  start.sensed = {1.0, 0.0, 0.0};
  ControlParams control;
  control.mode = "grn";
  control.signal_rate = 100.0;
  control.signal_decay = 1.0;
  control.update_interval = 5;
  GrnControl c(chain, start, control, SceneParams{}, PhysicsParams{});
  EXPECT_EQ(c.signal_substeps(), 17);
  control.signal_decay = 0.0;
  GrnControl d(chain, start, control, SceneParams{}, PhysicsParams{});
  SwimState s = state_of(chain, 0, PhysicsParams{}.dt);
  for (long step = 0; step < 100; ++step) {
    s.step = step;
    d.apply(s);
    for (double v : d.signals()) ASSERT_TRUE(v >= 0.0 && v <= 1.0) << v;
  }
  for (double v : d.signals()) EXPECT_NEAR(v, 1.0 / 3.0, 1e-12);
}

TEST(ControlConfig, KeysValidateAndNameTheValue) {
  Config c;
  EXPECT_EQ(c.control.mode, "open_loop");
  apply_override(c, "control.mode=grn");
  EXPECT_NO_THROW(validate(c));
  EXPECT_THROW(apply_override(c, "control.mode=closed"), ConfigError);
  c.control.update_interval = 100;  // 3 × 100 / 60 = 5 > 1
  try {
    validate(c);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("control.update_interval = 100"), std::string::npos)
        << e.what();
  }
  c = Config{};
  EXPECT_THROW(apply_override(c, "scene.chemical=ring"), ConfigError);
  c.scene.chemical_source = {1.0};
  EXPECT_THROW(validate(c), ConfigError);
}

TEST(ControlPush, AddsImpulseOverMassToTheListedCells) {
  SceneParams scene = scene_with({"springs"});
  scene.cell_mass = 2.0;
  Simulation sim(square(), scene);
  const std::vector<int> cells = {0, 2};
  sim.push(cells, Eigen::Vector2d(1.0, -3.0));
  const Points v = sim.velocities();
  EXPECT_DOUBLE_EQ(v(0, 0), 0.5);
  EXPECT_DOUBLE_EQ(v(0, 1), -1.5);
  EXPECT_DOUBLE_EQ(v(2, 0), 0.5);
  EXPECT_EQ(v(1, 0), 0.0);
  EXPECT_EQ(v(3, 1), 0.0);
  EXPECT_NEAR(sim.momentum().x(), 2.0, 1e-12);  // |cells|·impulse
  EXPECT_NEAR(sim.momentum().y(), -6.0, 1e-12);
  Simulation two(two_nodes(1.0, 1.0), scene);
  const std::vector<int> bad = {2};
  EXPECT_THROW(two.push(bad, Eigen::Vector2d(1.0, 0.0)), GeometryError);
  EXPECT_THROW(two.push(cells, Eigen::Vector2d(std::nan(""), 0.0)), GeometryError);
}

TEST(ControlGrn, SwimLoopAllocatesNothing) {
  // A controller with sensors, a morphogen (signalling on) and every update interval's code path.
  const Body body = swimmer(lattice_points(8, 4, 0.1, 2), Drive::none);
  const Genome g{2,
                 {special(ElementType::input, static_cast<int>(InputChannel::bias), 0, 0),
                  el(ElementType::promoter, 0.5, 0), el(ElementType::morphogen_gene, 1, 0),
                  special(ElementType::input, static_cast<int>(InputChannel::strain), 1, 0.5),
                  special(ElementType::input, static_cast<int>(InputChannel::chemical), 0, 1),
                  special(ElementType::output, static_cast<int>(OutputChannel::actuation), 1, 1)}};
  GrnControlStart start = start_for(g, body.node_count());
  ASSERT_EQ(start.grn.morphogen_units().size(), 1u);
  SceneParams scene = scene_with({"springs", "pressure", "drag", "collisions"});
  scene.chemical = "point";
  for (int k : {1, 5}) {
    ControlParams control;
    control.mode = "grn";
    control.update_interval = k;
    control.signal_rate = 1.0;
    Simulation sim(body, scene);
    auto effect = std::make_unique<GrnControl>(body, start, control, scene, PhysicsParams{});
    const GrnControl* c = effect.get();
    sim.add_effect(std::move(effect));
    sim.step(10);
    g_allocations = 0;
    g_counting = true;
    sim.step(2000);
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << "k = " << k;
    EXPECT_EQ(c->updates(), (2010 + k - 1) / k);
    EXPECT_GT(std::abs(c->terms()[0]), 0.0);
  }
}

TEST(ControlEvaluation, OpenLoopIsTheEngineAndGrnModeSwims) {
  // Open loop at the defaults: evaluate() is what it always was (the fingerprint tests of
  // test_evolution pin it); here: the extra keys at their defaults change nothing, and a GRN-mode
  // evaluation of a genome with an actuation output runs, updates its GRN and stays valid.
  Config config;
  config.evaluation.steps = 300;
  Rng rng(11);
  Genome viable;
  for (int tries = 0; tries < 5000; ++tries) {
    Genome g = random_genome(config.genome, rng);
    if (evaluate(g, config).viable) {
      viable = g;
      break;
    }
  }
  ASSERT_FALSE(viable.elements.empty());
  const EvaluationResult open = evaluate(viable, config);
  Config same = config;
  same.scene.chemical = "none";
  same.control.update_interval = 7;  // ignored in open loop
  EXPECT_EQ(evaluate(viable, same).fitness, open.fitness);
  EXPECT_EQ(open.grn_updates, 0);
  // The same genome plus an actuation output next to its first promoter.
  Genome active = viable;
  for (const Element& e : viable.elements)
    if (e.type == ElementType::promoter) {
      active.elements.push_back(
          Element{ElementType::output, 1, static_cast<int>(OutputChannel::actuation), e.coords});
      break;
    }
  Config grn = config;
  grn.control.mode = "grn";
  const EvaluationResult r = evaluate(active, grn);
  ASSERT_TRUE(r.viable);
  EXPECT_EQ(r.grn_updates, (300 + grn.control.update_interval - 1) / grn.control.update_interval);
  EXPECT_TRUE(r.stable) << (r.reasons.empty() ? "" : r.reasons[0]);
}

TEST(ControlEvaluation, AnUpdatePeriodKeepsTheControllerScheduleAtEveryPhysicsStep) {
  // The GRN's updates every update_interval Box2D steps happen more often per time unit at a finer
  // step; with update_period they happen at the same times at any step, and a period of k steps at
  // the default step is the update_interval k, bit for bit.
  Config config;
  config.evaluation.steps = 240;
  config.control.mode = "grn";
  Rng rng(11);
  Genome active;
  for (int tries = 0; tries < 5000 && active.elements.empty(); ++tries) {
    Genome g = random_genome(config.genome, rng);
    if (!evaluate(g, Config{}).viable) continue;
    for (const Element& e : g.elements)
      if (e.type == ElementType::promoter) {
        g.elements.push_back(
            Element{ElementType::output, 1, static_cast<int>(OutputChannel::actuation), e.coords});
        break;
      }
    active = g;
  }
  ASSERT_FALSE(active.elements.empty());
  const EvaluationResult steps = evaluate(active, config);
  Config period = config;
  period.control.update_period = config.control.update_interval * config.physics.dt;
  const EvaluationResult same = evaluate(active, period);
  EXPECT_EQ(same.fitness, steps.fitness);
  EXPECT_EQ(same.grn_updates, steps.grn_updates);
  for (const int substeps : {2, 4}) {
    Config finer = config;
    finer.physics.substeps = substeps;
    EXPECT_EQ(evaluate(active, finer).grn_updates, substeps * steps.grn_updates) << substeps;
    Config finer_period = period;
    finer_period.physics.substeps = substeps;
    EXPECT_EQ(evaluate(active, finer_period).grn_updates, steps.grn_updates) << substeps;
  }
  // A period that is not a whole number of steps is refused, naming the key and the step.
  period.control.update_period = 1.5 * config.physics.dt;
  try {
    validate(period);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("control.update_period = 0.025 is not a whole number"),
              std::string::npos)
        << e.what();
  }
}

TEST(ControlEvaluation, ChemotaxisAveragesProgressOverSeededDirections) {
  Config config;
  config.evaluation.objective = "chemotaxis";
  config.evaluation.source_directions = 3;
  const auto d0 = source_direction(config, 0), d1 = source_direction(config, 1);
  EXPECT_NEAR(std::hypot(d0[0], d0[1]), 20.0, 1e-12);  // |scene.chemical_source|
  EXPECT_EQ(source_direction(config, 1), d1);          // deterministic
  // An evenly spaced fan: 120° apart, so the sources sum to 0 (straight swimming gains nothing).
  const auto d2 = source_direction(config, 2);
  EXPECT_NEAR(d0[0] * d1[0] + d0[1] * d1[1], 400.0 * std::cos(2.0 * 3.14159265358979323846 / 3.0),
              1e-9);
  EXPECT_NEAR(d0[0] + d1[0] + d2[0], 0.0, 1e-12);
  EXPECT_NEAR(d0[1] + d1[1] + d2[1], 0.0, 1e-12);
  Config other = config;
  other.evaluation.source_seed = 2;
  EXPECT_NE(source_direction(other, 0), d0);  // the offset comes from the seed
  EXPECT_EQ(make_objective(config.evaluation)->name(), "chemotaxis");
}

TEST(ControlEvaluation, PushScheduleChangesTheSwimOnlyWhenOn) {
  Config config;
  config.evaluation.steps = 200;
  Rng rng(5);
  Genome viable;
  for (int tries = 0; tries < 5000; ++tries) {
    Genome g = random_genome(config.genome, rng);
    if (evaluate(g, config).viable) {
      viable = g;
      break;
    }
  }
  ASSERT_FALSE(viable.elements.empty());
  const EvaluationResult plain = evaluate(viable, config);
  Config pushed = config;
  pushed.evaluation.push_impulse = {5.0, 0.0};
  EXPECT_EQ(evaluate(viable, pushed).fitness, plain.fitness);  // push_step = -1: never
  pushed.evaluation.push_step = 100;
  const EvaluationResult p = evaluate(viable, pushed);
  EXPECT_NE(p.fitness, plain.fitness);
  EXPECT_GT(p.displacement.x() - plain.displacement.x(), 0.0);  // shoved along +x
  EXPECT_NE(p.displacement_at_push.norm(), 0.0);
}

TEST(ControlGrn, AmplitudeModeModulatesTheDevelopedOscillator) {
  // control.actuation = "amplitude": u_i = a_max·L·sin(f_i·t + φ_i) from the cell's start time on,
  // L the bias-driven actuation level (eq. 1 towards tanh(5)).
  const Points p = points({{0.0, 0.0}, {1.0, 0.0}, {0.5, 0.75}});
  Vector a(3), f(3), ph(3);
  a << 0.1, 0.1, 0.1;
  f << 2.0, 3.0, 4.0;
  ph << 0.0, 1.0, 4.0;
  const Body body = build_body(p, a, f, ph);
  ControlParams control;
  control.mode = "grn";
  control.actuation = "amplitude";
  control.update_interval = 3;
  control.start_ramp = 0.0;
  const PhysicsParams physics;
  const double h = physics.dt, delta = control.grn_rate * 3 * h;
  GrnControl c(body, start_for(follower(InputChannel::bias), 3, 0.2), control, SceneParams{},
               physics);
  SwimState s = state_of(body, 0, h);
  double level = 0.0;
  for (long step = 0; step < 300; ++step) {
    s.step = step;
    s.time = step * h;
    c.apply(s);
    if (step % 3 == 0) level += (std::tanh(5.0) - level) * delta;
    for (int i = 0; i < 3; ++i) {
      const double t0 = actuation_start_time(f(i), ph(i));
      const double expected = s.time >= t0 ? 0.2 * level * std::sin(f(i) * s.time + ph(i)) : 0.0;
      ASSERT_NEAR(c.terms()[static_cast<std::size_t>(i)], expected, 1e-13)
          << "step " << step << " cell " << i;
    }
  }
  EXPECT_GT(actuation_start_time(f(2), ph(2)), 0.0);  // one cell starts late, as in open loop
}
