// The crawl world (docs/worlds.md): effects "gravity" and "ground" (a floor with Coulomb
// friction), the settling phase before the fitness clock, and the horizontal-distance objective.
// Values are asserted against the analytic solutions of the discrete scheme (symplectic Euler, as
// Box2D integrates) and of the continuous equations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/embedding.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/objective.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "physics_support.hpp"

namespace animat {
namespace {

/// A row of `n` cells on y = y0, spacing 1, neighbours linked by springs (a chain; skin = the
/// chain).
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
                   {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}},
                   {{0, 1}, {1, 2}, {2, 5}, {5, 4}, {4, 3}, {3, 0}});
}

SceneParams floor_scene(std::vector<std::string> effects, double g = 2.0, double mu_s = 0.8,
                        double mu_k = 0.5) {
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
    const auto i = static_cast<std::size_t>(body.springs(sp, 0)),
               j = static_cast<std::size_t>(body.springs(sp, 1));
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
  Simulation sim(b,
                 floor_scene({"springs", "pressure", "collisions", "gravity", "ground"}, g, mu_s));
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
    EXPECT_NEAR(p(i, 0) - p0(i, 0), a * h * h * static_cast<double>(n * (n + 1)) / 2.0,
                kFloatPosition)
        << i;
    EXPECT_NEAR(p(i, 0) - p0(i, 0), 0.5 * a * t * t, 0.5 * a * h * t + kFloatPosition) << i;
    EXPECT_NEAR(v(i, 1), 0.0, 1e-6);
  }
  EXPECT_EQ(sim.counters().ground_slips, n * 3);
}

