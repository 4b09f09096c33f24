#include "bindings.hpp"

namespace animat::py {
void bind_development(nanobind::module_&) {}  // filled in by the development stage
}  // namespace animat::py
