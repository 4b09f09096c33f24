// The Verlet list of boxes behind the collisions effect's skin candidates and the embedding
// monitor's skin crossings (src/box_pair_list.hpp): while every box stays within its widened box,
// the listed pairs that overlap are exactly the pairs that overlap, at the edge of the bound too.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "../../src/box_pair_list.hpp"
#include "animat/embedding.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "counting_allocator.hpp"  // a build allocates nothing
#include "evolved_support.hpp"

namespace animat {
namespace {

using detail::Box;
using detail::BoxPairList;
using PairSet = std::set<std::pair<int, int>>;

PairSet listed_overlapping(const BoxPairList& list, const std::vector<Box>& boxes) {
  PairSet out;
  for (const auto& [p, q] : list.pairs())
    if (detail::boxes_overlap(boxes[static_cast<std::size_t>(p)],
                              boxes[static_cast<std::size_t>(q)]))
      out.insert({p, q});
  return out;
}

template <class Eligible>
PairSet every_overlapping(const std::vector<Box>& boxes, Eligible eligible) {
  PairSet out;
  for (int p = 0; p < static_cast<int>(boxes.size()); ++p)
    for (int q = p + 1; q < static_cast<int>(boxes.size()); ++q)
      if (eligible(p, q) && detail::boxes_overlap(boxes[static_cast<std::size_t>(p)],
                                                  boxes[static_cast<std::size_t>(q)]))
        out.insert({p, q});
  return out;
}

Box moved(const Box& b, double dx, double dy) {
  return {b.lo + dx, b.hi + dx, b.ylo + dy, b.yhi + dy};
}

TEST(BoxPairList, TwoBoxesThatEachMoveTheWholeMarginTowardsTheOtherTouchAndAreListed) {
  // Margin 0.25 and a gap of exactly 2·0.25 at the build (every value exact in binary): the
  // widened boxes touch, so the pair is listed; after each box moves the whole margin towards the
  // other, both lie on the edge of their widened boxes, the list still holds, and the boxes touch.
  const double margin = 0.25;
  auto yes = [](int, int) { return true; };
  std::vector<Box> boxes = {{0.0, 1.0, 0.0, 1.0}, {1.5, 2.5, 0.0, 1.0}};
  BoxPairList list;
  list.reset(boxes.size(), margin, 1);
  EXPECT_FALSE(list.holds(boxes.data()));  // nothing built yet
  ASSERT_TRUE(list.build(boxes.data(), yes));
  ASSERT_EQ(list.pairs().size(), 1u);
  EXPECT_TRUE(listed_overlapping(list, boxes).empty());
  boxes = {moved(boxes[0], margin, 0.0), moved(boxes[1], -margin, 0.0)};
  EXPECT_TRUE(list.holds(boxes.data()));
  EXPECT_EQ(listed_overlapping(list, boxes), (PairSet{{0, 1}}));
  EXPECT_EQ(listed_overlapping(list, boxes), every_overlapping(boxes, yes));
  // One ulp further and the bound no longer holds.
  boxes[0].hi = std::nextafter(boxes[0].hi, 2.0);
  EXPECT_FALSE(list.holds(boxes.data()));

  // A gap one ulp over 2·margin at the build: not listed, and moving each box the whole margin
  // towards the other leaves them apart, as the bound says.
  boxes = {{0.0, 1.0, 0.0, 1.0}, {std::nextafter(1.5, 2.0), 2.5, 0.0, 1.0}};
  ASSERT_TRUE(list.build(boxes.data(), yes));
  EXPECT_TRUE(list.pairs().empty());
  boxes = {moved(boxes[0], margin, 0.0), moved(boxes[1], -margin, 0.0)};
  EXPECT_TRUE(list.holds(boxes.data()));
  EXPECT_TRUE(every_overlapping(boxes, yes).empty());

  // The same along y.
  boxes = {{0.0, 1.0, 0.0, 1.0}, {0.0, 1.0, 1.5, 2.5}};
  ASSERT_TRUE(list.build(boxes.data(), yes));
  boxes = {moved(boxes[0], 0.0, margin), moved(boxes[1], 0.0, -margin)};
  EXPECT_TRUE(list.holds(boxes.data()));
  EXPECT_EQ(listed_overlapping(list, boxes), (PairSet{{0, 1}}));
}

TEST(BoxPairList, EachSideOfTheBoundIsChecked) {
  // Box 1 out of reach of box 0 in one of the four directions at the build (unlisted); box 0 moves
  // alone onto it, across that one side of its widened box: the list no longer holds, and the
  // rebuilt list has the pair.
  const double margin = 0.25;
  auto yes = [](int, int) { return true; };
  const std::vector<std::pair<double, double>> directions = {
      {1.0, 0.0}, {-1.0, 0.0}, {0.0, 1.0}, {0.0, -1.0}};
  for (const auto& [ux, uy] : directions) {
    const double gap = 2.0 * margin + 0.125, travel = gap + 0.0625;
    std::vector<Box> boxes = {{0.0, 1.0, 0.0, 1.0},
                              moved({0.0, 1.0, 0.0, 1.0}, ux * (1.0 + gap), uy * (1.0 + gap))};
    BoxPairList list;
    list.reset(boxes.size(), margin, 1);
    ASSERT_TRUE(list.build(boxes.data(), yes));
    EXPECT_TRUE(list.pairs().empty());
    boxes[0] = moved(boxes[0], ux * travel, uy * travel);
    ASSERT_EQ(every_overlapping(boxes, yes), (PairSet{{0, 1}}));
    EXPECT_FALSE(list.holds(boxes.data())) << "direction " << ux << ", " << uy;
    ASSERT_TRUE(list.build(boxes.data(), yes));
    EXPECT_EQ(listed_overlapping(list, boxes), (PairSet{{0, 1}}));
  }
}

TEST(BoxPairList, ANonFiniteBoxIsNeverListed) {
  auto yes = [](int, int) { return true; };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Box> boxes = {{0.0, 1.0, 0.0, 1.0}, {0.5, 1.5, 0.0, 1.0}};
  BoxPairList list;
  list.reset(boxes.size(), 0.1, 1);
  ASSERT_TRUE(list.build(boxes.data(), yes));
  boxes[1].ylo = nan;
  EXPECT_FALSE(list.holds(boxes.data()));
  EXPECT_FALSE(list.build(boxes.data(), yes));
  EXPECT_FALSE(list.holds(boxes.data()));  // a failed build leaves no list
  boxes[1].ylo = 0.0;
  boxes[0].lo = -inf;
  EXPECT_FALSE(list.build(boxes.data(), yes));
}

TEST(BoxPairList, BuildAllocatesNothingAndNorDoesACopysBuild) {
  // Ten boxes far apart (no pair kept), then all on top of each other (every pair kept): the
  // list, and a copy made while it kept nothing, build the 45 pairs in the room reset() made.
  auto yes = [](int, int) { return true; };
  std::vector<Box> apart, together;
  for (int k = 0; k < 10; ++k) {
    apart.push_back({10.0 * k, 10.0 * k + 1.0, 0.0, 1.0});
    together.push_back({0.0, 1.0, 0.0, 1.0});
  }
  BoxPairList list;
  list.reset(apart.size(), 0.25, apart.size() * (apart.size() - 1) / 2);
  ASSERT_TRUE(list.build(apart.data(), yes));
  ASSERT_TRUE(list.pairs().empty());
  BoxPairList copy = list;
  BoxPairList assigned;
  assigned = list;
  g_allocations = 0;
  g_counting = true;
  const bool built = list.build(together.data(), yes) && copy.build(together.data(), yes) &&
                     assigned.build(together.data(), yes);
  g_counting = false;
  ASSERT_TRUE(built);
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_EQ(list.pairs().size(), 45u);
  EXPECT_EQ(copy.pairs().size(), 45u);
  EXPECT_EQ(assigned.pairs().size(), 45u);
}

TEST(BoxPairList, ListedOverlapsAreEveryOverlapFrameByFrameOfRandomMotion) {
  // 60 boxes on random walks with steps up to the margin, a third of the pairs ineligible: in
  // every frame where the list holds or is rebuilt, its overlapping pairs are the brute force's.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(0.0, 8.0), size(0.05, 1.0), step(-0.2, 0.2);
  const double margin = 0.3;
  auto eligible = [](int p, int q) { return (p + q) % 3 != 0; };
  std::vector<Box> boxes;
  for (int k = 0; k < 60; ++k) {
    const double x = pos(rng), y = pos(rng);
    boxes.push_back({x, x + size(rng), y, y + size(rng)});
  }
  BoxPairList list;
  list.reset(boxes.size(), margin, boxes.size() * (boxes.size() - 1) / 2);
  long reused = 0, overlaps = 0;
  for (int frame = 0; frame < 3000; ++frame) {
    if (list.holds(boxes.data()))
      ++reused;
    else
      ASSERT_TRUE(list.build(boxes.data(), eligible));
    const PairSet want = every_overlapping(boxes, eligible);
    ASSERT_EQ(listed_overlapping(list, boxes), want) << "frame " << frame;
    overlaps += static_cast<long>(want.size());
    for (Box& b : boxes) b = moved(b, step(rng), step(rng));
  }
  // Both paths ran, and often, and there was something to find.
  EXPECT_GT(reused, 300);
  EXPECT_GT(list.builds(), 300);
  EXPECT_GT(overlaps, 3000);
}

TEST(Embedding, TheMonitorCountsEveryFrameAsTheSweepOverAllSkinEdgesDoes) {
  // The old penalty lets this evolved swimmer's skin cross itself (test_collisions.cpp): the
  // monitor's count from its kept pairs, frame by frame, against the sweep over every skin edge.
  const auto genomes = evolved_genomes();
  const Evolved& e = named(genomes, "exploit_old_physics_dn0.5.json");
  const Body body = body_of(e);
  SceneParams scene = e.config.scene;
  scene.effects = {"springs", "actuation", "pressure", "drag", "skin_collision"};
  Simulation sim(body, scene);
  EmbeddingMonitor monitor(body), sweep(body);
  long crossings = 0;
  for (int k = 0; k < 4000; ++k) {
    sim.step();
    const SwimState& s = sim.state();
    const long before = monitor.skin_crossings();
    monitor.observe(s.x, s.y);
    const int want = sweep.count_skin_crossings(s.x, s.y);
    ASSERT_EQ(monitor.skin_crossings() - before, want) << "step " << k;
    crossings += want;
  }
  EXPECT_GT(crossings, 100) << "the case must cross to test anything";
  // A copy goes on as the original does.
  EmbeddingMonitor copy = monitor;
  const SwimState& s = sim.state();
  EXPECT_EQ(copy.observe(s.x, s.y), monitor.observe(s.x, s.y));
  EXPECT_EQ(copy.skin_crossings(), monitor.skin_crossings());
}

}  // namespace
}  // namespace animat
