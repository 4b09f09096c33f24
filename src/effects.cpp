// The built-in swim effects (paper §3–4, eqs. 2–5): springs, actuation, pressure, drag and skin
// collision. Each is a small class with one job that stores its elements as structure-of-arrays at
// construction and loops over them in apply(), allocating nothing. Units and coefficient choices:
// docs/notes/physics.md.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"

namespace animat {
namespace {

constexpr double kPi = std::numbers::pi;

// --- parameter checks shared by SceneParams and PhysicsParams --------------------------------

template <class P>
void check_fields(P params, std::string_view section) {
  visit_fields(params, [&](const FieldInfo& info, auto& value) {
    using T = std::decay_t<decltype(value)>;
    auto fail = [&](const std::string& what) {
      throw ConfigError(fmt::format("{}.{}: {}", section, info.name, what));
    };
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, int>) {
      if (!std::isfinite(static_cast<double>(value)) || !info.bounds.contains(static_cast<double>(value)))
        fail(fmt::format("{} is out of range ({})", value, info.bounds.describe()));
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!info.choices.empty() && std::find(info.choices.begin(), info.choices.end(), value) == info.choices.end())
        fail(fmt::format("unknown value '{}' (expected one of {})", value, fmt::join(info.choices, ", ")));
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      for (std::size_t i = 0; i < value.size(); ++i) {
        if (!info.choices.empty() && std::find(info.choices.begin(), info.choices.end(), value[i]) == info.choices.end())
          fail(fmt::format("unknown entry '{}' (expected any of {})", value[i], fmt::join(info.choices, ", ")));
        for (std::size_t j = 0; j < i; ++j)
          if (value[j] == value[i]) fail(fmt::format("entry '{}' is listed twice", value[i]));
      }
    }
  });
}

int as_int(Eigen::Index i) { return static_cast<int>(i); }

// --- springs -----------------------------------------------------------------------------------

/// Damped Hooke springs: f = k·(len − rest) + c·(relative velocity along the spring), equal and
/// opposite on the two ends. Reads the current rest lengths from the state (actuation writes them).
class Springs final : public Effect {
 public:
  Springs(const Body& body, const SceneParams& p) : k_(p.spring_stiffness), c_(p.spring_damping) {
    const int m = body.spring_count();
    a_.resize(static_cast<std::size_t>(m));
    b_.resize(static_cast<std::size_t>(m));
    for (int s = 0; s < m; ++s) {
      a_[static_cast<std::size_t>(s)] = body.springs(s, 0);
      b_[static_cast<std::size_t>(s)] = body.springs(s, 1);
    }
  }
  std::string_view name() const override { return "springs"; }
  void apply(SwimState& s) override {
    ++calls_;
    const int* a = a_.data();
    const int* b = b_.data();
    const double* x = s.x.data();
    const double* y = s.y.data();
    const double* vx = s.vx.data();
    const double* vy = s.vy.data();
    const double* rest = s.rest.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const std::size_t m = a_.size();
    for (std::size_t e = 0; e < m; ++e) {
      const int i = a[e], j = b[e];
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      const double len = std::sqrt(dx * dx + dy * dy);
      if (!(len > 0.0)) continue;  // coincident ends: no direction, no force
      const double inv = 1.0 / len;
      const double ux = dx * inv, uy = dy * inv;
      const double rate = (vx[j] - vx[i]) * ux + (vy[j] - vy[i]) * uy;
      const double f = k_ * (len - rest[e]) + c_ * rate;
      const double gx = f * ux, gy = f * uy;
      fx[i] += gx;
      fy[i] += gy;
      fx[j] -= gx;
      fy[j] -= gy;
    }
  }

 private:
  double k_, c_;
  std::vector<int> a_, b_;
};

// --- actuation ---------------------------------------------------------------------------------

/// Eq. 2: rest = (1 + term_1 + term_2)·L0, term = a·sin(f·t + φ) once the cell has started
/// (actuation_start_time). sin/cos are advanced by an exact-angle rotation each step and recomputed
/// directly every kResync steps; a cell starts exactly at its first step at or after its start time.
class Actuation final : public Effect {
 public:
  static constexpr long kResync = 1024;

