// From cell centres to a spring-mass body (paper §3, Fig. 3). The geometry (Delaunay, Gabriel,
// rotation system) comes from body_geometry.cpp, the only CGAL translation unit; this file
// validates the input and walks the faces of the planar Gabriel graph.
#include "animat/body.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <numeric>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/shape.hpp"
#include "body_geometry.hpp"

namespace animat {
namespace {

using std::size_t;

void check_params(const BodyParams& params, std::string_view who) {
  if (!(params.merge_distance >= 0.0) || !std::isfinite(params.merge_distance)) {
    throw ConfigError(fmt::format("{}: body.merge_distance must be a finite number >= 0, got {}",
                                  who, params.merge_distance));
  }
  if (!(params.max_coordinate > 0.0)) {
    throw ConfigError(
        fmt::format("{}: body.max_coordinate must be > 0, got {}", who, params.max_coordinate));
  }
  if (std::find(std::begin(kBodyGraphNames), std::end(kBodyGraphNames), params.graph) ==
      std::end(kBodyGraphNames)) {
    throw ConfigError(
        fmt::format("{}: body.graph must be one of gabriel, distance, alpha_shape, got \"{}\"", who,
                    params.graph));
  }
  if (!(params.distance_threshold > 0.0) || !(params.distance_threshold <= kMaxLength)) {
    throw ConfigError(fmt::format("{}: body.distance_threshold must be in (0, {}], got {}", who,
                                  kMaxLength, params.distance_threshold));
  }
  if (!(params.alpha > 0.0) || !(params.alpha <= kMaxLength)) {
    throw ConfigError(
        fmt::format("{}: body.alpha must be in (0, {}], got {}", who, kMaxLength, params.alpha));
  }
}

detail::GraphSpec graph_spec(const BodyParams& params) {
  detail::GraphSpec spec;
  spec.kind = params.graph == "distance"      ? detail::GraphKind::distance
              : params.graph == "alpha_shape" ? detail::GraphKind::alpha_shape
                                              : detail::GraphKind::gabriel;
  spec.distance_threshold = params.distance_threshold;
  spec.alpha = params.alpha;
  return spec;
}

/// Finite, in range, and no two points at exactly the same place. O(n log n).
void check_points(const Points& points, const BodyParams& params, std::string_view who) {
  check_params(params, who);
  const int n = static_cast<int>(points.rows());
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 2; ++c) {
      const double x = points(i, c);
      const char axis = c == 0 ? 'x' : 'y';
      if (!std::isfinite(x)) {
        throw GeometryError(
            fmt::format("{}: point {} has a non-finite coordinate {} = {}", who, i, axis, x));
      }
      if (std::abs(x) > params.max_coordinate) {
        throw GeometryError(
            fmt::format("{}: point {} has coordinate {} = {}, beyond max_coordinate = {}", who, i,
                        axis, x, params.max_coordinate));
      }
    }
  }
  // Exact duplicates: CGAL would merge them silently, so find them before triangulating.
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (points(a, 0) != points(b, 0)) return points(a, 0) < points(b, 0);
    if (points(a, 1) != points(b, 1)) return points(a, 1) < points(b, 1);
    return a < b;
  });
  std::pair<int, int> first{-1, -1};
  for (int k = 0; k + 1 < n; ++k) {
    const int a = order[static_cast<size_t>(k)], b = order[static_cast<size_t>(k + 1)];
    if (points(a, 0) == points(b, 0) && points(a, 1) == points(b, 1)) {
      // Within a run of equal points the indices are ascending, so (a, b) with a < b.
      if (first.first < 0 || std::pair{a, b} < first) first = {a, b};
    }
  }
  if (first.first >= 0) {
    throw GeometryError(fmt::format(
        "{}: points {} and {} coincide at ({}, {}) (distance 0); duplicate cell centres "
        "are rejected",
        who, first.first, first.second, points(first.first, 0), points(first.first, 1)));
  }
}

double distance(const Points& p, int a, int b) {
  return std::hypot(p(b, 0) - p(a, 0), p(b, 1) - p(a, 1));
}

