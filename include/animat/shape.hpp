#pragma once
// Shape measures of a body at rest (the paper's §6): elongation, concavity, protrusions and their
// mirror symmetry, computed as animat.shape computes them (its module docstring defines them; every
// length in cell spacings s, cell_spacing() in body.hpp).
#include <array>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "animat/types.hpp"

namespace animat {

struct Body;

/// The descriptors' parameters, every length in cell spacings (animat.shape.ShapeParams).
struct ShapeParams {
  double cell_diameter = 1.0;   ///< each cell a disc of this diameter in the second moments
  double core_radius = 0.75;    ///< ρ: radius of the disc that defines the core
  double min_height = 0.5;      ///< a cell protrudes when its centre is this far from the core
  double pair_tolerance = 1.0;  ///< largest distance between a mirror image and its partner
};

/// Protruding cells joined into one protrusion.
struct Protrusion {
  std::vector<int> cells;       ///< cell indices, ascending
  double height = 0.0;          ///< the largest height of its cells (spacings)
  double centroid[2] = {0, 0};  ///< mean position of its cells
};

/// The descriptors of one body (animat.shape.Shape).
struct Shape {
  int cell_count = 0;
  double spacing = 1.0;  ///< s (length units)
  double elongation = 1.0;
  double concavity = 0.0;
  double outline_area = 0.0;            ///< in s²
  double hull_area = 0.0;               ///< in s²
  bool has_core = false;                ///< some disc of radius core_radius fits in the outline
  int core_cells = 0;                   ///< cells that do not protrude (0 without a core)
  std::vector<double> heights;          ///< per cell, spacings (all 0 without a core)
  std::vector<Protrusion> protrusions;  ///< largest first (size, then height, then cells)
  std::vector<std::pair<int, int>> symmetric_pairs;  ///< indices into protrusions, i < j
};

/// The principal second moments of the cells about their centroid (each cell a uniform disc of
/// diameter cell_diameter·s, which adds (cell_diameter·s)²/16 to both) and their axes.
struct PrincipalAxes {
  double minor = 0.0, major = 0.0;    ///< λ2 <= λ1
  double minor_axis[2] = {1.0, 0.0};  ///< unit eigenvector of λ2
  double major_axis[2] = {0.0, 1.0};  ///< unit eigenvector of λ1
};

/// The principal moments and axes of `positions` (at least one cell) with spacing s.
[[nodiscard]] PrincipalAxes principal_axes(const Points& positions, double cell_diameter,
                                           double spacing);

/// sqrt(λ1/λ2) of the cells' principal second moments (principal_axes with s = cell_spacing()): 1
/// for no cell; infinity when λ2 <= 1e-12 λ1 (possible only with cell_diameter = 0).
/// animat.shape.elongation computes it through this function.
[[nodiscard]] double elongation(const Points& positions, double cell_diameter = 1.0);
/// The same with the spacing s given.
[[nodiscard]] double elongation(const Points& positions, double cell_diameter, double spacing);

/// The descriptors of cells at `positions` with the outer `outline` (cell indices
/// counter-clockwise, Body::skin_loops[0]; empty for fewer than two cells); protruding cells are
/// grouped by the `springs` (nullptr: by distance < 1.5 s) and by the outline. `spacing` is s (NaN:
/// cell_spacing() of the positions). GeometryError for an outline index that is no cell.
[[nodiscard]] Shape describe_shape(const Points& positions, std::span<const int> outline,
                                   const IndexPairs* springs, const ShapeParams& params = {},
                                   double spacing = std::numeric_limits<double>::quiet_NaN());

/// Each cell's distance from the core of the cells at `positions` with the outer `outline`, in
/// spacings (`spacing` is s); empty when there is no core (animat.shape.cell_heights).
[[nodiscard]] std::vector<double> cell_heights(const Points& positions,
                                               std::span<const int> outline,
                                               const ShapeParams& params, double spacing);

/// The connected components of the graph on `members` (distinct cell indices) whose edges are the
/// `links` (a link with an end outside `members` is ignored): each sorted, in the order of the
/// first member of each in `members` (animat.shape.connected_groups).
[[nodiscard]] std::vector<std::vector<int>> connected_groups(
    const std::vector<int>& members, const std::vector<std::pair<int, int>>& links);

/// Index pairs (i, j), i < j, of the protrusions whose `centroids`, relative to the centroid of the
/// cells at `positions`, mirror each other about a principal axis of those cells within
/// pair_tolerance spacings, on opposite sides of it (animat.shape.symmetric_pairs).
[[nodiscard]] std::vector<std::pair<int, int>> symmetric_pairs(
    const Points& positions, const std::vector<std::array<double, 2>>& centroids,
    const ShapeParams& params, double spacing);

/// The descriptors of a body at rest: its positions, outer skin loop and springs.
[[nodiscard]] Shape body_shape(const Body& body, const ShapeParams& params = {});

}  // namespace animat