TEST(Ground, LaunchedBlockDeceleratesAtMuKGAndStops) {
  // A row launched at v0 with no applied force: v(t) = v0 − μ_k·g·t until it stops after
  // t* = v0/(μ_k·g), having slid v0²/(2·μ_k·g) (± one step of travel); then static friction holds
  // it.
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
  // value (the floor is inelastic, friction and spring damping dissipate, and symplectic Euler
  // loses ½·m·g²·h² per cell and free-fall step), and no cell centre is ever below the floor beyond
  // float rounding of the positions.
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
  SceneParams scene =
      floor_scene({"springs", "actuation", "pressure", "collisions", "gravity", "ground"}, 1.0);
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
    EXPECT_NE(std::string(e.what()).find("scene.ground_friction_kinetic"), std::string::npos)
        << e.what();
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

// --- the floor and the collisions together: the embedding survives every contact
// ------------------

/// One triangle (a region, its three springs, all skin) with the base cells a, b at y = 0.05 and
/// the apex c at y = 0.3 above the middle of the base.
Body falling_triangle() {
  return make_body(points({{0.0, 0.05}, {2.0, 0.05}, {1.0, 0.3}}), {{0, 1}, {1, 2}, {0, 2}},
                   {{0, 1, 2}}, {{0, 1}, {1, 2}, {2, 0}});
}

TEST(FloorAndCollisions, TriangleFallingFlatOntoTheFloorBouncesOffItsBase) {
  // The traced defect, analytically: the whole triangle falls at v = 30 with no force (effects
  // collisions and ground only), h·v = 0.5 per step. The base reaches the floor after 0.05/v and
  // stops (inelastic); the apex would reach it after 0.3/v, on the base. With the floor applied
  // after the collisions (as before), no cell crossed an edge under the motion the collisions saw,
  // and the floor then put all three cells on y = 0: a region of zero area. With the floor contacts
  // as events of the collision loop, the apex meets the stopped base at the band (tolerance 1e-3)
  // and bounces elastically off it, and since the base lies on the floor the edge cannot give: the
  // apex leaves at +v like off a wall, the base stays at rest on the floor, and the apex ends the
  // step mirrored about y = band: y = 2·band − (0.3 − h·v).
  const double v = 30.0;
  SceneParams scene = scene_with({"collisions", "ground"});
  const Body b = falling_triangle();
  Simulation sim(b, scene);
  sim.monitor_embedding(b);
  sim.set_velocities(points({{0.0, -v}, {0.0, -v}, {0.0, -v}}));
  const double h = sim.physics().dt, band = scene.collision_tolerance;
  sim.step();
  const Points p = sim.positions(), w = sim.velocities();
  for (int i : {0, 1}) {
    EXPECT_NEAR(p(i, 1), 0.0, 1e-6) << i;
    EXPECT_NEAR(w(i, 1), 0.0, 1e-6 * v) << i;  // Box2D's float velocity: −v + h·(v/h) rounds
    EXPECT_NEAR(p(i, 0), b.positions(i, 0), 1e-6) << i;
  }
  EXPECT_NEAR(w(2, 1), v, 1e-4 * v);
  EXPECT_NEAR(p(2, 1), 2.0 * band - (0.3 - h * v), 1e-6);
  EXPECT_EQ(sim.counters().collisions, 1);
  EXPECT_EQ(sim.counters().ground_contacts, 2);
  EXPECT_EQ(sim.counters().collisions_unresolved, 0);
  ASSERT_NE(sim.embedding_monitor(), nullptr);
  EXPECT_TRUE(sim.embedding_monitor()->intact());
  EXPECT_GT(sim.embedding_monitor()->min_area_ratio(), 0.0);
}

/// What a monitored floor swim saw.
struct FloorRun {
  long inverted = 0, crossings = 0, unresolved = 0, contacts = 0, slips = 0;
  double lowest = 1e9, min_area_ratio = 1.0;
  Points end;  ///< positions at the end
};

enum class FloorCase { pressed, dropped, rolled, dragged };

/// A 5 × 3 lattice body (springs, pressure, collisions, gravity, ground) in one of four hard floor
/// contacts, simulated for 6 time units at dt/refine with the embedding monitored every Box2D step:
///  - pressed: resting on the floor, its top row pushed down with 40 per cell (g = 1): the bottom
///    triangles are squeezed between the load and the floor;
///  - dropped: from 5 units above the floor under g = 20 (lands at about 14 units per time unit);
///  - rolled: from 2 units above, spinning at 4 rad per time unit and moving sideways at 3, g = 5;
///  - dragged: resting on the floor (g = 2), its top row pulled sideways with 8 per cell (above the
///    static limit of the whole body): it tilts, slides and sticks again.
FloorRun run_floor_case(FloorCase c, int refine, const std::string& contact = "impulse") {
  const Body b = swimmer(lattice_points(5, 3, 0.05, 11), Drive::none);
  Body body = b;
  body.positions.col(1).array() -= body.positions.col(1).minCoeff();
  SceneParams scene = floor_scene({"springs", "pressure", "collisions", "gravity", "ground"}, 1.0);
  scene.ground_contact = contact;
  const double top = body.positions.col(1).maxCoeff() - 0.1;
  std::vector<double> top_row;
  for (int i = 0; i < body.node_count(); ++i)
    top_row.push_back(body.positions(i, 1) > top ? 1.0 : 0.0);
  Points v0 = Points::Zero(body.node_count(), 2);
  switch (c) {
    case FloorCase::pressed: break;
    case FloorCase::dropped:
      scene.gravity = 20.0;
      body.positions.col(1).array() += 5.0;
      break;
    case FloorCase::rolled: {
      scene.gravity = 5.0;
      body.positions.col(1).array() += 2.0;
      const Eigen::RowVector2d centre = body.positions.colwise().mean();
      for (int i = 0; i < body.node_count(); ++i) {
        const Eigen::RowVector2d r = body.positions.row(i) - centre;
        v0(i, 0) = 3.0 - 4.0 * r(1);
        v0(i, 1) = 4.0 * r(0);
      }
      break;
    }
    case FloorCase::dragged: scene.gravity = 2.0; break;
  }
  PhysicsParams physics;
  physics.dt /= refine;
  Simulation sim(body, scene, physics);
  sim.monitor_embedding(body);
  sim.set_velocities(v0);
  if (c == FloorCase::pressed) sim.add_effect(std::make_unique<ConstantForce>(0.0, -40.0, top_row));
  if (c == FloorCase::dragged) sim.add_effect(std::make_unique<ConstantForce>(8.0, 0.0, top_row));
  FloorRun r;
  const long steps = 360L * refine;
  for (long k = 0; k < steps; ++k) {
    sim.step();
    r.lowest = std::min(r.lowest, min_y(sim));
  }
  const EmbeddingMonitor& m = *sim.embedding_monitor();
  r.inverted = m.inverted_region_frames();
  r.crossings = m.skin_crossing_frames();
  r.min_area_ratio = m.min_area_ratio();
  r.unresolved = sim.counters().collisions_unresolved;
  r.contacts = sim.counters().ground_contacts;
  r.slips = sim.counters().ground_slips;
  r.end = sim.positions();
  return r;
}

TEST(FloorAndCollisions, PressedDroppedRolledAndDraggedBodiesKeepTheirEmbeddingAtEveryStep) {
  const char* names[] = {"pressed", "dropped", "rolled", "dragged"};
  for (FloorCase c :
       {FloorCase::pressed, FloorCase::dropped, FloorCase::rolled, FloorCase::dragged})
    for (int refine : {1, 4, 16}) {
      const FloorRun r = run_floor_case(c, refine);
      const std::string what =
          std::string(names[static_cast<int>(c)]) + " at dt/" + std::to_string(refine);
      EXPECT_EQ(r.inverted, 0) << what;
      EXPECT_EQ(r.crossings, 0) << what;
      EXPECT_GT(r.min_area_ratio, 0.0) << what;
      EXPECT_EQ(r.unresolved, 0) << what;
      EXPECT_GE(r.lowest, -1e-6) << what;
      EXPECT_GT(r.contacts, 0) << what;
      if (c == FloorCase::dragged || c == FloorCase::rolled) {
        EXPECT_GT(r.slips, 0) << what;
      }
    }
}

/// The crawl genomes of tests/data/crawl (each with its config, crawl.toml there): offspring of
/// short crawl runs whose swims broke the embedding while the floor was resolved after the
/// collisions (the skin crossed itself; the step is recorded in the file).
std::vector<std::pair<std::string, Genome>> crawl_genomes(Config& config) {
  const std::filesystem::path dir =
      std::filesystem::path(ANIMAT_SOURCE_DIR) / "tests" / "data" / "crawl";
  config = load_config((dir / "crawl.toml").string());
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<std::pair<std::string, Genome>> out;
  for (const auto& f : files) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    const auto j = nlohmann::json::parse(ss.str());
    EXPECT_EQ(j.at("config").get<std::string>(), "crawl.toml") << f;
    out.emplace_back(f.filename().string(),
                     genome_from_json(j.at("genome").dump(), config.genome, f.string()));
  }
  return out;
}