/// The closest pair of points is a Delaunay edge (every point's nearest neighbour is a Delaunay
/// neighbour), so checking the Delaunay edges finds every point closer than merge_distance to
/// another one. Reports the closest such pair (lowest indices on ties).
void check_merge_distance(const Points& points, const IndexPairs& delaunay,
                          const BodyParams& params, std::string_view who) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (Eigen::Index e = 0; e < delaunay.rows(); ++e) {
    const double d = distance(points, delaunay(e, 0), delaunay(e, 1));
    if (d < params.merge_distance && d < best_d) {
      best = static_cast<int>(e);
      best_d = d;
    }
  }
  if (best >= 0) {
    throw GeometryError(
        fmt::format("{}: points {} and {} are {} apart, closer than merge_distance = {}; "
                    "near-coincident cell centres are rejected",
                    who, delaunay(best, 0), delaunay(best, 1), best_d, params.merge_distance));
  }
}

detail::GabrielGeometry checked_geometry(const Points& points, const BodyParams& params,
                                         std::string_view who, bool body_graph = false) {
  check_points(points, params, who);
  detail::GabrielGeometry g = detail::compute_gabriel_geometry(
      points, body_graph ? graph_spec(params) : detail::GraphSpec{});
  check_merge_distance(points, g.delaunay, params, who);
  return g;
}

/// Rotates a closed walk so that it starts with its lexicographically smallest half-edge
/// (walk[k], walk[k+1]). Each half-edge occurs once in a face walk, so the start is unique.
void canonical_start(std::vector<int>& walk) {
  const size_t k = walk.size();
  if (k < 2) return;
  size_t best = 0;
  for (size_t i = 1; i < k; ++i) {
    const std::pair a{walk[i], walk[(i + 1) % k]};
    const std::pair b{walk[best], walk[(best + 1) % k]};
    if (a < b) best = i;
  }
  std::rotate(walk.begin(), walk.begin() + static_cast<std::ptrdiff_t>(best), walk.end());
}

Vector oscillator(const Vector& v, int n, std::string_view name, std::string_view who) {
  if (v.size() == 0) return Vector::Zero(n);
  if (v.size() != n) {
    throw GeometryError(
        fmt::format("{}: {} has {} entries, expected {} (one per node) or 0 (all zero)", who, name,
                    v.size(), n));
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v(i)))
      throw GeometryError(fmt::format("{}: {}[{}] = {} is not finite", who, name, i, v(i)));
  }
  return v;
}

}  // namespace

double polygon_area(const Points& positions, const std::vector<int>& loop) {
  const size_t k = loop.size();
  if (k < 3) return 0.0;
  // Shoelace relative to the first vertex: fewer cancellations far from the origin.
  const double x0 = positions(loop[0], 0), y0 = positions(loop[0], 1);
  double twice = 0.0;
  for (size_t i = 1; i + 1 < k; ++i) {
    const double ax = positions(loop[i], 0) - x0, ay = positions(loop[i], 1) - y0;
    const double bx = positions(loop[i + 1], 0) - x0, by = positions(loop[i + 1], 1) - y0;
    twice += ax * by - ay * bx;
  }
  return 0.5 * twice;
}

IndexPairs delaunay_edges(const Points& points, const BodyParams& params) {
  return checked_geometry(points, params, "delaunay_edges").delaunay;
}

IndexPairs gabriel_graph(const Points& points, const BodyParams& params) {
  return checked_geometry(points, params, "gabriel_graph").gabriel;
}

