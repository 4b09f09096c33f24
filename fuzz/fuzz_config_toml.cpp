// libFuzzer target: the TOML config loader (config_from_toml) and --set overrides (apply_override).
//
// The first byte picks the entry point: even = the whole input is a TOML document; odd = every line
// of the rest is one --set assignment applied in turn. Failure = a crash, a sanitizer report, an
// exception other than animat::Error, or a broken oracle: an accepted config validates and
// round-trips exactly through to_toml.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "fuzz_util.hpp"

namespace {

void check_round_trip(const animat::Config& c) {
  using namespace animat;
  try {
    validate(c, "accepted");
  } catch (const Error&) {
    return;  // a failed override may leave a cross-field rule broken (the CLI exits on it)
  }
  Config back;
  try {
    back = config_from_toml(to_toml(c), "round trip");
  } catch (const Error& e) {
    fuzz::fail(std::string("to_toml output does not load back: ") + e.what());
  }
  if (!(back == c)) fuzz::fail("to_toml/config_from_toml round trip changed the config");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animat;
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] % 2 == 0) {
    try {
      check_round_trip(config_from_toml(text, "fuzz"));
    } catch (const Error&) {
    }
    return 0;
  }
  Config c;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    try {
      apply_override(c, text.substr(start, end - start));
    } catch (const Error&) {
    }
    start = end + 1;
  }
  check_round_trip(c);
  return 0;
}
