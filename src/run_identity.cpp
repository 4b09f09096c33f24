// A run's identity (run_identity.hpp): scheme 2 from the keys' descriptors, scheme 1 for older
// checkpoints.
#include "animat/run_identity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>
#include <utility>

namespace animat {
namespace {

#include "run_identity_v1_comments.inc"

// Without islands these keys change nothing, and no identity holds them (runs checkpointed before
// islands existed resume).
bool unused_island_key(const Config& c, std::string_view key) {
  return c.evolution.islands <= 1 &&
         (key == "evolution.islands" || key == "evolution.migration_interval" ||
          key == "evolution.migrants");
}

std::vector<std::string> keys_with(Identity identity) {
  std::vector<std::string> out;
  for (const auto& key : config_keys())
    if (config_identity(key) == identity) out.push_back(key);
  return out;
}

template <class Range>
bool contains(const Range& range, std::string_view key) {
  return std::find(std::begin(range), std::end(range), key) != std::end(range);
}

// Removes the line of `section.key` and the comment lines just above it from to_toml() text.
void erase_key_lines(std::string& text, std::string_view dotted) {
  const auto dot = dotted.find('.');
  const std::string header = fmt::format("[{}]\n", dotted.substr(0, dot));
  const std::string line = fmt::format("\n{} = ", dotted.substr(dot + 1));
  const auto section = text.find(header);
  if (section == std::string::npos) return;
  const auto next_section = text.find("\n[", section + header.size());
  const auto key = text.find(line, section);
  if (key == std::string::npos || (next_section != std::string::npos && key > next_section)) return;
  auto begin = key + 1;  // start of the key's line
  while (begin > 0) {    // and of the comment lines above it
    const auto prev = text.rfind('\n', begin - 2);
    const auto start = prev == std::string::npos ? 0 : prev + 1;
    if (text.compare(start, 1, "#") != 0) break;
    begin = start;
  }
  const auto end = text.find('\n', key + 1);
  text.erase(begin, end == std::string::npos ? std::string::npos : end + 1 - begin);
}

}  // namespace

const std::vector<std::string>& resumable_keys() {
  static const std::vector<std::string> keys = keys_with(Identity::resumable);
  return keys;
}

const std::vector<std::string>& late_keys() {
  static const std::vector<std::string> keys = keys_with(Identity::late);
  return keys;
}

std::uint64_t run_identity(const Config& config) {
  static const Config defaults;
  std::string text;
  for (const auto& key : config_keys()) {
    const Identity identity = config_identity(key);
    if (identity == Identity::resumable || unused_island_key(config, key)) continue;
    const ConfigValue value = get_value(config, key);
    if (identity == Identity::late && value == get_value(defaults, key)) continue;
    text += fmt::format("{} = {}\n", key, format_config_value(value));
  }
  return fnv1a(text);
}

std::uint64_t run_identity_v1(const Config& config) {
  const Config defaults;
  Config c = config;
  for (const auto& key : config_keys())
    if (contains(kV1ResumableKeys, key) || config_identity(key) == Identity::resumable)
      set_value(c, key, get_value(defaults, key));
  std::string text = to_toml(c, kV1Version, [](std::string_view key, std::string_view doc) {
    for (const auto& [k, comment] : kV1Comments)
      if (k == key) return std::string(comment);
    // a key newer than scheme 2: left out below unless away from its default
    return std::string(doc);
  });
  // The late keys at their defaults go, each with its comment line; so does every key newer than
  // scheme 2 (no scheme-1 run had it).
  for (const auto& key : config_keys()) {
    const bool late =
        contains(kV1LateKeys, key) || std::none_of(std::begin(kV1Comments), std::end(kV1Comments),
                                                   [&](const auto& e) { return e.first == key; });
    if (late && get_value(c, key) == get_value(defaults, key)) erase_key_lines(text, key);
  }
  // A section left without keys ([control] at its defaults) goes with its header.
  for (auto at = text.find("\n["); at != std::string::npos;) {
    const auto close = text.find("]\n", at);
    const auto after = close == std::string::npos ? std::string::npos : close + 2;
    if (after != std::string::npos &&
        (after == text.size() || text.compare(after, 2, "\n[") == 0)) {
      text.erase(at, after - at);
      at = text.find("\n[", at);
    } else {
      at = text.find("\n[", at + 1);
    }
  }
  // Without islands, the three island keys and their comment lines go.
  if (c.evolution.islands <= 1) {
    const auto key = text.find("\nislands = ");
    const auto last = text.find("\nmigrants = ", key == std::string::npos ? 0 : key);
    if (key != std::string::npos && last != std::string::npos) {
      const auto begin = text.rfind('\n', key - 1) + 1;  // the comment line of `islands`
      const auto end = text.find('\n', last + 1);        // the end of the `migrants` line
      text.erase(begin, end == std::string::npos ? std::string::npos : end + 1 - begin);
    }
  }
  return fnv1a(text);
}

}  // namespace animat
