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
/// apply() adds the elastic part and keeps the unit vectors; apply_velocity() adds the damping part
/// at the evaluation velocity s.ux, s.uy.
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
    ex_.assign(static_cast<std::size_t>(m), 0.0);
    ey_.assign(static_cast<std::size_t>(m), 0.0);
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

// --- pressure ---

/// Twice the signed area of a region, the same way Pressure computes it: triangles by the cross
/// product of two edges, other loops by Σ x_i·(y_next − y_prev).
template <class X, class Y>
double twice_area(const X& x, const Y& y, const std::vector<int>& loop) {
  const std::size_t k = loop.size();
  if (k == 3) {
    const int a = loop[0], b = loop[1], c = loop[2];
    return (x(b) - x(a)) * (y(c) - y(a)) - (x(c) - x(a)) * (y(b) - y(a));
  }
  double twice = 0.0;
  for (std::size_t q = 0; q < k; ++q) twice += x(loop[q]) * (y(loop[(q + 1) % k]) - y(loop[(q + k - 1) % k]));
  return twice;
}

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

// --- drag --------------------------------------------------------------------------------------

/// g(x) of the stable drag scheme: 1 for x <= 1/2, 1/(x + 1/2) beyond; x·g(x) < 1 for every x.
inline double drag_limiter(double x) { return x <= 0.5 ? 1.0 : 1.0 / (x + 0.5); }

