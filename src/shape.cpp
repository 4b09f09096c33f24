// Shape measures of a body at rest (shape.hpp).
#include "animat/shape.hpp"

namespace animat {}  // namespace animat
