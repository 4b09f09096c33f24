// Body: Gabriel graph against its O(n^3) definition, planar-graph invariants of regions and skin,
// and every documented degenerate case (paper §3, docs/model.md §3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/random.hpp"
#include "body_support.hpp"

namespace animat {
namespace {

using test::Edge;
using test::EdgeList;
using test::make_points;
using test::random_lattice_points;
using test::random_points;
using test::to_list;

/// The definition, O(n^3): a and b are joined iff no other point p lies in the CLOSED disc with
/// diameter ab, i.e. iff dot(a - p, b - p) > 0 for every other p (Thales). Exact on small integers.
EdgeList brute_gabriel(const Points& p) {
  const int n = static_cast<int>(p.rows());
  EdgeList out;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      bool empty = true;
      for (int k = 0; k < n && empty; ++k) {
        if (k == i || k == j) continue;
        const double dot =
            (p(i, 0) - p(k, 0)) * (p(j, 0) - p(k, 0)) + (p(i, 1) - p(k, 1)) * (p(j, 1) - p(k, 1));
        if (dot <= 0.0) empty = false;
      }
      if (empty) out.emplace_back(i, j);
    }
  }
  return out;
}

bool sorted_and_ordered(const IndexPairs& pairs) {
  const EdgeList list = to_list(pairs);
  for (const auto& [a, b] : list)
    if (!(a < b)) return false;
  return std::is_sorted(list.begin(), list.end()) &&
         std::adjacent_find(list.begin(), list.end()) == list.end();
}

/// Bridges by definition: edges whose removal disconnects the graph. O(E (V + E)).
std::set<Edge> bridges(int n, const EdgeList& edges) {
  std::set<Edge> out;
  for (std::size_t skip = 0; skip < edges.size(); ++skip) {
    std::vector<int> parent(static_cast<std::size_t>(n));
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](int x) {
      while (parent[static_cast<std::size_t>(x)] != x)
        x = parent[static_cast<std::size_t>(x)] =
            parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      return x;
    };
    for (std::size_t e = 0; e < edges.size(); ++e)
      if (e != skip) parent[static_cast<std::size_t>(find(edges[e].first))] = find(edges[e].second);
    if (find(edges[skip].first) != find(edges[skip].second)) out.insert(edges[skip]);
  }
  return out;
}

