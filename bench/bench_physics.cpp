// Swim-step benchmarks (docs/performance.md): the swim step against a bare Box2D Step of the same
// number of fixture-less bodies, the cost of each effect alone, and of each drag scheme.
//
//   build-phys/bench_physics --benchmark_out=bench_physics.csv --benchmark_out_format=csv
//
// Bodies are triangular lattices (spacing 1, jitter 0.05) with a travelling-wave actuation at
// f = 4 rad/time unit, amplitude 0.2: a typical evolved swimmer. One iteration = one control step
// (the "CPU" column is the cost per step). On a shared machine, prefer instruction counts:
//   valgrind --tool=callgrind build-phys/bench_physics --benchmark_filter=BM_SwimStep/32
// (docs/notes/physics.md quotes them per effect).
#include <benchmark/benchmark.h>
#include <box2d/box2d.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "../src/box2d_island.hpp"
#include "animat/body.hpp"
#include "animat/control.hpp"
#include "animat/errors.hpp"
#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "animat/scene.hpp"
#include "bench_context.hpp"

namespace {

using namespace animat;

Body lattice_swimmer(int cells) {
  const int nx = cells <= 32 ? 8 : cells <= 64 ? 8 : 16;
  const int ny = cells / nx;
  Rng rng(42);
  Points p(nx * ny, 2);
  Vector a(nx * ny), f(nx * ny), ph(nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int k = j * nx + i;
      p(k, 0) = i + (j % 2 ? 0.5 : 0.0) + rng.uniform(-0.05, 0.05);
      p(k, 1) = j * std::sqrt(3.0) / 2.0 + rng.uniform(-0.05, 0.05);
      a(k) = 0.2;
      f(k) = 4.0;
      ph(k) = std::fmod(2.0 * std::numbers::pi * p(k, 0) / 4.0, 2.0 * std::numbers::pi);
    }
  return build_body(p, a, f, ph);
}

/// Runs control steps in chunks; restarts the simulation if it ever fails (it should not).
void run_swim(benchmark::State& state, const Body& body, const SceneParams& scene,
              const PhysicsParams& physics) {
  auto sim = std::make_unique<Simulation>(body, scene, physics);
  for (auto _ : state) {
    try {
      sim->step(1);
    } catch (const SimulationError&) {
      state.PauseTiming();
      sim = std::make_unique<Simulation>(body, scene, physics);
      state.ResumeTiming();
    }
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = body.node_count();
}

/// Box2D alone: n fixture-less dynamic bodies, no forces, stepped at the default dt. Unlinked, each
/// body is its own island; linked, they are one island as in the swim world (src/box2d_island.hpp).
void run_box2d_only(benchmark::State& state, bool linked) {
  const int n = static_cast<int>(state.range(0));
  b2World world(b2Vec2(0.0f, 0.0f));
  world.SetAllowSleeping(false);
  world.SetContinuousPhysics(false);
  if (linked) world.SetWarmStarting(false);  // as the swim world
  b2MassData md;
  md.mass = 1.0f;
  md.center.SetZero();
  md.I = 0.0f;
  std::vector<b2Body*> bodies;
  for (int i = 0; i < n; ++i) {
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(static_cast<float>(i % 8), static_cast<float>(i / 8));
    def.allowSleep = false;
    def.fixedRotation = true;
    bodies.push_back(world.CreateBody(&def));
    bodies.back()->SetMassData(&md);
  }
  if (linked) link_into_one_island(world, bodies);
  for (auto _ : state) world.Step(1.0f / 60.0f, 1, 1);
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = n;
}

/// The floor: a bare Box2D Step over n unlinked fixture-less bodies with no forces.
void BM_Box2DBareStep(benchmark::State& state) { run_box2d_only(state, false); }
BENCHMARK(BM_Box2DBareStep)->Arg(32)->Arg(64)->Arg(128)->Arg(256);

/// The same bodies linked into one island: Box2D's own cost inside a swim step.
void BM_Box2DLinkedStep(benchmark::State& state) { run_box2d_only(state, true); }
BENCHMARK(BM_Box2DLinkedStep)->Arg(32)->Arg(64)->Arg(128)->Arg(256);

/// The default scene (all five effects, stable drag, d_N = 2).
void BM_SwimStep(benchmark::State& state) {
  run_swim(state, lattice_swimmer(static_cast<int>(state.range(0))), SceneParams{},
           PhysicsParams{});
}
BENCHMARK(BM_SwimStep)->Arg(32)->Arg(64)->Arg(128)->Arg(256);

/// The same swim step with physics.integrator = "box2d": a real b2World (one island) moves the
/// cells, bit for bit as the native integrator does (tests/cpp/test_integrator.cpp).
void BM_SwimStepBox2D(benchmark::State& state) {
  PhysicsParams physics;
  physics.integrator = "box2d";
  run_swim(state, lattice_swimmer(static_cast<int>(state.range(0))), SceneParams{}, physics);
}
BENCHMARK(BM_SwimStepBox2D)->Arg(32)->Arg(64)->Arg(128)->Arg(256);

/// One effect alone, 32 cells: 0-4 springs, actuation, pressure, drag, collisions; 5 = no effect at
/// all; 6 = all (the default scene); 7 skin_collision, 8 gravity, 9 ground (the floor 10 below the
/// body: the contact test runs for every cell, nothing touches); 10 = the crawl scene
/// (configs/crawl.toml's effects on the impulse floor, the body resting on it). 0-6 keep their
/// numbers so that older tables compare.
void BM_Effect(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  static constexpr const char* kLabels[] = {
      "springs", "actuation",      "pressure", "drag",   "collisions", "none",
      "all",     "skin_collision", "gravity",  "ground", "crawl scene"};
  const Body body = lattice_swimmer(32);
  SceneParams scene;
  if (k < 5)
    scene.effects = {std::string(kSceneEffectNames[k])};
  else if (k == 5)
    scene.effects = {};
  else if (k >= 7 && k <= 9)
    scene.effects = {std::string(kSceneEffectNames[k - 2])};
  else if (k == 10)
    scene.effects = {"springs", "actuation", "pressure", "collisions", "gravity", "ground"};
  const double lowest = body.positions.col(1).minCoeff();
  if (k == 9) scene.ground_height = lowest - 10.0;
  if (k == 10) scene.ground_height = lowest;
  state.SetLabel(kLabels[k]);
  run_swim(state, body, scene, PhysicsParams{});
}
BENCHMARK(BM_Effect)->DenseRange(0, 10);

/// Each drag scheme in the default scene, 32 cells.
void BM_DragScheme(benchmark::State& state) {
  PhysicsParams physics;
  physics.drag_scheme = std::string(kDragSchemeNames[state.range(0)]);
  state.SetLabel(physics.drag_scheme);
  run_swim(state, lattice_swimmer(32), SceneParams{}, physics);
}
BENCHMARK(BM_DragScheme)->DenseRange(0, 2);

/// Velocity-dependent forces at the midpoint (default, two passes) or start velocity, 32 cells.
void BM_VelocityForces(benchmark::State& state) {
  PhysicsParams physics;
  physics.velocity_forces = std::string(kVelocityForceNames[state.range(0)]);
  state.SetLabel(physics.velocity_forces);
  run_swim(state, lattice_swimmer(32), SceneParams{}, physics);
}
BENCHMARK(BM_VelocityForces)->DenseRange(0, 1);

/// Active control (docs/control.md): the swim step under control.mode = "grn" at update interval k
/// (Arg = k) against open loop (Arg = 0: the default scene with its oscillators), 32 cells. The
/// controller's GRN is a random genome with every extension channel (10 units, the paper's size),
/// signalling on (D = 1, one diffusible product or more), a point chemical source.
void BM_ControlStep(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  const Body body = lattice_swimmer(32);
  if (k == 0) {
    state.SetLabel("open_loop");
    run_swim(state, body, SceneParams{}, PhysicsParams{});
    return;
  }
  GenomeParams gp;
  gp.extra_inputs = "strain,pressure,chemical";
  gp.extra_outputs = "actuation";
  Rng rng(7);
  Genome g = random_genome(gp, rng);
  for (int tries = 0; tries < 1000 && Grn(g, gp).morphogen_units().empty(); ++tries)
    g = random_genome(gp, rng);
  GrnControlStart start;
  start.grn = Grn(g, gp);
  start.levels.assign(static_cast<std::size_t>(body.node_count() * start.grn.node_count()), 0.0);
  start.maternal.assign(static_cast<std::size_t>(body.node_count()) * 3, 0.0);
  SceneParams scene;
  std::erase(scene.effects, std::string("actuation"));
  scene.chemical = "point";
  ControlParams control;
  control.mode = "grn";
  control.update_interval = k;
  control.signal_rate = 1.0;
  const PhysicsParams physics;
  state.SetLabel("grn k=" + std::to_string(k));
  auto make = [&] {
    auto sim = std::make_unique<Simulation>(body, scene, physics);
    sim->add_effect(std::make_unique<GrnControl>(body, start, control, scene, physics));
    return sim;
  };
  auto sim = make();
  for (auto _ : state) {
    try {
      sim->step(1);
    } catch (const SimulationError&) {
      state.PauseTiming();
      sim = make();
      state.ResumeTiming();
    }
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = body.node_count();
  state.counters["grn_units"] = start.grn.unit_count();
}
BENCHMARK(BM_ControlStep)->Arg(0)->Arg(1)->Arg(5)->Arg(10)->Arg(20);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  animat::bench::add_context();
  benchmark::AddCustomContext(
      "bodies", "triangular lattices, spacing 1, jitter 0.05, travelling wave a=0.2 f=4");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
