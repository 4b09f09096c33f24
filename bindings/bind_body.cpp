// Python bindings of the body stage: Delaunay and Gabriel graphs, and the Body built from cell
// centres.
#include <fmt/format.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/shape.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

// Copies a vector into a freshly owned numpy array.
template <class T>
nb::ndarray<nb::numpy, T> to_numpy(std::vector<T> v, std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<T>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(heap->data(), shape.size(), shape.begin(), owner);
}

nb::ndarray<nb::numpy, std::int64_t> pairs_to_numpy(const IndexPairs& pairs) {
  std::vector<std::int64_t> v(pairs.data(), pairs.data() + pairs.size());  // row-major (m, 2)
  return to_numpy(std::move(v), {static_cast<std::size_t>(pairs.rows()), 2});
}

nb::ndarray<nb::numpy, double> points_to_numpy(const Points& p) {
  std::vector<double> v(p.data(), p.data() + p.size());  // row-major (n, 2)
  return to_numpy(std::move(v), {static_cast<std::size_t>(p.rows()), 2});
}

nb::ndarray<nb::numpy, double> vector_to_numpy(const Vector& x) {
  return to_numpy(std::vector<double>(x.data(), x.data() + x.size()),
                  {static_cast<std::size_t>(x.size())});
}

std::vector<nb::ndarray<nb::numpy, std::int64_t>> loops_to_numpy(
    const std::vector<std::vector<int>>& loops) {
  std::vector<nb::ndarray<nb::numpy, std::int64_t>> out;
  out.reserve(loops.size());
  for (const auto& loop : loops)
    out.push_back(to_numpy(std::vector<std::int64_t>(loop.begin(), loop.end()), {loop.size()}));
  return out;
}

using Contig = FloatArray;

