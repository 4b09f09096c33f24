// Effect "collisions": "penetration of an edge by a cell is not allowed and results in an elastic
// collision" [paper §4]. A cell never crosses an edge it is not an end of: every Box2D step, the
// motion of each nearby (cell, edge) pair over the step is tested (a swept point-versus-moving-segment
// test), and a crossing is resolved by an elastic impulse between the cell and the edge's two end
// cells. With collision_edges = "all" this keeps the body's planar embedding: two edges can only
// come to cross after an end of one has crossed the other, and a triangle only inverts when a vertex
// crosses the opposite edge (docs/model.md, "Collisions").
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// Roots of A·τ² + B·τ + C = 0 in [0, 1], ascending; returns how many (0–2).
int roots_in_unit_interval(double A, double B, double C, std::array<double, 2>& out) {
  int count = 0;
  auto keep = [&](double t) {
    if (t >= 0.0 && t <= 1.0) out[static_cast<std::size_t>(count++)] = t;
  };
  const double scale = std::abs(A) + std::abs(B) + std::abs(C);
  if (scale == 0.0) return 0;
  if (std::abs(A) <= 1e-14 * scale) {  // linear
    if (B != 0.0) keep(-C / B);
    return count;
  }
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0.0) return 0;
  const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  double r1 = q / A;
  double r2 = q != 0.0 ? C / q : r1;
  if (r1 > r2) std::swap(r1, r2);
  keep(r1);
  if (r2 != r1) keep(r2);
  return count;
}

/// Swept elastic collisions between cells and the edges they are not an end of (comment at the top
/// of the file), event by event in time order within each Box2D step. With every force already in
/// s.fx, s.fy:
///  1. w = v + h·F/m is the velocity Box2D will give every cell; within the step the cells move in
///     straight lines at w (what symplectic Euler does);
///  2. for each candidate pair (cell i, edge ab), the gap function cross(b − a, p − a) is
///     quadratic in time under that motion; the pair's first event is the first time at which the
///     cell comes within the tolerance band of the edge (on the side it is on) or reaches the
///     segment (from either side) with its projection inside the segment, while approaching the
///     edge point q = (1 − s)·a + s·b (relative normal velocity v_n < 0);
///  3. the earliest event of all pairs is processed: every cell advances to that time, and the
///     impulse J = −(1 + e)·v_n / (1/m_i + (1 − s)²/m_a + s²/m_b) along the normal changes w_i by
///     +J/m_i and w_a, w_b by −(1 − s)·J/m_a and −s·J/m_b: momentum is conserved exactly and, for
///     e = 1, kinetic energy too. Then the next earliest event from that time on, until none is
///     left in the step. After kMaxEvents events in one step the rest are resolved with e = 0
///     (counted as inelastic); a step that still has events after 2·kMaxEvents is counted as
///     unresolved (the swim is then invalid);
///  4. the velocity changes go to Box2D as forces m·Δw/h, and since a bounce happens at its event
///     time and not at the start of the step, the end positions of the cells involved differ from
///     x + h·w; the stepper applies that difference after Box2D's step (SwimState::cx, cy). Events
///     are thus located to O(h²) on the actual piecewise-straight paths.
/// Candidates come from a Verlet list: the pairs closer than tolerance + margin when it was built,
/// valid while every cell stays within margin/2 of its position then (relative to the centre of
/// mass), which bounds the change of any cell-edge distance by margin. It is checked at the start,
/// at every event and at the end of the step; if a step leaves it, the list is rebuilt with a wider
/// margin and the step resolved again from its start.
class Collisions final : public Effect {
 public:
  static constexpr double kMargin = 0.4;
  static constexpr int kMaxEvents = 64;

