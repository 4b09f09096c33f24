// Effect "springs": damped Hooke springs, the same stiffness and damping for all [paper §4].
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// Damped Hooke springs: f = k·(len − rest) + c·(relative velocity along the spring), equal and
/// opposite on the two ends. Reads the current rest lengths from the state (actuation writes them).
/// apply() adds the elastic part and keeps the unit vectors; apply_velocity() adds the damping part
/// at the evaluation velocity s.ux, s.uy.
class Springs final : public Effect {
 public:
  Springs(const Body& body, const SceneParams& p) : k_(p.spring_stiffness), c_(p.spring_damping) {
    const int m = body.spring_count();
    a_.resize(at(m));
    b_.resize(at(m));
    for (int s = 0; s < m; ++s) {
      a_[at(s)] = body.springs(s, 0);
      b_[at(s)] = body.springs(s, 1);
    }
    ex_.assign(at(m), 0.0);
    ey_.assign(at(m), 0.0);
  }
  std::string_view name() const override { return "springs"; }
  void apply(SwimState& s) override {
    ++calls_;
    const int* a = a_.data();
    const int* b = b_.data();
    const double* x = s.x.data();
    const double* y = s.y.data();
    const double* rest = s.rest.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    double* ex = ex_.data();
    double* ey = ey_.data();
    const std::size_t m = a_.size();
    for (std::size_t e = 0; e < m; ++e) {
      const int i = a[e], j = b[e];
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      const double len = std::sqrt(dx * dx + dy * dy);
      if (!(len > 0.0)) {  // coincident ends: no direction, no force
        ex[e] = 0.0;
        ey[e] = 0.0;
        continue;
      }
      const double inv = 1.0 / len;
      const double ux = dx * inv, uy = dy * inv;
      ex[e] = ux;
      ey[e] = uy;
      const double f = k_ * (len - rest[e]);
      const double gx = f * ux, gy = f * uy;
      fx[i] += gx;
      fy[i] += gy;
      fx[j] -= gx;
      fy[j] -= gy;
    }
  }
  bool velocity_dependent() const override { return c_ != 0.0; }
  void apply_velocity(SwimState& s) override {
    const int* a = a_.data();
    const int* b = b_.data();
    const double* vx = s.ux.data();
    const double* vy = s.uy.data();
    const double* ex = ex_.data();
    const double* ey = ey_.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const std::size_t m = a_.size();
    for (std::size_t e = 0; e < m; ++e) {
      const int i = a[e], j = b[e];
      const double f = c_ * ((vx[j] - vx[i]) * ex[e] + (vy[j] - vy[i]) * ey[e]);
      const double gx = f * ex[e], gy = f * ey[e];
      fx[i] += gx;
      fy[i] += gy;
      fx[j] -= gx;
      fy[j] -= gy;
    }
  }

 private:
  double k_, c_;
  std::vector<int> a_, b_;
  std::vector<double> ex_, ey_;  // unit vectors of the current step
};

}  // namespace

std::unique_ptr<Effect> make_springs(const Body& body, const SceneParams& scene) {
  return std::make_unique<Springs>(body, scene);
}

}  // namespace animat::effects