/// Eqs. 4–5 on skin edges (each once): the edge midpoint's velocity u split into normal and
/// tangential parts, F = −d·L·u·|u| per part, half the force to each end; u is the midpoint of the
/// evaluation velocities s.ux, s.uy (physics.velocity_forces). Three schemes, with
/// x = h·d·L·|u| / M the fraction of the velocity one explicit step would remove, where M is the
/// edge's conservative share of its end masses, 2m / max(skin degree of its ends) (so that even
/// when all the skin edges at a node push the same way their fractions add up to at most x):
///  - explicit: F as above. First order in time (second with the midpoint velocity); it
///    overshoots for x > 1 (reverses the velocity) and blows up for x > 2;
///  - stable (default): the explicit force times g(x) = 1 for x <= 1/2 and 1/(x + 1/2) beyond, so
///    one step removes at most the fraction x·g(x) < 1 of the velocity it acts on: the drag never
///    reverses an edge's normal or tangential velocity, whatever h, d or u. Where x <= 1/2 (every
///    paper environment at the default dt) it is exactly the explicit scheme, so terminal velocities
///    are exact;
///  - implicit: backward Euler per edge and per part, with every other force included: the
///    predicted midpoint velocity w (velocities at the start of the step plus h·F/m of the forces
///    added so far) becomes the u' of M·(u' − w) = −h·d·L·u'·|u'| (implicit_quadratic_drag), and
///    M·(u' − w)/h is the force. Never reverses either, but it is more dissipative, and with the
///    conservative M its terminal velocity is biased by O(x) where a node carries several skin edges.
/// apply() caches the edge geometry; apply_velocity() adds the forces.
class Drag final : public Effect {
 public:
  Drag(const Body& body, const SceneParams& p, const PhysicsParams& physics)
      : dn_(p.drag_normal),
        dt_(tangential_drag(p)),
        scheme_(physics.drag_scheme == "explicit"   ? Scheme::explicit_
                : physics.drag_scheme == "implicit" ? Scheme::implicit
                                                    : Scheme::stable) {
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
    len_.assign(a_.size(), 0.0);
    tx_.assign(a_.size(), 0.0);
    ty_.assign(a_.size(), 0.0);
    wx_.assign(static_cast<std::size_t>(n), 0.0);
    wy_.assign(static_cast<std::size_t>(n), 0.0);
  }
  std::string_view name() const override { return "drag"; }
  void apply(SwimState& s) override {
    ++calls_;
    const double* x = s.x.data();
    const double* y = s.y.data();
    for (std::size_t e = 0; e < a_.size(); ++e) {
      const int i = a_[e], j = b_[e];
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      const double len = std::sqrt(dx * dx + dy * dy);
      len_[e] = len;
      if (!(len > 0.0)) continue;
      tx_[e] = dx / len;
      ty_[e] = dy / len;
    }
  }
  bool velocity_dependent() const override { return true; }
  void apply_velocity(SwimState& s) override {
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const double* ux;
    const double* uy;
    if (scheme_ == Scheme::implicit) {
      const double k = s.h * s.inv_mass;
      for (int i = 0; i < s.n; ++i) {
        wx_[static_cast<std::size_t>(i)] = s.vx[static_cast<std::size_t>(i)] + k * fx[i];
        wy_[static_cast<std::size_t>(i)] = s.vy[static_cast<std::size_t>(i)] + k * fy[i];
      }
      ux = wx_.data();
      uy = wy_.data();
    } else {
      ux = s.ux.data();
      uy = s.uy.data();
    }
    const double inv_h = 1.0 / s.h;
    for (std::size_t e = 0; e < a_.size(); ++e) {
      const double len = len_[e];
      if (!(len > 0.0)) continue;
      const int i = a_[e], j = b_[e];
      const double tx = tx_[e], ty = ty_[e];  // tangent; normal = (−ty, tx)
      const double mx = 0.5 * (ux[i] + ux[j]), my = 0.5 * (uy[i] + uy[j]);
      const double wn = -mx * ty + my * tx;  // normal and tangential parts of the midpoint velocity
      const double wt = mx * tx + my * ty;
      double fn = -dn_ * len * wn * std::abs(wn);
      double ft = -dt_ * len * wt * std::abs(wt);
      if (scheme_ == Scheme::stable) {
        const double k = s.h * len / edge_mass_[e];  // x = k·d·|u|
        fn *= drag_limiter(k * dn_ * std::abs(wn));
        ft *= drag_limiter(k * dt_ * std::abs(wt));
      } else if (scheme_ == Scheme::implicit) {
        const double m = edge_mass_[e];
        const double k = s.h * len / m;
        fn = m * (implicit_quadratic_drag(wn, dn_ * k) - wn) * inv_h;
        ft = m * (implicit_quadratic_drag(wt, dt_ * k) - wt) * inv_h;
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
  enum class Scheme { explicit_, stable, implicit };
  double dn_, dt_;
  Scheme scheme_;
  std::vector<int> a_, b_;
  std::vector<double> edge_mass_;
  std::vector<double> len_, tx_, ty_;  // edge geometry of the current step
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
  static constexpr double kMargin = 0.4;

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
      // Cheap rejection: the cell is farther than the radius from the edge's bounding box.
      const double r = p.radius;
      if (x[i] + r < std::min(x[a], x[b]) || x[i] - r > std::max(x[a], x[b]) || y[i] + r < std::min(y[a], y[b]) ||
          y[i] - r > std::max(y[a], y[b]))
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
    const double reach = r_ + kMargin;
    for (std::size_t e = 0; e < a_.size(); ++e) {  // pairs stay sorted by (edge, cell)
      const int a = a_[e], b = b_[e];
      const auto au = static_cast<std::size_t>(a), bu = static_cast<std::size_t>(b);
      const double x0 = std::min(s.x[au], s.x[bu]) - reach, x1 = std::max(s.x[au], s.x[bu]) + reach;
      const double y0 = std::min(s.y[au], s.y[bu]) - reach, y1 = std::max(s.y[au], s.y[bu]) + reach;
      for (int i = 0; i < n_; ++i) {
        const auto iu = static_cast<std::size_t>(i);
        if (s.x[iu] < x0 || s.x[iu] > x1 || s.y[iu] < y0 || s.y[iu] > y1 || a == i || b == i) continue;
        const SegmentHit now = closest_on_segment(s.x[iu], s.y[iu], s.x[au], s.y[au], s.x[bu], s.y[bu]);
        if (!(now.d2 < reach * reach)) continue;
        const SegmentHit rest = closest_on_segment(x0_[iu], y0_[iu], x0_[au], y0_[au], x0_[bu], y0_[bu]);
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

// --- public pieces -------------------------------------------------------------------------------

Body swim_body(const Body& in) {
  Body b = in;
  const int n = b.node_count();
  double scale = 1.0;
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < 2; ++c) {
      b.positions(i, c) = static_cast<double>(static_cast<float>(in.positions(i, c)));
      scale = std::max(scale, std::abs(in.positions(i, c)));
    }
  }
  const double tol = 1e-6 * scale;
  for (int s = 0; s < b.spring_count() && s < b.rest_lengths.size(); ++s) {
    const int i = b.springs(s, 0), j = b.springs(s, 1);
    if (i < 0 || j < 0 || i >= n || j >= n) continue;
    const double dx = b.positions(j, 0) - b.positions(i, 0), dy = b.positions(j, 1) - b.positions(i, 1);
    const double len = std::sqrt(dx * dx + dy * dy);  // as Springs measures it
    if (std::abs(len - b.rest_lengths(s)) <= tol) b.rest_lengths(s) = len;
  }
  const auto px = [&](int i) { return b.positions(i, 0); };
  const auto py = [&](int i) { return b.positions(i, 1); };
  for (int r = 0; r < b.region_count() && r < b.rest_areas.size(); ++r) {
    const auto& loop = b.regions[static_cast<std::size_t>(r)];
    if (std::any_of(loop.begin(), loop.end(), [&](int v) { return v < 0 || v >= n; })) continue;
    double perimeter = 0.0;
    for (std::size_t q = 0; q < loop.size(); ++q) {
      const int i = loop[q], j = loop[(q + 1) % loop.size()];
      perimeter += std::hypot(px(j) - px(i), py(j) - py(i));
    }
    const double area = 0.5 * twice_area(px, py, loop);
    if (std::abs(area - b.rest_areas(r)) <= tol * perimeter) b.rest_areas(r) = area;
  }
  return b;
}

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
