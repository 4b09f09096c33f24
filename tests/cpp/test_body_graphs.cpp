// Other body graphs (docs/model.md): body.graph = distance | alpha_shape against brute-force
// definitions (O(n^3) / O(n^4)) on random clouds, lattices (cocircular points), circles,
// near-collinear and nearly duplicate points, and the body invariants for graphs with holes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
#include "animat/scene.hpp"
#include "body_support.hpp"

namespace animat {
namespace {

using test::Edge;
using test::EdgeList;
using test::make_points;
using test::random_lattice_points;
using test::random_points;
using test::to_list;

BodyParams graph_params(const std::string& graph, double value) {
  BodyParams bp;
  bp.graph = graph;
  if (graph == "distance") bp.distance_threshold = value;
  if (graph == "alpha_shape") bp.alpha = value;
  return bp;
}

// ------------------------------------------------------------------------ brute-force definitions

double sq(double x) { return x * x; }
double d2(const Points& p, int a, int b) { return sq(p(a, 0) - p(b, 0)) + sq(p(a, 1) - p(b, 1)); }

/// Mean distance to the nearest other point, in index order (the unit of threshold and alpha).
double brute_scale(const Points& p) {
  const int n = static_cast<int>(p.rows());
  if (n <= 1) return 0.0;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    double best = INFINITY;
    for (int j = 0; j < n; ++j)
      if (j != i) best = std::min(best, std::hypot(p(j, 0) - p(i, 0), p(j, 1) - p(i, 1)));
    sum += best;
  }
  return sum / n;
}

/// Delaunay-tessellation edge by definition: some circle through a and b has every other point
/// strictly outside. Centres c(t) = m + t * perp(b - a); with P = 2p - (a + b), H = perp(b - a).P
/// and E = |P|^2 - |b - a|^2, p is strictly outside iff t * H < E / 4. Exact on small integers.
bool brute_tessellation(const Points& p, int a, int b) {
  const int n = static_cast<int>(p.rows());
  const double ax = p(b, 0) - p(a, 0), ay = p(b, 1) - p(a, 1);
  // Feasible t: lo < t < hi, bounds as fractions num / den with den > 0.
  bool has_lo = false, has_hi = false;
  double lo_n = 0, lo_d = 1, hi_n = 0, hi_d = 1;
  for (int k = 0; k < n; ++k) {
    if (k == a || k == b) continue;
    const double px = 2 * p(k, 0) - p(a, 0) - p(b, 0), py = 2 * p(k, 1) - p(a, 1) - p(b, 1);
    const double h = -ay * px + ax * py;
    const double e = px * px + py * py - (ax * ax + ay * ay);
    if (h == 0.0) {
      if (!(e > 0.0)) return false;  // on the segment ab
      continue;
    }
    // t < e / (4h) if h > 0; t > e / (4h) if h < 0.
    const double num = h > 0 ? e : -e, den = 4 * std::abs(h);
    if (h > 0) {
      if (!has_hi || num * hi_d < hi_n * den) hi_n = num, hi_d = den, has_hi = true;
    } else {
      if (!has_lo || num * lo_d > lo_n * den) lo_n = num, lo_d = den, has_lo = true;
    }
  }
  if (!has_lo || !has_hi) return true;
  return lo_n * hi_d < hi_n * lo_d;
}

/// Relative neighbourhood graph: no point strictly closer to both ends than they are to each other.
bool brute_rng(const Points& p, int a, int b) {
  const int n = static_cast<int>(p.rows());
  for (int c = 0; c < n; ++c)
    if (c != a && c != b && d2(p, a, c) < d2(p, a, b) && d2(p, b, c) < d2(p, a, b)) return false;
  return true;
}

EdgeList brute_distance_graph(const Points& p, double threshold) {
  const int n = static_cast<int>(p.rows());
  const double limit = threshold * brute_scale(p);
  EdgeList out;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (!brute_tessellation(p, i, j)) continue;
      const double len = std::hypot(p(j, 0) - p(i, 0), p(j, 1) - p(i, 1));
      if (len <= limit || brute_rng(p, i, j)) out.emplace_back(i, j);
    }
  return out;
}

double orient(const Points& p, int a, int b, int c) {
  return (p(b, 0) - p(a, 0)) * (p(c, 1) - p(a, 1)) - (p(b, 1) - p(a, 1)) * (p(c, 0) - p(a, 0));
}