/// Every invariant a body must satisfy, whatever the input.
void check_body_invariants(const Body& body, const Points& points) {
  const int n = static_cast<int>(points.rows());
  ASSERT_EQ(body.node_count(), n);
  ASSERT_TRUE(body.positions == points);
  ASSERT_TRUE(sorted_and_ordered(body.springs));
  ASSERT_TRUE(sorted_and_ordered(body.skin));
  const EdgeList springs = to_list(body.springs);
  const std::set<Edge> spring_set(springs.begin(), springs.end());
  ASSERT_EQ(springs, brute_gabriel(points));

  // Rest lengths are the distances.
  ASSERT_EQ(body.rest_lengths.size(), body.springs.rows());
  for (Eigen::Index e = 0; e < body.springs.rows(); ++e) {
    const double d = (points.row(body.springs(e, 0)) - points.row(body.springs(e, 1))).norm();
    ASSERT_NEAR(body.rest_lengths(e), d, 1e-12 * (1.0 + d));
  }

  // Euler for a connected planar graph: V - E + F = 1 (F = bounded faces).
  const int V = n, E = body.spring_count(), F = body.region_count();
  if (n >= 1) {
    ASSERT_EQ(V - E + F, 1) << "V=" << V << " E=" << E << " F=" << F;
  }
  ASSERT_EQ(body.rest_areas.size(), F);

  // Every half-edge lies in exactly one face walk: regions CCW, the outer face = reversed skin
  // loop.
  std::map<Edge, int> halfedge_count;
  std::map<Edge, std::set<int>> faces_of_edge;  // face id -1 = outer
  std::map<Edge, int> edge_uses;
  const auto walk = [&](const std::vector<int>& loop, int face, bool reversed) {
    const std::size_t k = loop.size();
    for (std::size_t i = 0; i < k; ++i) {
      int a = loop[i], b = loop[(i + 1) % k];
      const Edge undirected{std::min(a, b), std::max(a, b)};
      ASSERT_TRUE(spring_set.count(undirected))
          << "loop step " << a << "->" << b << " is not a spring";
      if (reversed) std::swap(a, b);
      ++halfedge_count[{a, b}];
      faces_of_edge[undirected].insert(face);
      ++edge_uses[undirected];
    }
  };
  double region_area_sum = 0.0;
  for (int r = 0; r < F; ++r) {
    const auto& loop = body.regions[static_cast<std::size_t>(r)];
    ASSERT_GE(loop.size(), 3U);
    walk(loop, r, false);
    const double area = polygon_area(points, loop);
    ASSERT_GT(area, 0.0) << "region " << r << " is not CCW";
    ASSERT_DOUBLE_EQ(body.rest_areas(r), area);
    region_area_sum += area;
  }
  if (n <= 1) {
    ASSERT_TRUE(body.skin_loops.empty());
    ASSERT_EQ(body.skin.rows(), 0);
    return;
  }
  ASSERT_EQ(body.skin_loops.size(), 1U);
  const auto& skin_loop = body.skin_loops[0];
  walk(skin_loop, -1, true);
  ASSERT_EQ(halfedge_count.size(), 2 * springs.size());
  for (const auto& [h, count] : halfedge_count) ASSERT_EQ(count, 1) << h.first << "->" << h.second;

  // Each edge is used twice in all: a bridge (dangling/tree edge) twice by one face, any other
  // edge once by each of two different faces, counting the outer one.
  const std::set<Edge> bridge_set = bridges(n, springs);
  for (const Edge& e : springs) {
    ASSERT_EQ(edge_uses[e], 2);
    ASSERT_EQ(faces_of_edge[e].size(), bridge_set.count(e) ? 1U : 2U) << e.first << "-" << e.second;
  }

  // Skin edges = the edges of the skin walk, each once; dangling edges appear twice in the walk.
  std::set<Edge> walk_edges;
  std::map<Edge, int> walk_uses;
  for (std::size_t i = 0; i < skin_loop.size(); ++i) {
    const int a = skin_loop[i], b = skin_loop[(i + 1) % skin_loop.size()];
    walk_edges.insert({std::min(a, b), std::max(a, b)});
    ++walk_uses[{std::min(a, b), std::max(a, b)}];
  }
  const EdgeList skin = to_list(body.skin);
  ASSERT_EQ(EdgeList(walk_edges.begin(), walk_edges.end()), skin);
  for (const Edge& e : bridge_set) {
    if (walk_uses.count(e)) {
      ASSERT_EQ(walk_uses[e], 2);
    }
  }

  // The regions tile the area enclosed by the skin.
  const double skin_area = polygon_area(points, skin_loop);
  ASSERT_NEAR(region_area_sum, skin_area, 1e-9 * (1.0 + std::abs(skin_area)));
}

// ---------------------------------------------------------------- Gabriel against brute force

TEST(BodyGabriel, MatchesBruteForceOnRandomSets) {
  int sets = 0;
  for (int n = 3; n <= 30; ++n) {
    for (std::uint64_t seed = 0; seed < 12; ++seed, ++sets) {
      const Points p = random_points(n, 1000 * static_cast<std::uint64_t>(n) + seed);
      ASSERT_EQ(to_list(gabriel_graph(p)), brute_gabriel(p)) << "n=" << n << " seed=" << seed;
    }
  }
  for (int n = 40; n <= 300; n += 20) {
    for (std::uint64_t seed = 0; seed < 3; ++seed, ++sets) {
      const Points p = random_points(n, 7 + 1000 * static_cast<std::uint64_t>(n) + seed, 0.0, 1.0);
      ASSERT_EQ(to_list(gabriel_graph(p)), brute_gabriel(p)) << "n=" << n << " seed=" << seed;
    }
  }
  EXPECT_GT(sets, 350);
}

