#include "bindings.hpp"

namespace animat::py {
void bind_physics(nanobind::module_&) {}  // filled in by the physics stage
}  // namespace animat::py
