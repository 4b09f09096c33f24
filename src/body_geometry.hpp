#pragma once
// Private interface between body.cpp and body_geometry.cpp, the only translation unit that
// includes CGAL (one CGAL TU costs ~6 s and ~650 MB to compile). Plain types only: no CGAL here.
#include <vector>

#include "animat/types.hpp"

namespace animat::detail {

/// The Delaunay triangulation and the Gabriel graph of a point set, plus the Gabriel graph's
/// rotation system (neighbours of each vertex in counter-clockwise order), which is all the
/// combinatorial information needed to walk the faces of the planar Gabriel graph.
struct GabrielGeometry {
  int dimension = -1;  ///< affine dimension of the input: -1 (empty), 0 (one point), 1 (collinear), 2
  IndexPairs delaunay;  ///< Delaunay edges (i < j), sorted lexicographically
  IndexPairs gabriel;   ///< Gabriel edges (i < j), sorted lexicographically
  /// rotation[v] = Gabriel neighbours of v in counter-clockwise order around v (exact: it is the
  /// restriction of the Delaunay triangulation's CCW vertex circulator), any starting neighbour.
  std::vector<std::vector<int>> rotation;
  /// A half-edge (outer_from -> outer_to) of the Gabriel graph whose left side is the unbounded
  /// face; -1 when there are no edges.
  int outer_from = -1;
  int outer_to = -1;
};

/// Computes the Delaunay triangulation (CGAL, Exact_predicates_inexact_constructions_kernel) and
/// its Gabriel subgraph (closed diametral disc). Preconditions, checked by the caller: every
/// coordinate is finite and no two points coincide. Throws GeometryError if CGAL merged points
/// anyway. O(n log n).
[[nodiscard]] GabrielGeometry compute_gabriel_geometry(const Points& points);

}  // namespace animat::detail