/// > 0 if d is strictly inside the circle through a, b, c (a, b, c counter-clockwise).
double incircle(const Points& p, int a, int b, int c, int d) {
  const double adx = p(a, 0) - p(d, 0), ady = p(a, 1) - p(d, 1);
  const double bdx = p(b, 0) - p(d, 0), bdy = p(b, 1) - p(d, 1);
  const double cdx = p(c, 0) - p(d, 0), cdy = p(c, 1) - p(d, 1);
  const double al = adx * adx + ady * ady, bl = bdx * bdx + bdy * bdy, cl = cdx * cdx + cdy * cdy;
  return adx * (bdy * cl - bl * cdy) - ady * (bdx * cl - bl * cdx) + al * (bdx * cdy - bdy * cdx);
}

double circumradius2(const Points& p, int a, int b, int c) {
  const double ab = d2(p, a, b), bc = d2(p, b, c), ca = d2(p, c, a);
  const double twice_area = orient(p, a, b, c);
  return ab * bc * ca / (4.0 * twice_area * twice_area);
}

/// The alpha complex's filled cells by definition: point sets that lie on one empty circle (no
/// point strictly inside) through >= 3 points, of radius <= alpha * scale. `ambiguous` is set when
/// some empty circle's radius is within 1e-9 of the limit (double round-off may then decide).
std::set<std::vector<int>> brute_alpha_cells(const Points& p, double alpha, bool& ambiguous) {
  const int n = static_cast<int>(p.rows());
  const double limit2 = sq(alpha * brute_scale(p));
  std::set<std::vector<int>> cells;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c) {
        const double o = orient(p, a, b, c);
        if (o == 0.0) continue;
        const int cc = o > 0 ? c : b, bb = o > 0 ? b : c;
        std::vector<int> on{a, b, c};
        bool empty = true;
        for (int d = 0; d < n && empty; ++d) {
          if (d == a || d == b || d == c) continue;
          const double s = incircle(p, a, bb, cc, d);
          if (s > 0) empty = false;
          if (s == 0) on.push_back(d);
        }
        if (!empty) continue;
        const double r2 = circumradius2(p, a, b, c);
        if (std::abs(r2 - limit2) <= 1e-9 * limit2) ambiguous = true;
        if (r2 > limit2) continue;
        std::sort(on.begin(), on.end());
        cells.insert(on);
      }
  return cells;
}

EdgeList brute_alpha_graph(const Points& p, double alpha, bool& ambiguous) {
  const int n = static_cast<int>(p.rows());
  const auto cells = brute_alpha_cells(p, alpha, ambiguous);
  std::set<Edge> in_cell;
  for (const auto& cell : cells)
    for (std::size_t i = 0; i < cell.size(); ++i)
      for (std::size_t j = i + 1; j < cell.size(); ++j) in_cell.insert({cell[i], cell[j]});
  EdgeList out;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (!brute_tessellation(p, i, j)) continue;
      if (in_cell.count({i, j}) || brute_rng(p, i, j)) out.emplace_back(i, j);
    }
  return out;
}

// ------------------------------------------------------------------------ invariants

/// Proper crossing or an end of one segment on the interior of the other.
bool segments_cross(const Points& p, Edge e, Edge f) {
  const int a = e.first, b = e.second, c = f.first, d = f.second;
  if (a == c || a == d || b == c || b == d) {
    // Sharing an end: they overlap only if collinear and pointing the same way.
    const int s = (a == c || a == d) ? a : b;
    const int u = s == a ? b : a, v = (c == s) ? d : c;
    if (orient(p, s, u, v) != 0.0) return false;
    return (p(u, 0) - p(s, 0)) * (p(v, 0) - p(s, 0)) + (p(u, 1) - p(s, 1)) * (p(v, 1) - p(s, 1)) >
           0;
  }
  const double o1 = orient(p, a, b, c), o2 = orient(p, a, b, d), o3 = orient(p, c, d, a),
               o4 = orient(p, c, d, b);
  const auto on = [&](int s, int t, int q) {
    return std::min(p(s, 0), p(t, 0)) <= p(q, 0) && p(q, 0) <= std::max(p(s, 0), p(t, 0)) &&
           std::min(p(s, 1), p(t, 1)) <= p(q, 1) && p(q, 1) <= std::max(p(s, 1), p(t, 1));
  };
  if (o1 == 0 && on(a, b, c)) return true;
  if (o2 == 0 && on(a, b, d)) return true;
  if (o3 == 0 && on(c, d, a)) return true;
  if (o4 == 0 && on(c, d, b)) return true;
  return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 &&
         o4 != 0;
}