TEST(BodyGabriel, MatchesBruteForceOnClusteredSets) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Rng rng(seed + 99);
    const int n = 10 + static_cast<int>(rng.below(90));
    Points p(n, 2);
    for (int i = 0; i < n; ++i) {  // two Gaussian blobs of very different scale
      const double s = i % 2 ? 0.01 : 5.0;
      p(i, 0) = rng.normal(i % 2 ? 3.0 : 0.0, s);
      p(i, 1) = rng.normal(0.0, s);
    }
    ASSERT_EQ(to_list(gabriel_graph(p)), brute_gabriel(p)) << "seed=" << seed;
  }
}

TEST(BodyGabriel, MatchesBruteForceOnIntegerLattices) {
  // Lattice points are full of cocircular quadruples: the closed-disc rule decides many edges.
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    const int side = 4 + static_cast<int>(seed % 8);
    const int n = 3 + static_cast<int>(seed * 7 % static_cast<std::uint64_t>(side * side - 3));
    const Points p = random_lattice_points(n, side, seed);
    ASSERT_EQ(to_list(gabriel_graph(p)), brute_gabriel(p)) << "seed=" << seed << " n=" << n;
  }
}

TEST(BodyGabriel, SquareGridHasLatticeEdgesOnly) {
  for (int k = 2; k <= 14; ++k) {
    for (const double spacing : {1.0, 0.25, 3.0}) {
      Points p(k * k, 2);
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j)
          p(i * k + j, 0) = 17.0 + spacing * j, p(i * k + j, 1) = -5.0 + spacing * i;
      EdgeList expected;
      for (int i = 0; i < k; ++i) {
        for (int j = 0; j < k; ++j) {
          if (j + 1 < k) expected.emplace_back(i * k + j, i * k + j + 1);
          if (i + 1 < k) expected.emplace_back(i * k + j, (i + 1) * k + j);
        }
      }
      std::sort(expected.begin(), expected.end());
      const EdgeList got = to_list(gabriel_graph(p));
      ASSERT_EQ(got.size(), static_cast<std::size_t>(2 * k * (k - 1))) << "k=" << k;
      ASSERT_EQ(got, expected) << "k=" << k << " spacing=" << spacing;
      const Body body = build_body(p, {}, {}, {});
      ASSERT_EQ(body.region_count(), (k - 1) * (k - 1));
      for (int r = 0; r < body.region_count(); ++r) {
        ASSERT_EQ(body.regions[static_cast<std::size_t>(r)].size(), 4U);
        ASSERT_DOUBLE_EQ(body.rest_areas(r), spacing * spacing);
      }
      ASSERT_EQ(body.skin.rows(), 4 * (k - 1));
      check_body_invariants(body, p);
    }
  }
}

TEST(BodyGabriel, TriangularGridHasAllLatticeEdges) {
  for (int rows = 2; rows <= 9; ++rows) {
    for (int cols = 2; cols <= 9; cols += 3) {
      Points p(rows * cols, 2);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
          p(r * cols + c, 0) = c + 0.5 * (r % 2), p(r * cols + c, 1) = r * std::sqrt(3.0) / 2.0;
      const EdgeList got = to_list(gabriel_graph(p));
      ASSERT_EQ(got, brute_gabriel(p));
      // (cols - 1) per row + 2 cols - 1 between consecutive rows.
      ASSERT_EQ(got.size(),
                static_cast<std::size_t>(rows * (cols - 1) + (rows - 1) * (2 * cols - 1)));
      const Body body = build_body(p, {}, {}, {});
      ASSERT_EQ(body.region_count(), 2 * (rows - 1) * (cols - 1));
      for (int r = 0; r < body.region_count(); ++r) {
        ASSERT_EQ(body.regions[static_cast<std::size_t>(r)].size(), 3U);
        ASSERT_NEAR(body.rest_areas(r), std::sqrt(3.0) / 4.0, 1e-12);
      }
      check_body_invariants(body, p);
    }
  }
}

