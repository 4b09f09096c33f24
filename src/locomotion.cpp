// The locomotion mode of a swim (locomotion.hpp).
#include "animat/locomotion.hpp"

namespace animat {}  // namespace animat
