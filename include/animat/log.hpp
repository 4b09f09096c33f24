#pragma once
// Logging goes through spdlog's default logger, the one process-wide singleton we allow.
#include <spdlog/spdlog.h>

#include <string_view>

namespace animat {

/// Sets the level from a name (trace, debug, info, warn, error, critical, off); throws ConfigError
/// otherwise.
void set_log_level(std::string_view level);

}  // namespace animat
