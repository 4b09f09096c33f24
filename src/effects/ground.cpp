// Effect "ground" (crawl world, docs/worlds.md): the horizontal floor y = ground_height, which cell
// centres cannot pass through, with Coulomb friction (static μ_s, kinetic μ_k). Off in the default
// scene.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string_view>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// A constraint effect, resolved within the step like "collisions" (it runs after it). With every
/// force already in s.fx, s.fy, the velocity Box2D will give cell i is w = v + h·F/m, and within
/// the step the cell moves in a straight line at w. A floor contact is an event at the time τ·h the
/// cell reaches the floor y0 (τ = 0 for a cell on it, moving down):
///  - normal (inelastic): the cell is put on the floor and its vertical velocity becomes w_y' = 0
///    (a cell that float rounding left below the floor gets w_y' = (y0 − y)/h instead, which puts
///    it back on the floor by the end of the step); J_n = m·(w_y' − w_y) > 0 (the floor only
///    pushes);
///  - tangential (Coulomb, impulse form, floor_friction()): the impulse that stops the cell,
///    J_stick = −m·w_x, is taken if |J_stick| <= μ_s·J_n (sticking: no sliding below the static
///    limit); otherwise the cell slides and J_t = −sign(w_x)·μ_k·J_n (kinetic friction; μ_k <= μ_s,
///    so J_t never reverses the sliding velocity);
///  - a contact after the start of the step (τ > 0) makes the cell's end position differ from
///    Box2D's x + h·w' (it moved at w until τ): the difference goes to the stepper as a position
///    correction (SwimState::cx, cy), as for a collision.
/// For a cell resting on the floor under a constant force (F_x, −m·g + F_y) this is exactly
/// Coulomb's law per step: J_n = h·(m·g − F_y), it sticks iff |F_x| <= μ_s·(m·g − F_y), and
/// otherwise accelerates at (F_x ∓ μ_k·(m·g − F_y))/m. The impulses reach Box2D as forces J/h.
///
/// With effect collisions in the scene these events are resolved inside the collisions' event
/// loop (src/effects/collisions.cpp, the same law), so that no floor impulse can undo a collision
/// guarantee; this effect then only adds the floor impulses that loop computed
/// (SwimState::ground_fx, ground_fy), booked as the floor's. Without collisions it resolves each
/// cell's contact itself. Counted: contacts (cell-steps in which the floor pushed), slips (of
/// those, sliding ones) and airborne steps (no cell pushed). Nothing is allocated.
class Ground final : public Effect {
 public:
  explicit Ground(const SceneParams& p)
      : y0_(p.ground_height),
        mu_s_(p.ground_friction_static),
        mu_k_(p.ground_friction_kinetic),
        in_collisions_(has_effect(p.effects, "collisions")) {}
  std::string_view name() const override { return "ground"; }
  Stage stage() const override { return Stage::constraint; }
  void apply(SwimState& s) override {
    ++calls_;
    if (in_collisions_) {  // resolved (and counted) by effect collisions
      bool pushed = false;
      for (int i = 0; i < s.n; ++i) {
        s.fx[at(i)] += s.ground_fx[at(i)];
        s.fy[at(i)] += s.ground_fy[at(i)];
        pushed = pushed || s.ground_fy[at(i)] != 0.0;
      }
      if (!pushed) ++s.counters.airborne_steps;
      return;
    }
    const double h = s.h, inv_h = 1.0 / s.h, m = s.mass, kv = s.h * s.inv_mass;
    long contacts = 0, slips = 0;
    for (int i = 0; i < s.n; ++i) {
      const auto k = at(i);
      const double y = s.y[k];
      const double wy = s.vy[k] + kv * s.fy[k];
      double tau = 0.0, wy_new = 0.0;
      if (y <= y0_) {
        wy_new = y < y0_ ? (y0_ - y) * inv_h : 0.0;
        if (!(wy < wy_new)) continue;  // leaves the floor (or NaN: the stepper reports it)
      } else if (wy < 0.0 && y + h * wy < y0_) {
        tau = std::min(1.0, (y - y0_) / (-h * wy));
      } else {
        continue;  // stays above the floor
      }
      const double jn = wy_new - wy;
      const double wx = s.vx[k] + kv * s.fx[k];
      const FloorFriction f = floor_friction(wx, jn, mu_s_, mu_k_);
      s.fx[k] += m * f.dvx * inv_h;
      s.fy[k] += m * jn * inv_h;
      ++contacts;
      slips += f.slid ? 1 : 0;
      if (tau > 0.0) {
        // moved at w until τ, then at w': ends at (x + τ·h·w_x + (1 − τ)·h·w_x', y0)
        if (!s.position_corrected) {
          for (int j = 0; j < s.n; ++j) s.cx[at(j)] = s.cy[at(j)] = 0.0;
          s.position_corrected = true;
        }
        s.cx[k] += tau * h * (-f.dvx);
        s.cy[k] += y0_ - y;
      }
    }
    s.counters.ground_contacts += contacts;
    s.counters.ground_slips += slips;
    if (contacts == 0) ++s.counters.airborne_steps;
  }

 private:
  double y0_, mu_s_, mu_k_;
  bool in_collisions_;
};

}  // namespace

std::unique_ptr<Effect> make_ground(const SceneParams& scene) {
  return std::make_unique<Ground>(scene);
}

}  // namespace animat::effects
