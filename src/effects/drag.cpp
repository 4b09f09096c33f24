// Effect "drag": eqs. 4–5 on skin edges only [paper §4]. The midpoint velocity u of an edge is
// split into normal and tangential parts, F = −d·L·u·|u| per part (d_N, d_T), half the force to
// each end.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "effect_support.hpp"

namespace animat::effects {
namespace {

/// g(x) of the "stable" scheme: 1 for x <= 1/2, 1/(x + 1/2) beyond; x·g(x) < 1 for every x.
inline double drag_limiter(double x) { return x <= 0.5 ? 1.0 : 1.0 / (x + 0.5); }

/// Eqs. 4–5 on the skin edges (each once; a dangling edge is one thin segment and feels drag once).
/// Edge geometry (length L, tangent t, normal n = (−t_y, t_x)) is taken at the positions of the
/// start of the step, as every other force. Four schemes (physics.drag_scheme):
///
///  - semi_implicit (default): per part, F = −d·L·|u₀|·u₁, where u₀ is the edge's velocity at the
///    start of the step (Box2D's, which lives half a step behind the positions) and u₁ the velocity
///    at its end, solved for together with every other force already in s.fx (the effects before
///    drag). u₀·u₁ approximates u(t)² at the positions' time to second order (leapfrog), so the
///    scheme is second order; it is exact for a free edge (u₁ = u₀/(1 + c·h·|u₀|), the exact
///    solution of u' = −c·u·|u|), exact at terminal velocity (u₁ = u₀ gives eq. 5 itself, at any
///    step), and since the relation is linear in u₁ it never reverses an edge's velocity, at any
///    drag and step. The coupled linear system (neighbouring skin edges share nodes) is solved by
///    Gauss–Seidel sweeps over the edges, each edge solving its own relation exactly with its two
///    end masses: one sweep already leaves an error O(x²) in the force (x = h·d·L·|u|/m), so two
///    sweeps keep the scheme second order. The predictor pass of the midpoint scheme (which only
///    needs the forces to O(h)) takes the edge forces of the previous step. Nothing is clipped.
///  - explicit: F at the evaluation velocity s.ux, s.uy. It overshoots for x > 1 and blows up for
///    x > 2;
///  - stable: explicit times g(x) = 1 for x <= 1/2 and 1/(x + 1/2) beyond (x with a conservative
///    share of the end masses, 2m / max skin degree of the ends), so one step never reverses a
///    velocity; where g < 1 eq. 5 is not what is integrated, and every such edge-part step is
///    counted in SwimCounters::drag_limited;
///  - implicit: backward Euler of the quadratic law per edge and part with the conservative mass,
///    every other force included (implicit_quadratic_drag). First order and over-dissipative.
class Drag final : public Effect {
 public:
  Drag(const Body& body, const SceneParams& p, const PhysicsParams& physics)
      : dn_(p.drag_normal),
        dt_(tangential_drag(p)),
        scheme_(physics.drag_scheme == "explicit"   ? Scheme::explicit_
                : physics.drag_scheme == "stable"   ? Scheme::stable
                : physics.drag_scheme == "implicit" ? Scheme::implicit
                                                    : Scheme::semi_implicit) {
    const int n = body.node_count();
    const int e = as_int(body.skin.rows());
    std::vector<int> degree(at(n), 0);
    for (int k = 0; k < e; ++k) {
      ++degree[at(body.skin(k, 0))];
      ++degree[at(body.skin(k, 1))];
    }
    // Skin nodes get local indices, so the solver touches only them.
    std::vector<int> local(at(n), -1);
    for (int k = 0; k < e; ++k) {
      for (int c = 0; c < 2; ++c) {
        const int v = body.skin(k, c);
        if (local[at(v)] < 0) {
          local[at(v)] = static_cast<int>(nodes_.size());
          nodes_.push_back(v);
        }
      }
    }
    for (int k = 0; k < e; ++k) {
      const int i = body.skin(k, 0), j = body.skin(k, 1);
      a_.push_back(i);
      b_.push_back(j);
      la_.push_back(local[at(i)]);
      lb_.push_back(local[at(j)]);
      const int dmax = std::max(degree[at(i)], degree[at(j)]);
      edge_mass_.push_back(2.0 * p.cell_mass / dmax);
    }
    const std::size_t m = a_.size();
    for (auto* v : {&len_, &tx_, &ty_, &gn_, &gt_, &rn_, &rt_, &fn_, &ft_}) v->assign(m, 0.0);
    wx_.assign(nodes_.size(), 0.0);
    wy_.assign(nodes_.size(), 0.0);
    if (scheme_ == Scheme::implicit) {
      wxn_.assign(at(n), 0.0);
      wyn_.assign(at(n), 0.0);
    }
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
    if (scheme_ == Scheme::semi_implicit) {
      semi_implicit(s);
      return;
    }
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const double* ux;
    const double* uy;
    if (scheme_ == Scheme::implicit) {  // velocities predicted with every force added before drag
      const double k = s.h * s.inv_mass;
      for (int i = 0; i < s.n; ++i) {
        wxn_[at(i)] = s.vx[at(i)] + k * fx[i];
        wyn_[at(i)] = s.vy[at(i)] + k * fy[i];
      }
      ux = wxn_.data();
      uy = wyn_.data();
    } else {
      ux = s.ux.data();
      uy = s.uy.data();
    }
    const double inv_h = 1.0 / s.h;
    long limited = 0;
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
        const double gn = drag_limiter(k * dn_ * std::abs(wn));
        const double gt = drag_limiter(k * dt_ * std::abs(wt));
        limited += (gn < 1.0) + (gt < 1.0);
        fn *= gn;
        ft *= gt;
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
      if (s.normal_drag_fx != nullptr && !s.predictor) add_normal_part(s, i, j, fn, tx, ty);
    }
    if (!s.predictor) s.counters.drag_limited += limited;
  }

