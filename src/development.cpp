#include "animat/development.hpp"

#include "animat/errors.hpp"

namespace animat {
Embryo develop(const Genome&, const GenomeParams&, const GrnParams&, const DevelopmentParams&) {
  throw Error("develop: not implemented yet");
}
}  // namespace animat
