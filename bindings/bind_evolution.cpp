#include "bindings.hpp"

namespace animat::py {
void bind_evolution(nanobind::module_&) {}  // filled in by the evolution stage
}  // namespace animat::py
