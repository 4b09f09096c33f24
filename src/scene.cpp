// The scene: the registry of built-in swim effects (each in its own file in src/effects/),
// parameter checks, and the pure pieces of the effects that tests use directly. Units and
// coefficient choices: docs/notes/physics.md.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "effects/effect_support.hpp"

namespace animat {
namespace {

constexpr double kPi = std::numbers::pi;

// --- parameter checks shared by SceneParams and PhysicsParams --------------------------------

template <class P>
void check_fields(P params, std::string_view section) {
  visit_fields(params, [&](const FieldInfo& info, auto& value) {
    using T = std::decay_t<decltype(value)>;
    auto fail = [&](const std::string& what) {
      throw ConfigError(fmt::format("{}.{}: {}", section, info.name, what));
    };
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, int>) {
      if (!std::isfinite(static_cast<double>(value)) ||
          !info.bounds.contains(static_cast<double>(value)))
        fail(fmt::format("{} is out of range ({})", value, info.bounds.describe()));
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!info.choices.empty() &&
          std::find(info.choices.begin(), info.choices.end(), value) == info.choices.end())
        fail(fmt::format("unknown value '{}' (expected one of {})", value,
                         fmt::join(info.choices, ", ")));
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      for (std::size_t i = 0; i < value.size(); ++i) {
        if (!info.choices.empty() &&
            std::find(info.choices.begin(), info.choices.end(), value[i]) == info.choices.end())
          fail(fmt::format("unknown entry '{}' (expected any of {})", value[i],
                           fmt::join(info.choices, ", ")));
        for (std::size_t j = 0; j < i; ++j)
          if (value[j] == value[i]) fail(fmt::format("entry '{}' is listed twice", value[i]));
      }
    }
  });
}

}  // namespace

// --- public pieces -------------------------------------------------------------------------------

Body swim_body(const Body& in) {
  Body b = in;
  const int n = b.node_count();
  double scale = 1.0;
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 2; ++c) {
      b.positions(i, c) = static_cast<double>(static_cast<float>(in.positions(i, c)));
      scale = std::max(scale, std::abs(in.positions(i, c)));
    }
  }
  const double tol = 1e-6 * scale;
  for (int s = 0; s < b.spring_count() && s < b.rest_lengths.size(); ++s) {
    const int i = b.springs(s, 0), j = b.springs(s, 1);
    if (i < 0 || j < 0 || i >= n || j >= n) continue;
    const double dx = b.positions(j, 0) - b.positions(i, 0),
                 dy = b.positions(j, 1) - b.positions(i, 1);
    const double len = std::sqrt(dx * dx + dy * dy);  // as Springs measures it
    if (std::abs(len - b.rest_lengths(s)) <= tol) b.rest_lengths(s) = len;
  }
  const auto px = [&](int i) { return b.positions(i, 0); };
  const auto py = [&](int i) { return b.positions(i, 1); };
  for (int r = 0; r < b.region_count() && r < b.rest_areas.size(); ++r) {
    const auto& loop = b.regions[static_cast<std::size_t>(r)];
    if (std::any_of(loop.begin(), loop.end(), [&](int v) { return v < 0 || v >= n; })) continue;
    double perimeter = 0.0;
    for (std::size_t q = 0; q < loop.size(); ++q) {
      const int i = loop[q], j = loop[(q + 1) % loop.size()];
      perimeter += std::hypot(px(j) - px(i), py(j) - py(i));
    }
    const double area = 0.5 * effects::twice_area(px, py, loop);
    if (std::abs(area - b.rest_areas(r)) <= tol * perimeter) b.rest_areas(r) = area;
  }
  return b;
}

double actuation_start_time(double frequency, double phase) {
  double theta = std::fmod(phase, kPi);
  if (theta < 0.0) theta += kPi;
  if (theta == 0.0) return 0.0;
  if (!(frequency > 0.0)) return std::numeric_limits<double>::infinity();
  return (kPi - theta) / frequency;
}

double actuation_term(double amplitude, double frequency, double phase, double t) {
  if (!(t >= actuation_start_time(frequency, phase))) return 0.0;
  return amplitude * std::sin(frequency * t + phase);
}

double implicit_quadratic_drag(double w, double c_dt) {
  return 2.0 * w / (1.0 + std::sqrt(1.0 + 4.0 * c_dt * std::abs(w)));
}

void validate(const SceneParams& params) {
  check_fields(params, "scene");
  if (params.ground_friction_kinetic > params.ground_friction_static)
    throw ConfigError(
        fmt::format("scene.ground_friction_kinetic: {} is above scene.ground_friction_static = {} "
                    "(Coulomb friction needs mu_k <= mu_s)",
                    params.ground_friction_kinetic, params.ground_friction_static));
  if (params.chemical_source.size() != 2)
    throw ConfigError(
        fmt::format("scene.chemical_source: expected [x, y] (2 numbers), got {} numbers",
                    params.chemical_source.size()));
  for (double v : params.chemical_source)
    if (!std::isfinite(v) || std::abs(v) > kMaxLength)
      throw ConfigError(fmt::format("scene.chemical_source: {} is out of range (finite, |x| <= {})",
                                    v, kMaxLength));
}

void validate(const PhysicsParams& params) { check_fields(params, "physics"); }

std::unique_ptr<Effect> make_effect(std::string_view name, const Body& body,
                                    const SceneParams& scene, const PhysicsParams& physics) {
  if (name == "springs") return effects::make_springs(body, scene);
  if (name == "actuation") return effects::make_actuation(body, physics);
  if (name == "pressure") return effects::make_pressure(body, scene);
  if (name == "drag") return effects::make_drag(body, scene, physics);
  if (name == "collisions") return effects::make_collisions(body, scene);
  if (name == "skin_collision") return effects::make_skin_collision(body, scene);
  if (name == "gravity") return effects::make_gravity(scene);
  if (name == "ground")
    return scene.ground_contact == "compliant" ? effects::make_compliant_ground(scene)
                                               : effects::make_ground(scene);
  throw ConfigError(fmt::format("scene.effects: unknown effect '{}' (expected any of {})", name,
                                fmt::join(kSceneEffectNames, ", ")));
}

}  // namespace animat
