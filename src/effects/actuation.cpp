// Effect "actuation": eq. 2, the oscillating rest lengths, with the phase-delayed start [paper §3].
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include <limits>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// Eq. 2: rest = (1 + term_1 + term_2)·L0, term = a·sin(f·t + φ) once the cell has started
/// (actuation_start_time). sin/cos are advanced by an exact-angle rotation each step and recomputed
/// directly every kResync steps; a cell starts exactly at its first step at or after its start
/// time.
class Actuation final : public Effect {
 public:
  static constexpr long kResync = 1024;

  Actuation(const Body& body, const PhysicsParams& physics) {
    const int n = body.node_count();
    const int m = body.spring_count();
    const double h = physics.dt / physics.substeps;
    nodes_.resize(at(n));
    for (int i = 0; i < n; ++i) {
      Node& c = nodes_[at(i)];
      c.amplitude = body.amplitude.size() == n ? body.amplitude(i) : 0.0;
      c.frequency = body.frequency.size() == n ? body.frequency(i) : 0.0;
      c.phase = body.phase.size() == n ? body.phase(i) : 0.0;
      const double t0 = actuation_start_time(c.frequency, c.phase);
      const double k0 = std::ceil(t0 / h);
      c.start_step = (std::isfinite(k0) && k0 < 1e15) ? static_cast<long>(k0)
                                                      : std::numeric_limits<long>::max();
      c.cos_step = std::cos(c.frequency * h);
      c.sin_step = std::sin(c.frequency * h);
      if (c.amplitude == 0.0) c.start_step = std::numeric_limits<long>::max();  // never contributes
    }
    term_.assign(at(n), 0.0);
    a_.resize(at(m));
    b_.resize(at(m));
    rest0_.resize(at(m));
    for (int s = 0; s < m; ++s) {
      a_[at(s)] = body.springs(s, 0);
      b_[at(s)] = body.springs(s, 1);
      rest0_[at(s)] = body.rest_lengths(s);
    }
  }
  std::string_view name() const override { return "actuation"; }
  Stage stage() const override { return Stage::modifier; }
  void apply(SwimState& s) override {
    ++calls_;
    const long k = s.step;
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      Node& c = nodes_[i];
      if (k < c.start_step) {
        term_[i] = 0.0;
        continue;
      }
      if (k == c.last_step) {
        // same step again (compute_forces): keep sin/cos
      } else if (k == c.last_step + 1 && (k - c.start_step) % kResync != 0) {
        const double sn = c.sin * c.cos_step + c.cos * c.sin_step;
        const double cs = c.cos * c.cos_step - c.sin * c.sin_step;
        c.sin = sn;
        c.cos = cs;
      } else {
        const double angle = c.frequency * s.time + c.phase;
        c.sin = std::sin(angle);
        c.cos = std::cos(angle);
      }
      c.last_step = k;
      term_[i] = c.amplitude * c.sin;
    }
    const int* a = a_.data();
    const int* b = b_.data();
    const double* t = term_.data();
    double* rest = s.rest.data();
    for (std::size_t e = 0; e < a_.size(); ++e) rest[e] = (1.0 + t[a[e]] + t[b[e]]) * rest0_[e];
  }

 private:
  struct Node {
    double amplitude = 0, frequency = 0, phase = 0;
    long start_step = 0;
    long last_step = -2;
    double cos_step = 1, sin_step = 0;
    double sin = 0, cos = 1;
  };
  std::vector<Node> nodes_;
  std::vector<double> term_;
  std::vector<int> a_, b_;
  std::vector<double> rest0_;
};

}  // namespace

std::unique_ptr<Effect> make_actuation(const Body& body, const PhysicsParams& physics) {
  return std::make_unique<Actuation>(body, physics);
}

}  // namespace animat::effects
