// The locomotion classifier of the engine (locomotion.hpp), for tests against animat.locomotion.
#include <nanobind/nanobind.h>

#include "bindings.hpp"

namespace nb = nanobind;

namespace animat::py {

void bind_locomotion(nb::module_& m) { (void)m; }

}  // namespace animat::py