  Actuation(const Body& body, const PhysicsParams& physics) {
    const int n = body.node_count();
    const int m = body.spring_count();
    const double h = physics.dt / physics.substeps;
    nodes_.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      Node& c = nodes_[static_cast<std::size_t>(i)];
      c.amplitude = body.amplitude.size() == n ? body.amplitude(i) : 0.0;
      c.frequency = body.frequency.size() == n ? body.frequency(i) : 0.0;
      c.phase = body.phase.size() == n ? body.phase(i) : 0.0;
      const double t0 = actuation_start_time(c.frequency, c.phase);
      const double k0 = std::ceil(t0 / h);
      c.start_step = (std::isfinite(k0) && k0 < 1e15) ? static_cast<long>(k0) : std::numeric_limits<long>::max();
      c.cos_step = std::cos(c.frequency * h);
      c.sin_step = std::sin(c.frequency * h);
      if (c.amplitude == 0.0) c.start_step = std::numeric_limits<long>::max();  // never contributes
    }
    term_.assign(static_cast<std::size_t>(n), 0.0);
    a_.resize(static_cast<std::size_t>(m));
    b_.resize(static_cast<std::size_t>(m));
    rest0_.resize(static_cast<std::size_t>(m));
    for (int s = 0; s < m; ++s) {
      a_[static_cast<std::size_t>(s)] = body.springs(s, 0);
      b_[static_cast<std::size_t>(s)] = body.springs(s, 1);
      rest0_[static_cast<std::size_t>(s)] = body.rest_lengths(s);
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

// --- pressure ----------------------------------------------------------------------------------

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
      const auto& loop = body.regions[static_cast<std::size_t>(k)];
      const std::size_t len = loop.size();
      double lmax2 = 0.0;
      for (std::size_t q = 0; q < len; ++q) {
        const int i = loop[q], j = loop[(q + 1) % len];
        const double dx = body.positions(j, 0) - body.positions(i, 0);
        const double dy = body.positions(j, 1) - body.positions(i, 1);
        lmax2 = std::max(lmax2, dx * dx + dy * dy);
        node_.push_back(loop[q]);
        prev_.push_back(loop[(q + len - 1) % len]);
        next_.push_back(loop[(q + 1) % len]);
      }
      offset_.push_back(static_cast<int>(node_.size()));
      const double s0 = body.rest_areas(k);
      const double ref = std::max(s0, p.pressure_area_floor * lmax2);
      rest_area_.push_back(s0);
      coef_.push_back(ref > 0.0 ? p.pressure / ref : 0.0);
    }
  }
  std::string_view name() const override { return "pressure"; }
  void apply(SwimState& s) override {
    ++calls_;
    const double* x = s.x.data();
    const double* y = s.y.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const int* node = node_.data();
    const int* prev = prev_.data();
    const int* next = next_.data();
    const std::size_t regions = rest_area_.size();
    for (std::size_t r = 0; r < regions; ++r) {
      const int lo = offset_[r], hi = offset_[r + 1];
      double twice_area = 0.0;
      for (int q = lo; q < hi; ++q) twice_area += x[node[q]] * (y[next[q]] - y[prev[q]]);
      // F_i = c_p (S0 − S)/A · ∂S/∂p_i, with ∂S/∂p_i = ½ (y_next − y_prev, x_prev − x_next).
      const double g = 0.5 * coef_[r] * (rest_area_[r] - 0.5 * twice_area);
      for (int q = lo; q < hi; ++q) {
        fx[node[q]] += g * (y[next[q]] - y[prev[q]]);
        fy[node[q]] += g * (x[prev[q]] - x[next[q]]);
      }
    }
  }

 private:
  std::vector<int> offset_, node_, prev_, next_;
  std::vector<double> rest_area_, coef_;
};

// --- drag --------------------------------------------------------------------------------------