/// Every invariant of a body whose graph may have holes: planar, connected, every half-edge in
/// exactly one face walk (regions CCW; skin loop 0 = the outer face reversed; further skin loops =
/// holes reversed), positive rest areas, Σ S0 = Σ shoelace(skin loops).
void check_graph_body(const Body& body, const Points& points) {
  const int n = static_cast<int>(points.rows());
  ASSERT_EQ(body.node_count(), n);
  const EdgeList springs = to_list(body.springs);
  ASSERT_TRUE(std::is_sorted(springs.begin(), springs.end()));
  for (const auto& [a, b] : springs) ASSERT_LT(a, b);
  const std::set<Edge> spring_set(springs.begin(), springs.end());
  ASSERT_EQ(spring_set.size(), springs.size());
  for (Eigen::Index e = 0; e < body.springs.rows(); ++e) {
    const double d = (points.row(body.springs(e, 0)) - points.row(body.springs(e, 1))).norm();
    ASSERT_NEAR(body.rest_lengths(e), d, 1e-12 * (1.0 + d));
  }
  // No crossing springs.
  for (std::size_t i = 0; i < springs.size(); ++i)
    for (std::size_t j = i + 1; j < springs.size(); ++j)
      ASSERT_FALSE(segments_cross(points, springs[i], springs[j]))
          << springs[i].first << "-" << springs[i].second << " x " << springs[j].first << "-"
          << springs[j].second;
  // Connected.
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)];
    return x;
  };
  for (const auto& [a, b] : springs) parent[static_cast<std::size_t>(find(a))] = find(b);
  for (int v = 1; v < n; ++v) ASSERT_EQ(find(v), find(0)) << "node " << v << " is not connected";
  if (n <= 1) {
    ASSERT_TRUE(body.skin_loops.empty());
    return;
  }
  ASSERT_GE(body.skin_loops.size(), 1U);
  const int holes = static_cast<int>(body.skin_loops.size()) - 1;
  // Euler for a connected plane graph: V - E + F = 1, F = bounded faces = regions + holes.
  ASSERT_EQ(n - body.spring_count() + body.region_count() + holes, 1);
  std::map<Edge, int> halfedges;
  const auto walk = [&](const std::vector<int>& loop, bool reversed) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      int a = loop[i], b = loop[(i + 1) % loop.size()];
      ASSERT_TRUE(spring_set.count({std::min(a, b), std::max(a, b)})) << a << "->" << b;
      if (reversed) std::swap(a, b);
      ++halfedges[{a, b}];
    }
  };
  double region_sum = 0.0;
  ASSERT_EQ(body.rest_areas.size(), body.region_count());
  for (int r = 0; r < body.region_count(); ++r) {
    const auto& loop = body.regions[static_cast<std::size_t>(r)];
    ASSERT_GE(loop.size(), 3U);
    walk(loop, false);
    ASSERT_GT(body.rest_areas(r), 0.0);
    ASSERT_DOUBLE_EQ(body.rest_areas(r), polygon_area(points, loop));
    region_sum += body.rest_areas(r);
  }
  double skin_sum = 0.0;
  for (std::size_t k = 0; k < body.skin_loops.size(); ++k) {
    walk(body.skin_loops[k], true);
    const double area = polygon_area(points, body.skin_loops[k]);
    if (k == 0) {
      ASSERT_GE(area, -1e-12 * (1.0 + region_sum));  // 0 up to round-off for a tree
    } else {
      ASSERT_LT(area, 0.0) << "hole loop " << k << " must go clockwise (body on its left)";
    }
    skin_sum += area;
  }
  ASSERT_EQ(halfedges.size(), 2 * springs.size());
  for (const auto& [h, count] : halfedges) ASSERT_EQ(count, 1) << h.first << "->" << h.second;
  ASSERT_NEAR(region_sum, skin_sum, 1e-9 * (1.0 + std::abs(skin_sum)));
  // Skin = the edges of the skin loops.
  std::set<Edge> loop_edges;
  for (const auto& loop : body.skin_loops)
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const int a = loop[i], b = loop[(i + 1) % loop.size()];
      loop_edges.insert({std::min(a, b), std::max(a, b)});
    }
  ASSERT_EQ(EdgeList(loop_edges.begin(), loop_edges.end()), to_list(body.skin));
}