TEST(BodyGabriel, IntegerPointsOnACircleGiveTheCycle) {
  // Integer points on circles of radius 5, 25 and 65: exactly cocircular, so every diameter has
  // other points exactly on its diametral circle, and must be dropped.
  for (const int radius : {5, 25, 65}) {
    std::vector<std::pair<double, double>> xy;
    for (int x = -radius; x <= radius; ++x)
      for (int y = -radius; y <= radius; ++y)
        if (x * x + y * y == radius * radius) xy.emplace_back(x, y);
    std::sort(xy.begin(), xy.end(), [](auto a, auto b) {
      return std::atan2(a.second, a.first) < std::atan2(b.second, b.first);
    });
    const Points p = make_points(xy);
    const int k = static_cast<int>(xy.size());
    EdgeList cycle;
    for (int i = 0; i < k; ++i)
      cycle.emplace_back(std::min(i, (i + 1) % k), std::max(i, (i + 1) % k));
    std::sort(cycle.begin(), cycle.end());
    ASSERT_EQ(to_list(gabriel_graph(p)), cycle) << "radius " << radius;
    ASSERT_EQ(brute_gabriel(p), cycle);
    const Body body = build_body(p, {}, {}, {});
    ASSERT_EQ(body.region_count(), 1);
    std::vector<int> ccw(static_cast<std::size_t>(k));
    std::iota(ccw.begin(), ccw.end(), 0);
    ASSERT_EQ(body.regions[0], ccw);
    ASSERT_EQ(body.skin_loops[0], ccw);
    check_body_invariants(body, p);
  }
}

TEST(BodyGabriel, RegularPolygonsAndWheels) {
  for (int k = 3; k <= 64; ++k) {
    Points ring(k, 2), wheel(k + 1, 2);
    for (int i = 0; i < k; ++i) {
      const double t = 2.0 * M_PI * i / k;
      ring(i, 0) = wheel(i, 0) = 3.0 * std::cos(t);
      ring(i, 1) = wheel(i, 1) = 3.0 * std::sin(t);
    }
    wheel(k, 0) = wheel(k, 1) = 0.0;
    if (k % 2 == 1) {  // even k has exact diameters: their fate depends on rounding of cos/sin
      ASSERT_EQ(to_list(gabriel_graph(ring)), brute_gabriel(ring)) << "k=" << k;
      ASSERT_EQ(gabriel_graph(ring).rows(), k);
    }
    const EdgeList w = to_list(gabriel_graph(wheel));
    ASSERT_EQ(w, brute_gabriel(wheel)) << "k=" << k;
    // Spokes always; rim edges only when the centre is outside their disc (k >= 5).
    if (k != 4) {  // k = 4: the centre is on the rim edges' circles, so rounding of cos/sin decides
      ASSERT_EQ(w.size(), static_cast<std::size_t>(k >= 5 ? 2 * k : k)) << "k=" << k;
    }
    check_body_invariants(build_body(wheel, {}, {}, {}), wheel);
  }
}

TEST(BodyGabriel, NearCollinearSets) {
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    Rng rng(seed + 5);
    const int n = 3 + static_cast<int>(rng.below(60));
    const double noise = std::pow(10.0, -static_cast<double>(rng.below(10)) - 3.0);
    const double angle = rng.uniform(0.0, M_PI);
    Points p(n, 2);
    for (int i = 0; i < n; ++i) {
      const double s = rng.uniform(-20.0, 20.0), t = rng.uniform(-noise, noise);
      p(i, 0) = s * std::cos(angle) - t * std::sin(angle);
      p(i, 1) = s * std::sin(angle) + t * std::cos(angle);
    }
    ASSERT_EQ(to_list(gabriel_graph(p)), brute_gabriel(p)) << "seed=" << seed;
    check_body_invariants(build_body(p, {}, {}, {}), p);
  }
}

TEST(BodyGabriel, IndependentOfInputOrder) {
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const Points p = random_points(80, seed + 31);
    std::vector<int> perm(80);
    std::iota(perm.begin(), perm.end(), 0);
    Rng rng(seed);
    for (int i = 79; i > 0; --i)
      std::swap(perm[static_cast<std::size_t>(i)],
                perm[rng.below(static_cast<std::uint64_t>(i + 1))]);
    Points q(80, 2);
    // q[i] = p[perm[i]]
    for (int i = 0; i < 80; ++i) q.row(i) = p.row(perm[static_cast<std::size_t>(i)]);
    EdgeList mapped;
    for (const auto& [a, b] : to_list(gabriel_graph(q))) {
      const int x = perm[static_cast<std::size_t>(a)], y = perm[static_cast<std::size_t>(b)];
      mapped.emplace_back(std::min(x, y), std::max(x, y));
    }
    std::sort(mapped.begin(), mapped.end());
    ASSERT_EQ(mapped, to_list(gabriel_graph(p)));
  }
}

