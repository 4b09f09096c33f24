#pragma once
// Point sets and edge lists shared by the body tests (test_body.cpp, test_body_graphs.cpp).
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/random.hpp"

namespace animat::test {

using Edge = std::pair<int, int>;
using EdgeList = std::vector<Edge>;

inline Points make_points(const std::vector<std::pair<double, double>>& xy) {
  Points p(static_cast<Eigen::Index>(xy.size()), 2);
  for (std::size_t i = 0; i < xy.size(); ++i) {
    p(static_cast<Eigen::Index>(i), 0) = xy[i].first;
    p(static_cast<Eigen::Index>(i), 1) = xy[i].second;
  }
  return p;
}

inline EdgeList to_list(const IndexPairs& pairs) {
  EdgeList out;
  for (Eigen::Index r = 0; r < pairs.rows(); ++r) out.emplace_back(pairs(r, 0), pairs(r, 1));
  return out;
}

/// n points uniform in [lo, hi)^2.
inline Points random_points(int n, std::uint64_t seed, double lo = -10.0, double hi = 10.0) {
  Rng rng(seed);
  Points p(n, 2);
  for (int i = 0; i < n; ++i) {
    p(i, 0) = rng.uniform(lo, hi);
    p(i, 1) = rng.uniform(lo, hi);
  }
  return p;
}

/// n distinct points of the integer lattice [0, side)^2: many cocircular and collinear quadruples.
inline Points random_lattice_points(int n, int side, std::uint64_t seed) {
  Rng rng(seed);
  std::set<std::pair<int, int>> used;
  Points p(n, 2);
  for (int i = 0; i < n;) {
    const int x = static_cast<int>(rng.below(static_cast<std::uint64_t>(side)));
    const int y = static_cast<int>(rng.below(static_cast<std::uint64_t>(side)));
    if (!used.insert({x, y}).second) continue;
    p(i, 0) = x;
    p(i, 1) = y;
    ++i;
  }
  return p;
}

}  // namespace animat::test
