#pragma once
// Private helpers for reading untrusted JSON (genome files, checkpoints): bounded nesting and
// element counts while parsing, and integer reads that never wrap or convert out of range.
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace animat::detail {

/// Thrown from the parser callback; callers turn it into their own error type.
struct JsonLimit : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Parses with at most `max_depth` levels of nesting and, if `max_items` >= 0, at most `max_items`
/// objects closed at depth `item_depth` (the elements of an array at depth item_depth - 1). Nothing
/// deeper or longer is ever built, so memory and recursion stay bounded.
inline nlohmann::json parse_bounded(std::string_view text, int max_depth, int item_depth = -1, long long max_items = -1) {
  long long items = 0;
  auto callback = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json&) {
    using E = nlohmann::json::parse_event_t;
    if ((event == E::object_start || event == E::array_start) && depth >= max_depth)
      throw JsonLimit("nesting deeper than " + std::to_string(max_depth) + " levels");
    if (max_items >= 0 && event == E::object_end && depth == item_depth && ++items > max_items)
      throw JsonLimit("more than " + std::to_string(max_items) + " items");
    return true;
  };
  return nlohmann::json::parse(text.begin(), text.end(), callback);
}

/// An integer JSON value in [lo, hi], whatever integer type holds it; nullopt for anything else.
inline std::optional<long long> int_in(const nlohmann::json& v, long long lo, long long hi) {
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(hi) || static_cast<long long>(u) < lo) return std::nullopt;
    return static_cast<long long>(u);
  }
  if (!v.is_number_integer()) return std::nullopt;
  const auto x = v.get<std::int64_t>();
  if (x < lo || x > hi) return std::nullopt;
  return x;
}

/// A finite JSON number; nullopt for anything else.
inline std::optional<double> finite_number(const nlohmann::json& v) {
  if (!v.is_number()) return std::nullopt;
  const double x = v.get<double>();
  return std::isfinite(x) ? std::optional<double>(x) : std::nullopt;
}

/// A short description of a value for error messages (values come from parse_bounded, so their
/// nesting, and the recursion of dump(), is bounded).
inline std::string describe(const nlohmann::json& v) {
  std::string s = v.dump();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

}  // namespace animat::detail
