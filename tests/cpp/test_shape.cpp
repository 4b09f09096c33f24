// Shape measures (shape.hpp) on hand-built bodies with known answers (the cases of
// tests/python/test_shape.py; test_shape_engine.py checks the engine against animat.shape).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/shape.hpp"
#include "body_support.hpp"

using namespace animat;
using animat::test::make_points;

namespace {

const double kSq3 = std::sqrt(3.0);
constexpr double kRho = 0.75;
constexpr double kTol = 1e-9;
// One cell in the notch of a flat side: sqrt(3)/2 + sqrt(ρ² − 1/4) − ρ = 0.675.
const double kBumpHeight = kSq3 / 2 + std::sqrt(kRho * kRho - 0.25) - kRho;

using XY = std::vector<std::pair<double, double>>;

/// Hexagonally packed cells (spacing 1) within `radius` of the origin: 19 cells for 2.
XY hexagon(double radius = 2.0) {
  XY out;
  for (int j = -8; j <= 8; ++j)
    for (int i = -8; i <= 8; ++i) {
      const double x = i + 0.5 * j, y = j * kSq3 / 2;
      if (x * x + y * y <= radius * radius + 1e-9) out.emplace_back(x, y);
    }
  return out;
}

/// A hexagonally packed strip along x: 5 rows of 8 (even rows, shifted by 1/2) and 9 cells.
XY strip() {
  XY out;
  for (int r = 0; r < 5; ++r)
    for (int i = 0; i < 8 + r % 2; ++i) out.emplace_back(i + 0.5 * ((r + 1) % 2), r * kSq3 / 2);
  return out;
}

Shape shape_of(const XY& xy) { return body_shape(build_body(make_points(xy), {}, {}, {})); }

XY with(XY xy, const XY& more) {
  xy.insert(xy.end(), more.begin(), more.end());
  return xy;
}

}  // namespace

TEST(Shape, HexagonIsRoundConvexAndHasNoProtrusion) {
  const Shape sh = shape_of(hexagon());
  EXPECT_EQ(sh.cell_count, 19);
  EXPECT_NEAR(sh.spacing, 1.0, 1e-12);
  EXPECT_NEAR(sh.elongation, 1.0, 1e-12);
  EXPECT_NEAR(sh.concavity, 0.0, 1e-12);
  EXPECT_NEAR(sh.outline_area, 6 * kSq3, 1e-12 * 6 * kSq3);
  EXPECT_TRUE(sh.protrusions.empty());
  EXPECT_EQ(sh.core_cells, 19);
  std::vector<double> h = sh.heights;
  std::sort(h.begin(), h.end());
  const double corner = kRho * (2 / kSq3 - 1);  // the six 120° corners
  for (std::size_t i = 0; i < h.size(); ++i) EXPECT_NEAR(h[i], i < 13 ? 0.0 : corner, kTol) << i;
}

TEST(Shape, OneCellInANotchIsOneProtrusionOfSizeOne) {
  const XY body = strip();
  const double top = 4 * kSq3 / 2;
  const Shape sh = shape_of(with(body, {{4.0, top + kSq3 / 2}}));
  ASSERT_EQ(sh.protrusions.size(), 1u);
  EXPECT_EQ(sh.protrusions[0].cells, std::vector<int>{static_cast<int>(body.size())});
  EXPECT_NEAR(sh.protrusions[0].height, kBumpHeight, kTol);
  EXPECT_EQ(sh.core_cells, static_cast<int>(body.size()));
  EXPECT_TRUE(sh.symmetric_pairs.empty());
}

TEST(Shape, StripAreasAndConcavity) {
  const Shape sh = shape_of(strip());
  EXPECT_TRUE(sh.protrusions.empty());
  EXPECT_NEAR(sh.outline_area, 15 * kSq3, 1e-12 * 15 * kSq3);
  EXPECT_NEAR(sh.hull_area, 15.5 * kSq3, 1e-12 * 15.5 * kSq3);
  EXPECT_NEAR(sh.concavity, 1.0 / 31, 1e-12);
}