/// Eqs. 4–5 on skin edges (each once): the edge midpoint's velocity split into normal and
/// tangential parts, F = −d·L·u·|u| per part, half the force to each end.
///  - explicit: u is the midpoint velocity at the start of the step;
///  - stable: backward Euler with every other force included. Each edge takes the predicted
///    midpoint velocity w (velocities plus h·F/m of the forces added so far) and solves
///    M·(u' − w) = −h·d·L·u'·|u'| per component (implicit_quadratic_drag), with M its share of the
///    end masses, 2m / max(skin degree of its ends); the impulse M·(u' − w) is applied as a force.
///    |u'| <= |w| with the same sign: the drag never reverses an edge's normal or tangential
///    velocity, however large d·L·|w|·h/M. At a steady state (u' = w) it is eq. 4–5 exactly.
class Drag final : public Effect {
 public:
  Drag(const Body& body, const SceneParams& p, const PhysicsParams& physics)
      : dn_(p.drag_normal), dt_(tangential_drag(p)), stable_(physics.drag_scheme == "stable") {
    const int n = body.node_count();
    const int e = as_int(body.skin.rows());
    std::vector<int> degree(static_cast<std::size_t>(n), 0);
    for (int k = 0; k < e; ++k) {
      ++degree[static_cast<std::size_t>(body.skin(k, 0))];
      ++degree[static_cast<std::size_t>(body.skin(k, 1))];
    }
    for (int k = 0; k < e; ++k) {
      const int i = body.skin(k, 0), j = body.skin(k, 1);
      a_.push_back(i);
      b_.push_back(j);
      const int dmax = std::max(degree[static_cast<std::size_t>(i)], degree[static_cast<std::size_t>(j)]);
      edge_mass_.push_back(2.0 * p.cell_mass / dmax);
    }
    wx_.assign(static_cast<std::size_t>(n), 0.0);
    wy_.assign(static_cast<std::size_t>(n), 0.0);
  }
  std::string_view name() const override { return "drag"; }
  Stage stage() const override { return Stage::implicit; }
  void apply(SwimState& s) override {
    ++calls_;
    const double* x = s.x.data();
    const double* y = s.y.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const double* ux;
    const double* uy;
    if (stable_) {
      const double k = s.h * s.inv_mass;
      for (int i = 0; i < s.n; ++i) {
        wx_[static_cast<std::size_t>(i)] = s.vx[static_cast<std::size_t>(i)] + k * fx[i];
        wy_[static_cast<std::size_t>(i)] = s.vy[static_cast<std::size_t>(i)] + k * fy[i];
      }
      ux = wx_.data();
      uy = wy_.data();
    } else {
      ux = s.vx.data();
      uy = s.vy.data();
    }
    const double inv_h = 1.0 / s.h;
    for (std::size_t e = 0; e < a_.size(); ++e) {
      const int i = a_[e], j = b_[e];
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      const double len = std::sqrt(dx * dx + dy * dy);
      if (!(len > 0.0)) continue;
      const double tx = dx / len, ty = dy / len;  // tangent; normal = (−ty, tx)
      const double mx = 0.5 * (ux[i] + ux[j]), my = 0.5 * (uy[i] + uy[j]);
      const double vn = -mx * ty + my * tx;
      const double vt = mx * tx + my * ty;
      double fn, ft;
      if (stable_) {
        const double m = edge_mass_[e];
        const double k = s.h * len / m;
        fn = m * (implicit_quadratic_drag(vn, dn_ * k) - vn) * inv_h;
        ft = m * (implicit_quadratic_drag(vt, dt_ * k) - vt) * inv_h;
      } else {
        fn = -dn_ * len * vn * std::abs(vn);
        ft = -dt_ * len * vt * std::abs(vt);
      }
      const double gx = 0.5 * (-fn * ty + ft * tx);
      const double gy = 0.5 * (fn * tx + ft * ty);
      fx[i] += gx;
      fy[i] += gy;
      fx[j] += gx;
      fy[j] += gy;
    }
  }

 private:
  double dn_, dt_;
  bool stable_;
  std::vector<int> a_, b_;
  std::vector<double> edge_mass_;
  std::vector<double> wx_, wy_;
};

// --- skin collision ----------------------------------------------------------------------------

