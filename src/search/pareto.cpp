// NSGA-II's pieces on plain values (search.hpp): dominance, the fast non-dominated sort, the
// crowding distance and the two-objective hypervolume, as animat.moo computes them.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "animat/errors.hpp"
#include "animat/search.hpp"

namespace animat {

bool dominates(std::span<const double> a, std::span<const double> b) {
  bool better = false;
  for (std::size_t j = 0; j < a.size(); ++j) {
    if (a[j] > b[j]) return false;
    if (a[j] < b[j]) better = true;
  }
  return better;
}

std::vector<std::vector<std::size_t>> non_dominated_sort(
    const std::vector<std::vector<double>>& points) {
  const std::size_t n = points.size();
  std::vector<std::vector<std::size_t>> beats(n);  // beats[i]: the rows i dominates
  std::vector<std::size_t> count(n, 0);            // how many rows dominate row i
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (i != j && dominates(points[i], points[j])) {
        beats[i].push_back(j);
        ++count[j];
      }
  std::vector<std::vector<std::size_t>> fronts;
  std::vector<std::size_t> current;
  for (std::size_t i = 0; i < n; ++i)
    if (count[i] == 0) current.push_back(i);
  while (!current.empty()) {
    fronts.push_back(current);
    std::vector<std::size_t> next;
    for (std::size_t i : current)
      for (std::size_t j : beats[i])
        if (--count[j] == 0) next.push_back(j);
    std::sort(next.begin(), next.end());
    current = std::move(next);
  }
  return fronts;
}

std::vector<double> crowding_distance(const std::vector<std::vector<double>>& points) {
  const std::size_t n = points.size();
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<double> d(n, 0.0);
  if (n <= 2) return std::vector<double>(n, inf);
  for (std::size_t j = 0; j < points[0].size(); ++j) {
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return points[a][j] < points[b][j]; });
    const double span = points[order.back()][j] - points[order.front()][j];
    if (span > 0 && std::isfinite(span))
      for (std::size_t k = 1; k + 1 < n; ++k)
        d[order[k]] += (points[order[k + 1]][j] - points[order[k - 1]][j]) / span;
    d[order.front()] = d[order.back()] = inf;
  }
  return d;
}

double hypervolume(const std::vector<std::vector<double>>& points,
                   std::span<const double> reference) {
  const std::size_t m = reference.size();
  if (m != 1 && m != 2) throw Error(fmt::format("hypervolume: one or two objectives, got {}", m));
  std::vector<std::vector<double>> p;
  for (const auto& x : points) {
    bool inside = true;
    for (std::size_t j = 0; j < m; ++j)
      inside = inside && std::isfinite(x[j]) && x[j] < reference[j];
    if (inside) p.push_back(x);
  }
  if (p.empty()) return 0.0;
  if (m == 1) {
    double lowest = p[0][0];
    for (const auto& x : p) lowest = std::min(lowest, x[0]);
    return reference[0] - lowest;
  }
  std::sort(p.begin(), p.end());  // by the first objective, then the second
  std::vector<double> terms;
  double top = reference[1];
  for (const auto& x : p)
    if (x[1] < top) {
      terms.push_back((reference[0] - x[0]) * (top - x[1]));
      top = x[1];
    }
  return exact_sum(terms);
}

}  // namespace animat
