#pragma once
// Internal: shared by the swim (physics.cpp) and development (development.cpp) worlds.
//
// Box2D 2.4 moves our cells, and only moves them: they are fixture-less, fixed-rotation dynamic
// bodies in a world without gravity, contacts, joints that carry force, or sleeping, so all that
// b2World::Step does to them is b2Island::Solve's semi-implicit Euler step in float:
//
//     v += h · invMass · (gravityScale · mass · gravity + force);   v *= 1 / (1 + h · damping);
//     if |h·v|² > b2_maxTranslation²:  v *= b2_maxTranslation / |h·v|;   c += h · v.
//
// Around it Box2D pays, per step, island building, a chain of island-linking joints (their
// constraint set-up and solve), profiling clock reads, sincos of every body's fixed angle and the
// fixture synchronisation: more than half of a 32-cell swim step. CellIntegrator performs the same
// float operations in the same order on flat arrays, so positions and velocities are bitwise what
// b2World::Step gives (tests/cpp/test_integrator.cpp steps both side by side); physics.integrator
// = "box2d" still runs a real b2World for the swim, as the reference.
#include <box2d/b2_settings.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace animat {

struct CellIntegrator {
  /// Box2D's m_sweep.c (= position, the mass centre is the origin) and velocity
  std::vector<float> px, py, vx, vy;
  float mass = 1.0f;      ///< b2MassData::mass as Box2D stores it
  float inv_mass = 1.0f;  ///< Box2D's m_invMass = 1 / mass
  float damping = 0.0f;   ///< b2BodyDef::linearDamping

  void set_mass(double m) {
    mass = static_cast<float>(m);
    if (mass <= 0.0f) mass = 1.0f;  // b2Body::SetMassData
    inv_mass = 1.0f / mass;
  }
  void reserve(std::size_t n) {
    for (auto* v : {&px, &py, &vx, &vy}) v->reserve(n);
  }
  /// A body created at (x, y) with velocity (ux, uy), rounded to float as b2BodyDef does.
  std::size_t add(double x, double y, double ux, double uy) {
    px.push_back(static_cast<float>(x));
    py.push_back(static_cast<float>(y));
    vx.push_back(static_cast<float>(ux));
    vy.push_back(static_cast<float>(uy));
    return px.size() - 1;
  }
  [[nodiscard]] std::size_t size() const { return px.size(); }

  /// One b2World::Step(h) of every cell with the force (fx[i], fy[i]) applied by
  /// ApplyForceToCenter (a zero force may also be passed as "not applied": the sum is the same).
  void step(float h, const double* fx, const double* fy) {
    const std::size_t n = px.size();
    const float h_inv_mass = h * inv_mass;
    const float gravity_term = (1.0f * mass) * 0.0f;  // gravityScale · mass · gravity, gravity = 0
    const float damp = 1.0f / (1.0f + h * damping);
    constexpr float kMaxT2 = b2_maxTranslationSquared;
    for (std::size_t i = 0; i < n; ++i) {
      // m_force is cleared to +0 after every step, then ApplyForceToCenter adds the float force.
      const float f_x = 0.0f + static_cast<float>(fx[i]);
      const float f_y = 0.0f + static_cast<float>(fy[i]);
      float ux = vx[i] + h_inv_mass * (gravity_term + f_x);
      float uy = vy[i] + h_inv_mass * (gravity_term + f_y);
      ux *= damp;
      uy *= damp;
      const float tx = h * ux, ty = h * uy;
      const float t2 = tx * tx + ty * ty;
      if (t2 > kMaxT2) {
        const float ratio = b2_maxTranslation / std::sqrt(t2);
        ux *= ratio;
        uy *= ratio;
      }
      px[i] = px[i] + h * ux;
      py[i] = py[i] + h * uy;
      vx[i] = ux;
      vy[i] = uy;
    }
  }
};

}  // namespace animat