std::string shape_string(const Contig& a) {
  std::string s = "(";
  for (std::size_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// An (n, 2) float array (or anything numpy turns into one; an empty sequence [] is 0 points).
Points to_points(nb::handle obj, const char* who) {
  const Contig a = as_float_array(obj);
  if (a.ndim() == 1 && a.shape(0) == 0) return Points(0, 2);  // an empty sequence
  if (a.ndim() != 2 || a.shape(1) != 2)
    throw GeometryError(std::string(who) + ": points must be an (n, 2) array, got shape " +
                        shape_string(a));
  Points p(static_cast<Eigen::Index>(a.shape(0)), 2);
  std::copy(a.data(), a.data() + a.size(), p.data());
  return p;
}

/// None -> empty (all zeros); otherwise a 1-D float array (the length is checked by build_body).
Vector to_vector(nb::handle obj, const char* name) {
  if (obj.is_none()) return Vector();
  const Contig a = as_float_array(obj);
  if (a.ndim() != 1)
    throw GeometryError(std::string("build_body: ") + name + " must be a 1-D array, got shape " +
                        shape_string(a));
  Vector v(static_cast<Eigen::Index>(a.shape(0)));
  std::copy(a.data(), a.data() + a.size(), v.data());
  return v;
}

BodyParams body_params(const std::optional<Config>& config) {
  return config ? config->body : BodyParams{};
}

}  // namespace

void bind_body(nb::module_& m) {
  nb::class_<Body>(
      m, "Body",
      "The spring-mass structure an embryo becomes (paper §3, Fig. 3).\n\n"
      "Node i is cell i. Springs are the edges of config.body.graph (default: the Gabriel graph) "
      "of the\n"
      "cell centres; regions are the bounded faces of that planar graph (for alpha_shape, except "
      "the\n"
      "holes); the skin is the boundary of the unbounded face and of the holes. Loops are\n"
      "vertex index arrays with an implicit closing edge (last -> first), each starting at its\n"
      "lexicographically smallest directed edge. Properties return fresh numpy copies.")
      // Array getters return owned copies, so they must not use the default reference_internal
      // policy.
      .def_prop_ro(
          "positions", [](const Body& b) { return points_to_numpy(b.positions); },
          nb::rv_policy::move, "(n, 2) float64 node (cell centre) positions at rest.")
      .def_prop_ro(
          "springs", [](const Body& b) { return pairs_to_numpy(b.springs); }, nb::rv_policy::move,
          "(m, 2) int64 body-graph edges (i, j), i < j, sorted lexicographically.")
      .def_prop_ro(
          "rest_lengths", [](const Body& b) { return vector_to_numpy(b.rest_lengths); },
          nb::rv_policy::move,
          "(m,) float64 rest length L0 of each spring (its length at construction).")
      .def_prop_ro(
          "regions", [](const Body& b) { return loops_to_numpy(b.regions); }, nb::rv_policy::move,
          "list of (k,) int64 arrays: the bounded faces as vertex loops in counter-clockwise "
          "order,\n"
          "sorted. An edge hanging into a face (a bridge) appears twice in its loop.")
      .def_prop_ro(
          "rest_areas", [](const Body& b) { return vector_to_numpy(b.rest_areas); },
          nb::rv_policy::move, "(r,) float64 rest area S0 of each region (> 0, shoelace formula).")
      .def_prop_ro(
          "skin", [](const Body& b) { return pairs_to_numpy(b.skin); }, nb::rv_policy::move,
          "(k, 2) int64 edges bordering the unbounded face or a hole, each once, (i, j) with i < "
          "j, sorted.")
      .def_prop_ro(
          "skin_loops", [](const Body& b) { return loops_to_numpy(b.skin_loops); },
          nb::rv_policy::move,
          "list of (l,) int64 arrays: closed walks of the boundary, body on the left; a dangling "
          "edge\n"
          "appears twice. The first is the outer boundary (counter-clockwise around the body, one "
          "for\n"
          "n >= 2, none for n <= 1), then one per hole of an alpha_shape body (clockwise around "
          "it).")
      .def_prop_ro(
          "amplitude", [](const Body& b) { return vector_to_numpy(b.amplitude); },
          nb::rv_policy::move, "(n,) float64 oscillator amplitude per node.")
      .def_prop_ro(
          "frequency", [](const Body& b) { return vector_to_numpy(b.frequency); },
          nb::rv_policy::move, "(n,) float64 oscillator frequency per node (rad per time unit).")
      .def_prop_ro(
          "phase", [](const Body& b) { return vector_to_numpy(b.phase); }, nb::rv_policy::move,
          "(n,) float64 oscillator phase per node (rad).")
      .def_prop_ro(
          "stiffness", [](const Body& b) { return vector_to_numpy(b.stiffness); },
          nb::rv_policy::move,
          "(n,) float64 stiffness factor per node (GRN output `stiffness`), or (0,) when the body "
          "has\n"
          "the paper's uniform stiffness. Spring (i, j) has scene.spring_stiffness times the "
          "harmonic\n"
          "mean 2 f_i f_j / (f_i + f_j).")
      .def_prop_ro("node_count", &Body::node_count, "Number of nodes (cells).")
      .def_prop_ro("spring_count", &Body::spring_count, "Number of springs (body-graph edges).")
      .def_prop_ro("region_count", &Body::region_count, "Number of regions (bounded faces).")
      .def("__copy__", [](const Body& b) { return Body(b); })
      .def(
          "__deepcopy__", [](const Body& b, nb::handle) { return Body(b); }, "memo"_a)
      .def("__repr__", [](const Body& b) {
        return "<animat.Body " + std::to_string(b.node_count()) + " nodes, " +
               std::to_string(b.spring_count()) + " springs, " + std::to_string(b.region_count()) +
               " regions, " + std::to_string(b.skin.rows()) + " skin edges>";
      });

  m.def(
      "gabriel_graph",
      [](nb::handle points, std::optional<Config> config) {
        return pairs_to_numpy(
            gabriel_graph(to_points(points, "gabriel_graph"), body_params(config)));
      },
      "points"_a, "config"_a = nb::none(),
      "Gabriel graph of points, an (n, 2) float array: a and b are joined iff the closed disc "
      "with\n"
      "diameter ab holds no other point. Returns an (m, 2) int64 array of edges (i, j), i < j, "
      "sorted\n"
      "lexicographically. Built from CGAL's Delaunay triangulation in O(n log n); collinear points "
      "give\n"
      "the chain of consecutive points. Raises ValueError for a wrong shape, NaN/inf or "
      "coordinates\n"
      "beyond config.body.max_coordinate, and points closer than config.body.merge_distance "
      "(duplicates).");
  m.def(
      "delaunay_edges",
      [](nb::handle points, std::optional<Config> config) {
        return pairs_to_numpy(
            delaunay_edges(to_points(points, "delaunay_edges"), body_params(config)));
      },
      "points"_a, "config"_a = nb::none(),
      "Edges of the Delaunay triangulation of points, an (n, 2) float array, as an (m, 2) int64\n"
      "array (i, j), i < j, sorted (paper Fig. 3b). Same validation as gabriel_graph.");
  // The Embryo overload comes first: the array overload accepts any object.
  m.def(
      "build_body",
      [](const Embryo& embryo, std::optional<Config> config, bool allow_nonviable) {
        if (!embryo.viable && !allow_nonviable) {
          std::string why;
          for (const auto& r : embryo.reasons) why += (why.empty() ? "" : "; ") + r;
          throw GeometryError("build_body: the embryo is not viable (" +
                              std::to_string(embryo.cell_count()) + " cell(s): " + why +
                              "); draw one with Genome.random_viable(seed, config), or pass "
                              "allow_nonviable=True to build it anyway");
        }
        return build_body(embryo, body_params(config));
      },
      "embryo"_a, "config"_a = nb::none(), "allow_nonviable"_a = false,
      "Build the body of an animat.Embryo: its cell centres (radii are ignored) and its per-cell\n"
      "amplitude, frequency and phase. A non-viable embryo (e.g. one cell) raises ValueError "
      "unless\n"
      "allow_nonviable=True.");
  m.def(
      "build_body",
      [](nb::handle positions, nb::handle amplitude, nb::handle frequency, nb::handle phase,
         std::optional<Config> config) {
        const Points p = to_points(positions, "build_body");
        return build_body(p, to_vector(amplitude, "amplitude"), to_vector(frequency, "frequency"),
                          to_vector(phase, "phase"), body_params(config));
      },
      "positions"_a, "amplitude"_a = nb::none(), "frequency"_a = nb::none(), "phase"_a = nb::none(),
      "config"_a = nb::none(),
      "Build a body from cell centres, an (n, 2) float array, and optional (n,) float arrays of\n"
      "oscillator amplitude, frequency and phase (None = zeros). Springs are the edges of\n"
      "config.body.graph (default: Gabriel), regions the bounded faces (alpha_shape: except "
      "holes), the\n"
      "skin the outer boundary and the holes' boundaries. Raises ValueError for a wrong shape or\n"
      "length, NaN/inf, coordinates beyond config.body.max_coordinate, or points closer than\n"
      "config.body.merge_distance.");
  m.def(
      "polygon_area",
      [](nb::handle points, std::vector<int> loop) {
        const Points p = to_points(points, "polygon_area");
        for (const int v : loop)
          if (v < 0 || v >= p.rows())
            throw GeometryError("polygon_area: vertex index " + std::to_string(v) +
                                " out of range for " + std::to_string(p.rows()) + " points");
        return polygon_area(p, loop);
      },
      "points"_a, "loop"_a,
      "Signed shoelace area of the closed vertex loop `loop` (indices into the (n, 2) array "
      "`points`);\n"
      "positive when counter-clockwise.");
  m.def(
      "morphology_kind",
      [](nb::handle points) { return morphology_kind(to_points(points, "morphology_kind")); },
      "points"_a,
      "The coarse class of a body plan that evolution.protection_generations compares: cell "
      "count * 16 +\n"
      "elongation band, the band floor(log_1.5 elongation) clamped to [0, 15] (elongation as\n"
      "animat.shape.elongation of the cell centres `points`, an (n, 2) array: sqrt of the ratio "
      "of the\n"
      "principal second moments, each cell a disc of one cell spacing); 0 for no cell. "
      "EvaluationResult\n"
      "and Fitness carry it for an evaluated genome (its body's rest positions).");
  // The C++ geometry behind morphology_kind and animat.shape (which calls these two).
  m.def(
      "shape_elongation",
      [](nb::handle points, double cell_diameter, std::optional<double> spacing) {
        const Points p = to_points(points, "shape_elongation");
        return spacing ? elongation(p, cell_diameter, *spacing) : elongation(p, cell_diameter);
      },
      "points"_a, "cell_diameter"_a = 1.0, "spacing"_a = nb::none(),
      "The engine's elongation (shape.hpp), which animat.shape.elongation and morphology_kind "
      "use;\n"
      "`spacing` is s (default: the cell spacing of `points`).");
  m.def(
      "describe_shape",
      [](nb::handle points, const std::vector<int>& outline,
         std::optional<std::vector<int>> springs, double cell_diameter, double core_radius,
         double min_height, double pair_tolerance, std::optional<double> spacing) {
        const Points p = to_points(points, "describe_shape");
        IndexPairs links;
        if (springs) {
          if (springs->size() % 2 != 0)
            throw GeometryError(
                fmt::format("describe_shape: springs hold {} indices, not pairs", springs->size()));
          links = Eigen::Map<const IndexPairs>(springs->data(),
                                               static_cast<Eigen::Index>(springs->size() / 2), 2);
        }
        const Shape sh = describe_shape(p, outline, springs ? &links : nullptr,
                                        {cell_diameter, core_radius, min_height, pair_tolerance},
                                        spacing.value_or(std::numeric_limits<double>::quiet_NaN()));
        nb::list protrusions;
        for (const Protrusion& pr : sh.protrusions)
          protrusions.append(
              nb::make_tuple(pr.cells, pr.height, nb::make_tuple(pr.centroid[0], pr.centroid[1])));
        nb::list pairs;
        for (const auto& [i, j] : sh.symmetric_pairs) pairs.append(nb::make_tuple(i, j));
        nb::dict out;
        out["cell_count"] = sh.cell_count;
        out["spacing"] = sh.spacing;
        out["elongation"] = sh.elongation;
        out["concavity"] = sh.concavity;
        out["outline_area"] = sh.outline_area;
        out["hull_area"] = sh.hull_area;
        out["has_core"] = sh.has_core;
        out["core_cells"] = sh.core_cells;
        out["heights"] = sh.heights;
        out["protrusions"] = protrusions;
        out["symmetric_pairs"] = pairs;
        return out;
      },
      "points"_a, "outline"_a, "springs"_a, "cell_diameter"_a, "core_radius"_a, "min_height"_a,
      "pair_tolerance"_a, "spacing"_a = nb::none(),
      "The engine's shape descriptors (shape.hpp) of cells at `points` with the outer `outline`\n"
      "and the springs (flat [i0, j0, i1, j1, ...], or None: group by distance), `spacing` s\n"
      "(None: the cell spacing): a dict of animat.shape.Shape's fields and has_core, protrusions\n"
      "as (cells, height, centroid). animat.shape.describe calls it.");
  m.def(
      "_cell_spacing",
      [](nb::handle points) { return cell_spacing(to_points(points, "_cell_spacing")); },
      "points"_a,
      "The C++ cell spacing of morphology_kind (animat.shape.cell_spacing computes the same).");
}

}  // namespace animat::py