TEST(FloorAndCollisions, EvolvedCrawlersThatCrossedTheirSkinAreValid) {
  Config config;
  const auto genomes = crawl_genomes(config);
  ASSERT_EQ(genomes.size(), 3u);
  for (const auto& [name, genome] : genomes) {
    const EvaluationResult r = evaluate(genome, config);
    ASSERT_TRUE(r.viable) << name;
    EXPECT_TRUE(r.valid) << name << ": " << (r.reasons.empty() ? "" : r.reasons.front());
    EXPECT_EQ(r.skin_crossing_steps, 0) << name;
    EXPECT_EQ(r.inverted_region_steps, 0) << name;
    EXPECT_EQ(r.collisions_unresolved, 0) << name;
    EXPECT_GT(r.ground_contacts, 0) << name;
    EXPECT_EQ(r.swim_steps, config.evaluation.steps) << name;
  }
}

// --- settling and the crawl swim
// ------------------------------------------------------------------

TEST(Settle, BodyIsPlacedOnTheFloorAndFallingIsNotCounted) {
  // A still body (no actuation amplitude) high above the floor: swim() places its lowest cell on
  // the floor, settles it, and the measured swim then barely moves (the settling sag is not
  // counted).
  SceneParams scene =
      floor_scene({"springs", "actuation", "pressure", "collisions", "gravity", "ground"}, 1.0);
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

TEST(Ground, AirborneStepsCountTheFallUntilTheFirstContact) {
  // One cell from rest at y = 30 over the floor at 0, g = 2: at step k the floor is met when
  // y_start − g·h²·k(k+1)/2 < 0 (the free fall of FreeFallIsAnalytic, then the crossing within the
  // step), first at k = 329 for h = 1/60; from then on it rests and the floor pushes it every step.
  // The same count whether the floor is resolved by itself or inside effect collisions.
  for (const auto& effects : {std::vector<std::string>{"gravity", "ground"},
                              std::vector<std::string>{"gravity", "ground", "collisions"}}) {
    Simulation sim(make_body(points({{0.0, 30.0}}), {}, {}, {}), floor_scene(effects, 2.0));
    ASSERT_DOUBLE_EQ(sim.physics().dt, 1.0 / 60.0);
    sim.step(600);
    EXPECT_EQ(sim.counters().airborne_steps, 328) << effects.size();
    EXPECT_EQ(sim.counters().ground_contacts, 600 - 328) << effects.size();
  }
}

}  // namespace
}  // namespace animat

