#pragma once
// Internal: factories of the built-in swim effects (one file each in src/effects/) and the small
// geometric pieces several of them share. Not a public header.
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "animat/body.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"

namespace animat::effects {

[[nodiscard]] std::unique_ptr<Effect> make_springs(const Body& body, const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_actuation(const Body& body,
                                                     const PhysicsParams& physics);
[[nodiscard]] std::unique_ptr<Effect> make_pressure(const Body& body, const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_drag(const Body& body, const SceneParams& scene,
                                                const PhysicsParams& physics);
[[nodiscard]] std::unique_ptr<Effect> make_skin_collision(const Body& body,
                                                          const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_collisions(const Body& body, const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_gravity(const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_ground(const SceneParams& scene);
[[nodiscard]] std::unique_ptr<Effect> make_compliant_ground(const SceneParams& scene);

inline int as_int(Eigen::Index i) { return static_cast<int>(i); }
inline std::size_t at(int i) { return static_cast<std::size_t>(i); }

/// Twice the signed area of a vertex loop, the way Pressure computes it: triangles by the cross
/// product of two edges, other loops by Σ x_i·(y_next − y_prev).
template <class X, class Y>
double twice_area(const X& x, const Y& y, const std::vector<int>& loop) {
  const std::size_t k = loop.size();
  if (k == 3) {
    const int a = loop[0], b = loop[1], c = loop[2];
    return (x(b) - x(a)) * (y(c) - y(a)) - (x(c) - x(a)) * (y(b) - y(a));
  }
  double twice = 0.0;
  for (std::size_t q = 0; q < k; ++q)
    twice += x(loop[q]) * (y(loop[(q + 1) % k]) - y(loop[(q + k - 1) % k]));
  return twice;
}

/// Closest point of segment ab to p: the parameter t in [0, 1], the point and the squared distance.
struct SegmentHit {
  double t, qx, qy, d2;
};
inline SegmentHit closest_on_segment(double px, double py, double ax, double ay, double bx,
                                     double by) {
  const double ex = bx - ax, ey = by - ay;
  const double l2 = ex * ex + ey * ey;
  double t = l2 > 0.0 ? ((px - ax) * ex + (py - ay) * ey) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double qx = ax + t * ex, qy = ay + t * ey;
  const double dx = px - qx, dy = py - qy;
  return {t, qx, qy, dx * dx + dy * dy};
}

/// The floor's Coulomb friction (effect ground, docs/worlds.md) for a normal impulse jn >= 0 per
/// unit mass on a cell whose tangential velocity is wx: the velocity change that stops the cell,
/// −wx, if |wx| <= μ_s·jn (sticking), otherwise −sign(wx)·μ_k·jn (sliding; μ_k <= μ_s, so it never
/// reverses the cell). `slid` says which.
struct FloorFriction {
  double dvx;
  bool slid;
};
inline FloorFriction floor_friction(double wx, double jn, double mu_s, double mu_k) {
  if (std::abs(wx) <= mu_s * jn) return {-wx, false};
  return {-std::copysign(mu_k * jn, wx), true};
}

}  // namespace animat::effects