void check_distance(const Points& p, double threshold, const std::string& what) {
  SCOPED_TRACE(what + " threshold=" + std::to_string(threshold));
  const Body body = build_body(p, {}, {}, {}, graph_params("distance", threshold));
  ASSERT_EQ(to_list(body.springs), brute_distance_graph(p, threshold));
  // no holes: every bounded face is a region
  ASSERT_EQ(body.skin_loops.size(), p.rows() >= 2 ? 1U : 0U);
  check_graph_body(body, p);
}

/// Returns false (and checks nothing) when round-off could decide a radius against the limit.
bool check_alpha(const Points& p, double alpha, const std::string& what) {
  SCOPED_TRACE(what + " alpha=" + std::to_string(alpha));
  bool ambiguous = false;
  const EdgeList expected = brute_alpha_graph(p, alpha, ambiguous);
  if (ambiguous) return false;
  const Body body = build_body(p, {}, {}, {}, graph_params("alpha_shape", alpha));
  EXPECT_EQ(to_list(body.springs), expected);
  // Regions = the filled cells, each one region with exactly the cell's points.
  const auto cells = brute_alpha_cells(p, alpha, ambiguous);
  std::set<std::vector<int>> regions;
  for (auto loop : body.regions) {
    std::sort(loop.begin(), loop.end());
    regions.insert(loop);
  }
  EXPECT_EQ(regions, cells);
  EXPECT_EQ(body.regions.size(), cells.size());
  check_graph_body(body, p);
  return true;
}

// ------------------------------------------------------------------------ distance graph

TEST(BodyGraphDistance, MatchesBruteForceOnRandomSets) {
  for (int n = 2; n <= 40; n += 3)
    for (std::uint64_t seed = 0; seed < 4; ++seed)
      for (double t : {0.3, 1.0, 1.5, 2.5, 100.0})
        check_distance(random_points(n, 500 + 100 * static_cast<std::uint64_t>(n) + seed), t,
                       "n=" + std::to_string(n) + " seed=" + std::to_string(seed));
}

TEST(BodyGraphDistance, MatchesBruteForceOnIntegerLattices) {
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    const int side = 4 + static_cast<int>(seed % 6);
    const int n = 3 + static_cast<int>(seed * 7 % static_cast<std::uint64_t>(side * side - 3));
    for (double t : {0.9, 1.2, 1.5, 2.3, 50.0})
      check_distance(random_lattice_points(n, side, seed), t,
                     "lattice seed=" + std::to_string(seed));
  }
}

TEST(BodyGraphDistance, SquareGridKeepsItsSquares) {
  // Every grid square is 4 cocircular points: its diagonals are never kept, whatever the threshold.
  std::vector<std::pair<double, double>> xy;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) xy.emplace_back(i, j);
  const Points p = make_points(xy);
  for (double t : {1.0, 1.5, 10.0}) {
    const Body body = build_body(p, {}, {}, {}, graph_params("distance", t));
    EXPECT_EQ(body.spring_count(), 2 * 6 * 5);
    EXPECT_EQ(body.region_count(), 25);
    for (const auto& loop : body.regions) EXPECT_EQ(loop.size(), 4U);
    check_graph_body(body, p);
  }
}

TEST(BodyGraphDistance, CircleIsConnectedByRelativeNeighbours) {
  // The 12 integer points of the circle x^2 + y^2 = 25: all cocircular; nearest-neighbour distances
  // sqrt(2) and sqrt(10). A threshold below both still keeps the cycle's RNG edges: one piece.
  std::vector<std::pair<double, double>> xy{{5, 0},  {4, 3},   {3, 4},   {0, 5},  {-3, 4}, {-4, 3},
                                            {-5, 0}, {-4, -3}, {-3, -4}, {0, -5}, {3, -4}, {4, -3}};
  const Points p = make_points(xy);
  for (double t : {0.1, 1.0, 3.0, 100.0}) {
    check_distance(p, t, "circle");
    const Body body = build_body(p, {}, {}, {}, graph_params("distance", t));
    EXPECT_EQ(body.spring_count(), 12) << "the 12-gon's sides (its diagonals are all ambiguous)";
    EXPECT_EQ(body.region_count(), 1);
  }
}

