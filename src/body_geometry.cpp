// The only translation unit that includes CGAL. It turns a validated point set into the Delaunay
// triangulation, the Gabriel graph and the Gabriel graph's rotation system; body.cpp does the rest.
#include "body_geometry.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <numeric>
#include <string>
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
  if (n >= 2) {
    g.outer_from = order[0];
    g.outer_to = order[1];
  }
}

}  // namespace

GabrielGeometry compute_gabriel_geometry(const Points& points) {
  const int n = static_cast<int>(points.rows());
  GabrielGeometry g;

  std::vector<std::pair<Point, int>> input;
  input.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) input.emplace_back(Point(points(i, 0), points(i, 1)), i);
  Delaunay dt;
  dt.insert(input.begin(), input.end());  // spatially sorted insertion, O(n log n) expected
  if (static_cast<int>(dt.number_of_vertices()) != n) {
    // The caller rejects duplicates before we get here; this is a safety net, not a code path.
    throw GeometryError("gabriel_graph: CGAL merged " + std::to_string(n - static_cast<int>(dt.number_of_vertices())) +
                        " coincident point(s); duplicates must be rejected before triangulation");
  }
  g.dimension = dt.dimension();
  if (g.dimension < 2) {
    fill_chain(points, g);
    return g;
  }

  std::vector<std::pair<int, int>> delaunay_edges, gabriel_edges;
  delaunay_edges.reserve(3 * static_cast<std::size_t>(n));
  gabriel_edges.reserve(3 * static_cast<std::size_t>(n));
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const Delaunay::Face_handle f = e->first;
    const int i = e->second;
    const Delaunay::Vertex_handle a = f->vertex(Delaunay::cw(i));
    const Delaunay::Vertex_handle b = f->vertex(Delaunay::ccw(i));
    const auto edge = ordered(a->info(), b->info());
    delaunay_edges.push_back(edge);
    // Closed diametral disc: a point on the circle blocks the edge. Only the two vertices opposite
    // the edge need testing: if any point lies in the closed disc, one of them does (otherwise the
    // circumcircle of that side's triangle would strictly contain the point).
    bool gabriel = true;
    for (const Delaunay::Vertex_handle c : {f->vertex(i), dt.mirror_vertex(f, i)}) {
      if (dt.is_infinite(c)) continue;
      if (CGAL::side_of_bounded_circle(a->point(), b->point(), c->point()) != CGAL::ON_UNBOUNDED_SIDE) {
        gabriel = false;
        break;
      }
    }
    if (gabriel) gabriel_edges.push_back(edge);
  }
  g.delaunay = to_index_pairs(delaunay_edges);
  g.gabriel = to_index_pairs(gabriel_edges);

  // Sorted adjacency of the Gabriel graph, to filter the Delaunay circulator.
  std::vector<std::vector<int>> adjacency(static_cast<std::size_t>(n));
  for (const auto& [a, b] : gabriel_edges) {
    adjacency[static_cast<std::size_t>(a)].push_back(b);
    adjacency[static_cast<std::size_t>(b)].push_back(a);
  }
  for (auto& list : adjacency) std::sort(list.begin(), list.end());
  const auto is_gabriel = [&](int a, int b) {
    const auto& list = adjacency[static_cast<std::size_t>(a)];
    return std::binary_search(list.begin(), list.end(), b);
  };

  // Rotation system: the Delaunay circulator lists neighbours counter-clockwise (an exact,
  // combinatorial order); keep only the Gabriel neighbours.
  g.rotation.assign(static_cast<std::size_t>(n), {});
  for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) {
    const int vi = v->info();
    auto& rot = g.rotation[static_cast<std::size_t>(vi)];
    Delaunay::Vertex_circulator circ = dt.incident_vertices(v), done = circ;
    do {
      const Delaunay::Vertex_handle w = circ;
      if (!dt.is_infinite(w) && is_gabriel(vi, w->info())) rot.push_back(w->info());
    } while (++circ != done);
  }

  // A half-edge on the unbounded face: at a convex-hull vertex v, the unbounded face is the wedge
  // that holds the infinite vertex; it starts at the last Gabriel neighbour before the infinite
  // vertex in CCW order. The face to the left of v -> w is the wedge from w CCW to the next one.
  const Delaunay::Vertex_handle hull = dt.incident_vertices(dt.infinite_vertex());
  std::vector<int> ring;  // Delaunay neighbours of `hull` in CCW order, -1 for the infinite vertex
  {
    Delaunay::Vertex_circulator circ = dt.incident_vertices(hull), done = circ;
    do {
      const Delaunay::Vertex_handle w = circ;
      ring.push_back(dt.is_infinite(w) ? -1 : w->info());
    } while (++circ != done);
  }
  const auto inf_at = static_cast<std::size_t>(std::find(ring.begin(), ring.end(), -1) - ring.begin());
  for (std::size_t step = 1; step < ring.size(); ++step) {
    const int w = ring[(inf_at + ring.size() - step) % ring.size()];
    if (is_gabriel(hull->info(), w)) {
      g.outer_from = hull->info();
      g.outer_to = w;
      break;
    }
  }
  if (g.outer_from < 0) throw GeometryError("gabriel_graph: internal error: hull vertex without a Gabriel edge");
  return g;
}

}  // namespace animat::detail
