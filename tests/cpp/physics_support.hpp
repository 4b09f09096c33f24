#pragma once
// Hand-made bodies shared by the physics test files (test_physics, test_collisions).
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/random.hpp"
#include "animat/scene.hpp"
#include "animat/types.hpp"

namespace animat {
namespace {

constexpr double kPi = std::numbers::pi;

// --- hand-made bodies
// -----------------------------------------------------------------------------

double dist(const Points& p, int i, int j) { return (p.row(i) - p.row(j)).norm(); }

/// A body from explicit parts; rest lengths and areas measured from the positions unless given.
Body make_body(const Points& p, const std::vector<std::pair<int, int>>& springs,
               const std::vector<std::vector<int>>& regions,
               const std::vector<std::pair<int, int>>& skin) {
  Body b;
  b.positions = p;
  b.springs.resize(static_cast<Eigen::Index>(springs.size()), 2);
  b.rest_lengths.resize(static_cast<Eigen::Index>(springs.size()));
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const auto k = static_cast<Eigen::Index>(s);
    b.springs(k, 0) = springs[s].first;
    b.springs(k, 1) = springs[s].second;
    b.rest_lengths(k) = dist(p, springs[s].first, springs[s].second);
  }
  b.regions = regions;
  b.rest_areas.resize(static_cast<Eigen::Index>(regions.size()));
  for (std::size_t r = 0; r < regions.size(); ++r)
    b.rest_areas(static_cast<Eigen::Index>(r)) = polygon_area(p, regions[r]);
  b.skin.resize(static_cast<Eigen::Index>(skin.size()), 2);
  for (std::size_t e = 0; e < skin.size(); ++e) {
    b.skin(static_cast<Eigen::Index>(e), 0) = skin[e].first;
    b.skin(static_cast<Eigen::Index>(e), 1) = skin[e].second;
  }
  return b;
}

Points points(const std::vector<std::pair<double, double>>& xy) {
  Points p(static_cast<Eigen::Index>(xy.size()), 2);
  for (std::size_t i = 0; i < xy.size(); ++i) {
    p(static_cast<Eigen::Index>(i), 0) = xy[i].first;
    p(static_cast<Eigen::Index>(i), 1) = xy[i].second;
  }
  return p;
}

/// Two nodes on the x axis at distance d joined by one spring of rest length l0 (also a skin edge).
[[maybe_unused]] Body two_nodes(double d, double l0) {
  Body b = make_body(points({{0.0, 0.0}, {d, 0.0}}), {{0, 1}}, {}, {{0, 1}});
  b.rest_lengths(0) = l0;
  return b;
}

/// Unit square, CCW, one region, four edge springs, all skin.
[[maybe_unused]] Body square() {
  return make_body(points({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), {{0, 1}, {1, 2}, {2, 3}, {0, 3}},
                   {{0, 1, 2, 3}}, {{0, 1}, {1, 2}, {2, 3}, {0, 3}});
}

/// Triangular lattice of nx × ny cells (spacing 1) through build_body, with oscillators.
[[maybe_unused]] Points lattice_points(int nx, int ny, double jitter = 0.0,
                                       std::uint64_t seed = 1) {
  Rng rng(seed);
  Points p(nx * ny, 2);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      p(j * nx + i, 0) = i + (j % 2 ? 0.5 : 0.0) + jitter * rng.uniform(-1.0, 1.0);
      p(j * nx + i, 1) = j * std::sqrt(3.0) / 2.0 + jitter * rng.uniform(-1.0, 1.0);
    }
  return p;
}

enum class Drive { none, wave, random };

[[maybe_unused]] Body swimmer(const Points& p, Drive drive, double amplitude = 0.2,
                              double frequency = 4.0, std::uint64_t seed = 7) {
  const int n = static_cast<int>(p.rows());
  Vector a = Vector::Constant(n, drive == Drive::none ? 0.0 : amplitude);
  Vector f = Vector::Constant(n, frequency);
  Vector ph = Vector::Zero(n);
  Rng rng(seed);
  for (int i = 0; i < n; ++i) {
    if (drive == Drive::wave) ph(i) = std::fmod(2.0 * kPi * p(i, 0) / 4.0, 2.0 * kPi);
    if (drive == Drive::random) {
      a(i) = rng.uniform(0.0, amplitude);
      f(i) = rng.uniform(0.5, 12.0);
      ph(i) = rng.uniform(0.0, 2.0 * kPi);
    }
  }
  return build_body(p, a, f, ph);
}

SceneParams scene_with(std::vector<std::string> effects) {
  SceneParams s;
  s.effects = std::move(effects);
  return s;
}

/// Adds a constant force (fx, fy)·weight_i to every cell i (a stand-in for future effects such as
/// gravity). Without weights every cell gets (fx, fy).
class ConstantForce final : public Effect {
 public:
  ConstantForce(double fx, double fy, std::vector<double> weights = {})
      : fx_(fx), fy_(fy), w_(std::move(weights)) {}
  std::string_view name() const override { return "constant_force"; }
  void apply(SwimState& s) override {
    ++calls_;
    for (int i = 0; i < s.n; ++i) {
      const double w = w_.empty() ? 1.0 : w_[static_cast<std::size_t>(i)];
      s.fx[static_cast<std::size_t>(i)] += w * fx_;
      s.fy[static_cast<std::size_t>(i)] += w * fy_;
    }
  }

 private:
  double fx_, fy_;
  std::vector<double> w_;
};

/// A constant force f along y on every cell.
class ConstantForceY final : public Effect {
 public:
  explicit ConstantForceY(double f) : f_(f) {}
  std::string_view name() const override { return "constant_force_y"; }
  void apply(SwimState& s) override {
    for (int i = 0; i < s.n; ++i) s.fy[static_cast<std::size_t>(i)] += f_;
  }

 private:
  double f_;
};

}  // namespace
}  // namespace animat
