#include "animat/log.hpp"

#include <fmt/format.h>

#include "animat/errors.hpp"

namespace animat {

void set_log_level(std::string_view name) {
  const auto level = spdlog::level::from_str(std::string(name));
  // from_str maps unknown names to "off"; only accept "off" when it was asked for.
  if (level == spdlog::level::off && name != "off")
    throw ConfigError(fmt::format(
        "--log-level {}: expected one of trace, debug, info, warn, error, critical, off", name));
  spdlog::set_level(level);
}

}  // namespace animat