// --- the compliant floor (scene.ground_contact = "compliant") ------------------------------------
namespace animat {
namespace {

SceneParams compliant_scene(std::vector<std::string> effects, double g = 2.0, double mu = 0.5) {
  SceneParams s = floor_scene(std::move(effects), g, 0.8, mu);
  s.ground_contact = "compliant";
  return s;
}

TEST(CompliantGround, RestingRowSinksToTheStaticPenetrationMgOverK) {
  // Each cell of a row on the floor carries its own weight: at rest F_n = k_g·d = m·g, so every
  // cell ends d = m·g/k_g below the floor, whatever the damping (the backward-Euler solve has the
  // continuous law's equilibrium).
  const double g = 2.0;
  SceneParams scene = compliant_scene({"springs", "gravity", "ground"}, g);
  Simulation sim(row_block(4), scene);
  sim.step(1200);
  const double d = scene.cell_mass * g / scene.ground_stiffness;
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(sim.positions()(i, 1), -d, 1e-9 * d + kFloatPosition);
  EXPECT_LT(sim.velocities().cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(sim.counters().airborne_steps, 0);
}

TEST(CompliantGround, LaunchedRowDeceleratesAtMuGAndComesToRest) {
  // Resting at its static penetration, launched at v0 >> v_s: the friction is μ·m·g·v/sqrt(v² +
  // v_s²), so v(t) = v0 − μ·g·t to O(v_s²/v²) (backward Euler is exact for a constant force);
  // below v_s the floor grips viscously and the row comes to rest.
  const double g = 2.0, mu = 0.5, v0 = 3.0;
  SceneParams scene = compliant_scene({"springs", "gravity", "ground"}, g, mu);
  Body b = row_block(3, -scene.cell_mass * g / scene.ground_stiffness);
  Simulation sim(b, scene);
  sim.set_velocities(Points::Constant(3, 2, 0.0).rowwise() + Eigen::RowVector2d(v0, 0.0));
  const double h = sim.physics().dt;
  sim.step(60);
  const double v = v0 - mu * g * 60 * h;
  EXPECT_NEAR(sim.velocities()(1, 0), v, 1e-3 * v);
  EXPECT_EQ(sim.counters().ground_slips, 60L * 3);
  sim.step(900);
  EXPECT_LT(sim.velocities().cwiseAbs().maxCoeff(), 1e-6);
}

TEST(CompliantGround, DroppedCellBouncesLessTheHarderItLands) {
  // Hunt–Crossley damping dissipates in proportion to the impact speed: a lone cell dropped from
  // higher leaves the floor with a smaller fraction of its landing speed (restitution falls with
  // speed), and always with less than it landed with.
  double previous = 2.0;
  for (double height : {0.5, 2.0, 8.0}) {
    SceneParams scene = compliant_scene({"gravity", "ground"}, 2.0);
    PhysicsParams physics;
    physics.dt /= 16;
    Body b = make_body(points({{0.0, height}}), {}, {}, {});
    Simulation sim(b, scene, physics);
    double landing = 0.0, leaving = 0.0;
    bool touched = false;
    for (int k = 0; k < 16 * 600 && !(touched && leaving > 0.0); ++k) {
      const double vy = sim.velocities()(0, 1);
      sim.step();
      if (sim.positions()(0, 1) < 0.0 && !touched) {
        touched = true;
        landing = -vy;
      }
      if (touched && sim.positions()(0, 1) >= 0.0) leaving = sim.velocities()(0, 1);
    }
    ASSERT_TRUE(touched) << height;
    const double restitution = leaving / landing;
    std::printf("dropped from %g: lands at %.4g, leaves at %.4g (restitution %.4g)\n", height,
                landing, leaving, restitution);
    EXPECT_GT(restitution, 0.0) << height;
    EXPECT_LT(restitution, previous) << height;
    previous = restitution;
  }
}

TEST(CompliantGround, PressedDroppedRolledAndDraggedBodiesKeepTheirEmbeddingAtEveryStep) {
  // The compliant floor adds forces before the collision pass, so the collisions' guarantees hold
  // as they do without a floor; the cells sink into the floor by their load over k_g.
  const char* names[] = {"pressed", "dropped", "rolled", "dragged"};
  for (FloorCase c :
       {FloorCase::pressed, FloorCase::dropped, FloorCase::rolled, FloorCase::dragged})
    for (int refine : {1, 4, 16}) {
      const FloorRun r = run_floor_case(c, refine, "compliant");
      const std::string what =
          std::string(names[static_cast<int>(c)]) + " at dt/" + std::to_string(refine);
      EXPECT_EQ(r.inverted, 0) << what;
      EXPECT_EQ(r.crossings, 0) << what;
      EXPECT_GT(r.min_area_ratio, 0.0) << what;
      EXPECT_EQ(r.unresolved, 0) << what;
      EXPECT_GT(r.lowest, -0.5) << what;
      EXPECT_GT(r.contacts, 0) << what;
    }
}

TEST(CompliantGround, SwimsConvergeAsTheStepShrinks) {
  // The force is a continuous function of the state, so a smaller step refines the same solution:
  // the end positions of the rolled and dragged bodies (sliding, tilting, sticking again) approach
  // those at dt/64, by at least half per fourfold refinement from dt/4 on (the scheme is first
  // order).
  for (FloorCase c : {FloorCase::rolled, FloorCase::dragged}) {
    const Points fine = run_floor_case(c, 64, "compliant").end;
    double previous = 1e9;
    for (int refine : {4, 16}) {
      const double error =
          (run_floor_case(c, refine, "compliant").end - fine).cwiseAbs().maxCoeff();
      std::printf("case %d, dt/%d: largest position error %.4g\n", static_cast<int>(c), refine,
                  error);
      EXPECT_LT(error, 0.5 * previous) << static_cast<int>(c) << " dt/" << refine;
      previous = error;
    }
    EXPECT_LT(previous, 0.05) << static_cast<int>(c);
  }
}

TEST(CompliantGround, ConfigErrorsNameKeyAndValue) {
  SceneParams s;
  s.ground_contact = "soft";
  try {
    validate(s);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.ground_contact"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("soft"), std::string::npos) << e.what();
  }
  SceneParams k;
  k.ground_stiffness = 0.0;
  try {
    validate(k);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.ground_stiffness"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace animat
