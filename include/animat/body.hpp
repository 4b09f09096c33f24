#pragma once
// From cell centres to a spring-mass animat (paper §3, Fig. 3): Gabriel graph, regions, skin.
#include <string>
#include <string_view>
#include <vector>

#include "animat/params.hpp"
#include "animat/shape.hpp"  // elongation(), which morphology_kind() bands
#include "animat/types.hpp"

namespace animat {

struct Embryo;

/// The body graphs (docs/model.md "Other body graphs").
inline constexpr std::string_view kBodyGraphNames[] = {"gabriel", "distance", "alpha_shape"};

struct BodyParams {
  double merge_distance = 1e-6;   ///< points closer than this are duplicates (rejected) [choose]
  double max_coordinate = 1e6;    ///< |x| or |y| above this is rejected as absurd [choose]
  std::string graph = "gabriel";  ///< gabriel [paper] | distance | alpha_shape [choose]
  /// distance graph: Delaunay-tessellation edges up to this length, in mean nearest-neighbour
  /// distances
  double distance_threshold = 1.5;
  /// alpha_shape: largest circumradius, in mean nearest-neighbour distances
  double alpha = 1.0;
};

template <class V>
void visit_fields(BodyParams& p, V&& v) {
  v(FieldInfo{"merge_distance", "centres closer than this are duplicates and are rejected [choose]",
              Bounds::upto(kMaxLength)},
    p.merge_distance);
  v(FieldInfo{"max_coordinate", "coordinates beyond this magnitude are rejected [choose]",
              Bounds::positive_upto(kMaxLength)},
    p.max_coordinate);
  v(FieldInfo{"graph",
              "body graph: gabriel (paper: Gabriel graph, closed disc); distance "
              "(Delaunay-tessellation edges not longer than distance_threshold, plus the "
              "relative-neighbourhood edges that keep the body in one piece); alpha_shape "
              "(regularized alpha complex of radius alpha, same connecting edges; bounded faces "
              "outside the complex are holes: no pressure, skin) [choose]",
              Bounds::any(), kBodyGraphNames, Identity::late},
    p.graph);
  v(FieldInfo{"distance_threshold",
              "graph = distance: longest spring, in units of the mean nearest-neighbour distance "
              "of the cell centres (1 = a packed cell diameter), (0, 1e6] [choose]",
              Bounds::positive_upto(kMaxLength),
              {},
              Identity::late},
    p.distance_threshold);
  v(FieldInfo{"alpha",
              "graph = alpha_shape: largest circumradius of a filled triangle, in units of the "
              "mean nearest-neighbour distance of the cell centres (CGAL's alpha is its square), "
              "(0, 1e6] [choose]",
              Bounds::positive_upto(kMaxLength),
              {},
              Identity::late},
    p.alpha);
}

/// The spring-mass structure an embryo becomes.
///
/// Node i is cell i. Springs are the edges of the body graph (BodyParams::graph; by default the
/// Gabriel graph); regions are the bounded faces of that planar graph, except, for graph =
/// alpha_shape, the faces outside the alpha complex (holes: no region, no pressure); the skin is
/// the boundary of the unbounded face and of the holes. Loops are vertex lists with an
/// implicit closing edge (last -> first); each starts at its lexicographically smallest directed
/// edge (loop[0], loop[1]). See docs/notes/body.md for every choice and degenerate case.
struct Body {
  Points positions;     ///< node (cell centre) positions at rest, n × 2
  IndexPairs springs;   ///< body-graph edges (i < j), sorted lexicographically
  Vector rest_lengths;  ///< L0 per spring
  /// Bounded faces, vertex loops in CCW order (face on the left), sorted lexicographically. A loop
  /// is the face's boundary walk: an edge that hangs into the face (a bridge) appears twice in it.
  std::vector<std::vector<int>> regions;
  Vector rest_areas;  ///< S0 per region (> 0 by CCW orientation)
  /// edges bordering the unbounded face or a hole, each once (i < j)
  IndexPairs skin;
  /// Closed walks around the boundary, body on the left; dangling edges twice. skin_loops[0] is the
  /// outer boundary (CCW around the body; one for n >= 2: every body graph is connected), then one
  /// walk per hole (clockwise around the hole), sorted; none for n <= 1.
  std::vector<std::vector<int>> skin_loops;
  /// per-node oscillator parameters (zeros if none given)
  Vector amplitude, frequency, phase;
  /// Per-node stiffness factor f (evolvable stiffness: GRN output `stiffness`); empty = every
  /// spring has scene.spring_stiffness (the paper's uniform stiffness). Spring (i, j) then has
  /// stiffness k·spring_stiffness_factor(f_i, f_j).
  Vector stiffness;