TEST(Shape, FinsPairOnlyWhenMirroredAboutTheAxis) {
  const XY body = strip();
  const double top = 4 * kSq3 / 2 + kSq3 / 2, bottom = -kSq3 / 2;
  const Shape mirrored = shape_of(with(body, {{4.0, top}, {4.0, bottom}}));
  ASSERT_EQ(mirrored.protrusions.size(), 2u);
  EXPECT_EQ(mirrored.symmetric_pairs, (std::vector<std::pair<int, int>>{{0, 1}}));
  const Shape staggered = shape_of(with(body, {{1.0, top}, {5.0, bottom}}));
  EXPECT_EQ(staggered.protrusions.size(), 2u);
  EXPECT_TRUE(staggered.symmetric_pairs.empty());
}

TEST(Shape, ChainIsOneProtrusionWithOrWithoutSprings) {
  const Body body = build_body(make_points(with(hexagon(), {{3.0, 0.0}, {4.0, 0.0}})), {}, {}, {});
  const double eroded_corner = 2.0 - kRho / std::sin(M_PI / 3);
  for (const IndexPairs* springs : {&body.springs, static_cast<const IndexPairs*>(nullptr)}) {
    const Shape sh = describe_shape(body.positions, body.skin_loops[0], springs);
    ASSERT_EQ(sh.protrusions.size(), 1u);
    EXPECT_EQ(sh.protrusions[0].cells, (std::vector<int>{19, 20}));
    EXPECT_NEAR(sh.protrusions[0].height, 4.0 - eroded_corner - kRho, kTol);
    EXPECT_NEAR(sh.heights[19], 3.0 - eroded_corner - kRho, kTol);
  }
}

TEST(Shape, TriangleTipsProtrudeSquareCornersDoNot) {
  XY tri;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6 - j; ++i) tri.emplace_back(i + 0.5 * j, j * kSq3 / 2);
  const Shape sh = shape_of(tri);
  ASSERT_EQ(sh.protrusions.size(), 3u);
  std::vector<int> tips;
  for (const Protrusion& p : sh.protrusions) {
    EXPECT_EQ(p.cells.size(), 1u);
    EXPECT_NEAR(p.height, kRho, kTol);
    tips.push_back(p.cells[0]);
  }
  std::sort(tips.begin(), tips.end());
  EXPECT_EQ(tips, (std::vector<int>{0, 5, static_cast<int>(tri.size()) - 1}));
  XY square;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) square.emplace_back(i, j);
  const Shape sq = shape_of(square);
  EXPECT_TRUE(sq.protrusions.empty());
  EXPECT_NEAR(*std::max_element(sq.heights.begin(), sq.heights.end()), kRho * (std::sqrt(2.0) - 1),
              kTol);
}

TEST(Shape, LineHasNoCoreAndItsElongationIsAnalytic) {
  for (int k : {2, 10, 32}) {
    XY line;
    for (int i = 0; i < k; ++i) line.emplace_back(i, 0.0);
    const Shape sh = shape_of(line);
    const double expected = std::sqrt(1 + 4.0 * (k * k - 1) / 3);
    EXPECT_NEAR(sh.elongation, expected, 1e-12 * expected) << k;
    EXPECT_EQ(sh.core_cells, 0) << k;
    EXPECT_TRUE(sh.protrusions.empty()) << k;
    EXPECT_EQ(sh.concavity, 0.0) << k;
  }
}

TEST(Shape, SmallAndEmptyBodies) {
  const Shape none = describe_shape(Points(0, 2), {}, nullptr);
  EXPECT_EQ(none.cell_count, 0);
  EXPECT_EQ(none.elongation, 1.0);
  EXPECT_TRUE(none.heights.empty());
  const Shape one = describe_shape(make_points({{1.0, 2.0}}), {}, nullptr);
  EXPECT_EQ(one.cell_count, 1);
  EXPECT_EQ(one.elongation, 1.0);
  EXPECT_EQ(one.heights, std::vector<double>{0.0});
}

TEST(Shape, OutlineIndexOutOfRangeIsRefused) {
  const std::vector<int> outline = {0, 1, 7};
  EXPECT_THROW((void)describe_shape(make_points({{0, 0}, {1, 0}, {0, 1}}), outline, nullptr),
               GeometryError);
}
