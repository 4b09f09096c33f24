#include <nanobind/nanobind.h>

#include "animat/errors.hpp"
#include "bindings.hpp"

namespace nb = nanobind;

NB_MODULE(_core, m) {
  m.doc() = "animat: co-evolution of morphology and control of soft-bodied multicellular animats (compiled core)";
  m.attr("__version__") = ANIMAT_VERSION;
  // C++ errors become Python exceptions carrying the C++ message.
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const animat::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const animat::SimulationError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const animat::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  animat::py::bind_config(m);
  animat::py::bind_genome(m);
  animat::py::bind_development(m);
  animat::py::bind_body(m);
  animat::py::bind_physics(m);
  animat::py::bind_evolution(m);
}
