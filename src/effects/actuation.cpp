// Effect "actuation": eq. 2, the oscillating rest lengths, with the phase-delayed start [paper §3].
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "effect_support.hpp"
#include "oscillator.hpp"

namespace animat::effects {
namespace {

/// Eq. 2: rest = (1 + term_1 + term_2)·L0, term = a·sin(f·t + φ) once the cell has started
/// (actuation_start_time). sin/cos are advanced by an exact-angle rotation each step and recomputed
/// directly every CellOscillator::kResync steps; a cell starts exactly at its first step at or
/// after its start time.
class Actuation final : public Effect {
 public:
  Actuation(const Body& body, const PhysicsParams& physics) {
    const int n = body.node_count();
    const int m = body.spring_count();
    const double h = physics.dt / physics.substeps;
    nodes_.resize(at(n));
    for (int i = 0; i < n; ++i) {
      CellOscillator& c = nodes_[at(i)];
      c.amplitude = body.amplitude.size() == n ? body.amplitude(i) : 0.0;
      c.frequency = body.frequency.size() == n ? body.frequency(i) : 0.0;
      c.phase = body.phase.size() == n ? body.phase(i) : 0.0;
      c.start_step = c.delayed_start(0, 0.0, h);
      c.set_step(h);
      if (c.amplitude == 0.0) c.start_step = CellOscillator::kNever;  // never contributes
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
    for (std::size_t i = 0; i < nodes_.size(); ++i) term_[i] = nodes_[i].term(s.step, s.time);
    const int* a = a_.data();
    const int* b = b_.data();
    const double* t = term_.data();
    double* rest = s.rest.data();
    for (std::size_t e = 0; e < a_.size(); ++e) rest[e] = (1.0 + t[a[e]] + t[b[e]]) * rest0_[e];
  }

 private:
  std::vector<CellOscillator> nodes_;
  std::vector<double> term_;
  std::vector<int> a_, b_;
  std::vector<double> rest0_;
};

}  // namespace

std::unique_ptr<Effect> make_actuation(const Body& body, const PhysicsParams& physics) {
  return std::make_unique<Actuation>(body, physics);
}

}  // namespace animat::effects