  [[nodiscard]] int node_count() const { return static_cast<int>(positions.rows()); }
  [[nodiscard]] int spring_count() const { return static_cast<int>(springs.rows()); }
  [[nodiscard]] int region_count() const { return static_cast<int>(regions.size()); }
};

/// Stiffness factor of a spring between cells with factors fi and fj: their harmonic mean
/// 2·fi·fj/(fi + fj). Each cell owns half the spring; the halves (stiffness 2k·fi and 2k·fj) act in
/// series, so 1/k_spring = 1/(2k·fi) + 1/(2k·fj). Exactly 1 when fi = fj = 1.
[[nodiscard]] inline double spring_stiffness_factor(double fi, double fj) {
  return 2.0 * fi * fj / (fi + fj);
}

/// Delaunay edges (i < j, sorted) of the points; for Fig. 3(b). Same validation as gabriel_graph.
[[nodiscard]] IndexPairs delaunay_edges(const Points& points, const BodyParams& params = {});
/// Gabriel graph: Delaunay edges whose closed diametral disc holds no other point. O(n log n).
/// Rows (i, j) with i < j, sorted. Collinear input gives the chain of consecutive points.
/// Throws GeometryError for non-finite coordinates, |coordinate| > max_coordinate, and two points
/// at distance 0 or closer than merge_distance (the message names the indices and the value).
[[nodiscard]] IndexPairs gabriel_graph(const Points& points, const BodyParams& params = {});
/// Builds the body from any point set; oscillator vectors may be empty (zeros), else length n and
/// finite (GeometryError otherwise). Same point validation as gabriel_graph.
[[nodiscard]] Body build_body(const Points& positions, const Vector& amplitude,
                              const Vector& frequency, const Vector& phase,
                              const BodyParams& params = {});
/// Builds the body from an embryo's cell centres and oscillator parameters (radii are ignored).
[[nodiscard]] Body build_body(const Embryo& embryo, const BodyParams& params = {});

/// Signed shoelace area of the closed vertex loop (positive when counter-clockwise); 0 for fewer
/// than 3 vertices.
[[nodiscard]] double polygon_area(const Points& positions, const std::vector<int>& loop);

/// s: the median distance from a cell centre to its nearest neighbour (the mean of the two middle
/// values for an even count); 1 for fewer than 2 cells or a median of 0. The length unit of the
/// shape descriptors (animat.shape.cell_spacing computes the same).
[[nodiscard]] double cell_spacing(const Points& positions);

/// Elongation bands of morphology_kind(): band k holds the elongations in [1.5^k, 1.5^(k+1)), the
/// last one everything from 1.5^15 (438) up.
inline constexpr int kElongationBands = 16;

/// A coarse class of a body plan: cell count × kElongationBands + elongation band, the band
/// floor(log_1.5 elongation()) clamped to [0, 15] (computed against the exact powers 1.5^k, no
/// logarithm, so every machine agrees); 0 for no cell. Coarse on purpose: the GA's morphological
/// innovation protection (evolution.protection_generations) treats an offspring of another class
/// than its parents as a new morphology, and an exact signature of the body would change with
/// nearly every mutation.
[[nodiscard]] int morphology_kind(const Points& positions);

}  // namespace animat
