// Trustworthy swimmers: cell-edge collisions as the paper states them (elastic,
// momentum-conserving, never crossed), the planar-embedding invariant, eqs. 4–5 integrated without
// a limiter, and the diagnostics every swim reports. Analytic wherever the physics allows.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../src/effects/triangle_filter.hpp"
#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/embedding.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "animat/scene.hpp"
#include "evolved_support.hpp"
#include "physics_support.hpp"

namespace animat {
namespace {

SceneParams collisions_only() { return scene_with({"collisions"}); }

/// Signed distance of point p from the line through a and b (positive on the left of a -> b).
double side_of(const Points& x, int p, int a, int b) {
  const Eigen::Vector2d e = x.row(b) - x.row(a), r = x.row(p) - x.row(a);
  return (e.x() * r.y() - e.y() * r.x()) / e.norm();
}

/// Parameter of the projection of p on segment ab.
double along(const Points& x, int p, int a, int b) {
  const Eigen::Vector2d e = x.row(b) - x.row(a), r = x.row(p) - x.row(a);
  return r.dot(e) / e.squaredNorm();
}

/// A free two-cell edge (cells 0, 1 on the x axis, one spring, no springs effect so nothing but the
/// collision acts) and a free cell 2 above it at parameter s along the edge, moving at (vx, vy).
struct Throw {
  Body body;
  Points v;
};
Throw throw_at_edge(double s, double height, double vx, double vy) {
  Throw t;
  t.body = make_body(points({{0.0, 0.0}, {1.0, 0.0}, {s, height}}), {{0, 1}}, {}, {{0, 1}});
  t.v = Points::Zero(3, 2);
  t.v(2, 0) = vx;
  t.v(2, 1) = vy;
  return t;
}

/// The analytic outcome of an elastic collision between a cell and the point at parameter s of an
/// edge whose ends are at rest, all masses equal: along the normal the cell's velocity changes by
/// dv = 2·v_n / (1 + (1 − s)² + s²) and the ends by −(1 − s)·dv and −s·dv.
struct Outcome {
  Eigen::Vector2d cell, a, b;
};
Outcome analytic_bounce(double s, double vx, double vy) {
  const double vn = vy;  // the edge lies along x: its normal is y
  const double dv = 2.0 * -vn / (1.0 + (1.0 - s) * (1.0 - s) + s * s);
  return {{vx, vy + dv}, {0.0, -(1.0 - s) * dv}, {0.0, -s * dv}};
}

// --- the collision itself
// --------------------------------------------------------------------------

TEST(Collisions, CellThrownAtAFreeEdgeBouncesElasticallyAsTheImpulseSolutionSays) {
  for (double s : {0.5, 0.25, 0.9}) {
    for (double vx : {0.0, 0.7}) {
      const double vy = -3.0;
      Throw t = throw_at_edge(s, 0.3, vx, vy);
      Simulation sim(t.body, collisions_only());
      sim.set_velocities(t.v);
      const Eigen::Vector2d p0 = sim.momentum();
      const double e0 = sim.kinetic_energy();
      double lowest = 1.0;
      for (int k = 0; k < 120; ++k) {
        sim.step();
        lowest = std::min(lowest, side_of(sim.positions(), 2, 0, 1));
      }
      EXPECT_GT(lowest, 0.0) << "s=" << s << ": the cell crossed the edge";
      EXPECT_LT(lowest, 1e-3 + 3.0 * PhysicsParams{}.dt)
          << "s=" << s << ": the cell never came within a step of the edge";
      EXPECT_EQ(sim.counters().collisions, 1);
      const Points v = sim.velocities();
      const double hit = s + vx * (0.3 - 1e-3) / -vy;  // where along the edge it reaches the band
      const Outcome want = analytic_bounce(hit, vx, vy);
      const double tol = 1e-5 * std::abs(vy);  // float velocities
      EXPECT_NEAR(v(2, 0), want.cell.x(), tol) << "s=" << s;
      EXPECT_NEAR(v(2, 1), want.cell.y(), tol) << "s=" << s;
      EXPECT_NEAR(v(0, 1), want.a.y(), tol) << "s=" << s;
      EXPECT_NEAR(v(1, 1), want.b.y(), tol) << "s=" << s;
      EXPECT_NEAR((sim.momentum() - p0).norm(), 0.0, 1e-5) << "momentum, s=" << s;
      EXPECT_NEAR(sim.kinetic_energy() / e0, 1.0, 1e-6) << "kinetic energy, s=" << s;
      EXPECT_EQ(sim.counters().collisions_inelastic, 0);
      EXPECT_EQ(sim.counters().collisions_unresolved, 0);
    }
  }
}

TEST(Collisions, TheBounceHappensAtItsTimeWithinTheStep) {
  // The cell reaches the edge a third of the way into a step: its path after the step is the
  // reflected straight line from that instant, not from the start of the step.
  const PhysicsParams physics;
  const double h = physics.dt, vy = -3.0;
  const double height = 1e-3 + (10.0 + 1.0 / 3.0) * h * -vy;  // band reached at 10⅓ steps
  Throw t = throw_at_edge(0.5, height, 0.0, vy);
  Simulation sim(t.body, collisions_only(), physics);
  sim.set_velocities(t.v);
  sim.step(12);
  ASSERT_EQ(sim.counters().collisions, 1);
  const Outcome want = analytic_bounce(0.5, 0.0, vy);
  const double t_hit = 10.0 + 1.0 / 3.0, t_end = 12.0;
  const double cell_y = 1e-3 + want.cell.y() * (t_end - t_hit) * h;  // from the band, reflected
  const double edge_y = want.a.y() * (t_end - t_hit) * h;
  EXPECT_NEAR(sim.positions()(2, 1), cell_y, 2e-6);
  EXPECT_NEAR(sim.positions()(0, 1), edge_y, 2e-6);
  EXPECT_NEAR(sim.positions()(1, 1), edge_y, 2e-6);
}

TEST(Collisions, GrazingIncidenceNeverCrosses) {
  // Sliding along the edge at speed 4 and descending so slowly that the edge's line would be
  // reached at the middle of the edge: angles of 0.1 to 3 degrees.
  for (double height : {0.002, 0.01, 0.05, 0.2}) {
    const double vy = -height / 0.25;  // reaches y = 0 at x = 0.5
    Throw t = throw_at_edge(-0.5, height, 4.0, vy);
    Simulation sim(t.body, collisions_only());
    sim.set_velocities(t.v);
    for (int k = 0; k < 40; ++k) {
      sim.step();
      const Points x = sim.positions();
      const double s = along(x, 2, 0, 1);
      if (s >= 0.0 && s <= 1.0) {
        EXPECT_GT(side_of(x, 2, 0, 1), 0.0) << "height=" << height << " step " << k;
      }
    }
    EXPECT_EQ(sim.counters().collisions, 1) << "height=" << height;
    EXPECT_EQ(sim.counters().collisions_unresolved, 0);
  }
}

TEST(Collisions, ACellAimedAtAVertexCrossesNeitherEdge) {
  // Two edges meeting at cell 0 at a right angle; cell 3 flies diagonally at the vertex from inside
  // the wedge.
  for (double offset : {0.0, 1e-9, 1e-4, -1e-4}) {
    Body b = make_body(points({{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {0.5 + offset, 0.5}}),
                       {{0, 1}, {0, 2}}, {}, {{0, 1}, {0, 2}});
    Points v = Points::Zero(4, 2);
    v(3, 0) = -2.0;
    v(3, 1) = -2.0;
    Simulation sim(b, collisions_only());
    sim.set_velocities(v);
    for (int k = 0; k < 40; ++k) {
      sim.step();
      const Points x = sim.positions();
      const double s1 = along(x, 3, 0, 1), s2 = along(x, 3, 0, 2);
      if (s1 >= 0.0 && s1 <= 1.0) {
        EXPECT_GT(side_of(x, 3, 0, 1), 0.0) << "crossed 0-1, offset " << offset << " step " << k;
      }
      if (s2 >= 0.0 && s2 <= 1.0) {
        EXPECT_LT(side_of(x, 3, 0, 2), 0.0) << "crossed 0-2, offset " << offset << " step " << k;
      }
    }
    EXPECT_GE(sim.counters().collisions, 1);
    EXPECT_EQ(sim.counters().collisions_unresolved, 0);
  }
}

TEST(Collisions, AFastCellDoesNotTunnelThroughInOneStep) {
  // 0.2 above the edge at 48 length units per time: 0.8 per step, so an end-of-step overlap test
  // would see it 0.6 below the edge and never in contact.
  const PhysicsParams physics;
  const double vy = -48.0;
  ASSERT_GT(-vy * physics.dt, 0.2 + 0.25);  // past the edge and the old penalty radius in one step
  ASSERT_LT(-vy * physics.dt, physics.max_step_displacement);
  Throw t = throw_at_edge(0.4, 0.2, 0.0, vy);
  Simulation sim(t.body, collisions_only(), physics);
  sim.set_velocities(t.v);
  sim.step();
  EXPECT_GT(side_of(sim.positions(), 2, 0, 1), 0.0);
  EXPECT_EQ(sim.counters().collisions, 1);
  for (int k = 0; k < 30; ++k) sim.step();
  EXPECT_GT(side_of(sim.positions(), 2, 0, 1), 0.0);
  // The same throw with the soft penalty of the old default scene goes straight through.
  Simulation soft(t.body, scene_with({"skin_collision"}), physics);
  soft.set_velocities(t.v);
  soft.step();
  EXPECT_LT(side_of(soft.positions(), 2, 0, 1), 0.0);
}

TEST(Collisions, RestitutionZeroStopsTheApproachAndCostsEnergy) {
  Throw t = throw_at_edge(0.5, 0.3, 0.0, -3.0);
  SceneParams scene = collisions_only();
  scene.collision_restitution = 0.0;
  Simulation sim(t.body, scene);
  sim.set_velocities(t.v);
  sim.step(60);
  // e = 0 at s = 1/2: dv = 3/1.5 = 2, so the cell and both ends all move at -1 afterwards.
  const Points v = sim.velocities();
  EXPECT_NEAR(v(2, 1), -1.0, 1e-5);
  EXPECT_NEAR(v(0, 1), -1.0, 1e-5);
  EXPECT_NEAR(v(1, 1), -1.0, 1e-5);
  EXPECT_NEAR(sim.kinetic_energy(), 1.5, 1e-5);  // from 4.5: two thirds lost
}

// --- the planar embedding
// --------------------------------------------------------------------------

/// The collisions effect's cheaper triangle test only rejects triangles its full test rejects too
/// (so the candidates, and every result, stay the same): random triangles from fat to nearly flat,
/// bands from 0 to the tolerance, vertex velocities random or signed to shrink the area fastest,
/// their quantities derived as Collisions::gather derives them; for each, the motion is scaled to
/// the edge of what the cheaper test still rejects (bisection), where its bound is tightest.
TEST(Collisions, CheaperTriangleTestRejectsOnlyWhatTheFullTestRejects) {
  using animat::effects::triangle_band4;
  using animat::effects::triangle_stays_clear;
  using animat::effects::triangle_surely_clear;
  struct Case {
    std::array<double, 3> qx, qy, wx, wy;
    double span, band_max;
  };
  // Both tests on the case with every velocity scaled by `scale`: {cheaper rejects, full rejects}.
  auto tests = [](const Case& c, double scale) {
    const double abx = c.qx[1] - c.qx[0], aby = c.qy[1] - c.qy[0], acx = c.qx[2] - c.qx[0],
                 acy = c.qy[2] - c.qy[0];
    std::array<double, 3> wx{}, wy{}, wmax{};
    for (int v = 0; v < 3; ++v) {
      wx[v] = scale * c.wx[v];
      wy[v] = scale * c.wy[v];
      wmax[v] = c.span * (std::abs(wx[v]) + std::abs(wy[v]));
    }
    const double dbx = c.span * (wx[1] - wx[0]), dby = c.span * (wy[1] - wy[0]);
    const double dcx = c.span * (wx[2] - wx[0]), dcy = c.span * (wy[2] - wy[0]);
    return std::pair{triangle_surely_clear(abx, aby, acx, acy, wmax[0] + wmax[1] + wmax[2],
                                           triangle_band4(c.band_max)),
                     triangle_stays_clear(abx, aby, acx, acy, dbx, dby, dcx, dcy, c.band_max)};
  };
  animat::Rng rng(20261125);
  long cheap = 0, left_to_full = 0, probed = 0;
  for (int k = 0; k < 20000; ++k) {
    Case c{};
    const double size = std::pow(10.0, rng.uniform(-2.0, 1.0));
    for (int v = 0; v < 3; ++v) {
      c.qx[static_cast<std::size_t>(v)] = 50.0 + size * rng.uniform(-1.0, 1.0);
      c.qy[static_cast<std::size_t>(v)] = -20.0 + size * rng.uniform(-1.0, 1.0);
    }
    if (k % 3 == 0) {  // nearly flat: c between a and b, lifted off the line by a little
      const double s = rng.uniform(0.0, 1.0), lift = size * std::pow(10.0, rng.uniform(-6.0, -1.0));
      c.qx[2] = c.qx[0] + s * (c.qx[1] - c.qx[0]) + lift;
      c.qy[2] = c.qy[0] + s * (c.qy[1] - c.qy[0]) - lift;
    }
    for (int v = 0; v < 3; ++v) {
      c.wx[static_cast<std::size_t>(v)] = size * rng.uniform(-1.0, 1.0);
      c.wy[static_cast<std::size_t>(v)] = size * rng.uniform(-1.0, 1.0);
    }
    if (k % 2 == 0) {  // a stands still, b and c move to shrink the doubled area fastest (c1 < 0)
      const double abx = c.qx[1] - c.qx[0], aby = c.qy[1] - c.qy[0], acx = c.qx[2] - c.qx[0],
                   acy = c.qy[2] - c.qy[0];
      c.wx[0] = c.wy[0] = 0.0;
      c.wx[1] = -std::copysign(size, acy);
      c.wy[1] = std::copysign(size, acx);
      c.wx[2] = std::copysign(size, aby);
      c.wy[2] = -std::copysign(size, abx);
    }
    c.span = 1.0 / 60.0;
    c.band_max = k % 4 == 1 ? 0.0 : 0.05 * size * rng.uniform(0.0, 1.0);
    if (tests(c, 0.0).second && !tests(c, 0.0).first) ++left_to_full;
    // The largest motion the cheaper test still rejects (it rejects less as the motion grows).
    double lo = 0.0, hi = 1e6;
    if (!tests(c, lo).first) continue;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      (tests(c, mid).first ? lo : hi) = mid;
    }
    ++probed;
    for (const double scale : {0.0, 0.5 * lo, lo}) {
      const auto [surely, stays] = tests(c, scale);
      cheap += surely;
      if (surely && !stays) {
        ADD_FAILURE() << "case " << k << " at motion scale " << scale
                      << ": the cheaper test rejects a triangle the full test keeps";
        return;
      }
    }
  }
  EXPECT_GT(probed, 5000);       // a third of the triangles are clear of their band at rest
  EXPECT_EQ(cheap, 3 * probed);  // every probe checks three motions the cheaper test rejects
  EXPECT_GT(left_to_full, 100);  // at rest, some are rejected by the full test only
  // NaN anywhere: the cheaper test never rejects.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(triangle_surely_clear(nan, 0.0, 0.0, 1.0, 0.0, 0.1));
  EXPECT_FALSE(triangle_surely_clear(1.0, 0.0, 0.0, 1.0, nan, 0.1));
}

TEST(Embedding, SegmentsIntersectIncludingTouchingAndCollinearOverlap) {
  EXPECT_TRUE(segments_intersect(0, 0, 1, 1, 0, 1, 1, 0));
  EXPECT_FALSE(segments_intersect(0, 0, 1, 0, 0, 1, 1, 1));
  EXPECT_TRUE(segments_intersect(0, 0, 1, 0, 0.5, 0, 0.5, 1));  // touching
  EXPECT_TRUE(segments_intersect(0, 0, 1, 0, 0.5, 0, 2, 0));    // collinear overlap
  EXPECT_FALSE(segments_intersect(0, 0, 1, 0, 1.5, 0, 2, 0));   // collinear apart
}

TEST(Embedding, MonitorSeesAnInvertedRegionAndASelfCrossingSkin) {
  const Body b = square();
  EmbeddingMonitor m(b);
  std::vector<double> x = {0, 1, 1, 0}, y = {0, 0, 1, 1};
  EXPECT_TRUE(m.observe(x, y));
  x = {0, 1, 0, 1};  // a bow tie: edges 1-2 and 3-0 cross, the signed area is 0
  EXPECT_FALSE(m.observe(x, y));
  EXPECT_EQ(m.skin_crossing_frames(), 1);
  EXPECT_EQ(m.inverted_region_frames(), 1);
  x = {0, 1, 1, 0};
  y = {0, 0, -1, -1};  // mirrored: inside out
  EXPECT_FALSE(m.observe(x, y));
  EXPECT_EQ(m.inverted_region_frames(), 2);
  EXPECT_DOUBLE_EQ(m.min_area_ratio(), -1.0);
}

/// Swims `body` for `steps` with every step's embedding checked; returns the result.
SwimResult checked_swim(const Body& body, const SceneParams& scene, long steps = 4000) {
  SwimOptions options;
  options.check_embedding = true;
  options.stop_when_invalid = false;
  return swim(body, scene, PhysicsParams{}, steps, options);
}

TEST(Embedding, HoldsForHardHandMadeSwimmersAtEveryStep) {
  struct Case {
    Points p;
    Drive drive;
    double f;
  };
  const std::vector<Case> cases = {{lattice_points(8, 4, 0.05, 8), Drive::wave, 12.0},
                                   {lattice_points(8, 4, 0.15, 3), Drive::random, 12.0},
                                   {lattice_points(8, 8, 0.15, 5), Drive::random, 6.0}};
  for (const auto& c : cases) {
    for (double dn : {0.2, 2.0, 10.0}) {
      SceneParams scene;
      scene.drag_normal = dn;
      const SwimResult r = checked_swim(swimmer(c.p, c.drive, 0.2, c.f), scene);
      EXPECT_TRUE(r.valid) << r.failure;
      EXPECT_EQ(r.inverted_region_steps, 0);
      EXPECT_EQ(r.skin_crossing_steps, 0);
      EXPECT_GT(r.min_area_ratio, 0.0);
      EXPECT_EQ(r.collisions_unresolved, 0);
    }
  }
}

TEST(Embedding, SkinEdgesAloneDoNotKeepRegionsFromInverting) {
  // Why collision_edges = "all": with skin edges only, internal cells cross internal springs. The
  // whole body breathing at f = 12 under the pressure of the first release (c_p = 100, floor 0.1)
  // squeezes regions flat.
  Body b = swimmer(lattice_points(8, 4, 0.05, 8), Drive::wave, 0.2, 12.0);
  b.phase.setZero();
  SceneParams skin_only;
  skin_only.collision_edges = "skin";
  skin_only.drag_normal = 0.2;
  skin_only.pressure = 100.0;
  skin_only.pressure_area_floor = 0.1;
  SceneParams all = skin_only;
  all.collision_edges = "all";
  EXPECT_GT(checked_swim(b, skin_only).inverted_region_steps, 0);
  EXPECT_EQ(checked_swim(b, all).inverted_region_steps, 0);
}

TEST(Collisions, MomentumIsConservedThroughCollisionsWithDragOff) {
  // An evolved swimmer that collides hundreds of times per swim, without drag: every force and
  // impulse is internal.
  const auto genomes = evolved_genomes();
  const Evolved& e = named(genomes, "colliding_f12_dn0.5.json");
  // the c_p it evolved with: regions collapse and cells collide
  SceneParams scene = e.config.scene;
  scene.effects = {"springs", "actuation", "pressure", "collisions"};
  Simulation sim(body_of(e), scene);
  const Eigen::Vector2d c0 = sim.center_of_mass();
  double biggest = 0.0;
  for (int k = 0; k < 2000; ++k) {
    sim.step();
    biggest = std::max(biggest, sim.momentum().norm());
  }
  EXPECT_GT(sim.counters().collisions, 50) << "the case must collide to test anything";
  // Float velocities: each Box2D step rounds every velocity (relative 6e-8), a random walk of
  // ~6e-8·|v|·sqrt(n·steps) ~ 3e-5 for 32 cells at speeds ~2 over 2000 steps; 1e-3 is 30 times
  // that.
  EXPECT_LT(biggest, 1e-3);
  EXPECT_LT((sim.center_of_mass() - c0).norm(), 1e-3);
}

TEST(Embedding, TheOldPenaltyLetsAnEvolvedExploitThroughWhereCollisionsDoNot) {
  const auto genomes = evolved_genomes();
  // with the c_p it evolved under
  const Evolved& e = named(genomes, "exploit_old_physics_dn0.5.json");
  const Body b = body_of(e);
  SceneParams old_scene = e.config.scene;
  old_scene.effects = {"springs", "actuation", "pressure", "drag", "skin_collision"};
  const SwimResult soft = checked_swim(b, old_scene);
  const SwimResult hard = checked_swim(b, e.config.scene);
  EXPECT_GT(soft.inverted_region_steps, 100);
  EXPECT_FALSE(soft.valid);
  EXPECT_EQ(soft.distance, 0.0);  // an invalid swim has no fitness
  EXPECT_EQ(hard.inverted_region_steps, 0);
  EXPECT_EQ(hard.skin_crossing_steps, 0);
  EXPECT_GT(hard.collisions, 100);
  EXPECT_TRUE(hard.valid);
}

TEST(Embedding, HoldsForEvolvedBestsAtEveryStep) {
  const auto genomes = evolved_genomes();
  ASSERT_GE(genomes.size(), 4u);
  for (const auto& e : genomes) {
    const SwimResult r = checked_swim(body_of(e), e.config.scene);
    EXPECT_TRUE(r.valid) << e.name << ": " << r.failure;
    EXPECT_EQ(r.inverted_region_steps, 0) << e.name;
    EXPECT_EQ(r.skin_crossing_steps, 0) << e.name;
    EXPECT_GT(r.distance, 1.0) << e.name << " swims";
  }
}

// --- eqs. 4–5 without a limiter
// ---------------------------------------------------------------------

TEST(Drag, SemiImplicitTerminalVelocityOfARodIsExactAtTheDefaultStepWithoutALimiter) {
  // One edge pulled normal to itself by F on each end: terminal |u| = sqrt(2F / (d_N·L)).
  for (double dn : {10.0, 50.0}) {
    for (double f : {0.5, 5.0, 500.0}) {
      const Body b = two_nodes(1.0, 1.0);
      SceneParams scene = scene_with({"springs", "drag"});
      scene.drag_normal = dn;
      Simulation sim(b, scene);
      sim.add_effect(std::make_unique<ConstantForceY>(f));
      sim.step(4000);
      const double expected = std::sqrt(2.0 * f / dn);
      EXPECT_NEAR(sim.velocities()(0, 1) / expected, 1.0, 1e-3) << "d_N=" << dn << " F=" << f;
      EXPECT_EQ(sim.counters().drag_limited, 0);
      // x = h·d·L·|u|/M: beyond the explicit scheme's stability for the larger forces.
      if (f == 500.0) {
        EXPECT_GT(PhysicsParams{}.dt * dn * expected / 2.0, 0.5) << "the case must be stiff";
      }
    }
  }
}

TEST(Drag, SemiImplicitIsTheExactSolutionForAFreeEdge) {
  // u' = −c·u·|u| with c = d_N·L/(2m): u(t) = u0 / (1 + c·u0·t), and the scheme reproduces it at
  // every step, however stiff.
  for (double dn : {0.5, 10.0, 200.0}) {
    const Body b = two_nodes(1.0, 1.0);
    SceneParams scene = scene_with({"drag"});
    scene.drag_normal = dn;
    Simulation sim(b, scene);
    Points v = Points::Zero(2, 2);
    v(0, 1) = v(1, 1) = 3.0;
    sim.set_velocities(v);
    const double c = dn / 2.0;
    for (int k = 1; k <= 600; ++k) {
      sim.step();
      const double t = k * PhysicsParams{}.dt;
      EXPECT_NEAR(sim.velocities()(0, 1), 3.0 / (1.0 + c * 3.0 * t), 1e-5 * 3.0)
          << "d_N=" << dn << " step " << k;
    }
  }
}

TEST(Drag, TheStableSchemeCountsEveryLimitedStep) {
  const Body b = two_nodes(1.0, 1.0);
  SceneParams scene = scene_with({"springs", "drag"});
  scene.drag_normal = 50.0;
  PhysicsParams physics;
  physics.drag_scheme = "stable";
  Simulation sim(b, scene, physics);
  sim.add_effect(std::make_unique<ConstantForceY>(50.0));
  sim.step(400);
  EXPECT_GT(sim.counters().drag_limited, 100);
  physics.drag_scheme = "semi_implicit";
  Simulation exact(b, scene, physics);
  exact.add_effect(std::make_unique<ConstantForceY>(50.0));
  exact.step(400);
  EXPECT_EQ(exact.counters().drag_limited, 0);
}

// --- diagnostics
// -----------------------------------------------------------------------------------

TEST(Diagnostics, EvaluateReportsTheInvariantsAndAnInvalidSwimHasFitnessZero) {
  const auto genomes = evolved_genomes();
  const Evolved& e = named(genomes, "exploit_old_physics_dn0.5.json");
  const EvaluationResult r = evaluate(e.genome, e.config);
  EXPECT_TRUE(r.valid);
  EXPECT_GT(r.fitness, 0.0);
  EXPECT_EQ(r.inverted_region_steps, 0);
  EXPECT_EQ(r.skin_crossing_steps, 0);
  EXPECT_GT(r.min_area_ratio, 0.0);
  EXPECT_LE(r.min_area_ratio, 1.0);
  EXPECT_EQ(r.first_invalid_step, -1);
  EXPECT_EQ(r.drag_limited, 0);
  EXPECT_NEAR(r.max_kinetic_energy_per_cell * r.cell_count, r.max_kinetic_energy, 1e-12);

  Config old = e.config;  // the physics it evolved under lets it through itself
  old.scene.effects = {"springs", "actuation", "pressure", "drag", "skin_collision"};
  old.physics.drag_scheme = "stable";
  const EvaluationResult bad = evaluate(e.genome, old);
  EXPECT_FALSE(bad.valid);
  EXPECT_TRUE(bad.stable);
  EXPECT_EQ(bad.fitness, 0.0);
  EXPECT_EQ(bad.first_invalid_step, 35);
  EXPECT_GT(bad.inverted_region_steps, 0);
  EXPECT_LT(bad.min_area_ratio, 0.0);
  ASSERT_FALSE(bad.reasons.empty());
  EXPECT_NE(bad.reasons.back().find("invalid swim: a region turned inside out"), std::string::npos)
      << bad.reasons.back();
}

}  // namespace
}  // namespace animat