 private:
  enum class Scheme { semi_implicit, explicit_, stable, implicit };

  /// F = −d·L·|u₀|·u₁ per edge and part (see the class comment). Unknowns: the edge forces
  /// (fn_, ft_); W = v + h·(F_other + F_drag)/m is kept per skin node while the sweeps run.
  void semi_implicit(SwimState& s) {
    const double h = s.h;
    const double kv = h * s.inv_mass;  // velocity change per unit force on one node
    // midpoint velocity change per unit edge force (½ to each end)
    const double k_edge = 0.5 * kv;
    const double* vx = s.vx.data();
    const double* vy = s.vy.data();
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    const std::size_t m = a_.size();
    if (s.predictor) {  // the previous step's edge forces, in the current edge frames
      add_edge_forces(s);
      return;
    }
    for (std::size_t q = 0; q < nodes_.size(); ++q) {
      const int i = nodes_[q];
      wx_[q] = vx[i] + kv * fx[i];
      wy_[q] = vy[i] + kv * fy[i];
    }
    for (std::size_t e = 0; e < m; ++e) {
      fn_[e] = 0.0;
      ft_[e] = 0.0;
      const double len = len_[e];
      if (!(len > 0.0)) {
        gn_[e] = 0.0;
        gt_[e] = 0.0;
        continue;
      }
      const int i = a_[e], j = b_[e];
      const double mx = 0.5 * (vx[i] + vx[j]), my = 0.5 * (vy[i] + vy[j]);
      gn_[e] = dn_ * len * std::abs(-mx * ty_[e] + my * tx_[e]);  // d·L·|u₀|, normal
      gt_[e] = dt_ * len * std::abs(mx * tx_[e] + my * ty_[e]);   // tangential
      rn_[e] = 1.0 / (1.0 + gn_[e] * k_edge);
      rt_[e] = 1.0 / (1.0 + gt_[e] * k_edge);
    }
    for (int sweep = 0; sweep < 2; ++sweep) {
      for (std::size_t e = 0; e < m; ++e) {
        const double gn = gn_[e], gt = gt_[e];
        if (gn == 0.0 && gt == 0.0) continue;
        const int p = la_[e], q = lb_[e];
        const double tx = tx_[e], ty = ty_[e];
        const double cx = 0.5 * (wx_[at(p)] + wx_[at(q)]), cy = 0.5 * (wy_[at(p)] + wy_[at(q)]);
        const double cn = -cx * ty + cy * tx, ct = cx * tx + cy * ty;
        // This edge's relation F = −g·u₁ with u₁ = c + k_edge·ΔF (c already holds its current F):
        const double dfn = -(gn * cn + fn_[e]) * rn_[e];
        const double dft = -(gt * ct + ft_[e]) * rt_[e];
        fn_[e] += dfn;
        ft_[e] += dft;
        const double dvx = 0.5 * kv * (-dfn * ty + dft * tx),
                     dvy = 0.5 * kv * (dfn * tx + dft * ty);
        wx_[at(p)] += dvx;
        wy_[at(p)] += dvy;
        wx_[at(q)] += dvx;
        wy_[at(q)] += dvy;
      }
    }
    add_edge_forces(s);
  }

  /// Adds the edge forces fn_, ft_ (normal, tangential), half to each end.
  void add_edge_forces(SwimState& s) const {
    double* fx = s.fx.data();
    double* fy = s.fy.data();
    for (std::size_t e = 0; e < a_.size(); ++e) {
      const double fn = fn_[e], ft = ft_[e];
      const double tx = tx_[e], ty = ty_[e];
      const double gx = 0.5 * (-fn * ty + ft * tx);
      const double gy = 0.5 * (fn * tx + ft * ty);
      const int i = a_[e], j = b_[e];
      fx[i] += gx;
      fy[i] += gy;
      fx[j] += gx;
      fy[j] += gy;
    }
    if (s.normal_drag_fx != nullptr && !s.predictor)
      for (std::size_t e = 0; e < a_.size(); ++e)
        add_normal_part(s, a_[e], b_[e], fn_[e], tx_[e], ty_[e]);
  }

  /// Energy accounting: the normal part of one edge's force, half to each end, into the state's
  /// normal-drag buffer.
  static void add_normal_part(SwimState& s, int i, int j, double fn, double tx, double ty) {
    const double gx = -0.5 * fn * ty, gy = 0.5 * fn * tx;
    s.normal_drag_fx[i] += gx;
    s.normal_drag_fy[i] += gy;
    s.normal_drag_fx[j] += gx;
    s.normal_drag_fy[j] += gy;
  }

  double dn_, dt_;
  Scheme scheme_;
  std::vector<int> a_, b_;    // end nodes of each skin edge
  std::vector<int> la_, lb_;  // their local (skin node) indices
  std::vector<int> nodes_;    // skin nodes
  std::vector<double> edge_mass_;
  std::vector<double> len_, tx_, ty_;      // edge geometry of the current step
  std::vector<double> gn_, gt_, rn_, rt_;  // d·L·|u₀| per part, and 1/(1 + g·h/(2m))
  std::vector<double> fn_, ft_;            // edge forces (kept: the next predictor pass uses them)
  std::vector<double> wx_, wy_;            // end-of-step velocity estimate per skin node
  std::vector<double> wxn_, wyn_;          // implicit scheme: predicted velocity of every node
};

}  // namespace

std::unique_ptr<Effect> make_drag(const Body& body, const SceneParams& scene,
                                  const PhysicsParams& physics) {
  return std::make_unique<Drag>(body, scene, physics);
}

}  // namespace animat::effects
