#pragma once
// Field descriptors for the per-stage parameter structs.
//
// Every params struct (GrnParams, SceneParams, ...) lists its fields once, in a visit_fields()
// overload. TOML loading, printing, --set overrides, validation and the Python dict view are all
// written once against that list, so a new parameter is one line in one place.
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace animat {

/// Closed or open numeric interval a field must lie in.
struct Bounds {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static constexpr Bounds any() { return {}; }
  static constexpr Bounds positive() {
    return {0.0, std::numeric_limits<double>::infinity(), true, false};
  }
  static constexpr Bounds non_negative() {
    return {0.0, std::numeric_limits<double>::infinity(), false, false};
  }
  static constexpr Bounds closed(double a, double b) { return {a, b, false, false}; }
  static constexpr Bounds at_least(double a) {
    return {a, std::numeric_limits<double>::infinity(), false, false};
  }
  static constexpr Bounds unit() { return closed(0.0, 1.0); }
  /// (0, b]: a strictly positive quantity with a representable maximum.
  static constexpr Bounds positive_upto(double b) { return {0.0, b, true, false}; }
  /// [0, b].
  static constexpr Bounds upto(double b) { return closed(0.0, b); }

  [[nodiscard]] bool contains(double x) const {
    if (std::isnan(x)) return false;
    if (lo_open ? !(x > lo) : !(x >= lo)) return false;
    if (hi_open ? !(x < hi) : !(x <= hi)) return false;
    return true;
  }
  [[nodiscard]] std::string describe() const;
};

/// Limits derived from what the code can represent (docs/reliability.md, "Bounds from
/// representation"). Cell positions, forces, masses, damping and time steps reach Box2D as float
/// (FLT_MAX = 3.4e38, b2Assert(b2IsValid(...)) on positions and damping); a mass below FLT_MIN
/// would become 0, which Box2D silently replaces by 1. With every length <= kMaxLength, every
/// coefficient (stiffness, damping, drag, pressure, force cap, frequency) <= kMaxCoefficient and
/// every mass in [kMinMass, kMaxMass], the largest development force on a cell (4095 neighbours x
/// 1e12 x an overlap of 2.2e7) is 9e22 and the velocity it adds in one step at most 9e34, below
/// FLT_MAX; the swim checks every step in double before Box2D sees it (physics.cpp, check_forces).
inline constexpr double kMaxLength = 1e6;
inline constexpr double kMaxCoefficient = 1e12;
inline constexpr double kMinMass = 1e-12;
inline constexpr double kMaxMass = 1e12;
/// Shortest Box2D time step: 1/dt stays finite in float, and a step is not rounded to 0.
inline constexpr double kMinTimeStep = 1e-9;

/// A config field's part in a run's identity (run_identity(): what a resume may not change).
enum class Identity : std::uint8_t {
  defines_run,  ///< part of the identity: a resume may not change it
  resumable,    ///< a stopping or resource knob (generations, threads, ...): a resume may change it
  /// added after runs were first checkpointed, with a default that reproduces them: part
  late,
  ///< of the identity only away from its default, so those runs still resume
};

/// Static description of one field: name, meaning, allowed values, part in a run's identity.
struct FieldInfo {
  std::string_view name;
  std::string_view doc;
  Bounds bounds = Bounds::any();
  /// Allowed words for string and string-list fields; empty means any.
  std::span<const std::string_view> choices = {};
  /// A new key whose default keeps results as they were is Identity::late.
  Identity identity = Identity::defines_run;
};

/// Field value types a params struct may use.
template <class T>
concept ParamValue =
    std::same_as<T, bool> || std::same_as<T, int> || std::same_as<T, std::int64_t> ||
    std::same_as<T, double> || std::same_as<T, std::string> ||
    std::same_as<T, std::vector<std::string>> || std::same_as<T, std::vector<double>>;

/// Whether `name` is listed in an effects list (scene.effects, development.effects).
[[nodiscard]] inline bool has_effect(const std::vector<std::string>& effects,
                                     std::string_view name) {
  for (const auto& e : effects)
    if (e == name) return true;
  return false;
}

}  // namespace animat