TEST(BodyGraphDistance, NearCollinearAndNearlyDuplicatePoints) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Rng rng(seed + 7);
    const int n = 3 + static_cast<int>(seed % 15);
    Points p(n, 2);
    for (int i = 0; i < n; ++i) {
      p(i, 0) = i + rng.uniform(-0.3, 0.3);
      p(i, 1) = rng.uniform(-1e-6, 1e-6);
    }
    for (double t : {0.5, 1.5, 20.0})
      check_distance(p, t, "near-collinear seed=" + std::to_string(seed));
  }
  // Pairs 1e-5 apart (above merge_distance): a legal body.
  Points p = random_points(20, 77);
  for (int i = 0; i < 10; i += 2) {
    p(i + 1, 0) = p(i, 0) + 1e-5;
    p(i + 1, 1) = p(i, 1);
  }
  for (double t : {0.5, 1.5, 20.0}) check_distance(p, t, "near duplicates");
  // Closer than merge_distance: rejected like the Gabriel body.
  p(1, 0) = p(0, 0) + 1e-7;
  EXPECT_THROW((void)build_body(p, {}, {}, {}, graph_params("distance", 1.5)), GeometryError);
  EXPECT_THROW((void)build_body(p, {}, {}, {}, graph_params("alpha_shape", 1.0)), GeometryError);
}

TEST(BodyGraphDistance, CollinearIsTheChainAndScaleFree) {
  const Points line = make_points({{0, 0}, {3, 0}, {1, 0}, {7, 0}});
  for (const std::string graph : {"distance", "alpha_shape"}) {
    const Body body = build_body(line, {}, {}, {}, graph_params(graph, 0.5));
    EXPECT_EQ(to_list(body.springs), (EdgeList{{0, 2}, {1, 2}, {1, 3}}));
    EXPECT_EQ(body.region_count(), 0);
  }
  // Scaling every point scales nothing in the graph: thresholds are in nearest-neighbour units.
  const Points p = random_points(30, 5);
  for (const std::string graph : {"distance", "alpha_shape"}) {
    const Body a = build_body(p, {}, {}, {}, graph_params(graph, 1.3));
    const Body b = build_body(Points(p * 1000.0), {}, {}, {}, graph_params(graph, 1.3));
    EXPECT_EQ(to_list(a.springs), to_list(b.springs)) << graph;
    EXPECT_EQ(a.regions, b.regions) << graph;
  }
}

TEST(BodyGraphDistance, IndependentOfInputOrder) {
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const Points p = random_lattice_points(25, 7, seed);
    std::vector<int> perm(25);
    std::iota(perm.begin(), perm.end(), 0);
    Rng rng(seed);
    for (int i = 24; i > 0; --i)
      std::swap(perm[static_cast<std::size_t>(i)],
                perm[rng.below(static_cast<std::uint64_t>(i + 1))]);
    Points q(25, 2);
    for (int i = 0; i < 25; ++i) q.row(i) = p.row(perm[static_cast<std::size_t>(i)]);
    for (const std::string graph : {"distance", "alpha_shape"}) {
      const Body a = build_body(p, {}, {}, {}, graph_params(graph, 1.2));
      const Body b = build_body(q, {}, {}, {}, graph_params(graph, 1.2));
      std::set<Edge> ea, eb;
      for (const auto& [i, j] : to_list(a.springs)) ea.insert({i, j});
      for (const auto& [i, j] : to_list(b.springs)) {
        const int u = perm[static_cast<std::size_t>(i)], v = perm[static_cast<std::size_t>(j)];
        eb.insert({std::min(u, v), std::max(u, v)});
      }
      EXPECT_EQ(ea, eb) << graph << " seed=" << seed;
      EXPECT_EQ(a.region_count(), b.region_count());
      EXPECT_EQ(a.skin_loops.size(), b.skin_loops.size());
    }
  }
}

// ------------------------------------------------------------------------ alpha shape

TEST(BodyGraphAlpha, MatchesBruteForceOnRandomSets) {
  int checked = 0;
  for (int n = 3; n <= 30; n += 3)
    for (std::uint64_t seed = 0; seed < 4; ++seed)
      for (double alpha : {0.3, 0.6, 1.0, 1.7, 100.0})
        checked += check_alpha(random_points(n, 900 + 100 * static_cast<std::uint64_t>(n) + seed),
                               alpha, "n=" + std::to_string(n) + " seed=" + std::to_string(seed));
  EXPECT_GT(checked, 190);
}

