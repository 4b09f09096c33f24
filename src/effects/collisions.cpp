// Effect "collisions": "penetration of an edge by a cell is not allowed and results in an elastic
// collision" [paper §4]. A cell never crosses an edge it is not an end of: within every Box2D step,
// the motion of each (cell, edge) pair that could meet is tested (a swept
// point-versus-moving-segment test), and a crossing is resolved, at its time within the step, by an
// elastic impulse between the cell and the edge's two end cells.
//
// Which pairs can meet follows from the planar embedding itself. Just before a cell first touches
// an edge it is not an end of, the body is still planar, so the cell and the edge lie on a common
// face: a region (then the edge is an edge of that region) or the outer face (then both are on the
// skin). So with collision_edges = "all" it suffices to test, per region, its vertices against its
// edges, and skin vertices against skin edges; preventing those crossings keeps the embedding: no
// region turns inside out (a triangle inverts only when a vertex crosses the opposite edge) and the
// skin stays simple (two edges can only come to cross after an end of one has touched the other).
// collision_edges = "skin" tests only the skin pairs (measured: internal regions then invert).
//
// With effect "ground" in the scene, the floor contacts are events of the same loop (class comment,
// step 4b): a floor impulse changes velocities only at its event time, and every edge event after
// it is still found, so the floor cannot undo the guarantee above.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "../box_pair_list.hpp"
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
///     triangle: the doubled area is the cross product of all three pairs), the vertex-edge pairs
///     of larger regions whose swept boxes overlap, and the skin vertices against the skin edges
///     whose swept boxes overlap (sort and sweep along x);
///  3. for each candidate (cell i, edge ab) the gap function cross(b − a, p − a), quadratic in time
///     under that motion, gives the pair's first event: the first time at which the cell comes
///     within the tolerance band of the edge (on the side it is on) or reaches the segment (from
///     either side), with its projection inside the segment, while approaching the edge point
///     q = (1 − s)·a + s·b (relative normal velocity v_n < 0);
///  4. the earliest event of all is processed: every cell advances to that time, and the impulse
///     J = −(1 + e)·v_n / (1/m_i + (1 − s)²/m_a + s²/m_b) along the normal changes w_i by +J/m_i
///     and w_a, w_b by −(1 − s)·J/m_a and −s·J/m_b: momentum is conserved exactly and, for e = 1,
///     kinetic energy too. Then steps 2–4 again from that time on, until no event is left in the
///     step. After kMaxEvents events in one step the rest are resolved with e = 0 (counted as
///     inelastic); a step that still has events after 2·kMaxEvents is counted as unresolved (the
///     swim is then invalid);
///  4b. with effect ground (the floor y = y0, docs/worlds.md), a cell reaching the floor is an
///     event too (the floor wins ties): at its time the cell is put exactly on the floor and the
///     floor's inelastic normal impulse sets its vertical velocity to 0 (or, for a cell that float
///     rounding left below the floor at the start of the step, to the velocity that brings it back
///     onto the floor by the end of the step: the old projection), together with the Coulomb
///     friction impulse of that normal impulse (floor_friction(): sticking if the impulse that
///     stops the cell is within μ_s·J_n, else sliding with μ_k·J_n). The floor events at the start
///     of the step (cells resting on it) are resolved before the first search. A cell-edge impulse
///     that would push a cell lying on the floor (and not moving up) into it is solved together
///     with the floor: that cell's vertical inverse mass is 0 in the impulse, the floor takes the
///     vertical part (a normal impulse, with its friction as above), so an edge pressing a cell
///     onto the floor bounces off it like off a wall instead of an endless sequence of ever smaller
///     events;
///  5. the velocity changes go to Box2D as forces m·Δw/h, and since a bounce happens at its event
///     time and not at the start of the step, the end positions of the cells involved differ from
///     x + h·w; the stepper applies that difference after Box2D's step (SwimState::cx, cy). Events
///     are thus located to O(h²) on the actual piecewise-straight paths.
/// Nothing is allocated per step: every list is sized at construction.
class Collisions final : public Effect {
 public:
  static constexpr int kMaxEvents = 64;
  /// How far (length units) the skin items' boxes are widened for the list of skin pairs: the
  /// list is rebuilt when a box leaves its widened box.
  static constexpr double kSkinMargin = 0.5;

