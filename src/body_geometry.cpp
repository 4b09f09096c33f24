// The only translation unit that includes CGAL. It turns a validated point set into the Delaunay
// triangulation, the Gabriel graph, the body graph (Gabriel, distance or alpha shape) and its
// rotation system; body.cpp does the rest.
#include "body_geometry.hpp"

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "animat/errors.hpp"

namespace animat::detail {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;  // info = input index
using Fb = CGAL::Triangulation_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Delaunay = CGAL::Delaunay_triangulation_2<K, Tds>;
using Point = K::Point_2;
// The alpha shape's triangulation: same kernel and vertex info, with CGAL's alpha-shape bases.
using AVb = CGAL::Alpha_shape_vertex_base_2<K, Vb>;
using AFb = CGAL::Alpha_shape_face_base_2<K>;
using ATds = CGAL::Triangulation_data_structure_2<AVb, AFb>;
using ADelaunay = CGAL::Delaunay_triangulation_2<K, ATds>;
using AlphaShape = CGAL::Alpha_shape_2<ADelaunay>;

IndexPairs to_index_pairs(std::vector<std::pair<int, int>>& edges) {
  std::sort(edges.begin(), edges.end());
  IndexPairs out(static_cast<Eigen::Index>(edges.size()), 2);
  for (std::size_t k = 0; k < edges.size(); ++k) {
    out(static_cast<Eigen::Index>(k), 0) = edges[k].first;
    out(static_cast<Eigen::Index>(k), 1) = edges[k].second;
  }
  return out;
}

std::pair<int, int> ordered(int a, int b) { return a < b ? std::pair{a, b} : std::pair{b, a}; }

double point_distance(const Points& p, int a, int b) {
  return std::hypot(p(b, 0) - p(a, 0), p(b, 1) - p(a, 1));
}

double squared_distance(const Points& p, int a, int b) {
  const double dx = p(b, 0) - p(a, 0), dy = p(b, 1) - p(a, 1);
  return dx * dx + dy * dy;
}

/// Mean over the points (in index order) of the distance to the nearest other point. Every point's
/// nearest neighbour is a Delaunay neighbour, so the Delaunay edges suffice.
double mean_nearest_neighbour(const Points& points,
                              const std::vector<std::pair<int, int>>& delaunay) {
  const int n = static_cast<int>(points.rows());
  if (n <= 1) return 0.0;
  std::vector<double> nearest(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  for (const auto& [a, b] : delaunay) {
    const double d = point_distance(points, a, b);
    nearest[static_cast<std::size_t>(a)] = std::min(nearest[static_cast<std::size_t>(a)], d);
    nearest[static_cast<std::size_t>(b)] = std::min(nearest[static_cast<std::size_t>(b)], d);
  }
  double sum = 0.0;
  for (const double d : nearest) sum += d;
  return sum / n;
}

/// Relative neighbourhood graph test: no other point is strictly closer to both a and b than they
/// are to each other (open lune). O(n). Only called for Gabriel edges (the RNG is a subgraph).
bool relative_neighbours(const Points& points, int a, int b) {
  const int n = static_cast<int>(points.rows());
  const double d2 = squared_distance(points, a, b);
  for (int c = 0; c < n; ++c) {
    if (c == a || c == b) continue;
    if (squared_distance(points, a, c) < d2 && squared_distance(points, b, c) < d2) return false;
  }
  return true;
}

/// Collinear (or fewer than 3) points: the Delaunay "triangulation" is the chain of consecutive
/// points along the line, and so is the Gabriel graph (the diametral disc of two non-consecutive
/// points holds the points between them; that of two consecutive points meets the line only in
/// their segment). Lexicographic (x, y) order is the order along any line.
void fill_chain(const Points& points, GabrielGeometry& g) {
  const int n = static_cast<int>(points.rows());
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (points(a, 0) != points(b, 0)) return points(a, 0) < points(b, 0);
    return points(a, 1) < points(b, 1);
  });
  std::vector<std::pair<int, int>> edges;
  g.rotation.assign(static_cast<std::size_t>(n), {});
  for (int k = 0; k + 1 < n; ++k) {
    const int a = order[static_cast<std::size_t>(k)], b = order[static_cast<std::size_t>(k + 1)];
    edges.push_back(ordered(a, b));
    g.rotation[static_cast<std::size_t>(a)].push_back(b);
    g.rotation[static_cast<std::size_t>(b)].push_back(a);
  }
  g.delaunay = to_index_pairs(edges);
  g.gabriel = g.delaunay;
  g.edges = g.delaunay;
  g.scale = mean_nearest_neighbour(points, edges);
  if (n >= 2) {
    g.outer_from = order[0];
    g.outer_to = order[1];
  }
}

