// Python view of development (paper §2.2, Fig. 2): animat.develop(genome, config) -> Embryo.
#include <nanobind/eigen/dense.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <string>

#include "animat/config.hpp"
#include "animat/development.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

std::string embryo_repr(const Embryo& e) {
  std::string out = "<Embryo " + std::to_string(e.cell_count()) +
                    (e.cell_count() == 1 ? " cell" : " cells") + ", " +
                    std::to_string(e.division_steps.size()) + " divisions, " +
                    std::to_string(e.steps_run) + " steps, ";
  if (e.viable) return out + "viable>";
  out += "not viable";
  for (const auto& r : e.reasons) out += "; " + r;
  return out + ">";
}

}  // namespace

void bind_development(nb::module_& m) {
  nb::class_<DevelopmentTrace>(
      m, "DevelopmentTrace",
      "Snapshots of a development every ``development.trace_every`` steps (paper Fig. 2).\n\n"
      "``steps[k]`` is the step of snapshot k; ``positions[k]`` (n_k × 2), ``radii[k]`` (n_k)\n"
      "and ``orientations[k]`` (n_k × 2 unit vectors) describe its cells. The first snapshot is\n"
      "step 0 (one cell); the last is the final state.")
      .def_prop_ro(
          "steps", [](const DevelopmentTrace& t) { return t.steps; },
          "Step of every snapshot (list of int).")
      .def_prop_ro(
          "positions", [](const DevelopmentTrace& t) { return t.positions; },
          "Cell centres of every snapshot (list of n_k × 2 arrays).")
      .def_prop_ro(
          "radii", [](const DevelopmentTrace& t) { return t.radii; },
          "Cell radii of every snapshot (list of arrays).")
      .def_prop_ro(
          "orientations", [](const DevelopmentTrace& t) { return t.orientations; },
          "Unit orientation vectors of every snapshot (list of n_k × 2 arrays).")
      .def(
          "__len__", [](const DevelopmentTrace& t) { return t.steps.size(); },
          "Number of snapshots.")
      .def("__repr__", [](const DevelopmentTrace& t) {
        std::string out = "<DevelopmentTrace " + std::to_string(t.steps.size()) + " snapshots";
        if (!t.steps.empty())
          out += ", steps " + std::to_string(t.steps.front()) + ".." +
                 std::to_string(t.steps.back()) + ", " + std::to_string(t.positions.back().rows()) +
                 " cells at the end";
        return out + ">";
      });

  nb::class_<Embryo>(
      m, "Embryo",
      "A grown embryo (paper §2.2): cell centres, radii, orientations, the six GRN outputs of "
      "every\n"
      "cell, the oscillator parameters derived from them, and the viability verdict (paper §5).")
      .def_prop_ro(
          "positions", [](const Embryo& e) -> Points { return e.positions; },
          "Cell centres, n × 2 float array.")
      .def_prop_ro(
          "radii", [](const Embryo& e) -> Vector { return e.radii; }, "Cell radii, n array.")
      .def_prop_ro(
          "orientations", [](const Embryo& e) -> Points { return e.orientations; },
          "Unit orientation vectors, n × 2 array.")
      .def_prop_ro(
          "outputs", [](const Embryo& e) -> OutputLevels { return e.outputs; },
          "GRN output levels, n × 6 array; columns: divide, rotate, grow, amplitude, frequency, "
          "phase.")
      .def_prop_ro(
          "amplitude", [](const Embryo& e) -> Vector { return e.amplitude; },
          "Oscillator amplitude per cell: development.amplitude_max × amplitude output, in [0, "
          "0.2].")
      .def_prop_ro(
          "frequency", [](const Embryo& e) -> Vector { return e.frequency; },
          "Oscillator frequency per cell (rad per time unit): frequency_min + (frequency_max -\n"
          "frequency_min) × frequency output.")
      .def_prop_ro(
          "phase", [](const Embryo& e) -> Vector { return e.phase; },
          "Oscillator phase per cell: 2π × phase output, in [0, 2π).")
      .def_prop_ro(
          "stiffness", [](const Embryo& e) -> Vector { return e.stiffness; },
          "Spring stiffness factor per cell, "
          "development.stiffness_min·(stiffness_max/stiffness_min)^output\n"
          "(evolvable stiffness); empty unless genome.extra_outputs enables the stiffness output.")
      .def_prop_ro(
          "division_steps", [](const Embryo& e) { return e.division_steps; },
          "Step (1-based) of every division, in order (list of int); len == cell_count - 1.")
      .def_prop_ro(
          "steps_run", [](const Embryo& e) { return e.steps_run; },
          "Steps simulated: development.steps, or fewer when development stopped as soon as the "
          "embryo\n"
          "was certainly not viable (0 when the GRN lacks the required paths).")
      .def_prop_ro(
          "viable", [](const Embryo& e) { return e.viable; },
          "Viability (paper §5): GRN paths from an input to divide and the oscillator outputs, at "
          "least\n"
          "min_cells cells, last division at least quiet_steps steps before the end.")
      .def_prop_ro(
          "reasons", [](const Embryo& e) { return e.reasons; },
          "Why the embryo is not viable (list of str); empty when viable.")
      .def_prop_ro(
          "trace",
          [](const Embryo& e) -> std::optional<DevelopmentTrace> {
            if (e.trace.empty()) return std::nullopt;
            return e.trace;
          },
          "The DevelopmentTrace, or None when development.trace_every is 0.")
      .def_prop_ro("cell_count", &Embryo::cell_count, "Number of cells.")
      .def("__len__", &Embryo::cell_count, "Number of cells.")
      .def("__repr__", &embryo_repr);

  m.def(
      "develop",
      [](const Genome& genome, const Config* config) {
        const Config fallback;
        const Config& c = config ? *config : fallback;
        return develop(genome, c.genome, c.grn, c.development);
      },
      "genome"_a, "config"_a = nb::none(), nb::call_guard<nb::gil_scoped_release>(),
      "Grow an embryo from one cell (paper §2.2, Fig. 2) with the [genome], [grn] and "
      "[development]\n"
      "sections of `config` (an animat.Config; None = defaults). Deterministic: the same genome "
      "and\n"
      "config give bit-identical results. Set ``config.development.trace_every = k`` to record a "
      "trace.\n"
      "Raises ValueError for an invalid config, RuntimeError if the simulation leaves its valid "
      "domain.");
}

}  // namespace animat::py