TEST(BodyGabriel, IsASubgraphOfDelaunay) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const Points p = random_points(50, seed + 77);
    const EdgeList d = to_list(delaunay_edges(p));
    const EdgeList g = to_list(gabriel_graph(p));
    ASSERT_TRUE(sorted_and_ordered(delaunay_edges(p)));
    ASSERT_TRUE(std::includes(d.begin(), d.end(), g.begin(), g.end()));
    // A triangulation of n points with h on the hull has 3n - 3 - h edges: at most 3n - 6.
    ASSERT_LE(d.size(), 3U * 50 - 6);
    ASSERT_GE(d.size(), 2U * 50 - 3);
  }
}

// ---------------------------------------------------------------- regions and skin

TEST(BodyRegions, InvariantsOnRandomSets) {
  for (int n = 3; n <= 120; n += 3) {
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
      const Points p = random_points(n, 500 + 1000 * static_cast<std::uint64_t>(n) + seed);
      check_body_invariants(build_body(p, {}, {}, {}), p);
      const Points q =
          random_lattice_points(std::min(n, 40), 9, seed + static_cast<std::uint64_t>(n));
      check_body_invariants(build_body(q, {}, {}, {}), q);
    }
  }
}

TEST(BodyRegions, StarIsATreeWalkedTwice) {
  // The square's corners lie on the diametral circles of its sides, so only the spokes remain.
  const Points p = make_points({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}});
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(to_list(body.springs), (EdgeList{{0, 4}, {1, 4}, {2, 4}, {3, 4}}));
  EXPECT_TRUE(body.regions.empty());
  EXPECT_EQ(to_list(body.skin), to_list(body.springs));
  ASSERT_EQ(body.skin_loops.size(), 1U);
  EXPECT_EQ(body.skin_loops[0], (std::vector<int>{0, 4, 1, 4, 2, 4, 3, 4}));
  check_body_invariants(body, p);
}

TEST(BodyRegions, TriangleWithDanglingEdge) {
  const Points p = make_points({{0, 0}, {1, 0}, {0.5, 0.9}, {3, 0}});
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(to_list(body.springs), (EdgeList{{0, 1}, {0, 2}, {1, 2}, {1, 3}}));
  ASSERT_EQ(body.regions.size(), 1U);
  EXPECT_EQ(body.regions[0], (std::vector<int>{0, 1, 2}));
  EXPECT_NEAR(body.rest_areas(0), 0.45, 1e-15);
  EXPECT_EQ(to_list(body.skin), to_list(body.springs));
  EXPECT_EQ(body.skin_loops[0], (std::vector<int>{0, 1, 3, 1, 2}));
  check_body_invariants(body, p);
}

TEST(BodyRegions, BridgeInsideARegionIsWalkedTwiceByIt) {
  // A 10 x 12 rectangular ring of 44 points (spacing 1) whose bottom-middle vertex 5 is pushed
  // inwards (reflex), plus point 44 above it: 44's only Gabriel neighbour is 5, so edge 5-44 hangs
  // into the ring's face.
  std::vector<std::pair<double, double>> xy;
  for (int i = 0; i < 10; ++i) xy.emplace_back(i, i == 5 ? 0.6 : 0.0);
  for (int i = 0; i < 12; ++i) xy.emplace_back(10, i);
  for (int i = 10; i > 0; --i) xy.emplace_back(i, 12);
  for (int i = 12; i > 0; --i) xy.emplace_back(0, i);
  xy.emplace_back(5.0, 2.0);
  const Points p = make_points(xy);
  const Body body = build_body(p, {}, {}, {});
  ASSERT_EQ(body.spring_count(), 45);
  ASSERT_EQ(body.region_count(), 1);
  std::vector<int> expected = {0, 1, 2, 3, 4, 5, 44, 5};
  for (int i = 6; i < 44; ++i) expected.push_back(i);
  EXPECT_EQ(body.regions[0], expected);
  EXPECT_EQ(body.skin.rows(), 44);  // the inner spike is not skin
  std::vector<int> ring(44);
  std::iota(ring.begin(), ring.end(), 0);
  EXPECT_EQ(body.skin_loops[0], ring);
  EXPECT_DOUBLE_EQ(body.rest_areas(0), 120.0 - 0.6);
  check_body_invariants(body, p);
}

