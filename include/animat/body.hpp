#pragma once
// From cell centres to a spring-mass animat (paper §3, Fig. 3): Gabriel graph, regions, skin.
#include <string>
#include <vector>

#include "animat/params.hpp"
#include "animat/types.hpp"

namespace animat {

struct Embryo;

struct BodyParams {
  double merge_distance = 1e-6;    ///< points closer than this are duplicates (rejected) [choose]
  double max_coordinate = 1e6;     ///< |x| or |y| above this is rejected as absurd [choose]
};

template <class V>
void visit_fields(BodyParams& p, V&& v) {
  v(FieldInfo{"merge_distance", "centres closer than this are duplicates and are rejected [choose]", Bounds::non_negative()}, p.merge_distance);
  v(FieldInfo{"max_coordinate", "coordinates beyond this magnitude are rejected [choose]", Bounds::positive()}, p.max_coordinate);
}

/// The spring-mass structure an embryo becomes.
struct Body {
  Points positions;                          ///< node (cell centre) positions at rest, n × 2
  IndexPairs springs;                        ///< Gabriel edges (i < j), sorted lexicographically
  Vector rest_lengths;                       ///< L0 per spring
  std::vector<std::vector<int>> regions;     ///< bounded faces, vertex loops in CCW order
  Vector rest_areas;                         ///< S0 per region (> 0 by CCW orientation)
  IndexPairs skin;                           ///< edges bordering the unbounded face, each once (i < j)
  std::vector<std::vector<int>> skin_loops;  ///< closed walks around the outer boundary; dangling edges twice
  Vector amplitude, frequency, phase;        ///< per-node oscillator parameters (zeros if none given)

  [[nodiscard]] int node_count() const { return static_cast<int>(positions.rows()); }
  [[nodiscard]] int spring_count() const { return static_cast<int>(springs.rows()); }
};

/// Delaunay edges (i < j, sorted) of the points; for Fig. 3(b).
[[nodiscard]] IndexPairs delaunay_edges(const Points& points, const BodyParams& params = {});
/// Gabriel graph: Delaunay edges whose closed diametral disc holds no other point. O(n log n).
[[nodiscard]] IndexPairs gabriel_graph(const Points& points, const BodyParams& params = {});
/// Builds the body from any point set; oscillator vectors may be empty (zeros).
[[nodiscard]] Body build_body(const Points& positions, const Vector& amplitude, const Vector& frequency,
                              const Vector& phase, const BodyParams& params = {});
[[nodiscard]] Body build_body(const Embryo& embryo, const BodyParams& params = {});

}  // namespace animat