  Collisions(const Body& body, const SceneParams& p)
      : restitution_(p.collision_restitution),
        tol_(p.collision_tolerance),
        floor_(has_effect(p.effects, "ground") && p.ground_contact == "impulse"),
        y0_(p.ground_height),
        mu_s_(p.ground_friction_static),
        mu_k_(p.ground_friction_kinetic) {
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
    for (int s = 0; s < as_int(body.skin.rows()); ++s)
      skin_edges.push_back(edge_of(body.skin(s, 0), body.skin(s, 1)));
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
    // Cells on the outer face: the ends of skin edges, and cells without any edge (a hand-made
    // body).
    std::vector<char> on_skin(at(n_), 1);
    for (int s = 0; s < body.spring_count(); ++s) {
      on_skin[at(body.springs(s, 0))] = 0;
      on_skin[at(body.springs(s, 1))] = 0;
    }
    for (int e : skin_edges) {
      on_skin[at(a_[at(e)])] = 1;
      on_skin[at(b_[at(e)])] = 1;
    }
    // A skin vertex farther than 2·tolerance (at rest) from every skin edge not its own has the
    // band `tolerance` with all of them; the others get theirs computed per candidate.
    exact_band_.assign(at(n_), 0);
    for (int i = 0; i < n_; ++i) {
      if (!on_skin[at(i)]) continue;
      items_.push_back({i, -1});
      for (int e : skin_edges)
        if (i != a_[at(e)] && i != b_[at(e)] && band_of(i, e) < tol_) exact_band_[at(i)] = 1;
    }
    for (int e : skin_edges) items_.push_back({-1, e});
    for (std::size_t k = 0; k < items_.size(); ++k) order_.push_back(static_cast<int>(k));
    boxes_.assign(items_.size(), detail::Box{0.0, 0.0, 0.0, 0.0});
    rank_.assign(items_.size(), 0);

    for (auto* v : {&w0x_, &w0y_, &wx_, &wy_, &qx_, &qy_, &motion_, &ex_, &ey_})
      v->assign(at(n_), 0.0);
    kicked_.assign(at(n_), 0);
    if (floor_) {
      for (auto* v : {&fvx_, &fvy_, &floor_wy_, &floor_u_}) v->assign(at(n_), 0.0);
      floor_state_.assign(at(n_), 0);
    }
    const std::size_t skin_vertices = items_.size() - skin_edges.size();
    candidates_.reserve(3 * tris_.size() + fixed_.size() + skin_vertices * skin_edges.size());
    skin_pairs_.reset(items_.size(), kSkinMargin, skin_vertices * skin_edges.size());
    listed_.reserve(skin_vertices * skin_edges.size());
#if ANIMAT_SELF_CHECK
    self_check_.reserve(skin_vertices * skin_edges.size());
#endif
  }
  std::string_view name() const override { return "collisions"; }
  Stage stage() const override { return Stage::constraint; }

