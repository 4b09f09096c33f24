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

/// Thrown by the counting pass of parse_bounded; callers turn it into their own error type.
struct JsonLimit : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Parses with at most `max_depth` levels of nesting and, if `max_items` >= 0, at most `max_items`
/// objects closed at depth `item_depth` (the elements of an array at depth item_depth - 1). A first
/// pass only counts (SAX, builds nothing), so a document beyond the limits is refused before any of
/// it is built and memory and recursion stay bounded; the second pass builds the document. Both are
/// linear in the text (nlohmann's parse with a callback is quadratic in an array's length).
/// `Json` is nlohmann::json everywhere but in tests/cpp/test_parse_cost.cpp, which parses into a
/// basic_json whose arrays count the iterator steps taken over them, to prove the linearity.
template <class Json = nlohmann::json>
Json parse_bounded(std::string_view text, int max_depth, int item_depth = -1,
                   long long max_items = -1) {
  struct Counter {
    int max_depth, item_depth;
    long long max_items;
    int depth = 0;
    long long items = 0;
    bool open() {
      if (depth >= max_depth)
        throw JsonLimit("nesting deeper than " + std::to_string(max_depth) + " levels");
      ++depth;
      return true;
    }
    bool close_object() {
      --depth;
      if (max_items >= 0 && depth == item_depth && ++items > max_items)
        throw JsonLimit("more than " + std::to_string(max_items) + " items");
      return true;
    }
    bool null() { return true; }
    bool boolean(bool) { return true; }
    bool number_integer(typename Json::number_integer_t) { return true; }
    bool number_unsigned(typename Json::number_unsigned_t) { return true; }
    bool number_float(typename Json::number_float_t, const typename Json::string_t&) {
      return true;
    }
    bool string(typename Json::string_t&) { return true; }
    bool binary(typename Json::binary_t&) { return true; }
    bool start_object(std::size_t) { return open(); }
    bool key(typename Json::string_t&) { return true; }
    bool end_object() { return close_object(); }
    bool start_array(std::size_t) { return open(); }
    bool end_array() {
      --depth;
      return true;
    }
    // A syntax error stops the count; the building pass below then reports it exactly as parse()
    // does.
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) {
      return false;
    }
  };
  Counter counter{max_depth, item_depth, max_items};
  Json::sax_parse(text.begin(), text.end(), &counter);
  return Json::parse(text.begin(), text.end());
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
