#include <nanobind/nanobind.h>

#include <cstring>

#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/run.hpp"
#include "bindings.hpp"

namespace nb = nanobind;

namespace {
// Messages can quote bytes of a bad input file; invalid UTF-8 is replaced, never a second
// exception.
void set_error(PyObject* type, const char* message) {
  PyObject* text =
      PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)), "replace");
  if (!text) {
    PyErr_Clear();
    PyErr_SetString(type, "animat: error message could not be decoded");
    return;
  }
  PyErr_SetObject(type, text);
  Py_DECREF(text);
}
}  // namespace

NB_MODULE(_core, m) {
  m.doc() =
      "animat: co-evolution of morphology and control of soft-bodied multicellular animats "
      "(compiled core)";
  m.attr("__version__") = ANIMAT_VERSION;
  // C++ errors become Python exceptions carrying the C++ message.
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const animat::RunDirectoryBusy& e) {
      set_error(PyExc_BlockingIOError, e.what());
    } catch (const animat::RunExists& e) {
      set_error(PyExc_FileExistsError, e.what());
    } catch (const animat::IoError& e) {
      set_error(PyExc_OSError, e.what());
    } catch (const animat::Interrupted& e) {
      // Ctrl-C in a Python objective (animat.evaluate, GA.step, ...)
      set_error(PyExc_KeyboardInterrupt, e.what());
    } catch (const animat::SimulationError& e) {
      set_error(PyExc_RuntimeError, e.what());
    } catch (const animat::Error& e) {
      set_error(PyExc_ValueError, e.what());
    }
  });
  animat::py::bind_config(m);
  animat::py::bind_genome(m);
  animat::py::bind_development(m);
  animat::py::bind_body(m);
  animat::py::bind_physics(m);
  animat::py::bind_evolution(m);
  animat::py::bind_research(m);
  animat::py::bind_locomotion(m);
}
