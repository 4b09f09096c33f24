// Effect "pressure": eq. 3 with the signed area of every region [paper §4].
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include <algorithm>
#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// Eq. 3 with the signed area: on each edge of a region, F = c_p·L·(S0 − S)/A along the edge's
/// outward normal (CCW loop), half to each end, with A = max(S0, floor·Lmax²) (A = S0 except for
/// slivers). Summed per vertex, this is c_p·(S0 − S)/A · ∂S/∂p: minus the gradient of
/// c_p·(S − S0)²/(2A), so the forces on a region sum to zero, conserve angular momentum and push
/// an inverted region (S < 0) back.
class Pressure final : public Effect {
 public:
  Pressure(const Body& body, const SceneParams& p) {
    const int r = body.region_count();
    offset_.push_back(0);
    for (int k = 0; k < r; ++k) {
      const auto& loop = body.regions[at(k)];
      const std::size_t len = loop.size();
      double lmax2 = 0.0;
      for (std::size_t q = 0; q < len; ++q) {
        const int i = loop[q], j = loop[(q + 1) % len];
        const double dx = body.positions(j, 0) - body.positions(i, 0);
        const double dy = body.positions(j, 1) - body.positions(i, 1);
        lmax2 = std::max(lmax2, dx * dx + dy * dy);
      }
      const double s0 = body.rest_areas(k);
      const double ref = std::max(s0, p.pressure_area_floor * lmax2);
      const double coef = ref > 0.0 ? p.pressure / ref : 0.0;
      if (len == 3) {  // most regions: a specialised loop
        tri_.push_back({loop[0], loop[1], loop[2]});
        tri_area_.push_back(2.0 * s0);
        tri_coef_.push_back(0.5 * coef);
        continue;
      }
      for (std::size_t q = 0; q < len; ++q) {
        node_.push_back(loop[q]);
        prev_.push_back(loop[(q + len - 1) % len]);
        next_.push_back(loop[(q + 1) % len]);
      }
      offset_.push_back(static_cast<int>(node_.size()));
      rest_area_.push_back(s0);
      coef_.push_back(coef);
    }
  }
  std::string_view name() const override { return "pressure"; }
  /// Σ c_p·(S − S0)²/(2A), whose gradient apply() adds (with the opposite sign).
  bool has_potential_energy() const override { return true; }
  double potential_energy(const SwimState& s) const override {
    double u = 0.0;
    const double* x = s.x.data();
    const double* y = s.y.data();
    for (std::size_t r = 0; r < tri_.size(); ++r) {
      const auto [a, b, c] = tri_[r];
      const double twice = (x[b] - x[a]) * (y[c] - y[a]) - (x[c] - x[a]) * (y[b] - y[a]);
      const double d = twice - tri_area_[r];
      u += 0.25 * tri_coef_[r] * d * d;
    }
    for (std::size_t r = 0; r < rest_area_.size(); ++r) {
      double twice_area = 0.0;
      for (int q = offset_[r]; q < offset_[r + 1]; ++q)
        twice_area += x[node_[at(q)]] * (y[next_[at(q)]] - y[prev_[at(q)]]);
      const double d = 0.5 * twice_area - rest_area_[r];
      u += 0.5 * coef_[r] * d * d;
    }
    return u;
  }
  void apply(SwimState& s) override {
    ++calls_;
    const double* x = s.x.data();
    const double* y = s.y.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    // F_i = c_p (S0 − S)/A · ∂S/∂p_i, with ∂S/∂p_i = ½ (y_next − y_prev, x_prev − x_next).
    for (std::size_t r = 0; r < tri_.size(); ++r) {
      const auto [a, b, c] = tri_[r];
      const double xa = x[a], ya = y[a], xb = x[b], yb = y[b], xc = x[c], yc = y[c];
      const double twice = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya);
      const double g = 0.5 * tri_coef_[r] * (tri_area_[r] - twice);  // = ½·c_p·(S0 − S)/A
      fx[a] += g * (yb - yc);
      fy[a] += g * (xc - xb);
      fx[b] += g * (yc - ya);
      fy[b] += g * (xa - xc);
      fx[c] += g * (ya - yb);
      fy[c] += g * (xb - xa);
    }
    const int* node = node_.data();
    const int* prev = prev_.data();
    const int* next = next_.data();
    for (std::size_t r = 0; r < rest_area_.size(); ++r) {
      const int lo = offset_[r], hi = offset_[r + 1];
      double twice_area = 0.0;
      for (int q = lo; q < hi; ++q) twice_area += x[node[q]] * (y[next[q]] - y[prev[q]]);
      const double g = 0.5 * coef_[r] * (rest_area_[r] - 0.5 * twice_area);
      for (int q = lo; q < hi; ++q) {
        fx[node[q]] += g * (y[next[q]] - y[prev[q]]);
        fy[node[q]] += g * (x[prev[q]] - x[next[q]]);
      }
    }
  }

 private:
  struct Triangle {
    int a, b, c;
  };
  std::vector<Triangle> tri_;
  std::vector<double> tri_area_, tri_coef_;  // 2·S0, ½·c_p/A
  std::vector<int> offset_, node_, prev_, next_;
  std::vector<double> rest_area_, coef_;
};

}  // namespace

std::unique_ptr<Effect> make_pressure(const Body& body, const SceneParams& scene) {
  return std::make_unique<Pressure>(body, scene);
}

}  // namespace animat::effects
