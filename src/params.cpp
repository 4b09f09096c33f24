// Field descriptors (params.hpp): what every params struct's checks and documentation share.
#include "animat/params.hpp"

#include <fmt/format.h>

#include <cmath>

namespace animat {

std::string Bounds::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "any finite value";
  if (has_lo && !has_hi) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
  if (!has_lo && has_hi) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
  return fmt::format("in {}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
}

}  // namespace animat