Body build_body(const Points& positions, const Vector& amplitude, const Vector& frequency,
                const Vector& phase, const BodyParams& params) {
  constexpr std::string_view who = "build_body";
  const int n = static_cast<int>(positions.rows());
  const detail::GabrielGeometry g = checked_geometry(positions, params, who, true);
  Body body;
  body.amplitude = oscillator(amplitude, n, "amplitude", who);
  body.frequency = oscillator(frequency, n, "frequency", who);
  body.phase = oscillator(phase, n, "phase", who);
  body.positions = positions;
  body.springs = g.edges;
  const Eigen::Index m = body.springs.rows();
  body.rest_lengths.resize(m);
  for (Eigen::Index e = 0; e < m; ++e)
    body.rest_lengths(e) = distance(positions, body.springs(e, 0), body.springs(e, 1));
  body.skin.resize(0, 2);
  body.rest_areas.resize(0);
  if (m == 0) return body;

  // Half-edge structure from the rotation system. Half-edge h = (from[h] -> to[h]); the out-edges
  // of v are first[v] .. first[v+1]-1, in CCW order around v.
  std::vector<int> first(static_cast<size_t>(n) + 1, 0);
  for (int v = 0; v < n; ++v)
    first[static_cast<size_t>(v) + 1] =
        first[static_cast<size_t>(v)] + static_cast<int>(g.rotation[static_cast<size_t>(v)].size());
  const int halfedges = first[static_cast<size_t>(n)];
  std::vector<int> from(static_cast<size_t>(halfedges)), to(static_cast<size_t>(halfedges));
  for (int v = 0; v < n; ++v) {
    const auto& rot = g.rotation[static_cast<size_t>(v)];
    for (size_t k = 0; k < rot.size(); ++k) {
      from[static_cast<size_t>(first[static_cast<size_t>(v)]) + k] = v;
      to[static_cast<size_t>(first[static_cast<size_t>(v)]) + k] = rot[k];
    }
  }
  // twin[h]: the half-edge (to[h] -> from[h]), found by binary search over (from, to)-sorted ids.
  std::vector<int> by_key(static_cast<size_t>(halfedges));
  std::iota(by_key.begin(), by_key.end(), 0);
  const auto key = [&](int h) {
    return std::pair{from[static_cast<size_t>(h)], to[static_cast<size_t>(h)]};
  };
  std::sort(by_key.begin(), by_key.end(), [&](int a, int b) { return key(a) < key(b); });
  const auto find_halfedge = [&](int u, int v) {
    const auto it =
        std::lower_bound(by_key.begin(), by_key.end(), std::pair{u, v},
                         [&](int h, const std::pair<int, int>& k) { return key(h) < k; });
    return *it;  // present: the rotation system is symmetric
  };
  // next(u -> v) = (v -> w), w = the neighbour of v just before u in CCW order around v (the next
  // one clockwise). This walks each face with the face on its left: bounded faces CCW, the outer
  // face CW.
  std::vector<int> next(static_cast<size_t>(halfedges));
  for (int h = 0; h < halfedges; ++h) {
    const int t = find_halfedge(to[static_cast<size_t>(h)], from[static_cast<size_t>(h)]);
    const int v = from[static_cast<size_t>(t)];
    const int lo = first[static_cast<size_t>(v)], deg = first[static_cast<size_t>(v) + 1] - lo;
    next[static_cast<size_t>(h)] = lo + (t - lo + deg - 1) % deg;
  }

  const int outer_start = find_halfedge(g.outer_from, g.outer_to);
  std::vector<int> face_of(static_cast<size_t>(halfedges), -1);
  std::vector<int> outer_walk;
  std::vector<std::vector<int>> hole_walks;  // alpha_shape: bounded faces outside the alpha complex
  const auto is_hole_halfedge = [&](int h) {
    return std::binary_search(g.hole_halfedges.begin(), g.hole_halfedges.end(),
                              std::pair{from[static_cast<size_t>(h)], to[static_cast<size_t>(h)]});
  };
  for (int h0 = 0; h0 < halfedges; ++h0) {
    if (face_of[static_cast<size_t>(h0)] >= 0) continue;
    std::vector<int> walk;
    bool hole = false;
    int h = h0;
    do {
      face_of[static_cast<size_t>(h)] = h0;
      walk.push_back(from[static_cast<size_t>(h)]);
      hole = hole || (!g.hole_halfedges.empty() && is_hole_halfedge(h));
      h = next[static_cast<size_t>(h)];
    } while (h != h0);
    if (face_of[static_cast<size_t>(outer_start)] == h0) {
      outer_walk = std::move(walk);
    } else if (hole) {
      hole_walks.push_back(std::move(walk));
    } else {
      canonical_start(walk);
      body.regions.push_back(std::move(walk));
    }
  }
  std::sort(body.regions.begin(), body.regions.end());
  body.rest_areas.resize(static_cast<Eigen::Index>(body.regions.size()));
  for (size_t r = 0; r < body.regions.size(); ++r) {
    const double area = polygon_area(positions, body.regions[r]);
    if (!(area > 0.0) || !std::isfinite(area)) {
      // A bounded face is CCW by construction (exact predicates), so only round-off far beyond what
      // merge_distance allows can get here.
      throw GeometryError(
          fmt::format("{}: region {} (starting at point {}) has computed area {} <= 0; the points "
                      "are too close for double precision (raise merge_distance)",
                      who, r, body.regions[r][0], area));
    }
    body.rest_areas(static_cast<Eigen::Index>(r)) = area;
  }

  // Skin: the outer walk reversed, so that it goes CCW around the body (body on its left); then the
  // walk of each hole reversed (clockwise around the hole, body on its left), sorted.
  std::reverse(outer_walk.begin() + 1, outer_walk.end());
  canonical_start(outer_walk);
  for (auto& walk : hole_walks) {
    std::reverse(walk.begin() + 1, walk.end());
    canonical_start(walk);
  }
  std::sort(hole_walks.begin(), hole_walks.end());
  std::vector<std::pair<int, int>> skin_edges;
  const auto add_skin = [&](const std::vector<int>& loop) {
    for (size_t i = 0; i < loop.size(); ++i) {
      const int a = loop[i], b = loop[(i + 1) % loop.size()];
      skin_edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  };
  add_skin(outer_walk);
  for (const auto& loop : hole_walks) add_skin(loop);
  std::sort(skin_edges.begin(), skin_edges.end());
  skin_edges.erase(std::unique(skin_edges.begin(), skin_edges.end()), skin_edges.end());
  body.skin.resize(static_cast<Eigen::Index>(skin_edges.size()), 2);
  for (size_t k = 0; k < skin_edges.size(); ++k) {
    body.skin(static_cast<Eigen::Index>(k), 0) = skin_edges[k].first;
    body.skin(static_cast<Eigen::Index>(k), 1) = skin_edges[k].second;
  }
  body.skin_loops.push_back(std::move(outer_walk));
  for (auto& walk : hole_walks) body.skin_loops.push_back(std::move(walk));
  return body;
}

Body build_body(const Embryo& embryo, const BodyParams& params) {
  Body body =
      build_body(embryo.positions, embryo.amplitude, embryo.frequency, embryo.phase, params);
  if (embryo.stiffness.size() != 0) {
    body.stiffness = oscillator(embryo.stiffness, body.node_count(), "stiffness", "build_body");
    for (int i = 0; i < body.node_count(); ++i) {
      if (!(body.stiffness(i) > 0.0)) {
        throw GeometryError(
            fmt::format("build_body: stiffness[{}] = {} is not > 0", i, body.stiffness(i)));
      }
    }
  }
  return body;
}

double cell_spacing(const Points& positions) {
  const auto n = static_cast<std::size_t>(positions.rows());
  if (n < 2) return 1.0;
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const auto a = static_cast<Eigen::Index>(i), b = static_cast<Eigen::Index>(j);
      const double dx = positions(a, 0) - positions(b, 0), dy = positions(a, 1) - positions(b, 1);
      const double d = std::sqrt(dx * dx + dy * dy);
      nearest[i] = std::min(nearest[i], d);
      nearest[j] = std::min(nearest[j], d);
    }
  std::sort(nearest.begin(), nearest.end());
  const double s =
      n % 2 ? nearest[n / 2] : (nearest[n / 2 - 1] + nearest[n / 2]) / 2.0;  // numpy's median
  return s > 0.0 ? s : 1.0;
}

int morphology_kind(const Points& positions) {
  const auto n = static_cast<int>(positions.rows());
  if (n == 0) return 0;
  const double e = elongation(positions);
  int band = 0;
  double threshold = 1.5;  // 1.5^(band + 1), exact: 3^16 < 2^53
  while (band + 1 < kElongationBands && e >= threshold) {
    ++band;
    threshold *= 1.5;
  }
  return n * kElongationBands + band;
}

}  // namespace animat