TEST(BodyRegions, SliverRegionIsKept) {
  // Acute but very thin triangle: all three edges are Gabriel; area eps/2.
  for (const double eps : {1e-3, 1e-6, 1e-9}) {
    const Points p = make_points({{0, 0}, {0, eps}, {1, eps / 2}});
    BodyParams params;
    params.merge_distance = eps / 10;
    const Body body = build_body(p, {}, {}, {}, params);
    ASSERT_EQ(body.region_count(), 1);
    EXPECT_GT(body.rest_areas(0), 0.0);
    EXPECT_NEAR(body.rest_areas(0), eps / 2, 1e-12 * eps);
    check_body_invariants(body, p);
  }
}

TEST(BodyRegions, LargeBodyIsFast) {
  const Points p = random_points(20000, 3);
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(body.node_count() - body.spring_count() + body.region_count(), 1);
  double sum = body.rest_areas.sum();
  EXPECT_NEAR(sum, polygon_area(p, body.skin_loops[0]), 1e-9 * sum);
}

// ---------------------------------------------------------------- oscillators and embryo

TEST(BodyOscillators, CopiedOrZero) {
  const Points p = make_points({{0, 0}, {1, 0}, {0.5, 0.9}});
  const Vector a = Vector::LinSpaced(3, 0.0, 0.2), f = Vector::Constant(3, 2.0),
               ph = Vector::LinSpaced(3, 0, 6);
  const Body body = build_body(p, a, f, ph);
  EXPECT_EQ(body.amplitude, a);
  EXPECT_EQ(body.frequency, f);
  EXPECT_EQ(body.phase, ph);
  const Body zeros = build_body(p, {}, {}, {});
  EXPECT_EQ(zeros.amplitude, Vector::Zero(3));
  EXPECT_EQ(zeros.frequency, Vector::Zero(3));
  EXPECT_EQ(zeros.phase, Vector::Zero(3));
}

TEST(BodyOscillators, WrongLengthOrNonFiniteIsRejected) {
  const Points p = make_points({{0, 0}, {1, 0}, {0.5, 0.9}});
  try {
    (void)build_body(p, Vector::Zero(2), {}, {});
    FAIL() << "expected GeometryError";
  } catch (const GeometryError& e) {
    EXPECT_STREQ(e.what(),
                 "build_body: amplitude has 2 entries, expected 3 (one per node) or 0 (all zero)");
  }
  Vector ph = Vector::Zero(3);
  ph(1) = std::nan("");
  try {
    (void)build_body(p, {}, {}, ph);
    FAIL() << "expected GeometryError";
  } catch (const GeometryError& e) {
    EXPECT_STREQ(e.what(), "build_body: phase[1] = nan is not finite");
  }
}

TEST(BodyOscillators, FromEmbryo) {
  Embryo embryo;
  embryo.positions = make_points({{0, 0}, {1, 0}, {0.5, 0.9}, {3, 0}});
  embryo.radii = Vector::Constant(4, 0.5);
  embryo.amplitude = Vector::Constant(4, 0.1);
  embryo.frequency = Vector::Constant(4, 3.0);
  embryo.phase = Vector::LinSpaced(4, 0.0, 3.0);
  const Body body = build_body(embryo);
  EXPECT_EQ(to_list(body.springs), (EdgeList{{0, 1}, {0, 2}, {1, 2}, {1, 3}}));
  EXPECT_EQ(body.amplitude, embryo.amplitude);
  EXPECT_EQ(body.frequency, embryo.frequency);
  EXPECT_EQ(body.phase, embryo.phase);
  check_body_invariants(body, embryo.positions);
}

// ---------------------------------------------------------------- degenerate input

template <class F>
std::string geometry_error(F&& f) {
  try {
    f();
  } catch (const GeometryError& e) {
    return e.what();
  }
  return "<no GeometryError>";
}