/// Everything after the triangulation, for the plain Delaunay triangulation (gabriel, distance) and
/// for the alpha shape (which is-a Delaunay triangulation). `alpha` is null unless kind is
/// alpha_shape.
template <class Dt>
GabrielGeometry finish_geometry(const Dt& dt, const Points& points, const GraphSpec& spec,
                                GabrielGeometry g, [[maybe_unused]] AlphaShape* alpha) {
  const int n = static_cast<int>(points.rows());
  using Face_handle = typename Dt::Face_handle;
  using Vertex_handle = typename Dt::Vertex_handle;
  struct EdgeInfo {
    std::pair<int, int> ends;  // ordered
    Face_handle f;
    int i;
    bool gabriel;
  };
  std::vector<EdgeInfo> infos;
  std::vector<std::pair<int, int>> delaunay_edges, gabriel_edges, kept_edges;
  delaunay_edges.reserve(3 * static_cast<std::size_t>(n));
  gabriel_edges.reserve(3 * static_cast<std::size_t>(n));
  if (spec.kind != GraphKind::gabriel) infos.reserve(3 * static_cast<std::size_t>(n));
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const Face_handle f = e->first;
    const int i = e->second;
    const Vertex_handle a = f->vertex(Dt::cw(i));
    const Vertex_handle b = f->vertex(Dt::ccw(i));
    const auto edge = ordered(a->info(), b->info());
    delaunay_edges.push_back(edge);
    // Closed diametral disc: a point on the circle blocks the edge. Only the two vertices opposite
    // the edge need testing: if any point lies in the closed disc, one of them does (otherwise the
    // circumcircle of that side's triangle would strictly contain the point).
    bool gabriel = true;
    for (const Vertex_handle c : {f->vertex(i), dt.mirror_vertex(f, i)}) {
      if (dt.is_infinite(c)) continue;
      if (CGAL::side_of_bounded_circle(a->point(), b->point(), c->point()) !=
          CGAL::ON_UNBOUNDED_SIDE) {
        gabriel = false;
        break;
      }
    }
    if (gabriel) gabriel_edges.push_back(edge);
    if (spec.kind != GraphKind::gabriel) infos.push_back({edge, f, i, gabriel});
  }
  // The Gabriel graph (the default) needs no length unit: nothing more to compute for it.
  if (spec.kind != GraphKind::gabriel) g.scale = mean_nearest_neighbour(points, delaunay_edges);

  std::vector<std::pair<int, int>> holes;
  if (spec.kind == GraphKind::gabriel) {
    kept_edges = gabriel_edges;
  } else {
    const double limit = spec.distance_threshold * g.scale;
    for (const EdgeInfo& info : infos) {
      const Face_handle f = info.f;
      const int i = info.i;
      const Face_handle m = f->neighbor(i);
      // An edge of the Delaunay triangulation that is not an edge of the Delaunay tessellation: its
      // two triangles share their circumcircle (cocircular points), so the triangulation chose it
      // arbitrarily (a grid square's diagonal). Never kept: the graphs stay independent of CGAL's
      // choice and of the input order.
      const bool ambiguous = !dt.is_infinite(f) && !dt.is_infinite(m) &&
                             dt.side_of_oriented_circle(f, dt.mirror_vertex(f, i)->point(),
                                                        false) == CGAL::ON_ORIENTED_BOUNDARY;
      const auto rng = [&] {
        return info.gabriel && relative_neighbours(points, info.ends.first, info.ends.second);
      };
      bool keep = false;
      if constexpr (!std::is_same_v<Dt, ADelaunay>) {
        keep = !ambiguous &&
               (point_distance(points, info.ends.first, info.ends.second) <= limit || rng());
      } else {
        const auto cls = alpha->classify(f, i);
        const bool in_complex = cls == AlphaShape::REGULAR || cls == AlphaShape::INTERIOR;
        // Both triangles in the complex and cocircular: one region (a grid square), no diagonal.
        const bool merged = ambiguous && cls == AlphaShape::INTERIOR;
        keep = (in_complex && !merged) || rng();
        if (keep) {
          // f is on the left of ccw(i) -> cw(i), the mirror face on the left of cw(i) -> ccw(i).
          const int a = f->vertex(Dt::cw(i))->info(), b = f->vertex(Dt::ccw(i))->info();
          if (!dt.is_infinite(f) && alpha->classify(f) == AlphaShape::EXTERIOR)
            holes.emplace_back(b, a);
          if (!dt.is_infinite(m) && alpha->classify(m) == AlphaShape::EXTERIOR)
            holes.emplace_back(a, b);
        }
      }
      if (keep) kept_edges.push_back(info.ends);
    }
  }
  std::sort(holes.begin(), holes.end());
  g.hole_halfedges = std::move(holes);
  g.delaunay = to_index_pairs(delaunay_edges);
  g.gabriel = to_index_pairs(gabriel_edges);
  g.edges = to_index_pairs(kept_edges);

  // Sorted adjacency of the body graph, to filter the Delaunay circulator.
  std::vector<std::vector<int>> adjacency(static_cast<std::size_t>(n));
  for (const auto& [a, b] : kept_edges) {
    adjacency[static_cast<std::size_t>(a)].push_back(b);
    adjacency[static_cast<std::size_t>(b)].push_back(a);
  }
  for (auto& list : adjacency) std::sort(list.begin(), list.end());
  const auto is_kept = [&](int a, int b) {
    const auto& list = adjacency[static_cast<std::size_t>(a)];
    return std::binary_search(list.begin(), list.end(), b);
  };

  // Rotation system: the Delaunay circulator lists neighbours counter-clockwise (an exact,
  // combinatorial order); keep only the body graph's neighbours.
  g.rotation.assign(static_cast<std::size_t>(n), {});
  for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) {
    const int vi = v->info();
    auto& rot = g.rotation[static_cast<std::size_t>(vi)];
    auto circ = dt.incident_vertices(v), done = circ;
    do {
      const Vertex_handle w = circ;
      if (!dt.is_infinite(w) && is_kept(vi, w->info())) rot.push_back(w->info());
    } while (++circ != done);
  }

  // A half-edge on the unbounded face: at a convex-hull vertex v, the unbounded face is the wedge
  // that holds the infinite vertex; it starts at the last body-graph neighbour before the infinite
  // vertex in CCW order. The face to the left of v -> w is the wedge from w CCW to the next one.
  const Vertex_handle hull = dt.incident_vertices(dt.infinite_vertex());
  std::vector<int> ring;  // Delaunay neighbours of `hull` in CCW order, -1 for the infinite vertex
  {
    auto circ = dt.incident_vertices(hull), done = circ;
    do {
      const Vertex_handle w = circ;
      ring.push_back(dt.is_infinite(w) ? -1 : w->info());
    } while (++circ != done);
  }
  const auto inf_at =
      static_cast<std::size_t>(std::find(ring.begin(), ring.end(), -1) - ring.begin());
  for (std::size_t step = 1; step < ring.size(); ++step) {
    const int w = ring[(inf_at + ring.size() - step) % ring.size()];
    if (is_kept(hull->info(), w)) {
      g.outer_from = hull->info();
      g.outer_to = w;
      break;
    }
  }
  if (g.outer_from < 0)
    throw GeometryError("gabriel_graph: internal error: hull vertex without a body-graph edge");
  return g;
}