TEST(BodyGraphAlpha, MatchesBruteForceOnIntegerLattices) {
  int checked = 0, total = 0;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    const int side = 4 + static_cast<int>(seed % 5);
    const int n = 3 + static_cast<int>(seed * 7 % static_cast<std::uint64_t>(side * side - 3));
    for (double alpha : {0.55, 0.8, 1.1, 1.9, 50.0}) {
      ++total;
      checked += check_alpha(random_lattice_points(n, side, seed), alpha,
                             "lattice seed=" + std::to_string(seed));
    }
  }
  EXPECT_GT(checked, total / 2);
}

TEST(BodyGraphAlpha, SquareGridFilledOrAllHoles) {
  std::vector<std::pair<double, double>> xy;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) xy.emplace_back(i, j);
  const Points p = make_points(xy);
  // A unit square's circumradius is 0.707 nearest-neighbour distances.
  const Body filled = build_body(p, {}, {}, {}, graph_params("alpha_shape", 0.75));
  EXPECT_EQ(filled.region_count(), 16);
  EXPECT_EQ(filled.skin_loops.size(), 1U);
  check_graph_body(filled, p);
  // Below it no square is filled: the lattice edges (relative neighbours) keep the body in one
  // piece, and every square is a hole.
  const Body hollow = build_body(p, {}, {}, {}, graph_params("alpha_shape", 0.65));
  EXPECT_EQ(hollow.spring_count(), 40);
  EXPECT_EQ(hollow.region_count(), 0);
  EXPECT_EQ(hollow.skin_loops.size(), 17U);
  EXPECT_EQ(hollow.skin.rows(), 40);
  check_graph_body(hollow, p);
}

TEST(BodyGraphAlpha, AnnulusIsHollow) {
  // Two concentric rings of 24 and 18 points: the alpha complex fills the band between them and
  // leaves the middle a hole, whose boundary (the inner ring) is skin and carries no region.
  std::vector<std::pair<double, double>> xy;
  for (int k = 0; k < 24; ++k)
    xy.emplace_back(6.0 * std::cos(k * std::numbers::pi / 12),
                    6.0 * std::sin(k * std::numbers::pi / 12));
  for (int k = 0; k < 18; ++k)
    xy.emplace_back(5.0 * std::cos((k + 0.5) * std::numbers::pi / 9),
                    5.0 * std::sin((k + 0.5) * std::numbers::pi / 9));
  const Points p = make_points(xy);
  ASSERT_TRUE(check_alpha(p, 2.0, "annulus"));
  const Body body = build_body(p, {}, {}, {}, graph_params("alpha_shape", 2.0));
  ASSERT_EQ(body.skin_loops.size(), 2U);
  std::vector<int> inner = body.skin_loops[1];
  std::sort(inner.begin(), inner.end());
  std::vector<int> expected(18);
  std::iota(expected.begin(), expected.end(), 24);
  EXPECT_EQ(inner, expected);
  double band = 0.0;
  for (int r = 0; r < body.region_count(); ++r) band += body.rest_areas(r);
  EXPECT_NEAR(band, polygon_area(p, body.skin_loops[0]) + polygon_area(p, body.skin_loops[1]),
              1e-9);
  EXPECT_LT(band, 0.5 * polygon_area(p, body.skin_loops[0]));
  // A large alpha fills the middle too.
  const Body solid = build_body(p, {}, {}, {}, graph_params("alpha_shape", 100.0));
  EXPECT_EQ(solid.skin_loops.size(), 1U);
}

TEST(BodyGraphAlpha, HollowBodySwimsInThePapersScene) {
  // The annulus with a travelling wave of actuation in the default scene (springs, actuation,
  // pressure, drag, collisions): the hole's boundary is skin and feels drag, the hole has no
  // pressure, and nothing in the physics assumes one skin loop.
  std::vector<std::pair<double, double>> xy;
  for (int k = 0; k < 24; ++k)
    xy.emplace_back(6.0 * std::cos(k * std::numbers::pi / 12),
                    6.0 * std::sin(k * std::numbers::pi / 12));
  for (int k = 0; k < 18; ++k)
    xy.emplace_back(5.0 * std::cos((k + 0.5) * std::numbers::pi / 9),
                    5.0 * std::sin((k + 0.5) * std::numbers::pi / 9));
  const Points p = make_points(xy);
  const int n = static_cast<int>(p.rows());
  Vector amplitude = Vector::Constant(n, 0.15), frequency = Vector::Constant(n, 3.0), phase(n);
  for (int i = 0; i < n; ++i) phase(i) = std::atan2(p(i, 1), p(i, 0)) + std::numbers::pi;
  const Body body = build_body(p, amplitude, frequency, phase, graph_params("alpha_shape", 2.0));
  ASSERT_EQ(body.skin_loops.size(), 2U);
  Simulation sim(body, SceneParams{}, PhysicsParams{});
  ASSERT_NO_THROW(sim.step(3000));
  for (int i = 0; i < n; ++i) {
    ASSERT_TRUE(std::isfinite(sim.state().x[static_cast<std::size_t>(i)]));
    ASSERT_TRUE(std::isfinite(sim.state().y[static_cast<std::size_t>(i)]));
  }
}