  void apply(SwimState& s) override {
    ++calls_;
    if (!floor_ && (a_.empty() || n_ < 3)) return;
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
    h_ = s.h;
    int events = 0, floor_passes = 0;  // cell-edge events; floor events after the start of the step
    long collisions = 0, inelastic = 0;
    bool resolved = true;
    bool floor_kicked = false;
    if (floor_) {
      for (int i = 0; i < n_; ++i) {
        const auto u = at(i);
        kicked_[u] = 0;
        fvx_[u] = fvy_[u] = floor_wy_[u] = 0.0;
        floor_state_[u] = 0;
      }
      floor_kicked = floor_events(s.h, 0.0, true);  // cells on the floor at the start of the step
    }
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
      const double floor_u = floor_ ? first_floor_event(span) : 2.0;
      if (first_u > 1.0 && floor_u > 1.0) break;
      const bool floor_first = floor_u <= first_u;  // the floor wins ties
      if (floor_first ? floor_passes >= 2 * kMaxEvents + n_ : events >= 2 * kMaxEvents) {
        resolved = false;
        break;
      }
      if (events == 0 && !floor_)
        for (int i = 0; i < n_; ++i) kicked_[at(i)] = 0;
      const double event_u = floor_first ? floor_u : first_u;
      const double dt = event_u * span;
      for (int i = 0; i < n_; ++i) {
        qx_[at(i)] += dt * wx_[at(i)];
        qy_[at(i)] += dt * wy_[at(i)];
      }
      tau_ += event_u * (1.0 - tau_);
      if (floor_first) {
        ++floor_passes;
        floor_events(span, floor_u, false);
        floor_kicked = true;
        continue;
      }
      const bool fallback = events >= kMaxEvents;
      ++events;
      bounce(candidates_[first], fallback ? 0.0 : restitution_);
      ++collisions;
      if (fallback && restitution_ > 0.0) ++inelastic;
    }
    s.counters.collisions += collisions;
    s.counters.collisions_inelastic += inelastic;
    s.counters.collision_max_passes =
        std::max(s.counters.collision_max_passes, static_cast<long>(events + floor_passes));
    if (!resolved) ++s.counters.collisions_unresolved;
    const double mh = s.mass / s.h;
    if (floor_) {
      long contacts = 0, slips = 0;
      for (int i = 0; i < n_; ++i) {
        const auto u = at(i);
        s.ground_fx[u] = fvx_[u] * mh;
        s.ground_fy[u] = fvy_[u] * mh;
        contacts += floor_state_[u] & 1;
        slips += (floor_state_[u] >> 1) & 1;
      }
      s.counters.ground_contacts += contacts;
      s.counters.ground_slips += slips;
    }
    if (events == 0 && !floor_kicked) return;
    for (int i = 0; i < n_; ++i) {
      const auto u = at(i);
      s.cx[u] = 0.0;
      s.cy[u] = 0.0;
      if (!kicked_[u]) continue;
      if (floor_) {  // the floor's share goes to effect ground (s.ground_fx, s.ground_fy)
        s.fx[u] += ((wx_[u] - w0x_[u]) - fvx_[u]) * mh;
        s.fy[u] += ((wy_[u] - w0y_[u]) - fvy_[u]) * mh;
      } else {
        s.fx[u] += (wx_[u] - w0x_[u]) * mh;
        s.fy[u] += (wy_[u] - w0y_[u]) * mh;
      }
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
    // 4·band_max·(1 + 1e-12): the cheaper test's bound on band_max·lmax per (reach + d)
    double band4;
  };
  struct Item {  // a skin vertex (vertex >= 0) or a skin edge (edge >= 0) in the sort and sweep
    int vertex, edge;
  };

