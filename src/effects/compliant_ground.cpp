// Effect "ground" with scene.ground_contact = "compliant" (crawl world, docs/worlds.md): the floor
// y = ground_height as a stiff, damped spring under every cell centre below it, with regularised
// Coulomb friction. Unlike the impulse floor (ground.cpp), its force is a continuous function of
// the state, so a swim on it is the solution of one ordinary differential equation that a smaller
// step refines; the impulse floor's contact events (touchdown, stick/slip switches) fall on
// different steps at different step sizes.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string_view>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// A velocity-dependent force effect, solved implicitly per cell (backward Euler in its own force,
/// every force computed before it included, as drag's scheme is), so that it is stable at any
/// floor stiffness, damping and slip speed. For a cell at y with end-of-step velocity w (Box2D:
/// y' = y + h·w), a = v + h·F/m its end velocity without the floor:
///  - normal (Hunt–Crossley, linear): the penetration d = y0 − y' and its rate −w_y give
///    F_n = k_g·d·(1 − λ·w_y) for d > 0 and 1 − λ·w_y > 0, else 0 (k_g = ground_stiffness, λ =
///    ground_damping). It is zero at first touch and grows with the penetration, so the force is a
///    continuous function of the state (a Kelvin–Voigt damper would jump at touchdown), and it
///    dissipates in proportion to the impact speed. With D = y0 − y − h·a_y, d = D − (h²/m)·F_n and
///    w_y = a_y + (h/m)·F_n, the law is a quadratic in F_n whose smaller root is the solution
///    (it keeps d >= 0 and 1 − λ·w_y >= 0), taken in the cancellation-free form 2·D·K/(B + √…);
///  - tangential: F_t = −μ·F_n·w_x / sqrt(w_x² + v_s²) (μ = ground_friction_kinetic, v_s =
///    ground_slip_speed): Coulomb's μ·F_n against sliding faster than v_s, a viscous grip below it.
///    w_x = a_x + h·F_t/m is monotone in w_x, with its root between 0 and a_x: solved by Newton's
///    method kept inside that bracket (bisection when a step leaves it), to 1e-13 of |a_x|.
/// The midpoint scheme's predictor pass evaluates it too (its forces are then discarded). Counted:
/// contacts (cell-steps with F_n > 0), slips (of those, |w_x| > v_s) and airborne steps (no cell
/// pushed). Nothing is allocated.
class CompliantGround final : public Effect {
 public:
  explicit CompliantGround(const SceneParams& p)
      : y0_(p.ground_height),
        mu_(p.ground_friction_kinetic),
        k_(p.ground_stiffness),
        lambda_(p.ground_damping),
        vs_(p.ground_slip_speed) {}
  std::string_view name() const override { return "ground"; }
  bool velocity_dependent() const override { return true; }
  void apply(SwimState& s) override {
    (void)s;
    ++calls_;
  }
  void apply_velocity(SwimState& s) override {
    const double h = s.h, m = s.mass, kv = h * s.inv_mass;
    const double alpha = h * h * s.inv_mass;
    long contacts = 0, slips = 0;
    for (int i = 0; i < s.n; ++i) {
      const auto u = at(i);
      const double ay = s.vy[u] + kv * s.fy[u];
      const double d = y0_ - s.y[u] - h * ay;         // penetration at the end without the floor
      const double grip = k_ * (1.0 - lambda_ * ay);  // k_g·(1 − λ·w_y) at that velocity
      if (!(d > 0.0 && grip > 0.0)) continue;         // no contact (or NaN: the stepper reports it)
      // F = (d − α·F)·(grip − k_g·λ·(h/m)·F): the smaller root of a·F² − b·F + d·grip = 0
      const double beta = k_ * lambda_ * kv;
      const double b = 1.0 + d * beta + alpha * grip;
      const double fn =
          2.0 * d * grip / (b + std::sqrt(std::max(0.0, b * b - 4.0 * alpha * beta * d * grip)));
      const double ax = s.vx[u] + kv * s.fx[u];
      const double wx = sliding_velocity(ax, kv * mu_ * fn);
      s.fy[u] += fn;
      s.fx[u] += m * (wx - ax) / h;
      ++contacts;
      slips += std::abs(wx) > vs_ ? 1 : 0;
    }
    if (s.predictor) return;
    s.counters.ground_contacts += contacts;
    s.counters.ground_slips += slips;
    if (contacts == 0) ++s.counters.airborne_steps;
  }

 private:
  /// The root w of w − a + g·w/sqrt(w² + v_s²) = 0 (g = h·μ·F_n/m >= 0): between 0 and a.
  double sliding_velocity(double a, double g) const {
    if (a == 0.0 || g == 0.0) return a;
    const double sign = a > 0.0 ? 1.0 : -1.0;
    const double target = std::abs(a);
    double lo = 0.0, hi = target, w = target;
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double r = std::sqrt(w * w + vs_ * vs_);
      const double f = w - target + g * w / r;
      if (f > 0.0)
        hi = w;
      else
        lo = w;
      const double df = 1.0 + g * vs_ * vs_ / (r * r * r);
      double next = w - f / df;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - w) <= 1e-13 * target) return sign * next;
      w = next;
    }
    return sign * w;
  }

  double y0_, mu_, k_, lambda_, vs_;
};

}  // namespace

std::unique_ptr<Effect> make_compliant_ground(const SceneParams& scene) {
  return std::make_unique<CompliantGround>(scene);
}

}  // namespace animat::effects
