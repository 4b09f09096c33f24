// Effect "skin_collision" (optional, not in the default scene): a soft penalty pushing cells out of
// skin edges that are not their own. It does not stop a fast cell; the default scene uses the
// swept, elastic "collisions" effect instead (collisions.cpp).
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include <algorithm>
#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// A cell may not pass through a skin edge that is not its own: within distance r of the edge,
/// the cell feels k·(r − d) away from the closest point q = (1 − t)·a + t·b, and the edge's ends
/// feel (1 − t) and t of the opposite force. That is minus the gradient of k·(r − d)²/2: elastic
/// (conservative), and it conserves momentum and angular momentum. The radius of a pair is
/// min(r, half its rest distance), so a body at rest feels nothing even with near-coincident
/// cells. A Verlet list (pairs within r + margin, rebuilt when some cell has moved margin/2
/// relative to the centre of mass since the last build) makes the step cost proportional to the
/// near pairs; it never misses a pair, so forces equal the all-pairs computation.
class SkinCollision final : public Effect {
 public:
  static constexpr double kMargin = 0.4;

  SkinCollision(const Body& body, const SceneParams& p)
      : k_(p.collision_stiffness), r_(p.collision_radius) {
    n_ = body.node_count();
    for (int e = 0; e < as_int(body.skin.rows()); ++e) {
      a_.push_back(body.skin(e, 0));
      b_.push_back(body.skin(e, 1));
    }
    x0_.resize(at(n_));
    y0_.resize(at(n_));
    for (int i = 0; i < n_; ++i) {
      x0_[at(i)] = body.positions(i, 0);
      y0_[at(i)] = body.positions(i, 1);
    }
    xr_.assign(at(n_), 0.0);
    yr_.assign(at(n_), 0.0);
    pairs_.reserve(at(n_) * a_.size());
  }
  std::string_view name() const override { return "skin_collision"; }
  void apply(SwimState& s) override {
    ++calls_;
    if (a_.empty() || !(k_ > 0.0) || !(r_ > 0.0)) return;
    const double* x = s.x.data();
    const double* y = s.y.data();
    if (!built_ || moved_too_far(s)) rebuild(s);
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    for (const Pair& p : pairs_) {
      const int i = p.cell, a = a_[at(p.edge)], b = b_[at(p.edge)];
      // Cheap rejection: the cell is farther than the radius from the edge's bounding box.
      const double r = p.radius;
      if (x[i] + r < std::min(x[a], x[b]) || x[i] - r > std::max(x[a], x[b]) ||
          y[i] + r < std::min(y[a], y[b]) || y[i] - r > std::max(y[a], y[b]))
        continue;
      const SegmentHit hit = closest_on_segment(x[i], y[i], x[a], y[a], x[b], y[b]);
      if (!(hit.d2 < r * r)) continue;
      const double d = std::sqrt(hit.d2);
      double nx, ny;
      if (d > 0.0) {
        nx = (x[i] - hit.qx) / d;
        ny = (y[i] - hit.qy) / d;
      } else {  // exactly on the edge: push along the edge's left normal
        const double ex = x[b] - x[a], ey = y[b] - y[a];
        const double l = std::sqrt(ex * ex + ey * ey);
        if (!(l > 0.0)) continue;
        nx = -ey / l;
        ny = ex / l;
      }
      const double f = k_ * (r - d);
      const double gx = f * nx, gy = f * ny;
      fx[i] += gx;
      fy[i] += gy;
      fx[a] -= (1.0 - hit.t) * gx;
      fy[a] -= (1.0 - hit.t) * gy;
      fx[b] -= hit.t * gx;
      fy[b] -= hit.t * gy;
    }
  }
  [[nodiscard]] long rebuilds() const { return rebuilds_; }

 private:
  struct Pair {
    int cell;
    int edge;
    double radius;
  };

  static void centre(const SwimState& s, double& cx, double& cy) {
    cx = 0.0;
    cy = 0.0;
    for (int i = 0; i < s.n; ++i) {
      cx += s.x[at(i)];
      cy += s.y[at(i)];
    }
    cx /= s.n;
    cy /= s.n;
  }
  bool moved_too_far(const SwimState& s) const {
    double cx, cy;
    centre(s, cx, cy);
    const double limit2 = 0.25 * kMargin * kMargin;
    for (int i = 0; i < n_; ++i) {
      const double dx = (s.x[at(i)] - cx) - xr_[at(i)];
      const double dy = (s.y[at(i)] - cy) - yr_[at(i)];
      if (!(dx * dx + dy * dy <= limit2)) return true;
    }
    return false;
  }
  void rebuild(const SwimState& s) {
    ++rebuilds_;
    built_ = true;
    double cx, cy;
    centre(s, cx, cy);
    for (int i = 0; i < n_; ++i) {
      xr_[at(i)] = s.x[at(i)] - cx;
      yr_[at(i)] = s.y[at(i)] - cy;
    }
    pairs_.clear();
    const double reach = r_ + kMargin;
    for (std::size_t e = 0; e < a_.size(); ++e) {  // pairs stay sorted by (edge, cell)
      const int a = a_[e], b = b_[e];
      const auto au = at(a), bu = at(b);
      const double x0 = std::min(s.x[au], s.x[bu]) - reach, x1 = std::max(s.x[au], s.x[bu]) + reach;
      const double y0 = std::min(s.y[au], s.y[bu]) - reach, y1 = std::max(s.y[au], s.y[bu]) + reach;
      for (int i = 0; i < n_; ++i) {
        const auto iu = at(i);
        if (s.x[iu] < x0 || s.x[iu] > x1 || s.y[iu] < y0 || s.y[iu] > y1 || a == i || b == i)
          continue;
        const SegmentHit now =
            closest_on_segment(s.x[iu], s.y[iu], s.x[au], s.y[au], s.x[bu], s.y[bu]);
        if (!(now.d2 < reach * reach)) continue;
        const SegmentHit rest =
            closest_on_segment(x0_[iu], y0_[iu], x0_[au], y0_[au], x0_[bu], y0_[bu]);
        const double radius = std::min(r_, 0.5 * std::sqrt(rest.d2));
        if (radius > 0.0) pairs_.push_back({i, static_cast<int>(e), radius});
      }
    }
  }

  double k_, r_;
  int n_ = 0;
  std::vector<int> a_, b_;
  std::vector<double> x0_, y0_, xr_, yr_;
  std::vector<Pair> pairs_;
  bool built_ = false;
  long rebuilds_ = 0;
};

}  // namespace

std::unique_ptr<Effect> make_skin_collision(const Body& body, const SceneParams& scene) {
  return std::make_unique<SkinCollision>(body, scene);
}

}  // namespace animat::effects
