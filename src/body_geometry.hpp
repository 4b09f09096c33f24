#pragma once
// Private interface between body.cpp and body_geometry.cpp, the only translation unit that
// includes CGAL (one CGAL TU costs ~6 s and ~650 MB to compile). Plain types only: no CGAL here.
#include <utility>
#include <vector>

#include "animat/types.hpp"

namespace animat::detail {

/// Which planar graph of the centres becomes the body (BodyParams::graph, docs/model.md).
enum class GraphKind { gabriel, distance, alpha_shape };

struct GraphSpec {
  GraphKind kind = GraphKind::gabriel;
  double distance_threshold = 0.0;  ///< distance: in units of the mean nearest-neighbour distance
  double alpha = 0.0;               ///< alpha_shape: circumradius, same unit
};

/// The Delaunay triangulation, the Gabriel graph and the body's graph of a point set, plus the body
/// graph's rotation system (neighbours of each vertex in counter-clockwise order), which is all the
/// combinatorial information needed to walk the faces of the planar body graph.
struct GabrielGeometry {
  /// affine dimension of the input: -1 (empty), 0 (one point), 1 (collinear), 2
  int dimension = -1;
  IndexPairs delaunay;  ///< Delaunay edges (i < j), sorted lexicographically
  IndexPairs gabriel;   ///< Gabriel edges (i < j), sorted lexicographically
  IndexPairs edges;     ///< the body graph's edges (= gabriel for GraphKind::gabriel)
  /// rotation[v] = body-graph neighbours of v in counter-clockwise order around v (exact: it is the
  /// restriction of the Delaunay triangulation's CCW vertex circulator), any starting neighbour.
  std::vector<std::vector<int>> rotation;
  /// A half-edge (outer_from -> outer_to) of the body graph whose left side is the unbounded
  /// face; -1 when there are no edges.
  int outer_from = -1;
  int outer_to = -1;
  /// alpha_shape only: half-edges (u, v) of the body graph whose left side is a finite Delaunay
  /// triangle outside the alpha complex, i.e. whose face is a hole. Sorted.
  std::vector<std::pair<int, int>> hole_halfedges;
  /// Mean nearest-neighbour distance of the points (0 for n <= 1): the unit of the graph lengths.
  /// Not computed (0) for GraphKind::gabriel with 3 or more non-collinear points.
  double scale = 0.0;
};

/// Computes the Delaunay triangulation (CGAL, Exact_predicates_inexact_constructions_kernel), its
/// Gabriel subgraph (closed diametral disc) and the body graph of `spec`. Preconditions, checked
/// by the caller: every coordinate is finite and no two points coincide. Throws GeometryError if
/// CGAL merged points anyway. O(n log n) for the Gabriel graph.
[[nodiscard]] GabrielGeometry compute_gabriel_geometry(const Points& points,
                                                       const GraphSpec& spec = {});

}  // namespace animat::detail