template <class Dt>
void insert_checked(Dt& dt, const Points& points) {
  const int n = static_cast<int>(points.rows());
  std::vector<std::pair<Point, int>> input;
  input.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) input.emplace_back(Point(points(i, 0), points(i, 1)), i);
  dt.insert(input.begin(), input.end());  // spatially sorted insertion, O(n log n) expected
  if (static_cast<int>(dt.number_of_vertices()) != n) {
    // The caller rejects duplicates before we get here; this is a safety net, not a code path.
    throw GeometryError("gabriel_graph: CGAL merged " +
                        std::to_string(n - static_cast<int>(dt.number_of_vertices())) +
                        " coincident point(s); duplicates must be rejected before triangulation");
  }
}

}  // namespace

GabrielGeometry compute_gabriel_geometry(const Points& points, const GraphSpec& spec) {
  GabrielGeometry g;
  if (spec.kind != GraphKind::alpha_shape) {
    Delaunay dt;
    insert_checked(dt, points);
    g.dimension = dt.dimension();
    if (g.dimension < 2) {
      fill_chain(points, g);
      return g;
    }
    return finish_geometry(dt, points, spec, std::move(g), nullptr);
  }
  ADelaunay dt;
  insert_checked(dt, points);
  g.dimension = dt.dimension();
  if (g.dimension < 2) {
    fill_chain(points, g);
    return g;
  }
  // Alpha_shape_2 takes the triangulation over (swap) and computes every face's alpha interval.
  AlphaShape shape(dt, 0.0, AlphaShape::REGULARIZED);
  // The alpha shape is built before the scale is known: the scale needs the Delaunay edges, which
  // are the same in the shape's triangulation.
  std::vector<std::pair<int, int>> delaunay;
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e)
    delaunay.push_back(ordered(e->first->vertex(AlphaShape::cw(e->second))->info(),
                               e->first->vertex(AlphaShape::ccw(e->second))->info()));
  const double r = spec.alpha * mean_nearest_neighbour(points, delaunay);
  shape.set_alpha(r * r);  // CGAL's alpha is a squared radius
  return finish_geometry(static_cast<const ADelaunay&>(shape), points, spec, std::move(g), &shape);
}

}  // namespace animat::detail