/// Closest point of segment ab to p: returns the parameter t in [0, 1] and the squared distance.
struct SegmentHit {
  double t, qx, qy, d2;
};
inline SegmentHit closest_on_segment(double px, double py, double ax, double ay, double bx, double by) {
  const double ex = bx - ax, ey = by - ay;
  const double l2 = ex * ex + ey * ey;
  double t = l2 > 0.0 ? ((px - ax) * ex + (py - ay) * ey) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double qx = ax + t * ex, qy = ay + t * ey;
  const double dx = px - qx, dy = py - qy;
  return {t, qx, qy, dx * dx + dy * dy};
}

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
  static constexpr double kMargin = 0.3;

  SkinCollision(const Body& body, const SceneParams& p) : k_(p.collision_stiffness), r_(p.collision_radius) {
    n_ = body.node_count();
    for (int e = 0; e < as_int(body.skin.rows()); ++e) {
      a_.push_back(body.skin(e, 0));
      b_.push_back(body.skin(e, 1));
    }
    x0_.resize(static_cast<std::size_t>(n_));
    y0_.resize(static_cast<std::size_t>(n_));
    for (int i = 0; i < n_; ++i) {
      x0_[static_cast<std::size_t>(i)] = body.positions(i, 0);
      y0_[static_cast<std::size_t>(i)] = body.positions(i, 1);
    }
    xr_.assign(static_cast<std::size_t>(n_), 0.0);
    yr_.assign(static_cast<std::size_t>(n_), 0.0);
    pairs_.reserve(static_cast<std::size_t>(n_) * a_.size());
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
      const int i = p.cell, a = a_[static_cast<std::size_t>(p.edge)], b = b_[static_cast<std::size_t>(p.edge)];
      const SegmentHit hit = closest_on_segment(x[i], y[i], x[a], y[a], x[b], y[b]);
      if (!(hit.d2 < p.radius * p.radius)) continue;
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
      const double f = k_ * (p.radius - d);
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
      cx += s.x[static_cast<std::size_t>(i)];
      cy += s.y[static_cast<std::size_t>(i)];
    }
    cx /= s.n;
    cy /= s.n;
  }
  bool moved_too_far(const SwimState& s) const {
    double cx, cy;
    centre(s, cx, cy);
    const double limit2 = 0.25 * kMargin * kMargin;
    for (int i = 0; i < n_; ++i) {
      const double dx = (s.x[static_cast<std::size_t>(i)] - cx) - xr_[static_cast<std::size_t>(i)];
      const double dy = (s.y[static_cast<std::size_t>(i)] - cy) - yr_[static_cast<std::size_t>(i)];
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
      xr_[static_cast<std::size_t>(i)] = s.x[static_cast<std::size_t>(i)] - cx;
      yr_[static_cast<std::size_t>(i)] = s.y[static_cast<std::size_t>(i)] - cy;
    }
    pairs_.clear();
    for (int i = 0; i < n_; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      for (std::size_t e = 0; e < a_.size(); ++e) {
        const int a = a_[e], b = b_[e];
        if (a == i || b == i) continue;
        const auto au = static_cast<std::size_t>(a), bu = static_cast<std::size_t>(b);
        const SegmentHit rest = closest_on_segment(x0_[iu], y0_[iu], x0_[au], y0_[au], x0_[bu], y0_[bu]);
        const double radius = std::min(r_, 0.5 * std::sqrt(rest.d2));
        if (!(radius > 0.0)) continue;
        const SegmentHit now = closest_on_segment(s.x[iu], s.y[iu], s.x[au], s.y[au], s.x[bu], s.y[bu]);
        const double reach = radius + kMargin;
        if (now.d2 < reach * reach) pairs_.push_back({i, static_cast<int>(e), radius});
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

// --- public pieces -------------------------------------------------------------------------------

double actuation_start_time(double frequency, double phase) {
  double theta = std::fmod(phase, kPi);
  if (theta < 0.0) theta += kPi;
  if (theta == 0.0) return 0.0;
  if (!(frequency > 0.0)) return std::numeric_limits<double>::infinity();
  return (kPi - theta) / frequency;
}

double actuation_term(double amplitude, double frequency, double phase, double t) {
  if (!(t >= actuation_start_time(frequency, phase))) return 0.0;
  return amplitude * std::sin(frequency * t + phase);
}

double implicit_quadratic_drag(double w, double c_dt) {
  return 2.0 * w / (1.0 + std::sqrt(1.0 + 4.0 * c_dt * std::abs(w)));
}

void validate(const SceneParams& params) { check_fields(params, "scene"); }

void validate(const PhysicsParams& params) { check_fields(params, "physics"); }

std::unique_ptr<Effect> make_effect(std::string_view name, const Body& body, const SceneParams& scene,
                                    const PhysicsParams& physics) {
  if (name == "springs") return std::make_unique<Springs>(body, scene);
  if (name == "actuation") return std::make_unique<Actuation>(body, physics);
  if (name == "pressure") return std::make_unique<Pressure>(body, scene);
  if (name == "drag") return std::make_unique<Drag>(body, scene, physics);
  if (name == "skin_collision") return std::make_unique<SkinCollision>(body, scene);
  throw ConfigError(fmt::format("scene.effects: unknown effect '{}' (expected any of {})", name,
                                fmt::join(kSceneEffectNames, ", ")));
}

}  // namespace animat
