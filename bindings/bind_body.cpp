#include "bindings.hpp"

namespace animat::py {
void bind_body(nanobind::module_&) {}  // filled in by the body stage
}  // namespace animat::py
