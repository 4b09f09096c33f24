// Effect "ground" (crawl world, docs/worlds.md): the horizontal floor y = ground_height, which cell
// centres cannot pass through, with Coulomb friction (static μ_s, kinetic μ_k). Off in the default
// scene.
#include <cmath>
#include <memory>
#include <string_view>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// A constraint effect, resolved within the step like "collisions" (it runs after it): with every
/// force already in s.fx, s.fy, the velocity Box2D will give cell i is w = v + h·F/m and its end
/// position y + h·w_y (+ the position correction a collision asked for). If that end position is
/// below the floor y0, the contact is resolved by one impulse J = (J_t, J_n) on the cell:
///  - normal (inelastic): w_y' = (y0 − y − c_y)/h, so the cell ends the step exactly on the floor;
///    J_n = m·(w_y' − w_y) >= 0 (the floor only pushes);
///  - tangential (Coulomb, impulse form): the impulse that stops the cell, J_stick = −m·w_x, is
///    taken if |J_stick| <= μ_s·J_n (sticking: no sliding below the static limit); otherwise the
///    cell slides and J_t = −sign(w_x)·μ_k·J_n (kinetic friction; μ_k <= μ_s, so J_t never reverses
///    the sliding velocity).
/// For a cell resting on the floor under a constant force (F_x, −m·g + F_y) this is exactly
/// Coulomb's law per step: J_n = h·(m·g − F_y), it sticks iff |F_x| <= μ_s·(m·g − F_y), and
/// otherwise accelerates at (F_x ∓ μ_k·(m·g − F_y))/m. The impulses reach Box2D as forces J/h.
/// Counted: contacts (cell-steps in which the floor pushed) and slips (of those, sliding ones).
/// Nothing is allocated.
class Ground final : public Effect {
 public:
  explicit Ground(const SceneParams& p)
      : y0_(p.ground_height), mu_s_(p.ground_friction_static), mu_k_(p.ground_friction_kinetic) {}
  std::string_view name() const override { return "ground"; }
  Stage stage() const override { return Stage::constraint; }
  void apply(SwimState& s) override {
    ++calls_;
    const double h = s.h, inv_h = 1.0 / s.h, m = s.mass, kv = s.h * s.inv_mass;
    const double* y = s.y.data();
    const double* vx = s.vx.data();
    const double* vy = s.vy.data();
    const double* cy = s.cy.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const bool corrected = s.position_corrected;
    long contacts = 0, slips = 0;
    for (int i = 0; i < s.n; ++i) {
      const double c = corrected ? cy[i] : 0.0;
      const double wy = vy[i] + kv * fy[i];
      if (!(y[i] + h * wy + c < y0_)) continue;  // stays above the floor (or NaN: the stepper reports it)
      const double jn = m * ((y0_ - y[i] - c) * inv_h - wy);
      const double wx = vx[i] + kv * fx[i];
      double jt = -m * wx;
      if (!(std::abs(jt) <= mu_s_ * jn)) {
        jt = -std::copysign(mu_k_ * jn, wx);
        ++slips;
      }
      fx[i] += jt * inv_h;
      fy[i] += jn * inv_h;
      ++contacts;
    }
    s.counters.ground_contacts += contacts;
    s.counters.ground_slips += slips;
  }

 private:
  double y0_, mu_s_, mu_k_;
};

}  // namespace

std::unique_ptr<Effect> make_ground(const SceneParams& scene) { return std::make_unique<Ground>(scene); }

}  // namespace animat::effects
