// Effect "gravity" (crawl world, docs/worlds.md): a uniform field g along −y, force −m·g on every
// cell. Not in the paper (it swims in a neutrally buoyant medium); off in the default scene.
#include <memory>
#include <string_view>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// Adds (0, −m·g) to every cell's force: a position-independent force effect.
class Gravity final : public Effect {
 public:
  explicit Gravity(const SceneParams& p) : g_(p.gravity) {}
  std::string_view name() const override { return "gravity"; }
  /// Σ m·g·y.
  bool has_potential_energy() const override { return true; }
  double potential_energy(const SwimState& s) const override {
    double u = 0.0;
    for (int i = 0; i < s.n; ++i) u += s.y[static_cast<std::size_t>(i)];
    u *= s.mass * g_;
    return u;
  }
  void apply(SwimState& s) override {
    ++calls_;
    const double w = s.mass * g_;
    double* fy = s.fy.data();
    for (int i = 0; i < s.n; ++i) fy[i] -= w;
  }

 private:
  double g_;
};

}  // namespace

std::unique_ptr<Effect> make_gravity(const SceneParams& scene) {
  return std::make_unique<Gravity>(scene);
}

}  // namespace animat::effects