  Collisions(const Body& body, const SceneParams& p) : restitution_(p.collision_restitution), tol_(p.collision_tolerance) {
    n_ = body.node_count();
    const IndexPairs& edges = p.collision_edges == "skin" ? body.skin : body.springs;
    for (int e = 0; e < as_int(edges.rows()); ++e) {
      a_.push_back(edges(e, 0));
      b_.push_back(edges(e, 1));
    }
    x0_.resize(at(n_));
    y0_.resize(at(n_));
    for (int i = 0; i < n_; ++i) {
      x0_[at(i)] = body.positions(i, 0);
      y0_[at(i)] = body.positions(i, 1);
    }
    for (auto* v : {&w0x_, &w0y_, &wx_, &wy_, &qx_, &qy_, &xr_, &yr_}) v->assign(at(n_), 0.0);
    kicked_.assign(at(n_), 0);
    pairs_.reserve(at(n_) * a_.size());
  }
  std::string_view name() const override { return "collisions"; }
  Stage stage() const override { return Stage::constraint; }

  void apply(SwimState& s) override {
    ++calls_;
    if (a_.empty() || n_ < 3) return;
    const double kv = s.h * s.inv_mass;
    for (int i = 0; i < n_; ++i) {
      w0x_[at(i)] = s.vx[at(i)] + kv * s.fx[at(i)];
      w0y_[at(i)] = s.vy[at(i)] + kv * s.fy[at(i)];
    }
    Outcome outcome = Outcome::left_list;
    for (int round = 0; round < 4 && outcome == Outcome::left_list; ++round) {
      if (round > 0) {
        built_ = false;  // the resolved motion left the list: rebuild it wider
        wide_ = 2.0 * margin_;
      }
      if (!covers_straight_step(s)) rebuild(s);
      outcome = run_events(s);
    }
    if (outcome != Outcome::resolved) ++s.counters.collisions_unresolved;
    if (events_ == 0) return;
    const double mh = s.mass / s.h;
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      s.cx[u] = 0.0;
      s.cy[u] = 0.0;
      if (!kicked_[u]) continue;
      s.fx[u] += (wx_[u] - w0x_[u]) * mh;
      s.fy[u] += (wy_[u] - w0y_[u]) * mh;
      // End position q + (1 − τ)·h·w against Box2D's x + h·w.
      s.cx[u] = (qx_[u] - s.x[u]) - tau_ * s.h * wx_[u];
      s.cy[u] = (qy_[u] - s.y[u]) - tau_ * s.h * wy_[u];
    }
    s.position_corrected = true;
  }

  [[nodiscard]] long rebuilds() const { return rebuilds_; }

 private:
  struct Pair {
    int cell;
    int edge;
    double band;  // tolerance of this pair: min(tolerance, half the rest distance)
  };
  enum class Outcome { resolved, unresolved, left_list };
  struct Event {
    double u = 2.0;  // fraction of the remaining step; > 1: none
    std::size_t pair = 0;
  };

  /// Processes the events of one step in time order (see the class comment).
  Outcome run_events(SwimState& s) {
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      wx_[u] = w0x_[u];
      wy_[u] = w0y_[u];
      qx_[u] = s.x[u];
      qy_[u] = s.y[u];
      kicked_[u] = 0;
    }
    tau_ = 0.0;
    events_ = 0;
    long collisions = 0, inelastic = 0;
    Outcome outcome = Outcome::resolved;
    while (tau_ < 1.0) {
      const double span = (1.0 - tau_) * s.h;  // time left in the step
      Event first;
      for (std::size_t k = 0; k < pairs_.size(); ++k) {
        const double u = event_time(pairs_[k], span);
        if (u < first.u) first = {u, k};  // ties: the first pair in list order
      }
      if (first.u > 1.0) break;
      if (events_ >= 2 * kMaxEvents) {
        outcome = Outcome::unresolved;
        break;
      }
      const bool fallback = events_ >= kMaxEvents;
      ++events_;
      const double dt = first.u * span;
      for (int i = 0; i < n_; ++i) {
        qx_[at(i)] += dt * wx_[at(i)];
        qy_[at(i)] += dt * wy_[at(i)];
      }
      tau_ += first.u * (1.0 - tau_);
      if (!within_list(s, 0.0)) return Outcome::left_list;
      bounce(pairs_[first.pair], fallback ? 0.0 : restitution_);
      ++collisions;
      if (fallback && restitution_ > 0.0) ++inelastic;
    }
    if (!within_list(s, (1.0 - tau_) * s.h)) return Outcome::left_list;
    s.counters.collisions += collisions;
    s.counters.collisions_inelastic += inelastic;
    s.counters.collision_max_passes = std::max(s.counters.collision_max_passes, static_cast<long>(events_));
    return outcome;
  }

  /// The pair's first approaching event within the next `span` of time, as a fraction u in [0, 1]
  /// of it (> 1: none), with the cells at q moving at w.
  double event_time(const Pair& pr, double span) const {
    const int i = pr.cell, a = a_[at(pr.edge)], b = b_[at(pr.edge)];
    const double px = qx_[at(i)], py = qy_[at(i)], ax = qx_[at(a)], ay = qy_[at(a)], bx = qx_[at(b)], by = qy_[at(b)];
    const double dpx = span * wx_[at(i)], dpy = span * wy_[at(i)];
    const double dax = span * wx_[at(a)], day = span * wy_[at(a)];
    const double dbx = span * wx_[at(b)], dby = span * wy_[at(b)];
    const double band = pr.band;
    // Swept bounding boxes, widened by the band: no overlap, no event.
    const double pminx = std::min(px, px + dpx), pmaxx = std::max(px, px + dpx);
    const double pminy = std::min(py, py + dpy), pmaxy = std::max(py, py + dpy);
    const double eminx = std::min({ax, ax + dax, bx, bx + dbx}) - band, emaxx = std::max({ax, ax + dax, bx, bx + dbx}) + band;
    const double eminy = std::min({ay, ay + day, by, by + dby}) - band, emaxy = std::max({ay, ay + day, by, by + dby}) + band;
    if (pmaxx < eminx || pminx > emaxx || pmaxy < eminy || pminy > emaxy) return 2.0;

    // e(u) = e0 + u·de (edge vector), r(u) = r0 + u·dr (cell relative to a); cross(e, r) = c0 + c1·u + c2·u².
    const double ex0 = bx - ax, ey0 = by - ay, dex = dbx - dax, dey = dby - day;
    const double rx0 = px - ax, ry0 = py - ay, drx = dpx - dax, dry = dpy - day;
    const double l2 = ex0 * ex0 + ey0 * ey0;
    if (!(l2 > 0.0)) return 2.0;
    const double len = std::sqrt(l2);
    const double c0 = ex0 * ry0 - ey0 * rx0;
    const double c1 = ex0 * dry - ey0 * drx + dex * ry0 - dey * rx0;
    const double c2 = dex * dry - dey * drx;
    const double sigma = c0 > 0.0 ? 1.0 : c0 < 0.0 ? -1.0 : (c1 >= 0.0 ? 1.0 : -1.0);

    // Candidates: entry into the band on the starting side (σ·cross = band·|e0|), and the cell
    // reaching the edge's line (cross = 0) from either side.
    // Each candidate carries the side the cell comes from: σ for the band, and for the line the
    // side it leaves (the sign of cross just before the root).
    std::array<std::pair<double, double>, 4> events{};
    int count = 0;
    const double g0 = sigma * c0 - band * len;
    std::array<double, 2> r{};
    if (g0 <= 0.0) {
      events[at(count++)] = {0.0, sigma};
    } else {
      const int k = roots_in_unit_interval(sigma * c2, sigma * c1, g0, r);
      for (int q = 0; q < k; ++q) events[at(count++)] = {r[at(q)], sigma};
    }
    const int k = roots_in_unit_interval(c2, c1, c0, r);
    for (int q = 0; q < k; ++q) {
      const double rate = c1 + 2.0 * c2 * r[at(q)];
      events[at(count++)] = {r[at(q)], rate > 0.0 ? -1.0 : rate < 0.0 ? 1.0 : sigma};
    }
    std::sort(events.begin(), events.begin() + count);

    const double slack = band / len;  // the band, as a fraction of the edge, beyond its ends
    for (int q = 0; q < count; ++q) {
      const auto [u, side] = events[at(q)];
      const double ex = ex0 + u * dex, ey = ey0 + u * dey;
      const double rx = rx0 + u * drx, ry = ry0 + u * dry;
      const double el2 = ex * ex + ey * ey;
      if (!(el2 > 0.0)) continue;
      const double sp = (rx * ex + ry * ey) / el2;
      if (sp < -slack || sp > 1.0 + slack) continue;
      // Approaching the edge at the projection, from the side the cell is on just before u.
      const double sc = std::clamp(sp, 0.0, 1.0);
      const double vx = wx_[at(i)] - ((1.0 - sc) * wx_[at(a)] + sc * wx_[at(b)]);
      const double vy = wy_[at(i)] - ((1.0 - sc) * wy_[at(a)] + sc * wy_[at(b)]);
      if (side * (ex * vy - ey * vx) < 0.0) return u;  // the gap closes
    }
    return 2.0;
  }

  /// The elastic (e = 1) or partly inelastic impulse of a pair whose cells are at their event.
  void bounce(const Pair& pr, double e) {
    const int i = pr.cell, a = a_[at(pr.edge)], b = b_[at(pr.edge)];
    const double ex = qx_[at(b)] - qx_[at(a)], ey = qy_[at(b)] - qy_[at(a)];
    const double rx = qx_[at(i)] - qx_[at(a)], ry = qy_[at(i)] - qy_[at(a)];
    const double el2 = ex * ex + ey * ey;
    const double el = std::sqrt(el2);
    const double sc = std::clamp((rx * ex + ry * ey) / el2, 0.0, 1.0);
    const double vx = wx_[at(i)] - ((1.0 - sc) * wx_[at(a)] + sc * wx_[at(b)]);
    const double vy = wy_[at(i)] - ((1.0 - sc) * wy_[at(a)] + sc * wy_[at(b)]);
    // Unit normal pointing to the side the cell approaches from.
    double nx = -ey / el, ny = ex / el;
    const double vn0 = nx * vx + ny * vy;
    if (vn0 > 0.0) {
      nx = -nx;
      ny = -ny;
    }
    const double vn = -std::abs(vn0);
    // Equal masses: 1/m_eff = (1 + (1 − s)² + s²)/m; the velocity changes are J/m per unit weight.
    const double dv = -(1.0 + e) * vn / (1.0 + (1.0 - sc) * (1.0 - sc) + sc * sc);
    kick(i, dv * nx, dv * ny);
    kick(a, -(1.0 - sc) * dv * nx, -(1.0 - sc) * dv * ny);
    kick(b, -sc * dv * nx, -sc * dv * ny);
  }

  void kick(int i, double dvx, double dvy) {
    wx_[at(i)] += dvx;
    wy_[at(i)] += dvy;
    kicked_[at(i)] = 1;
  }

  void centre(const std::vector<double>& x, const std::vector<double>& y, double& cx, double& cy) const {
    cx = 0.0;
    cy = 0.0;
    for (int i = 0; i < n_; ++i) {
      cx += x[at(i)];
      cy += y[at(i)];
    }
    cx /= n_;
    cy /= n_;
  }

  /// Whether every cell, at q advanced by `ahead`·w, is within margin/2 of where it was when the
  /// list was built, relative to the centre of mass.
  bool within_list(const SwimState& s, double ahead) const {
    (void)s;
    double cx = 0.0, cy = 0.0, vx = 0.0, vy = 0.0;
    centre(qx_, qy_, cx, cy);
    centre(wx_, wy_, vx, vy);
    const double limit2 = 0.25 * margin_ * margin_;
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      const double dx = qx_[u] - cx + ahead * (wx_[u] - vx) - xr_[u];
      const double dy = qy_[u] - cy + ahead * (wy_[u] - vy) - yr_[u];
      if (!(dx * dx + dy * dy <= limit2)) return false;
    }
    return true;
  }

  /// Whether the list covers the straight motion of the step at w0 (start and end; a straight
  /// path's distance to a point is largest at an end).
  bool covers_straight_step(const SwimState& s) const {
    if (!built_) return false;
    double cx = 0.0, cy = 0.0, vx = 0.0, vy = 0.0;
    centre(s.x, s.y, cx, cy);
    centre(w0x_, w0y_, vx, vy);
    const double limit2 = 0.25 * margin_ * margin_;
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      const double sx = s.x[u] - cx - xr_[u], sy = s.y[u] - cy - yr_[u];
      const double ex = sx + s.h * (w0x_[u] - vx), ey = sy + s.h * (w0y_[u] - vy);
      if (!(sx * sx + sy * sy <= limit2) || !(ex * ex + ey * ey <= limit2)) return false;
    }
    return true;
  }

  void rebuild(const SwimState& s) {
    ++rebuilds_;
    built_ = true;
    double cx = 0.0, cy = 0.0, vx = 0.0, vy = 0.0;
    centre(s.x, s.y, cx, cy);
    centre(w0x_, w0y_, vx, vy);
    double step2 = 0.0;  // largest displacement of the step relative to the centre of mass
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      xr_[u] = s.x[u] - cx;
      yr_[u] = s.y[u] - cy;
      const double dx = w0x_[u] - vx, dy = w0y_[u] - vy;
      step2 = std::max(step2, dx * dx + dy * dy);
    }
    margin_ = std::max({kMargin, wide_, 2.5 * s.h * std::sqrt(step2)});
    wide_ = 0.0;
    pairs_.clear();
    const double reach = tol_ + margin_;
    for (std::size_t e = 0; e < a_.size(); ++e) {  // pairs stay sorted by (edge, cell)
      const int a = a_[e], b = b_[e];
      const auto au = at(a), bu = at(b);
      const double x0 = std::min(s.x[au], s.x[bu]) - reach, x1 = std::max(s.x[au], s.x[bu]) + reach;
      const double y0 = std::min(s.y[au], s.y[bu]) - reach, y1 = std::max(s.y[au], s.y[bu]) + reach;
      for (int i = 0; i < n_; ++i) {
        const auto iu = at(i);
        if (s.x[iu] < x0 || s.x[iu] > x1 || s.y[iu] < y0 || s.y[iu] > y1 || a == i || b == i) continue;
        const SegmentHit now = closest_on_segment(s.x[iu], s.y[iu], s.x[au], s.y[au], s.x[bu], s.y[bu]);
        if (!(now.d2 < reach * reach)) continue;
        const SegmentHit rest = closest_on_segment(x0_[iu], y0_[iu], x0_[au], y0_[au], x0_[bu], y0_[bu]);
        pairs_.push_back({i, static_cast<int>(e), std::min(tol_, 0.5 * std::sqrt(rest.d2))});
      }
    }
  }

  double restitution_, tol_;
  int n_ = 0;
  std::vector<int> a_, b_;              // edges a cell may not cross
  std::vector<double> x0_, y0_;         // rest positions (per-pair tolerance)
  std::vector<double> w0x_, w0y_;       // end-of-step velocities before any bounce
  std::vector<double> wx_, wy_;         // current velocities while the events are processed
  std::vector<double> qx_, qy_;         // positions at the current event time
  std::vector<char> kicked_;            // cells whose velocity a bounce changed this step
  std::vector<double> xr_, yr_;         // positions relative to the centre of mass at the last build
  std::vector<Pair> pairs_;
  double margin_ = kMargin;             // margin of the current list
  double wide_ = 0.0;                   // a wider margin the next rebuild must use (a step left the list)
  double tau_ = 0.0;                    // fraction of the step done
  int events_ = 0;
  bool built_ = false;
  long rebuilds_ = 0;
};

}  // namespace

std::unique_ptr<Effect> make_collisions(const Body& body, const SceneParams& scene) {
  return std::make_unique<Collisions>(body, scene);
}

}  // namespace animat::effects