TEST(BodyGraphAlpha, CircleIsARingOrADisc) {
  std::vector<std::pair<double, double>> xy{{5, 0},  {4, 3},   {3, 4},   {0, 5},  {-3, 4}, {-4, 3},
                                            {-5, 0}, {-4, -3}, {-3, -4}, {0, -5}, {3, -4}, {4, -3}};
  const Points p = make_points(xy);
  const double scale = brute_scale(p);  // radius 5 = 5 / scale nearest-neighbour distances
  const Body ring = build_body(p, {}, {}, {}, graph_params("alpha_shape", 0.9 * 5.0 / scale));
  EXPECT_EQ(ring.region_count(), 0);
  EXPECT_EQ(ring.skin_loops.size(), 2U);
  check_graph_body(ring, p);
  const Body disc = build_body(p, {}, {}, {}, graph_params("alpha_shape", 1.1 * 5.0 / scale));
  EXPECT_EQ(disc.region_count(), 1);
  EXPECT_EQ(disc.regions[0].size(), 12U);
  EXPECT_EQ(disc.skin_loops.size(), 1U);
  check_graph_body(disc, p);
}

TEST(BodyGraphAlpha, NearCollinearSets) {
  int checked = 0;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Rng rng(seed + 11);
    const int n = 3 + static_cast<int>(seed % 15);
    Points p(n, 2);
    for (int i = 0; i < n; ++i) {
      p(i, 0) = i + rng.uniform(-0.3, 0.3);
      p(i, 1) = rng.uniform(-1e-6, 1e-6);
    }
    for (double alpha : {0.5, 1.5, 1e5})
      checked += check_alpha(p, alpha, "near-collinear seed=" + std::to_string(seed));
  }
  EXPECT_GT(checked, 50);
}

// ------------------------------------------------------------------------ default and config

TEST(BodyGraphConfig, GabrielIsTheDefaultAndUnchanged) {
  const BodyParams defaults;
  EXPECT_EQ(defaults.graph, "gabriel");
  const Points p = random_points(40, 3);
  const Body body = build_body(p, {}, {}, {}, defaults);
  EXPECT_EQ(to_list(body.springs), to_list(gabriel_graph(p)));
  // The graph keys do not change the Gabriel graph.
  BodyParams other = defaults;
  other.distance_threshold = 0.1;
  other.alpha = 0.1;
  EXPECT_EQ(to_list(build_body(p, {}, {}, {}, other).springs), to_list(body.springs));
}

TEST(BodyGraphConfig, BadValuesAreConfigErrorsNamingKeyAndValue) {
  const auto message = [](const std::string& assignment) {
    Config c;
    try {
      apply_override(c, assignment);
      validate(c);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  for (const auto& [assignment, key, value] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"body.graph=\"voronoi\"", "graph", "voronoi"},
           {"body.distance_threshold=0", "distance_threshold", "0"},
           {"body.alpha=-1", "alpha", "-1"}}) {
    const std::string msg = message(assignment);
    EXPECT_NE(msg.find(key), std::string::npos) << msg;
    EXPECT_NE(msg.find(value), std::string::npos) << msg;
  }
  BodyParams bp;
  bp.graph = "voronoi";
  try {
    (void)build_body(random_points(5, 1), {}, {}, {}, bp);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("body.graph"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("voronoi"), std::string::npos);
  }
  Config c;
  apply_override(c, "body.graph=alpha_shape");
  apply_override(c, "body.alpha=0.8");
  EXPECT_EQ(c.body.graph, "alpha_shape");
  EXPECT_EQ(c.body.alpha, 0.8);
  EXPECT_EQ(config_from_toml(to_toml(c)), c);
}

}  // namespace
}  // namespace animat