TEST(BodyDegenerate, NoPoints) {
  const Points p(0, 2);
  EXPECT_EQ(gabriel_graph(p).rows(), 0);
  EXPECT_EQ(delaunay_edges(p).rows(), 0);
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(body.node_count(), 0);
  EXPECT_EQ(body.spring_count(), 0);
  EXPECT_EQ(body.rest_lengths.size(), 0);
  EXPECT_TRUE(body.regions.empty());
  EXPECT_EQ(body.rest_areas.size(), 0);
  EXPECT_EQ(body.skin.rows(), 0);
  EXPECT_TRUE(body.skin_loops.empty());
  EXPECT_EQ(body.amplitude.size(), 0);
}

TEST(BodyDegenerate, OnePoint) {
  const Points p = make_points({{2, 3}});
  EXPECT_EQ(gabriel_graph(p).rows(), 0);
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(body.node_count(), 1);
  EXPECT_EQ(body.spring_count(), 0);
  EXPECT_TRUE(body.regions.empty());
  EXPECT_EQ(body.skin.rows(), 0);
  EXPECT_TRUE(body.skin_loops.empty());
  EXPECT_EQ(body.amplitude, Vector::Zero(1));
  check_body_invariants(body, p);
}

TEST(BodyDegenerate, TwoPoints) {
  const Points p = make_points({{1, 1}, {-2, 5}});
  EXPECT_EQ(to_list(gabriel_graph(p)), (EdgeList{{0, 1}}));
  const Body body = build_body(p, {}, {}, {});
  EXPECT_EQ(body.spring_count(), 1);
  EXPECT_DOUBLE_EQ(body.rest_lengths(0), 5.0);
  EXPECT_TRUE(body.regions.empty());
  EXPECT_EQ(to_list(body.skin), (EdgeList{{0, 1}}));
  ASSERT_EQ(body.skin_loops.size(), 1U);
  EXPECT_EQ(body.skin_loops[0], (std::vector<int>{0, 1}));
  check_body_invariants(body, p);
}

TEST(BodyDegenerate, CollinearGivesAChain) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Rng rng(seed);
    const int n = 3 + static_cast<int>(rng.below(40));
    // Exactly collinear integer points on a random lattice direction, in shuffled order.
    const int dx = static_cast<int>(rng.integer(-3, 3)),
              dy = seed % 4 == 0 ? 0 : static_cast<int>(rng.integer(1, 3));
    std::vector<int> steps(static_cast<std::size_t>(n));
    std::iota(steps.begin(), steps.end(), -n / 2);
    for (int i = n - 1; i > 0; --i)
      std::swap(steps[static_cast<std::size_t>(i)],
                steps[rng.below(static_cast<std::uint64_t>(i + 1))]);
    Points p(n, 2);
    for (int i = 0; i < n; ++i) {
      p(i, 0) = 4 + (dx == 0 && dy == 0 ? 1 : dx) * steps[static_cast<std::size_t>(i)];
      p(i, 1) = -1 + dy * steps[static_cast<std::size_t>(i)];
    }
    // Chain: consecutive steps.
    std::vector<int> at(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      at[static_cast<std::size_t>(steps[static_cast<std::size_t>(i)] + n / 2)] = i;
    EdgeList chain;
    for (int s = 0; s + 1 < n; ++s) {
      const int a = at[static_cast<std::size_t>(s)], b = at[static_cast<std::size_t>(s + 1)];
      chain.emplace_back(std::min(a, b), std::max(a, b));
    }
    std::sort(chain.begin(), chain.end());
    ASSERT_EQ(to_list(gabriel_graph(p)), chain) << "seed=" << seed;
    ASSERT_EQ(to_list(delaunay_edges(p)), chain);
    const Body body = build_body(p, {}, {}, {});
    EXPECT_TRUE(body.regions.empty());
    EXPECT_EQ(to_list(body.skin), chain);
    ASSERT_EQ(body.skin_loops.size(), 1U);
    EXPECT_EQ(body.skin_loops[0].size(), static_cast<std::size_t>(2 * (n - 1)));
    check_body_invariants(body, p);
  }
}