  double band_of(int v, int e) const {
    const SegmentHit rest =
        closest_on_segment(rx_[at(v)], ry_[at(v)], rx_[at(a_[at(e)])], ry_[at(a_[at(e)])],
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
      // where the cell is at the end of the span
      ex[i] = qx[i] + span * wx[i];
      ey[i] = qy[i] + span * wy[i];
    }
    for (const Triangle& t : tris_) {
      const int a = t.v[0], b = t.v[1], c = t.v[2];
      const double abx = qx[b] - qx[a], aby = qy[b] - qy[a], acx = qx[c] - qx[a],
                   acy = qy[c] - qy[a];
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
    // Skin: the swept boxes of the skin vertices (widened by the tolerance) and edges, sorted by
    // their lower x (insertion sort: the order barely changes). The candidates are the pairs a
    // sweep along that order finds, in its order; from the list of pairs that can overlap while
    // every box stays within its box of the list's last build widened by kSkinMargin
    // (src/box_pair_list.hpp), or from the sweep itself when no list can be built.
    bool held = skin_pairs_.built();  // every box within its widened box (skin_pairs_.holds())
    for (std::size_t k = 0; k < items_.size(); ++k) {
      const Item& it = items_[k];
      detail::Box& box = boxes_[k];
      if (it.vertex >= 0) {
        const auto v = at(it.vertex);
        const double x1 = ex[v], y1 = ey[v];
        box.lo = std::min(qx[v], x1) - tol_;
        box.hi = std::max(qx[v], x1) + tol_;
        box.ylo = std::min(qy[v], y1) - tol_;
        box.yhi = std::max(qy[v], y1) + tol_;
      } else {
        const auto a = at(a_[at(it.edge)]), b = at(b_[at(it.edge)]);
        const double ax1 = ex[a], ay1 = ey[a];
        const double bx1 = ex[b], by1 = ey[b];
        box.lo = std::min(std::min(qx[a], ax1), std::min(qx[b], bx1));
        box.hi = std::max(std::max(qx[a], ax1), std::max(qx[b], bx1));
        box.ylo = std::min(std::min(qy[a], ay1), std::min(qy[b], by1));
        box.yhi = std::max(std::max(qy[a], ay1), std::max(qy[b], by1));
      }
      held = skin_pairs_.contains(k, box) && held;
    }
    for (std::size_t q = 1; q < order_.size(); ++q)
      for (std::size_t r = q; r > 0 && boxes_[at(order_[r])].lo < boxes_[at(order_[r - 1])].lo; --r)
        std::swap(order_[r], order_[r - 1]);
#if ANIMAT_SELF_CHECK
    const std::size_t first_skin = candidates_.size();
#endif
    if (held ||
        skin_pairs_.build(boxes_.data(), [&](int p, int o) { return skin_pair(p, o) >= 0; }))
      add_listed_skin_pairs();
    else
      sweep_skin();
#if ANIMAT_SELF_CHECK
    check_skin_candidates(first_skin);
#endif
  }

  /// For skin items p and o, a vertex and an edge that may collide, the vertex's item; else -1
  /// (two vertices, two edges, or the vertex is an end of the edge or its triangle's opposite
  /// vertex).
  [[nodiscard]] int skin_pair(int p, int o) const {
    const Item& ip = items_[at(p)];
    const Item& io = items_[at(o)];
    if ((ip.vertex >= 0) == (io.vertex >= 0)) return -1;
    const int vi = ip.vertex >= 0 ? p : o;
    const int v = items_[at(vi)].vertex;
    const int e = ip.vertex >= 0 ? io.edge : ip.edge;
    if (v == a_[at(e)] || v == b_[at(e)] || v == opposite_[at(e)]) return -1;
    return vi;
  }

  void add_skin_candidate(const Item& p, const Item& o) {
    const int v = p.vertex >= 0 ? p.vertex : o.vertex;
    const int e = p.vertex >= 0 ? o.edge : p.edge;
    candidates_.push_back({v, e, exact_band_[at(v)] ? band_of(v, e) : tol_});
  }

  /// The skin candidates by the sort and sweep over every item (boxes_ sorted in order_).
  void sweep_skin() {
    for (std::size_t q = 0; q < order_.size(); ++q) {
      const detail::Box& p = boxes_[at(order_[q])];
      for (std::size_t r = q + 1; r < order_.size(); ++r) {
        const detail::Box& o = boxes_[at(order_[r])];
        if (o.lo > p.hi) break;
        if (skin_pair(order_[q], order_[r]) < 0) continue;
        if (o.ylo > p.yhi || o.yhi < p.ylo) continue;
        add_skin_candidate(items_[at(order_[q])], items_[at(order_[r])]);
      }
    }
  }

  /// The same candidates in the same order from skin_pairs_ (every box finite and within its
  /// widened box, so the list holds every overlapping pair). With the items sorted, the sweep
  /// finds exactly the eligible pairs whose (closed) boxes overlap: for p before o, p.lo <= o.lo
  /// <= o.hi, so `o.lo <= p.hi` is the x overlap; and it adds them ordered by the position of the
  /// earlier item in order_, then of the later one.
  void add_listed_skin_pairs() {
    listed_.clear();
    for (const auto& [p, o] : skin_pairs_.pairs())
      if (detail::boxes_overlap(boxes_[at(p)], boxes_[at(o)]))
        listed_.push_back((static_cast<std::uint64_t>(p) << 32) | static_cast<std::uint64_t>(o));
    if (listed_.size() > 1) {  // their order in the sweep (one pair has no order to keep)
      for (std::size_t q = 0; q < order_.size(); ++q) rank_[at(order_[q])] = static_cast<int>(q);
      for (std::uint64_t& key : listed_) {
        const auto rp = static_cast<std::uint64_t>(rank_[static_cast<std::size_t>(key >> 32)]);
        const auto ro =
            static_cast<std::uint64_t>(rank_[static_cast<std::size_t>(key & 0xffffffffU)]);
        key = rp < ro ? (rp << 32) | ro : (ro << 32) | rp;
      }
      std::sort(listed_.begin(), listed_.end());
      for (std::uint64_t& key : listed_)
        key = (static_cast<std::uint64_t>(order_[static_cast<std::size_t>(key >> 32)]) << 32) |
              static_cast<std::uint64_t>(order_[static_cast<std::size_t>(key & 0xffffffffU)]);
    }
    for (const std::uint64_t key : listed_)
      add_skin_candidate(items_[static_cast<std::size_t>(key >> 32)],
                         items_[static_cast<std::size_t>(key & 0xffffffffU)]);
  }

#if ANIMAT_SELF_CHECK
  /// Whether the skin candidates from `first` on are those of the sweep over every item, in the
  /// same order; aborts if not.
  void check_skin_candidates(std::size_t first) {
    self_check_.assign(candidates_.begin() + static_cast<std::ptrdiff_t>(first), candidates_.end());
    candidates_.resize(first);
    sweep_skin();
    const bool same = self_check_.size() == candidates_.size() - first &&
                      std::equal(self_check_.begin(), self_check_.end(),
                                 candidates_.begin() + static_cast<std::ptrdiff_t>(first),
                                 [](const Pair& x, const Pair& y) {
                                   return x.cell == y.cell && x.edge == y.edge && x.band == y.band;
                                 });
    if (same) return;
    std::fprintf(stderr,
                 "collisions: the listed skin candidates (%zu) differ from the sweep's (%zu)\n",
                 self_check_.size(), candidates_.size() - first);
    std::abort();
  }
#endif

#if ANIMAT_SELF_CHECK
  /// The full triangle test of gather(): whether it rejects the triangle.
  bool full_test_rejects(const Triangle& t, double span) const {
    const int a = t.v[0], b = t.v[1], c = t.v[2];
    return triangle_stays_clear(qx_[b] - qx_[a], qy_[b] - qy_[a], qx_[c] - qx_[a], qy_[c] - qy_[a],
                                span * (wx_[b] - wx_[a]), span * (wy_[b] - wy_[a]),
                                span * (wx_[c] - wx_[a]), span * (wy_[c] - wy_[a]), t.band_max);
  }
  [[noreturn]] static void self_check_failed(const Triangle& t, double span) {
    std::fprintf(stderr,
                 "collisions: the cheaper triangle test rejected triangle (%d, %d, %d) at span "
                 "%.17g, the full test does not\n",
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
    // inside the capsule already, closing in
    if (approaching_within(pr, 0.0, span, l2)) return 0.0;
    std::array<double, 8> times{};  // two roots per side and per cap
    int count = 0;
    std::array<double, 2> r{};
    // Sides: the signed distance cross(e, r)/|e0| reaches ±band (|e| taken at the start: the band
    // is a tolerance).
    const double len = std::sqrt(l2);
    const double c0 = ex0 * ry0 - ey0 * rx0;
    const double c1 = ex0 * dry - ey0 * drx + dex * ry0 - dey * rx0;
    const double c2 = dex * dry - dey * drx;
    for (double sign : {1.0, -1.0}) {
      const int k = roots_in_unit_interval(sign * c2, sign * c1, sign * c0 - band * len, r);
      for (int q = 0; q < k; ++q) times[at(count++)] = r[at(q)];
    }
    // End caps: |cell − a| or |cell − b| reaches band.
    // cell relative to b
    const double sx0 = rx0 - ex0, sy0 = ry0 - ey0, dsx = drx - dex, dsy = dry - dey;
    const int ka = roots_in_unit_interval(drx * drx + dry * dry, 2.0 * (rx0 * drx + ry0 * dry),
                                          rx0 * rx0 + ry0 * ry0 - band * band, r);
    for (int q = 0; q < ka; ++q) times[at(count++)] = r[at(q)];
    const int kb = roots_in_unit_interval(dsx * dsx + dsy * dsy, 2.0 * (sx0 * dsx + sy0 * dsy),
                                          sx0 * sx0 + sy0 * sy0 - band * band, r);
    for (int q = 0; q < kb; ++q) times[at(count++)] = r[at(q)];
    for (int q = 1; q < count; ++q)  // insertion sort: at most eight
      for (int k = q; k > 0 && times[at(k)] < times[at(k - 1)]; --k)
        std::swap(times[at(k)], times[at(k - 1)]);
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

  /// The elastic (e = 1) or partly inelastic impulse of a pair whose cells are at their event:
  /// along the direction from the closest point of the edge to the cell.
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
    if (floor_ && bounce_on_floor(i, a, b, sc, nx, ny, vn, e)) return;
    // Equal masses: 1/m_eff = (1 + (1 − s)² + s²)/m; the velocity changes are J/m per unit weight.
    const double dv = -(1.0 + e) * vn / (1.0 + (1.0 - sc) * (1.0 - sc) + sc * sc);
    kick(i, dv * nx, dv * ny);
    kick(a, -(1.0 - sc) * dv * nx, -(1.0 - sc) * dv * ny);
    kick(b, -sc * dv * nx, -sc * dv * ny);
  }

  /// Whether cell k lies on the floor and is not moving up (beyond the velocity the floor gave it).
  bool pinned(std::size_t k) const { return qy_[k] <= y0_ && wy_[k] <= floor_wy_[k]; }

  /// The floor's earliest event in the next `span` of time, as a fraction of it (> 1: none): a cell
  /// on (or, by float rounding, below) the floor moving down, or below it and not moving up fast
  /// enough to be back on it by the end of the span, has its event now (0); a cell above it that
  /// would end the span below it, when it reaches it. Each cell's time is kept in floor_u_.
  double first_floor_event(double span) {
    double first = 2.0;
    for (int i = 0; i < n_; ++i) {
      const auto k = at(i);
      const double y = qy_[k], wy = wy_[k];
      double u = 2.0;
      if (y <= y0_) {
        if (wy < 0.0 || (y < y0_ && wy < (y0_ - y) / span)) u = 0.0;
      } else if (wy < 0.0 && y + span * wy < y0_) {
        u = std::min(1.0, (y - y0_) / (-span * wy));
      }
      floor_u_[k] = u;
      first = std::min(first, u);
    }
    return first;
  }

  /// Resolves the floor events at fraction `u` of `span` (the cells have been advanced to it):
  /// every cell whose floor event is at u (all cells with an event at the start of the step when
  /// `start`) is put on the floor with the floor's normal impulse and its friction. Returns whether
  /// any cell was kicked.
  bool floor_events(double span, double u, bool start) {
    if (start) (void)first_floor_event(span);
    bool any = false;
    const double left = (1.0 - tau_) * h_;  // time left in the step after the event
    for (int i = 0; i < n_; ++i) {
      const auto k = at(i);
      if (floor_u_[k] != u || floor_u_[k] > 1.0) continue;
      if (u > 0.0) qy_[k] = y0_;  // reached the floor now (removes the rounding of the advance)
      const double wy_new = qy_[k] < y0_ ? (y0_ - qy_[k]) / left : 0.0;
      const double jn = wy_new - wy_[k];
      if (!(jn > 0.0)) continue;
      wy_[k] = wy_new;
      fvy_[k] += jn;
      floor_wy_[k] = wy_new;
      floor_friction_kick(k, jn);
      any = true;
    }
    return any;
  }

  /// The friction of a floor normal impulse jn (per unit mass) on cell k, and the contact's books.
  void floor_friction_kick(std::size_t k, double jn) {
    const FloorFriction f = floor_friction(wx_[k], jn, mu_s_, mu_k_);
    wx_[k] += f.dvx;
    fvx_[k] += f.dvx;
    kicked_[k] = 1;
    floor_state_[k] |= f.slid ? 3 : 1;
  }

  /// bounce() when a cell the impulse pushes down lies on the floor (pinned()): the impulse along n
  /// with that cell's vertical inverse mass 0 (the floor takes the vertical part: a normal impulse,
  /// with its friction). Returns false when no cell is in that case (bounce() then goes on as
  /// usual).
  bool bounce_on_floor(std::size_t i, std::size_t a, std::size_t b, double sc, double nx, double ny,
                       double vn, double e) {
    // The impulse acts on i along +n and on a, b along −n: downwards on i if ny < 0, on a, b if ny
    // > 0.
    const bool pi = ny < 0.0 && pinned(i);
    const bool pa = ny > 0.0 && sc < 1.0 && pinned(a);
    const bool pb = ny > 0.0 && sc > 0.0 && pinned(b);
    if (!(pi || pa || pb)) return false;
    const double nx2 = nx * nx, ra = 1.0 - sc;
    const double inv = (pi ? nx2 : 1.0) + ra * ra * (pa ? nx2 : 1.0) + sc * sc * (pb ? nx2 : 1.0);
    // at least 1/2: i and {a, b} are never pinned together
    const double dv = -(1.0 + e) * vn / inv;
    auto push = [&](std::size_t k, bool pin, double w) {
      const double dvx = w * dv * nx, dvy = w * dv * ny;
      if (!pin) {
        kick(k, dvx, dvy);
        return;
      }
      wx_[k] += dvx;  // the vertical part goes into the floor: its normal impulse is −dvy > 0
      fvy_[k] += -dvy;
      floor_friction_kick(k, -dvy);
    };
    push(i, pi, 1.0);
    push(a, pa, -ra);
    push(b, pb, -sc);
    return true;
  }

  void kick(std::size_t i, double dvx, double dvy) {
    wx_[i] += dvx;
    wy_[i] += dvy;
    kicked_[i] = 1;
  }

  double restitution_, tol_;
  bool floor_;               // effect ground is in the scene: floor contacts are events here
  double y0_, mu_s_, mu_k_;  // the floor (effect ground)
  int n_ = 0;
  std::vector<int> a_, b_;  // edges a cell may not cross
  // per edge: the opposite vertex of its triangular region (-1: none)
  std::vector<int> opposite_;
  std::vector<double> rx_, ry_;        // rest positions (per-pair tolerance)
  std::vector<Triangle> tris_;         // triangular regions
  std::vector<Pair> fixed_;            // vertex-edge pairs of larger regions
  std::vector<Item> items_;            // skin vertices and skin edges
  std::vector<detail::Box> boxes_;     // per item, its swept box in the current gather
  std::vector<int> order_;             // items sorted by their swept x-extent (kept between steps)
  std::vector<int> rank_;              // per item, its position in order_ (add_listed_skin_pairs)
  detail::BoxPairList skin_pairs_;     // the skin item pairs that can overlap (a Verlet list)
  std::vector<std::uint64_t> listed_;  // scratch: the overlapping listed pairs' positions
#if ANIMAT_SELF_CHECK
  std::vector<Pair> self_check_;  // scratch of check_skin_candidates()
#endif
  // skin vertices whose band differs from the tolerance for some edge
  std::vector<char> exact_band_;
  std::vector<Pair> candidates_;
  std::vector<double> w0x_, w0y_;  // end-of-step velocities before any bounce
  std::vector<double> wx_, wy_;    // current velocities while the events are processed
  std::vector<double> qx_, qy_;    // positions at the current event time
  std::vector<double> motion_;     // per cell, span·(|wx| + |wy|) (the triangles' cheaper test)
  // per cell, q + span·w: its position at the end of the span (gather)
  std::vector<double> ex_, ey_;
  std::vector<char> kicked_;  // cells whose velocity a bounce changed this step
  // per cell, the floor's velocity changes this step (floor_ only)
  std::vector<double> fvx_, fvy_;
  // per cell, the vertical velocity the floor last gave it this step
  std::vector<double> floor_wy_;
  std::vector<double> floor_u_;    // per cell, its floor event in the current span (> 1: none)
  std::vector<char> floor_state_;  // per cell, this step: 1 the floor pushed it, 2 it slid
  double tau_ = 0.0;               // fraction of the step done
  double h_ = 0.0;                 // the step
};

}  // namespace

std::unique_ptr<Effect> make_collisions(const Body& body, const SceneParams& scene) {
  return std::make_unique<Collisions>(body, scene);
}

}  // namespace animat::effects
