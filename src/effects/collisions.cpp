// Effect "collisions": "penetration of an edge by a cell is not allowed and results in an elastic
// collision" [paper §4]. A cell never crosses an edge it is not an end of: within every Box2D step,
// the motion of each (cell, edge) pair that could meet is tested (a swept point-versus-moving-segment
// test), and a crossing is resolved, at its time within the step, by an elastic impulse between the
// cell and the edge's two end cells.
//
// Which pairs can meet follows from the planar embedding itself. Just before a cell first touches an
// edge it is not an end of, the body is still planar, so the cell and the edge lie on a common face:
// a region (then the edge is an edge of that region) or the outer face (then both are on the skin).
// So with collision_edges = "all" it suffices to test, per region, its vertices against its edges,
// and skin vertices against skin edges; preventing those crossings keeps the embedding: no region
// turns inside out (a triangle inverts only when a vertex crosses the opposite edge) and the skin
// stays simple (two edges can only come to cross after an end of one has touched the other).
// collision_edges = "skin" tests only the skin pairs (measured: internal regions then invert).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "effect_support.hpp"
#include "triangle_filter.hpp"

namespace animat::effects {
namespace {

/// Roots of A·u² + B·u + C = 0 in [0, 1], ascending; returns how many (0–2).
int roots_in_unit_interval(double A, double B, double C, std::array<double, 2>& out) {
  int count = 0;
  auto keep = [&](double t) {
    if (t >= 0.0 && t <= 1.0) out[at(count++)] = t;
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
///  2. the candidate pairs are gathered: the three vertex-edge pairs of every triangular region
///     whose signed area can come within the band in the rest of the step (one quadratic per
///     triangle: the doubled area is the cross product of all three pairs), the vertex-edge pairs of
///     larger regions whose swept boxes overlap, and the skin vertices against the skin edges whose
///     swept boxes overlap (sort and sweep along x);
///  3. for each candidate (cell i, edge ab) the gap function cross(b − a, p − a), quadratic in time
///     under that motion, gives the pair's first event: the first time at which the cell comes
///     within the tolerance band of the edge (on the side it is on) or reaches the segment (from
///     either side), with its projection inside the segment, while approaching the edge point
///     q = (1 − s)·a + s·b (relative normal velocity v_n < 0);
///  4. the earliest event of all is processed: every cell advances to that time, and the impulse
///     J = −(1 + e)·v_n / (1/m_i + (1 − s)²/m_a + s²/m_b) along the normal changes w_i by +J/m_i and
///     w_a, w_b by −(1 − s)·J/m_a and −s·J/m_b: momentum is conserved exactly and, for e = 1,
///     kinetic energy too. Then steps 2–4 again from that time on, until no event is left in the
///     step. After kMaxEvents events in one step the rest are resolved with e = 0 (counted as
///     inelastic); a step that still has events after 2·kMaxEvents is counted as unresolved (the
///     swim is then invalid);
///  5. the velocity changes go to Box2D as forces m·Δw/h, and since a bounce happens at its event
///     time and not at the start of the step, the end positions of the cells involved differ from
///     x + h·w; the stepper applies that difference after Box2D's step (SwimState::cx, cy). Events
///     are thus located to O(h²) on the actual piecewise-straight paths.
/// Nothing is allocated per step: every list is sized at construction.
class Collisions final : public Effect {
 public:
  static constexpr int kMaxEvents = 64;

  Collisions(const Body& body, const SceneParams& p) : restitution_(p.collision_restitution), tol_(p.collision_tolerance) {
    n_ = body.node_count();
    rx_.resize(at(n_));
    ry_.resize(at(n_));
    for (int i = 0; i < n_; ++i) {
      rx_[at(i)] = body.positions(i, 0);
      ry_[at(i)] = body.positions(i, 1);
    }
    // Edges: every spring, or only the skin.
    std::map<std::pair<int, int>, int> index;
    auto edge_of = [&](int u, int v) {
      const auto key = std::minmax(u, v);
      auto it = index.find({key.first, key.second});
      if (it != index.end()) return it->second;
      const int e = static_cast<int>(a_.size());
      a_.push_back(key.first);
      b_.push_back(key.second);
      index.emplace(std::make_pair(key.first, key.second), e);
      return e;
    };
    const bool all = p.collision_edges != "skin";
    if (all)
      for (int s = 0; s < body.spring_count(); ++s) edge_of(body.springs(s, 0), body.springs(s, 1));
    std::vector<int> skin_edges;
    for (int s = 0; s < as_int(body.skin.rows()); ++s) skin_edges.push_back(edge_of(body.skin(s, 0), body.skin(s, 1)));
    opposite_.assign(a_.size(), -1);
    if (all) {
      std::vector<std::pair<int, int>> region_pairs;
      for (const auto& loop : body.regions) {
        const std::size_t k = loop.size();
        if (k == 3 && loop[0] != loop[1] && loop[1] != loop[2] && loop[0] != loop[2]) {
          Triangle t{};
          for (std::size_t c = 0; c < 3; ++c) {
            t.v[c] = loop[c];
            t.e[c] = edge_of(loop[(c + 1) % 3], loop[(c + 2) % 3]);  // the edge opposite vertex c
            t.band[c] = band_of(t.v[c], t.e[c]);
            opposite_[at(t.e[c])] = t.v[c];
          }
          t.band_max = std::max({t.band[0], t.band[1], t.band[2]});
          t.band4 = triangle_band4(t.band_max);
          tris_.push_back(t);
          continue;
        }
        for (std::size_t q = 0; q < k; ++q) {
          const int e = edge_of(loop[q], loop[(q + 1) % k]);
          for (std::size_t r = 0; r < k; ++r) {
            const int v = loop[r];
            if (v != a_[at(e)] && v != b_[at(e)]) region_pairs.emplace_back(v, e);
          }
        }
      }
      std::sort(region_pairs.begin(), region_pairs.end());
      region_pairs.erase(std::unique(region_pairs.begin(), region_pairs.end()), region_pairs.end());
      for (const auto& [v, e] : region_pairs) fixed_.push_back({v, e, band_of(v, e)});
    }
    // Skin items for the sort and sweep: skin vertices and skin edges.
    // Cells on the outer face: the ends of skin edges, and cells without any edge (a hand-made body).
    std::vector<char> on_skin(at(n_), 1);
    for (int s = 0; s < body.spring_count(); ++s) {
      on_skin[at(body.springs(s, 0))] = 0;
      on_skin[at(body.springs(s, 1))] = 0;
    }
    for (int e : skin_edges) {
      on_skin[at(a_[at(e)])] = 1;
      on_skin[at(b_[at(e)])] = 1;
    }
    // A skin vertex farther than 2·tolerance (at rest) from every skin edge not its own has the band
    // `tolerance` with all of them; the others get theirs computed per candidate.
    exact_band_.assign(at(n_), 0);
    for (int i = 0; i < n_; ++i) {
      if (!on_skin[at(i)]) continue;
      items_.push_back({0, 0, 0, 0, i, -1});
      for (int e : skin_edges)
        if (i != a_[at(e)] && i != b_[at(e)] && band_of(i, e) < tol_) exact_band_[at(i)] = 1;
    }
    for (int e : skin_edges) items_.push_back({0, 0, 0, 0, -1, e});
    for (std::size_t k = 0; k < items_.size(); ++k) order_.push_back(static_cast<int>(k));

    for (auto* v : {&w0x_, &w0y_, &wx_, &wy_, &qx_, &qy_, &motion_, &ex_, &ey_}) v->assign(at(n_), 0.0);
    kicked_.assign(at(n_), 0);
    const std::size_t skin_vertices = items_.size() - skin_edges.size();
    candidates_.reserve(3 * tris_.size() + fixed_.size() + skin_vertices * skin_edges.size());
  }
  std::string_view name() const override { return "collisions"; }
  Stage stage() const override { return Stage::constraint; }

  void apply(SwimState& s) override {
    ++calls_;
    if (a_.empty() || n_ < 3) return;
    const double kv = s.h * s.inv_mass;
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      w0x_[u] = s.vx[u] + kv * s.fx[u];
      w0y_[u] = s.vy[u] + kv * s.fy[u];
      wx_[u] = w0x_[u];
      wy_[u] = w0y_[u];
      qx_[u] = s.x[u];
      qy_[u] = s.y[u];
    }
    tau_ = 0.0;
    int events = 0;
    long collisions = 0, inelastic = 0;
    bool resolved = true;
    while (tau_ < 1.0) {
      const double span = (1.0 - tau_) * s.h;  // time left in the step
      gather(span);
      double first_u = 2.0;
      std::size_t first = 0;
      for (std::size_t k = 0; k < candidates_.size(); ++k) {
        const double u = event_time(candidates_[k], span);
        if (u < first_u) {  // ties: the first candidate in order
          first_u = u;
          first = k;
        }
      }
      if (first_u > 1.0) break;
      if (events >= 2 * kMaxEvents) {
        resolved = false;
        break;
      }
      if (events == 0)
        for (int i = 0; i < n_; ++i) kicked_[at(i)] = 0;
      const bool fallback = events >= kMaxEvents;
      ++events;
      const double dt = first_u * span;
      for (int i = 0; i < n_; ++i) {
        qx_[at(i)] += dt * wx_[at(i)];
        qy_[at(i)] += dt * wy_[at(i)];
      }
      tau_ += first_u * (1.0 - tau_);
      bounce(candidates_[first], fallback ? 0.0 : restitution_);
      ++collisions;
      if (fallback && restitution_ > 0.0) ++inelastic;
    }
    s.counters.collisions += collisions;
    s.counters.collisions_inelastic += inelastic;
    s.counters.collision_max_passes = std::max(s.counters.collision_max_passes, static_cast<long>(events));
    if (!resolved) ++s.counters.collisions_unresolved;
    if (events == 0) return;
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

 private:
  struct Pair {
    int cell;
    int edge;
    double band;  // tolerance of this pair: min(tolerance, half the rest distance)
  };
  struct Triangle {
    std::array<int, 3> v;        // vertices (CCW at rest)
    std::array<int, 3> e;        // e[c]: the edge opposite v[c]
    std::array<double, 3> band;  // band of the pair (v[c], e[c])
    double band_max;
    double band4;                // 4·band_max·(1 + 1e-12): the cheaper test's bound on band_max·lmax per (reach + d)
  };
  struct Item {  // a skin vertex (vertex >= 0) or a skin edge (edge >= 0) in the sort and sweep
    double lo, hi, ylo, yhi;
    int vertex, edge;
  };

  double band_of(int v, int e) const {
    const SegmentHit rest = closest_on_segment(rx_[at(v)], ry_[at(v)], rx_[at(a_[at(e)])], ry_[at(a_[at(e)])],
                                               rx_[at(b_[at(e)])], ry_[at(b_[at(e)])]);
    return std::min(tol_, 0.5 * std::sqrt(rest.d2));
  }

  /// The pairs that can have an event in the next `span` of time (step 2 of the class comment).
  void gather(double span) {
    candidates_.clear();
    const double* qx = qx_.data();
    const double* qy = qy_.data();
    const double* wx = wx_.data();
    const double* wy = wy_.data();
    double* motion = motion_.data();
    double* ex = ex_.data();
    double* ey = ey_.data();
    for (int i = 0; i < n_; ++i) {
      motion[i] = span * (std::abs(wx[i]) + std::abs(wy[i]));  // (a sum: NaN stays NaN)
      ex[i] = qx[i] + span * wx[i];                           // where the cell is at the end of the span
      ey[i] = qy[i] + span * wy[i];
    }
    for (const Triangle& t : tris_) {
      const int a = t.v[0], b = t.v[1], c = t.v[2];
      const double abx = qx[b] - qx[a], aby = qy[b] - qy[a], acx = qx[c] - qx[a], acy = qy[c] - qy[a];
      // The cheaper test first: it only rejects triangles the full test rejects too.
      if (triangle_surely_clear(abx, aby, acx, acy, motion[a] + motion[b] + motion[c], t.band4)) {
#if ANIMAT_SELF_CHECK
        if (!full_test_rejects(t, span)) self_check_failed(t, span);
#endif
        continue;
      }
      const double dbx = span * (wx[b] - wx[a]), dby = span * (wy[b] - wy[a]);
      const double dcx = span * (wx[c] - wx[a]), dcy = span * (wy[c] - wy[a]);
      if (triangle_stays_clear(abx, aby, acx, acy, dbx, dby, dcx, dcy, t.band_max)) continue;
      for (std::size_t k = 0; k < 3; ++k) candidates_.push_back({t.v[k], t.e[k], t.band[k]});
    }
    for (const Pair& p : fixed_)
      if (boxes_meet(p)) candidates_.push_back(p);
    if (items_.empty()) return;
    // Skin: sort and sweep the swept x-extents (insertion sort: the order barely changes).
    for (Item& it : items_) {
      if (it.vertex >= 0) {
        const auto v = at(it.vertex);
        const double x1 = ex[v], y1 = ey[v];
        it.lo = std::min(qx[v], x1) - tol_;
        it.hi = std::max(qx[v], x1) + tol_;
        it.ylo = std::min(qy[v], y1) - tol_;
        it.yhi = std::max(qy[v], y1) + tol_;
      } else {
        const auto a = at(a_[at(it.edge)]), b = at(b_[at(it.edge)]);
        const double ax1 = ex[a], ay1 = ey[a];
        const double bx1 = ex[b], by1 = ey[b];
        it.lo = std::min(std::min(qx[a], ax1), std::min(qx[b], bx1));
        it.hi = std::max(std::max(qx[a], ax1), std::max(qx[b], bx1));
        it.ylo = std::min(std::min(qy[a], ay1), std::min(qy[b], by1));
        it.yhi = std::max(std::max(qy[a], ay1), std::max(qy[b], by1));
      }
    }
    for (std::size_t q = 1; q < order_.size(); ++q)
      for (std::size_t r = q; r > 0 && items_[at(order_[r])].lo < items_[at(order_[r - 1])].lo; --r)
        std::swap(order_[r], order_[r - 1]);
    for (std::size_t q = 0; q < order_.size(); ++q) {
      const Item& p = items_[at(order_[q])];
      for (std::size_t r = q + 1; r < order_.size(); ++r) {
        const Item& o = items_[at(order_[r])];
        if (o.lo > p.hi) break;
        if ((p.vertex >= 0) == (o.vertex >= 0)) continue;
        if (o.ylo > p.yhi || o.yhi < p.ylo) continue;
        const int v = p.vertex >= 0 ? p.vertex : o.vertex;
        const int e = p.vertex >= 0 ? o.edge : p.edge;
        if (v == a_[at(e)] || v == b_[at(e)] || v == opposite_[at(e)]) continue;  // own edge, or its triangle's
        candidates_.push_back({v, e, exact_band_[at(v)] ? band_of(v, e) : tol_});
      }
    }
  }

#if ANIMAT_SELF_CHECK
  /// The full triangle test of gather(): whether it rejects the triangle.
  bool full_test_rejects(const Triangle& t, double span) const {
    const int a = t.v[0], b = t.v[1], c = t.v[2];
    return triangle_stays_clear(qx_[b] - qx_[a], qy_[b] - qy_[a], qx_[c] - qx_[a], qy_[c] - qy_[a],
                                span * (wx_[b] - wx_[a]), span * (wy_[b] - wy_[a]), span * (wx_[c] - wx_[a]),
                                span * (wy_[c] - wy_[a]), t.band_max);
  }
  [[noreturn]] static void self_check_failed(const Triangle& t, double span) {
    std::fprintf(stderr, "collisions: the cheaper triangle test rejected triangle (%d, %d, %d) at span %.17g, the full test does not\n",
                 t.v[0], t.v[1], t.v[2], span);
    std::abort();
  }
#endif

  /// Whether the swept boxes of a pair's cell and edge (widened by the band) overlap.
  bool boxes_meet(const Pair& p) const {
    const auto i = at(p.cell), a = at(a_[at(p.edge)]), b = at(b_[at(p.edge)]);
    const double px1 = ex_[i], py1 = ey_[i];
    const double ax1 = ex_[a], ay1 = ey_[a];
    const double bx1 = ex_[b], by1 = ey_[b];
    const double band = p.band;
    return !(std::max(qx_[i], px1) < std::min({qx_[a], ax1, qx_[b], bx1}) - band ||
             std::min(qx_[i], px1) > std::max({qx_[a], ax1, qx_[b], bx1}) + band ||
             std::max(qy_[i], py1) < std::min({qy_[a], ay1, qy_[b], by1}) - band ||
             std::min(qy_[i], py1) > std::max({qy_[a], ay1, qy_[b], by1}) + band);
  }

  /// The pair's first event within the next `span` of time, as a fraction u in [0, 1] of it
  /// (> 1: none), with the cells at q moving at w: the first time the cell enters the capsule of
  /// radius `band` around the segment (through one of its two sides or one of its two end caps)
  /// while approaching it, or u = 0 if it is inside and approaching. The capsule keeps the cell
  /// `band` away from the edge itself, so float rounding can never put it on the wrong side.
  double event_time(const Pair& pr, double span) const {
    const auto i = at(pr.cell), a = at(a_[at(pr.edge)]), b = at(b_[at(pr.edge)]);
    const double band = pr.band;
    // e(u) = e0 + u·de (edge vector), r(u) = r0 + u·dr (cell relative to a).
    const double ex0 = qx_[b] - qx_[a], ey0 = qy_[b] - qy_[a];
    const double dex = span * (wx_[b] - wx_[a]), dey = span * (wy_[b] - wy_[a]);
    const double rx0 = qx_[i] - qx_[a], ry0 = qy_[i] - qy_[a];
    const double drx = span * (wx_[i] - wx_[a]), dry = span * (wy_[i] - wy_[a]);
    const double l2 = ex0 * ex0 + ey0 * ey0;
    if (!(l2 > 0.0)) return 2.0;
    if (approaching_within(pr, 0.0, span, l2)) return 0.0;  // inside the capsule already, closing in
    std::array<double, 8> times{};  // two roots per side and per cap
    int count = 0;
    std::array<double, 2> r{};
    // Sides: the signed distance cross(e, r)/|e0| reaches ±band (|e| taken at the start: the band is
    // a tolerance).
    const double len = std::sqrt(l2);
    const double c0 = ex0 * ry0 - ey0 * rx0;
    const double c1 = ex0 * dry - ey0 * drx + dex * ry0 - dey * rx0;
    const double c2 = dex * dry - dey * drx;
    for (double sign : {1.0, -1.0}) {
      const int k = roots_in_unit_interval(sign * c2, sign * c1, sign * c0 - band * len, r);
      for (int q = 0; q < k; ++q) times[at(count++)] = r[at(q)];
    }
    // End caps: |cell − a| or |cell − b| reaches band.
    const double sx0 = rx0 - ex0, sy0 = ry0 - ey0, dsx = drx - dex, dsy = dry - dey;  // cell relative to b
    const int ka = roots_in_unit_interval(drx * drx + dry * dry, 2.0 * (rx0 * drx + ry0 * dry),
                                          rx0 * rx0 + ry0 * ry0 - band * band, r);
    for (int q = 0; q < ka; ++q) times[at(count++)] = r[at(q)];
    const int kb = roots_in_unit_interval(dsx * dsx + dsy * dsy, 2.0 * (sx0 * dsx + sy0 * dsy),
                                          sx0 * sx0 + sy0 * sy0 - band * band, r);
    for (int q = 0; q < kb; ++q) times[at(count++)] = r[at(q)];
    for (int q = 1; q < count; ++q)  // insertion sort: at most eight
      for (int k = q; k > 0 && times[at(k)] < times[at(k - 1)]; --k) std::swap(times[at(k)], times[at(k - 1)]);
    for (int q = 0; q < count; ++q)
      if (approaching_within(pr, times[at(q)], span, l2)) return times[at(q)];
    return 2.0;
  }

  /// Whether, at fraction u of the next `span`, the cell is within its band of the segment and
  /// approaching it. The side roots measure the distance with the edge's length at the start of
  /// the span (l2_start, squared), so the band is widened by that length over the current one; the
  /// relative slack of 1e-9 covers the rounding of roots that put the cell exactly on the band.
  bool approaching_within(const Pair& pr, double u, double span, double l2_start) const {
    const auto i = at(pr.cell), a = at(a_[at(pr.edge)]), b = at(b_[at(pr.edge)]);
    const double t = u * span;
    const double ax = qx_[a] + t * wx_[a], ay = qy_[a] + t * wy_[a];
    const double bx = qx_[b] + t * wx_[b], by = qy_[b] + t * wy_[b];
    const double px = qx_[i] + t * wx_[i], py = qy_[i] + t * wy_[i];
    const SegmentHit hit = closest_on_segment(px, py, ax, ay, bx, by);
    const double l2_now = (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
    const double widen = l2_now < l2_start && l2_now > 0.0 ? std::sqrt(l2_start / l2_now) : 1.0;
    const double reach = pr.band * widen * (1.0 + 1e-9);
    if (!(hit.d2 <= reach * reach)) return false;
    const double vx = wx_[i] - ((1.0 - hit.t) * wx_[a] + hit.t * wx_[b]);
    const double vy = wy_[i] - ((1.0 - hit.t) * wy_[a] + hit.t * wy_[b]);
    return (px - hit.qx) * vx + (py - hit.qy) * vy < 0.0;
  }

  /// The elastic (e = 1) or partly inelastic impulse of a pair whose cells are at their event: along
  /// the direction from the closest point of the edge to the cell.
  void bounce(const Pair& pr, double e) {
    const auto i = at(pr.cell), a = at(a_[at(pr.edge)]), b = at(b_[at(pr.edge)]);
    const SegmentHit hit = closest_on_segment(qx_[i], qy_[i], qx_[a], qy_[a], qx_[b], qy_[b]);
    const double sc = hit.t;
    double nx = qx_[i] - hit.qx, ny = qy_[i] - hit.qy;
    const double d = std::sqrt(nx * nx + ny * ny);
    if (!(d > 0.0)) return;  // cannot happen: events keep the band between them
    nx /= d;
    ny /= d;
    const double vx = wx_[i] - ((1.0 - sc) * wx_[a] + sc * wx_[b]);
    const double vy = wy_[i] - ((1.0 - sc) * wy_[a] + sc * wy_[b]);
    const double vn = nx * vx + ny * vy;
    if (!(vn < 0.0)) return;
    // Equal masses: 1/m_eff = (1 + (1 − s)² + s²)/m; the velocity changes are J/m per unit weight.
    const double dv = -(1.0 + e) * vn / (1.0 + (1.0 - sc) * (1.0 - sc) + sc * sc);
    kick(i, dv * nx, dv * ny);
    kick(a, -(1.0 - sc) * dv * nx, -(1.0 - sc) * dv * ny);
    kick(b, -sc * dv * nx, -sc * dv * ny);
  }

  void kick(std::size_t i, double dvx, double dvy) {
    wx_[i] += dvx;
    wy_[i] += dvy;
    kicked_[i] = 1;
  }

  double restitution_, tol_;
  int n_ = 0;
  std::vector<int> a_, b_;          // edges a cell may not cross
  std::vector<int> opposite_;       // per edge: the opposite vertex of its triangular region (-1: none)
  std::vector<double> rx_, ry_;     // rest positions (per-pair tolerance)
  std::vector<Triangle> tris_;      // triangular regions
  std::vector<Pair> fixed_;         // vertex-edge pairs of larger regions
  std::vector<Item> items_;         // skin vertices and skin edges
  std::vector<int> order_;          // items sorted by their swept x-extent (kept between steps)
  std::vector<char> exact_band_;    // skin vertices whose band differs from the tolerance for some edge
  std::vector<Pair> candidates_;
  std::vector<double> w0x_, w0y_;   // end-of-step velocities before any bounce
  std::vector<double> wx_, wy_;     // current velocities while the events are processed
  std::vector<double> qx_, qy_;     // positions at the current event time
  std::vector<double> motion_;      // per cell, span·(|wx| + |wy|) (the triangles' cheaper test)
  std::vector<double> ex_, ey_;     // per cell, q + span·w: its position at the end of the span (gather)
  std::vector<char> kicked_;        // cells whose velocity a bounce changed this step
  double tau_ = 0.0;                // fraction of the step done
};

}  // namespace

std::unique_ptr<Effect> make_collisions(const Body& body, const SceneParams& scene) {
  return std::make_unique<Collisions>(body, scene);
}

}  // namespace animat::effects