TEST(BodyDegenerate, DuplicatePointsAreRejected) {
  const Points p = make_points({{0, 0}, {1, 0}, {0.5, 1}, {3, 3}, {1, 0}, {0.5, 1}});
  EXPECT_EQ(geometry_error([&] { (void)gabriel_graph(p); }),
            "gabriel_graph: points 1 and 4 coincide at (1, 0) (distance 0); duplicate cell centres "
            "are rejected");
  EXPECT_EQ(geometry_error([&] { (void)build_body(p, {}, {}, {}); }),
            "build_body: points 1 and 4 coincide at (1, 0) (distance 0); duplicate cell centres "
            "are rejected");
  // Duplicates are rejected even with merge_distance = 0.
  BodyParams params;
  params.merge_distance = 0.0;
  EXPECT_EQ(geometry_error([&] { (void)delaunay_edges(p, params); }),
            "delaunay_edges: points 1 and 4 coincide at (1, 0) (distance 0); duplicate cell "
            "centres are rejected");
  // Collinear duplicates too (CGAL would merge them into a dimension-1 triangulation).
  const Points q = make_points({{0, 0}, {0, 0}});
  EXPECT_EQ(geometry_error([&] { (void)gabriel_graph(q); }),
            "gabriel_graph: points 0 and 1 coincide at (0, 0) (distance 0); duplicate cell centres "
            "are rejected");
}

TEST(BodyDegenerate, NearlyCoincidentPointsAreRejected) {
  const Points p = make_points({{1, 0}, {0, 1}, {0, 0}, {2.5e-7, 0}, {3, 3}});
  EXPECT_EQ(geometry_error([&] { (void)build_body(p, {}, {}, {}); }),
            "build_body: points 2 and 3 are 2.5e-07 apart, closer than merge_distance = 1e-06; "
            "near-coincident cell "
            "centres are rejected");
  BodyParams params;
  params.merge_distance = 1e-7;  // now they are far enough apart
  const Body body = build_body(p, {}, {}, {}, params);
  check_body_invariants(body, p);
  params.merge_distance = 1.5;  // the closest pair is reported
  EXPECT_EQ(geometry_error([&] { (void)gabriel_graph(p, params); }),
            "gabriel_graph: points 2 and 3 are 2.5e-07 apart, closer than merge_distance = 1.5; "
            "near-coincident cell "
            "centres are rejected");
  // Collinear input is checked too.
  const Points q = make_points({{0, 0}, {1, 0}, {1.0000001, 0}});
  EXPECT_NE(geometry_error([&] { (void)gabriel_graph(q); }).find("points 1 and 2 are "),
            std::string::npos);
}

TEST(BodyDegenerate, NonFiniteOrHugeCoordinatesAreRejected) {
  Points p = make_points({{0, 0}, {1, 0}, {0.5, 1}});
  p(1, 1) = std::nan("");
  EXPECT_EQ(geometry_error([&] { (void)gabriel_graph(p); }),
            "gabriel_graph: point 1 has a non-finite coordinate y = nan");
  p(1, 1) = 0;
  p(2, 0) = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(geometry_error([&] { (void)build_body(p, {}, {}, {}); }),
            "build_body: point 2 has a non-finite coordinate x = -inf");
  p(2, 0) = 2.5e6;
  EXPECT_EQ(geometry_error([&] { (void)build_body(p, {}, {}, {}); }),
            "build_body: point 2 has coordinate x = 2500000, beyond max_coordinate = 1000000");
  BodyParams params;
  params.max_coordinate = 1e7;
  const Body body = build_body(p, {}, {}, {}, params);  // now accepted
  check_body_invariants(body, p);
}

TEST(BodyDegenerate, BadParamsAreConfigErrors) {
  const Points p = make_points({{0, 0}, {1, 0}, {0.5, 1}});
  BodyParams params;
  params.merge_distance = -1.0;
  EXPECT_THROW((void)gabriel_graph(p, params), ConfigError);
  params.merge_distance = 0.0;
  params.max_coordinate = 0.0;
  EXPECT_THROW((void)gabriel_graph(p, params), ConfigError);
}

}  // namespace
}  // namespace animat
