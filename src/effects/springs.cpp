// Effect "springs": damped Hooke springs, the same stiffness and damping for all [paper §4], or a
// stiffness per spring from the cells' evolved stiffness factors (docs/model.md).
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
/// It also meters the mechanical work of actuation: when a rest length changes from r₀ (previous
/// step) to r while the length goes from ℓ₀ to ℓ, the elastic energy ½k(ℓ − r)² receives
/// ΔW = k·(r − r₀)·((r + r₀)/2 − (ℓ + ℓ₀)/2) from the actuator: the midpoint rule of the power
/// k·(r − ℓ)·dr/dt over the step (second order; exactly zero over a period whenever ℓ is an affine
/// function of r, e.g. an undamped spring in its periodic forced response). docs/worlds.md.
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
    n_ = body.node_count();
    prev_rest_.assign(body.rest_lengths.data(),
                      body.rest_lengths.data() + body.rest_lengths.size());
    prev_rest_.resize(at(m), 0.0);
    prev_len_.assign(at(m), 0.0);
    for (int s = 0; s < m; ++s) {
      const int i = a_[at(s)], j = b_[at(s)];
      if (i < 0 || j < 0 || i >= n_ || j >= n_) continue;
      prev_len_[at(s)] = std::hypot(body.positions(j, 0) - body.positions(i, 0),
                                    body.positions(j, 1) - body.positions(i, 1));
    }
    work_positive_.assign(at(m), 0.0);
    work_absolute_.assign(at(m), 0.0);
    if (body.stiffness.size() == n_) {  // evolved stiffness: k per spring from its two end cells
      ks_.assign(at(m), k_);
      for (int s = 0; s < m; ++s) {
        const int i = a_[at(s)], j = b_[at(s)];
        if (i < 0 || j < 0 || i >= n_ || j >= n_) continue;
        ks_[at(s)] = k_ * spring_stiffness_factor(body.stiffness(i), body.stiffness(j));
      }
    }
  }
  std::string_view name() const override { return "springs"; }
  void apply(SwimState& s) override {
    ++calls_;
    if (ks_.empty())
      apply_elastic<false>(s);
    else
      apply_elastic<true>(s);
  }
  bool velocity_dependent() const override { return c_ != 0.0; }
  /// Σ ½·k·(ℓ − r)² at the current rest lengths.
  bool has_potential_energy() const override { return true; }
  double potential_energy(const SwimState& s) const override {
    double u = 0.0;
    for (std::size_t e = 0; e < a_.size(); ++e) {
      const int i = a_[e], j = b_[e];
      const double dx = s.x[at(j)] - s.x[at(i)], dy = s.y[at(j)] - s.y[at(i)];
      const double d = std::sqrt(dx * dx + dy * dy) - s.rest[e];
      u += 0.5 * (ks_.empty() ? k_ : ks_[e]) * d * d;
    }
    return u;
  }

 private:
  /// The elastic pass; kPerSpring: evolved stiffness (ks_), else the paper's uniform k_ (two loops,
  /// so the uniform default pays nothing for the option).
  template <bool kPerSpring>
  void apply_elastic(SwimState& s) {
    const int* a = a_.data();
    const int* b = b_.data();
    const double* x = s.x.data();
    const double* y = s.y.data();
    const double* rest = s.rest.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    double* ex = ex_.data();
    double* ey = ey_.data();
    double* prev_rest = prev_rest_.data();
    double* prev_len = prev_len_.data();
    double net = 0.0, positive = 0.0, absolute = 0.0;
    const std::size_t m = a_.size();
    const double* ks = ks_.data();
    for (std::size_t e = 0; e < m; ++e) {
      const int i = a[e], j = b[e];
      const double k = kPerSpring ? ks[e] : k_;
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      const double len = std::sqrt(dx * dx + dy * dy);
      // Actuation work (SwimCounters::actuation_work): only where the rest length changed.
      const double r = rest[e], r0 = prev_rest[e];
      if (r != r0) {
        const double dw = k * (r - r0) * (0.5 * (r + r0) - 0.5 * (len + prev_len[e]));
        const double pos = dw > 0.0 ? dw : 0.0;
        net += dw;
        positive += pos;
        absolute += std::abs(dw);
        work_positive_[e] += pos;
        work_absolute_[e] += std::abs(dw);
        prev_rest[e] = r;
      }
      prev_len[e] = len;
      if (!(len > 0.0)) {  // coincident ends: no direction, no force
        ex[e] = 0.0;
        ey[e] = 0.0;
        continue;
      }
      const double inv = 1.0 / len;
      const double ux = dx * inv, uy = dy * inv;
      ex[e] = ux;
      ey[e] = uy;
      const double f = k * (len - rest[e]);
      const double gx = f * ux, gy = f * uy;
      fx[i] += gx;
      fy[i] += gy;
      fx[j] -= gx;
      fy[j] -= gy;
    }
    if (absolute != 0.0) {
      s.counters.actuation_work += net;
      s.counters.actuation_work_positive += positive;
      s.counters.actuation_work_absolute += absolute;
    }
  }

 public:
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

  /// Each spring's work split evenly between its two end cells.
  void work_per_cell(std::vector<double>& positive, std::vector<double>& absolute) const {
    positive.assign(at(n_), 0.0);
    absolute.assign(at(n_), 0.0);
    for (std::size_t e = 0; e < a_.size(); ++e) {
      for (const int v : {a_[e], b_[e]}) {
        if (v < 0 || v >= n_) continue;
        positive[at(v)] += 0.5 * work_positive_[e];
        absolute[at(v)] += 0.5 * work_absolute_[e];
      }
    }
  }

 private:
  double k_, c_;
  std::vector<double> ks_;  // per-spring stiffness; empty = k_ for every spring
  int n_ = 0;
  std::vector<int> a_, b_;
  std::vector<double> ex_, ey_;  // unit vectors of the current step
  // Actuation work: rest length and length of every spring at the previous step, and each spring's
  // positive and absolute work so far.
  std::vector<double> prev_rest_, prev_len_;
  std::vector<double> work_positive_, work_absolute_;
};

}  // namespace

std::unique_ptr<Effect> make_springs(const Body& body, const SceneParams& scene) {
  return std::make_unique<Springs>(body, scene);
}

}  // namespace animat::effects

namespace animat {

bool actuation_work_per_cell(const Effect& springs, std::vector<double>& positive,
                             std::vector<double>& absolute) {
  const auto* s = dynamic_cast<const effects::Springs*>(&springs);
  if (s == nullptr) return false;
  s->work_per_cell(positive, absolute);
  return true;
}

}  // namespace animat
