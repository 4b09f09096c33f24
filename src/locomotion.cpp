// The locomotion mode of a swim (locomotion.hpp): a port of animat.locomotion.classify_motion and
// of animat.protrusion.stroke_motion; the constants and the order of every test are Python's.
#include "animat/locomotion.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>

#include "animat/body.hpp"
#include "animat/random.hpp"
#include "animat/shape.hpp"

namespace animat {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// animat.locomotion's thresholds (its module docstring says where each comes from).
constexpr double kNoneDeformation = 0.01;
constexpr double kContractionFloor = 1e-9;
constexpr double kProtrusionConcentration = 0.65;
constexpr double kTopFraction = 0.2;
constexpr double kLocalContrast = 3.5;
constexpr double kWaveFit = 0.8;
constexpr double kWaveLag = kPi / 2;
constexpr double kWaveTi = 0.15;
constexpr double kBendFit = 0.65;
constexpr double kBendP = 0.01;
constexpr int kBendPermutations = 999;
constexpr double kBendBackward = 135.0;
constexpr double kBendCone = 30.0;
constexpr double kBendBand = 0.25;
constexpr double kSyncCoherence = 0.8;
// animat.protrusion's thresholds.
constexpr double kStrokeScore = 0.4;
constexpr double kStrokeArea = 0.1;
constexpr int kStrokeSamples = 8;
constexpr double kGrowShare = 0.5;
// circular_linear_fit's search: a coarse grid over |g_k| <= pi, then four 21-point refinements.
constexpr int kGrid = 81;
constexpr int kRefine = 21;
constexpr int kRefinements = 4;

using Frame = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// a · b without the NaN and infinity recovery of std::complex's operator* (a library call per
/// product): the values here are finite.
Complex mul(Complex a, Complex b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}

/// numpy.median: the mean of the two middle values for an even count.
double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  if (v.size() % 2) return v[h];
  const double hi = v[h];
  return 0.5 * (*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)) + hi);
}

/// Indices of the `count` largest values (ties: the lower index first, a stable argsort of -v),
/// ascending.
std::vector<int> top_indices(const std::vector<double>& v, int count) {
  std::vector<int> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return v[a] > v[b]; });
  order.resize(static_cast<std::size_t>(count));
  std::sort(order.begin(), order.end());
  return order;
}

/// Least-squares complex amplitudes at omega (harmonic_amplitudes): s = c + Re z sin + Im z cos.
class Harmonic {
 public:
  Harmonic(const std::vector<double>& t, double omega) : basis_(t.size(), 3) {
    for (std::size_t f = 0; f < t.size(); ++f) {
      basis_(static_cast<Eigen::Index>(f), 0) = 1.0;
      basis_(static_cast<Eigen::Index>(f), 1) = std::sin(omega * t[f]);
      basis_(static_cast<Eigen::Index>(f), 2) = std::cos(omega * t[f]);
    }
    solver_ = basis_.colPivHouseholderQr();
  }
  /// Amplitude of each column of `signals` (frames × k).
  std::vector<Complex> fit(const Eigen::MatrixXd& signals) const {
    const Eigen::MatrixXd coef = solver_.solve(signals);
    std::vector<Complex> z(static_cast<std::size_t>(signals.cols()));
    for (Eigen::Index k = 0; k < signals.cols(); ++k) z[k] = Complex(coef(1, k), coef(2, k));
    return z;
  }

 private:
  Eigen::MatrixXd basis_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> solver_;
};

double phase_coherence(const std::vector<Complex>& z) {
  double total = 0.0;
  Complex sum = 0.0;
  for (const Complex& v : z) {
    total += std::abs(v);
    sum += v;
  }
  return total > 0 ? std::abs(sum) / total : 0.0;
}

double travelling_index(const std::vector<Complex>& z) {
  double pp = 0.0, pq = 0.0, qq = 0.0;
  for (const Complex& v : z) {
    pp += v.real() * v.real();
    pq += v.real() * v.imag();
    qq += v.imag() * v.imag();
  }
  const double mid = 0.5 * (pp + qq);
  const double r = std::hypot(0.5 * (pp - qq), pq);
  const double hi = mid + r;
  return hi > 0 ? (mid - r) / hi : 0.0;
}

/// Unit eigenvector of the largest eigenvalue of the 2 × 2 scatter of `c` (the long axis).
std::array<double, 2> principal_axis(const Frame& c) {
  const Eigen::Matrix2d s = c.transpose() * c;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(s);
  const Eigen::Vector2d v = eig.eigenvectors().col(1);
  return {v(0), v(1)};
}

double angle_between(const std::array<double, 2>& a, const std::array<double, 2>& b) {
  const double c = std::clamp(a[0] * b[0] + a[1] * b[1], -1.0, 1.0);
  return std::acos(c) * 180.0 / kPi;
}

/// One refinement axis of circular_linear_fit: numpy.linspace(centre - step, centre + step, 21).
double refine_point(double centre, double step, int j) {
  const double lo = centre - step, hi = centre + step;
  return j == kRefine - 1 ? hi : lo + j * ((hi - lo) / (kRefine - 1));
}
double grid_point(int j) { return j == kGrid - 1 ? kPi : -kPi + j * ((2 * kPi) / (kGrid - 1)); }

/// circular_linear_fit in 1-D or 2-D: the gradient g maximising |Σ w e^{i(φ − g·x)}| / Σ w.
/// zw = w e^{iφ}; coords: one (dims = 1) or two per value. Returns (g, R).
std::pair<std::array<double, 2>, double> circular_linear_fit(const std::vector<Complex>& zw,
                                                             double total,
                                                             const std::vector<double>& coords,
                                                             int dims) {
  const std::size_t m = zw.size();
  std::array<double, 2> best{0.0, 0.0};
  double best_r = -1.0;
  // e^{-i g x} per axis point and value, so a 2-D grid point costs m complex products.
  std::vector<Complex> ex, ey;
  auto factors = [&](std::vector<Complex>& out, int axis, auto point, int points) {
    out.assign(static_cast<std::size_t>(points) * m, 0.0);
    for (int a = 0; a < points; ++a) {
      const double g = point(a);
      for (std::size_t k = 0; k < m; ++k)
        out[a * m + k] = std::polar(1.0, -g * coords[k * dims + axis]);
    }
  };
  auto search = [&](auto px, auto py, int points) {
    factors(ex, 0, px, points);
    if (dims == 2) factors(ey, 1, py, points);
    std::array<double, 2> g{0.0, 0.0};
    double r = -1.0;
    for (int a = 0; a < points; ++a) {
      for (int b = 0; b < (dims == 2 ? points : 1); ++b) {
        Complex sum = 0.0;
        if (dims == 2) {
          for (std::size_t k = 0; k < m; ++k) sum += mul(zw[k], mul(ex[a * m + k], ey[b * m + k]));
        } else {
          for (std::size_t k = 0; k < m; ++k) sum += mul(zw[k], ex[a * m + k]);
        }
        const double v = std::abs(sum) / total;
        if (v > r) {  // numpy.argmax: the first maximum in the grid's (row-major) order
          r = v;
          g = {px(a), dims == 2 ? py(b) : 0.0};
        }
      }
    }
    best = g;
    best_r = r;
  };
  search(grid_point, grid_point, kGrid);
  double step = 2 * kPi / (kGrid - 1);
  for (int round = 0; round < kRefinements; ++round) {
    const std::array<double, 2> c = best;
    search([&](int j) { return refine_point(c[0], step, j); },
           [&](int j) { return refine_point(c[1], step, j); }, kRefine);
    step /= 10;
  }
  return {best, best_r};
}

/// One grid search of a shuffle: the first of the `points` rows of `table` (m values each) that
/// maximises |Σ_k from[k] · row[index[k]]| / total (numpy.argmax); `to` (may be `from`) becomes
/// from · that row. Returns the maximum.
double search_shuffled(const std::vector<Complex>& from, const Complex* table, int points,
                       const std::vector<std::size_t>& index, double total,
                       std::vector<Complex>& to) {
  const std::size_t m = from.size();
  int best = 0;
  double r = -1.0;
  for (int j = 0; j < points; ++j) {
    Complex sum = 0.0;
    for (std::size_t k = 0; k < m; ++k) sum += mul(from[k], table[j * m + index[k]]);
    const double v = std::abs(sum) / total;
    if (v > r) {
      r = v;
      best = j;
    }
  }
  for (std::size_t k = 0; k < m; ++k) to[k] = mul(from[k], table[best * m + index[k]]);
  return r;
}

/// shuffled_fits, counted: how many of `permutations` shuffles of `coords` fit zw at least as well
/// as `fit` (the 1-D fit, same search), stopping once `enough` do. The shuffles come from
/// Rng(kBendSeed) (Fisher-Yates).
int shuffles_fitting(const std::vector<Complex>& zw, double total,
                     const std::vector<double>& coords, int permutations, double fit, int enough) {
  const std::size_t m = zw.size();
  int count = 0;
  Rng rng(kBendSeed);
  // A shuffle only reorders the positions, so every e^{-i g x} it needs is in a table over the
  // unshuffled positions: e^{-i g_a x} of the coarse grid, and e^{-i o_j x} of the offsets o_j of
  // each refinement's 21 points from its centre (the value at a point is then the value at the
  // centre times that factor).
  std::vector<Complex> coarse(static_cast<std::size_t>(kGrid) * m);
  for (int a = 0; a < kGrid; ++a)
    for (std::size_t k = 0; k < m; ++k)
      coarse[a * m + k] = std::polar(1.0, -grid_point(a) * coords[k]);
  std::vector<Complex> offset(static_cast<std::size_t>(kRefinements * kRefine) * m);
  double step = 2 * kPi / (kGrid - 1);
  for (int round = 0; round < kRefinements; ++round, step /= 10) {
    for (int j = 0; j < kRefine; ++j)
      for (std::size_t k = 0; k < m; ++k)
        offset[(round * kRefine + j) * m + k] =
            std::polar(1.0, -refine_point(0.0, step, j) * coords[k]);
  }
  std::vector<std::size_t> index(m);
  std::vector<Complex> at(m);  // zw e^{-i g x} at the current best g, shuffled order
  for (int p = 0; p < permutations; ++p) {
    std::iota(index.begin(), index.end(), std::size_t{0});
    for (std::size_t k = m; k > 1; --k) std::swap(index[k - 1], index[rng.below(k)]);
    double r = search_shuffled(zw, coarse.data(), kGrid, index, total, at);
    for (int round = 0; round < kRefinements; ++round)
      r = search_shuffled(at, offset.data() + static_cast<std::size_t>(round * kRefine) * m,
                          kRefine, index, total, at);
    if (r >= fit && ++count >= enough) break;
  }
  return count;
}

/// The window's body-frame frames (procrustes_frames, 4 rounds): Q[f] = (P[f] − centroid) R[f].
struct Aligned {
  std::vector<Frame> q;
  std::vector<Eigen::Matrix2d> rotation;
  Frame mean;
};

Aligned procrustes(const std::vector<Frame>& p) {
  const std::size_t nf = p.size();
  Aligned out;
  std::vector<Frame> x(nf);
  for (std::size_t f = 0; f < nf; ++f) x[f] = p[f].rowwise() - p[f].colwise().mean();
  Frame ref = x.back();
  out.rotation.assign(nf, Eigen::Matrix2d::Identity());
  out.q.assign(nf, Frame());
  auto align = [&]() {
    for (std::size_t f = 0; f < nf; ++f) {
      // The rotation maximising tr(Rᵀ H), H = X_fᵀ ref: the Kabsch rotation without reflection.
      const Eigen::Matrix2d h = x[f].transpose() * ref;
      const double th = std::atan2(h(1, 0) - h(0, 1), h(0, 0) + h(1, 1));
      Eigen::Matrix2d r;
      r << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
      out.rotation[f] = r;
      out.q[f] = x[f] * r;
    }
  };
  for (int round = 0; round < 4; ++round) {
    align();
    ref = Frame::Zero(ref.rows(), 2);
    for (const Frame& q : out.q) ref += q;
    ref /= static_cast<double>(nf);
    ref = ref.rowwise() - ref.colwise().mean();
  }
  out.mean = Frame::Zero(ref.rows(), 2);
  for (const Frame& q : out.q) out.mean += q;
  out.mean /= static_cast<double>(nf);
  return out;
}

/// Connected components of the spring graph restricted to `cells` (animat.locomotion._groups).
int spring_groups(const std::vector<int>& cells, const IndexPairs& springs) {
  std::vector<std::pair<int, int>> links;
  links.reserve(static_cast<std::size_t>(springs.rows()));
  for (Eigen::Index s = 0; s < springs.rows(); ++s)
    links.emplace_back(springs(s, 0), springs(s, 1));
  return static_cast<int>(connected_groups(cells, links).size());
}

WaveMeasure wave_fit(const std::vector<Complex>& z, const Frame& coords,
                     const std::array<double, 2>& motion) {
  WaveMeasure w;
  w.angle = kNaN;
  w.p_value = kNaN;
  std::vector<double> a(z.size());
  double amax = 0.0, total = 0.0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    a[k] = std::abs(z[k]);
    amax = std::max(amax, a[k]);
    total += a[k];
  }
  if (amax <= 0) return w;
  std::vector<Complex> zw(z.size());
  std::vector<double> x(2 * z.size());
  for (std::size_t k = 0; k < z.size(); ++k) {
    zw[k] = std::polar(a[k], std::arg(z[k]));
    x[2 * k] = coords(static_cast<Eigen::Index>(k), 0);
    x[2 * k + 1] = coords(static_cast<Eigen::Index>(k), 1);
  }
  const auto [g, fit] = circular_linear_fit(zw, total, x, 2);
  const double norm = std::hypot(g[0], g[1]);
  if (norm > 0) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t k = 0; k < z.size(); ++k) {
      if (!(a[k] >= 0.1 * amax)) continue;
      const double s = (x[2 * k] * g[0] + x[2 * k + 1] * g[1]) / norm;
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    w.lag = norm * (hi - lo);
    w.angle = angle_between({-g[0] / norm, -g[1] / norm}, motion);
  }
  w.gradient = g;
  w.fit = fit;
  w.travelling_index = travelling_index(z);
  w.coherence = phase_coherence(z);
  w.is_wave = fit >= kWaveFit && w.lag >= kWaveLag && w.travelling_index >= kWaveTi;
  return w;
}

/// bending_wave: the wave fit of the side-signed strain of the springs along the body's long axis.
WaveMeasure bending_wave(const Aligned& al, const Harmonic& harmonic, const IndexPairs& springs,
                         const std::array<double, 2>& motion) {
  WaveMeasure none;
  none.angle = kNaN;
  none.p_value = kNaN;
  const Eigen::Index n = al.mean.rows();
  if (springs.rows() == 0 || n < 3) return none;
  const Frame c = al.mean.rowwise() - al.mean.colwise().mean();
  const std::array<double, 2> axis = principal_axis(c);
  const std::array<double, 2> normal{-axis[1], axis[0]};
  const double cone = std::cos(kBendCone * kPi / 180.0);
  std::vector<double> rest_ok;
  struct Candidate {
    int i, j;
    double u, v;
  };
  std::vector<Candidate> along;
  for (Eigen::Index s = 0; s < springs.rows(); ++s) {
    const int i = springs(s, 0), j = springs(s, 1);
    const double dx = c(j, 0) - c(i, 0), dy = c(j, 1) - c(i, 1);
    const double rest = std::hypot(dx, dy);
    if (!(rest > 0)) continue;
    rest_ok.push_back(rest);
    if (std::abs(dx * axis[0] + dy * axis[1]) / rest < cone) continue;
    const double mx = 0.5 * (c(i, 0) + c(j, 0)), my = 0.5 * (c(i, 1) + c(j, 1));
    along.push_back({i, j, mx * axis[0] + my * axis[1], mx * normal[0] + my * normal[1]});
  }
  const double band = kBendBand * median(rest_ok);
  std::vector<Candidate> keep;
  for (const Candidate& s : along)
    if (std::abs(s.v) >= band) keep.push_back(s);
  if (keep.size() < 3) return none;
  const auto nf = static_cast<Eigen::Index>(al.q.size());
  const auto m = static_cast<Eigen::Index>(keep.size());
  Eigen::MatrixXd strain(nf, m);
  for (Eigen::Index s = 0; s < m; ++s) {
    const Candidate& k = keep[static_cast<std::size_t>(s)];
    for (Eigen::Index f = 0; f < nf; ++f)
      strain(f, s) = (al.q[f].row(k.j) - al.q[f].row(k.i)).norm();
    strain.col(s) = strain.col(s) / strain.col(s).mean() - Eigen::VectorXd::Ones(nf);
  }
  std::vector<Complex> z = harmonic.fit(strain);
  std::vector<double> a(z.size()), u(z.size());
  double amax = 0.0, total = 0.0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    const double v = keep[k].v;
    z[k] *= static_cast<double>((v > 0) - (v < 0));
    a[k] = std::abs(z[k]);
    u[k] = keep[k].u;
    amax = std::max(amax, a[k]);
    total += a[k];
  }
  if (amax < kContractionFloor) return none;
  std::vector<Complex> zw(z.size());
  for (std::size_t k = 0; k < z.size(); ++k) zw[k] = std::polar(a[k], std::arg(z[k]));
  const auto [gradient, fit] = circular_linear_fit(zw, total, u, 1);
  const double g = gradient[0];
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t k = 0; k < z.size(); ++k) {
    if (!(a[k] >= 0.1 * amax)) continue;
    lo = std::min(lo, u[k]);
    hi = std::max(hi, u[k]);
  }
  WaveMeasure w;
  w.fit = fit;
  w.lag = std::abs(g) * (hi - lo);
  w.gradient = {g * axis[0], g * axis[1]};
  const double sign = static_cast<double>((g > 0) - (g < 0));
  w.angle = g != 0 ? angle_between({-sign * axis[0], -sign * axis[1]}, motion) : kNaN;
  w.travelling_index = travelling_index(z);
  w.coherence = phase_coherence(z);
  // The permutation test costs most of the classifier: run it only when it decides, i.e. when
  // every other criterion holds, and only until it fails (else p_value stays NaN).
  w.p_value = kNaN;
  if (fit >= kBendFit && w.lag >= kWaveLag && w.travelling_index >= kWaveTi &&
      w.angle >= kBendBackward) {
    // p = (1 + beat) / (1 + N) <= kBendP needs beat <= kBendP (1 + N) - 1: stop at one more.
    const int enough = static_cast<int>(std::floor(kBendP * (1 + kBendPermutations) + 1e-9));
    const int beat = shuffles_fitting(zw, total, u, kBendPermutations, fit, enough);
    if (beat < enough) {
      w.p_value = static_cast<double>(1 + beat) / (1 + kBendPermutations);
      w.is_wave = w.p_value <= kBendP;
    }
  }
  return w;
}

// --- the paper's stroke (animat.protrusion)
// -------------------------------------------------------

/// The cells of one frame that stand out of its core by min_height (none without a core).
std::vector<int> protruding(const Points& positions, std::span<const int> outline,
                            const ShapeParams& params, double spacing) {
  const std::vector<double> h = cell_heights(positions, outline, params, spacing);
  std::vector<int> out;
  for (std::size_t i = 0; i < h.size(); ++i)
    if (h[i] >= params.min_height) out.push_back(static_cast<int>(i));
  return out;
}

Eigen::RowVector2d mean_of(const Frame& q, const std::vector<int>& cells) {
  Eigen::RowVector2d c = Eigen::RowVector2d::Zero();
  for (int i : cells) c += q.row(i);
  return c / static_cast<double>(cells.size());
}

/// +1 or −1: the side of the motion (`normal` its left) to which `group` sticks out of its
/// `anchors` in the mean shape (from the body's centre when that is 0 or there are no anchors).
double side_of(const Frame& mean, const std::vector<int>& group, const std::vector<int>& anchors,
               const Eigen::RowVector2d& normal) {
  const Eigen::RowVector2d c = mean_of(mean, group);
  double v = anchors.empty() ? 0.0 : (c - mean_of(mean, anchors)).dot(normal);
  if (v == 0) v = c.dot(normal);
  return v >= 0 ? 1.0 : -1.0;
}

/// grow_protrusions: each group grown by the spring neighbours whose loop on its side (`left`, or
/// its negation on the right) is at least kGrowShare of its largest and at least kStrokeArea s².
std::vector<std::vector<int>> grow_protrusions(const std::vector<std::vector<int>>& groups,
                                               const std::vector<std::set<int>>& neighbours,
                                               const std::vector<double>& left, const Frame& mean,
                                               const Eigen::RowVector2d& normal, double spacing) {
  std::set<int> taken;
  for (const auto& g : groups) taken.insert(g.begin(), g.end());
  const double floor = kStrokeArea * spacing * spacing;
  std::vector<std::vector<int>> out;
  for (const auto& g : groups) {
    std::set<int> gs(g.begin(), g.end());
    std::set<int> around;
    for (int c : gs) around.insert(neighbours[c].begin(), neighbours[c].end());
    std::vector<int> anchors;
    for (int v : around)
      if (!gs.count(v)) anchors.push_back(v);
    const double sign = side_of(mean, g, anchors, normal) > 0 ? 1.0 : -1.0;
    for (;;) {
      double top = -std::numeric_limits<double>::infinity();
      for (int c : gs) top = std::max(top, sign * left[c]);
      if (!(top > 0)) break;  // the protrusion makes no stroke's loop: nothing strokes with it
      std::set<int> add;
      for (int c : gs)
        for (int v : neighbours[c])
          if (!taken.count(v) && sign * left[v] >= std::max(floor, kGrowShare * top)) add.insert(v);
      if (add.empty()) break;
      gs.insert(add.begin(), add.end());
      taken.insert(add.begin(), add.end());
    }
    out.emplace_back(gs.begin(), gs.end());
  }
  return out;
}

/// stroke_motion of the window's body-frame frames: `disp` the cells' complex displacement
/// amplitudes (x, y per cell), `d` the unit direction of motion.
ProtrusionStroke stroke_motion(const Aligned& al, const std::vector<double>& t,
                               const Harmonic& harmonic, const std::vector<Complex>& disp,
                               double omega, const std::array<double, 2>& motion,
                               const StrokeBody& body, const IndexPairs& springs) {
  ProtrusionStroke out;
  const ShapeParams params;
  const std::span<const int> loop = body.outline;
  const auto nf = static_cast<Eigen::Index>(al.q.size());
  const Eigen::Index n = al.mean.rows();
  if (loop.size() < 3 || n < 3 || !(omega > 0) || nf < 4) return out;
  const Frame& mean = al.mean;
  const double s = cell_spacing(body.rest_positions ? *body.rest_positions : Points(mean));
  std::vector<int> rest;
  if (body.rest_positions) rest = protruding(*body.rest_positions, loop, params, s);
  const double period = 2 * kPi / omega;
  std::vector<Eigen::Index> in_last;
  for (Eigen::Index f = 0; f < nf; ++f)
    if (t[f] >= t.back() - period) in_last.push_back(f);
  std::set<int> cell_set(rest.begin(), rest.end());
  std::set<Eigen::Index> picks;  // numpy.linspace(0, len - 1, samples).round(), unique
  const double last = static_cast<double>(in_last.size() - 1);
  for (int j = 0; j < kStrokeSamples; ++j) {
    const double x = j == kStrokeSamples - 1 ? last : j * (last / (kStrokeSamples - 1));
    picks.insert(in_last[static_cast<std::size_t>(std::nearbyint(x))]);
  }
  for (Eigen::Index f : picks)
    for (int c : protruding(Points(al.q[f]), loop, params, s)) cell_set.insert(c);
  if (cell_set.empty()) return out;
  const std::vector<int> cells(cell_set.begin(), cell_set.end());
  std::vector<std::pair<int, int>> links;
  for (std::size_t k = 0; k < loop.size(); ++k)
    links.emplace_back(loop[k], loop[(k + 1) % loop.size()]);
  std::vector<std::set<int>> neighbours(static_cast<std::size_t>(n));
  for (Eigen::Index e = 0; e < springs.rows(); ++e) {
    links.emplace_back(springs(e, 0), springs(e, 1));
    neighbours[springs(e, 0)].insert(springs(e, 1));
    neighbours[springs(e, 1)].insert(springs(e, 0));
  }
  const std::set<int> rest_set(rest.begin(), rest.end());
  auto touches_rest = [&](const std::vector<int>& g) {
    return std::any_of(g.begin(), g.end(), [&](int c) { return rest_set.count(c) > 0; });
  };
  std::vector<std::vector<int>> groups = connected_groups(cells, links);
  std::stable_sort(groups.begin(), groups.end(), [&](const auto& a, const auto& b) {
    const bool ra = !touches_rest(a), rb = !touches_rest(b);
    const auto la = -static_cast<long>(a.size()), lb = -static_cast<long>(b.size());
    return std::tie(ra, la, a) < std::tie(rb, lb, b);
  });
  const Eigen::RowVector2d d(motion[0], motion[1]);
  const Eigen::RowVector2d unit = d / d.norm();
  const Eigen::RowVector2d normal(-unit(1), unit(0));
  // cell_loops on the left: −π Im(Y X̄), X and Y the amplitudes along the motion and its normal.
  std::vector<double> left(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Complex x = disp[2 * i] * unit(0) + disp[2 * i + 1] * unit(1);
    const Complex y = disp[2 * i] * normal(0) + disp[2 * i + 1] * normal(1);
    left[i] = -kPi * (y * std::conj(x)).imag();
  }
  groups = grow_protrusions(groups, neighbours, left, mean, normal, s);
  std::set<int> member;
  for (const auto& g : groups) member.insert(g.begin(), g.end());
  std::vector<std::array<double, 2>> centroids;
  for (const auto& g : groups) {
    const std::set<int> gs(g.begin(), g.end());
    std::set<int> anchor_set;
    for (Eigen::Index e = 0; e < springs.rows(); ++e) {
      const int i = springs(e, 0), j = springs(e, 1);
      if ((gs.count(i) > 0) == (gs.count(j) > 0)) continue;
      for (int v : {i, j})
        if (!member.count(v)) anchor_set.insert(v);
    }
    const std::vector<int> anchors(anchor_set.begin(), anchor_set.end());
    const Eigen::RowVector2d centre = mean_of(mean, g);
    centroids.push_back({centre(0), centre(1)});
    const Eigen::RowVector2d origin =
        anchors.empty() ? Eigen::RowVector2d::Zero() : mean_of(mean, anchors);
    if (!((centre - origin).norm() > 0)) {
      out.scores.push_back(kNaN);
      out.areas.push_back(kNaN);
      continue;
    }
    // cell_strokes: the sweep along the motion and the extension across it, on the group's side.
    const Eigen::RowVector2d outward = side_of(mean, g, anchors, normal) * normal;
    const auto k = static_cast<Eigen::Index>(g.size());
    Eigen::MatrixXd signals(nf, 2 * k);
    for (Eigen::Index f = 0; f < nf; ++f) {
      const Eigen::RowVector2d base =
          anchors.empty() ? Eigen::RowVector2d::Zero() : mean_of(al.q[f], anchors);
      for (Eigen::Index c = 0; c < k; ++c) {
        const Eigen::RowVector2d q = al.q[f].row(g[c]);
        signals(f, c) = q.dot(unit);
        signals(f, k + c) = (q - base).dot(outward);
      }
    }
    const std::vector<Complex> z = harmonic.fit(signals);
    double rowing = 0.0, weight = 0.0;
    for (Eigen::Index c = 0; c < k; ++c) {
      const double r = -(z[k + c] * std::conj(z[c])).imag();
      rowing += r;
      weight += std::abs(z[c]) * std::abs(z[k + c]);
    }
    out.scores.push_back(weight > 0 ? rowing / weight : kNaN);
    out.areas.push_back(kPi * rowing / (s * s));
  }
  out.pairs = symmetric_pairs(Points(mean), centroids, params, s);
  for (const auto& g : groups) out.at_rest.push_back(touches_rest(g));
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < out.pairs.size(); ++p) {
    const auto [a, b] = out.pairs[p];
    const double v = std::isfinite(out.scores[a]) && std::isfinite(out.scores[b])
                         ? std::min(out.scores[a], out.scores[b])
                         : kNaN;
    out.pair_scores.push_back(v);
    // With the body at rest known, a pair counts only when both protrude at rest.
    const bool eligible =
        std::isfinite(v) && (!body.rest_positions || (out.at_rest[a] && out.at_rest[b]));
    if (eligible && v > best) {
      best = v;
      out.pair = static_cast<int>(p);
    }
  }
  if (out.pair >= 0) {
    const auto [a, b] = out.pairs[static_cast<std::size_t>(out.pair)];
    out.score = out.pair_scores[static_cast<std::size_t>(out.pair)];
    out.area = std::min(out.areas[a], out.areas[b]);
  }
  out.protrusions = std::move(groups);
  return out;
}

/// The window of classify_motion: its first frame and its length in periods.
std::pair<int, double> window(const std::vector<double>& t, double swim_start, double omega,
                              double cycles) {
  const int nf = static_cast<int>(t.size());
  const double t0 = std::isnan(swim_start) ? t.front() : swim_start;
  const double duration = t.back() - t0;
  int first = nf;
  double k = 0.0;
  if (omega > 0 && std::isfinite(omega)) {
    const double period = 2 * kPi / omega;
    const double whole = std::floor(0.5 * duration / period + 1e-9);
    k = whole >= 1 ? std::min(cycles, whole) : std::min(cycles, duration / period);
    k = std::max(k, 0.0);
    const double start = t.back() - k * period;
    const double from = start - 1e-9 * std::max(1.0, std::abs(start));
    while (first > 0 && t[first - 1] >= from) --first;
    if (nf - first < 8) first = nf - 8;
  } else {
    const double from = t0 + 0.5 * duration;
    while (first > 0 && t[first - 1] >= from) --first;
  }
  return {first, k};
}

}  // namespace

const char* locomotion_name(Locomotion mode) {
  switch (mode) {
    case Locomotion::undulation: return "undulation";
    case Locomotion::synchronous_contraction: return "synchronous contraction";
    case Locomotion::protrusions: return "protrusions";
    case Locomotion::tail: return "tail";
    case Locomotion::other: return "other";
    case Locomotion::none: return "none";
  }
  return "none";
}

double dominant_frequency(const Vector& amplitude, const Vector& frequency) {
  std::vector<std::pair<double, double>> cells;  // (f, a)
  for (Eigen::Index i = 0; i < std::min(amplitude.size(), frequency.size()); ++i)
    if (amplitude(i) > 0 && frequency(i) > 0) cells.emplace_back(frequency(i), amplitude(i));
  if (cells.empty()) return 0.0;
  std::stable_sort(cells.begin(), cells.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  double total = 0.0;
  for (const auto& c : cells) total += c.second;
  double cum = 0.0;
  for (const auto& c : cells) {  // numpy.searchsorted(cumsum, total / 2): the first cum >= half
    cum += c.second;
    if (cum >= 0.5 * total) return c.first;
  }
  return cells.back().first;
}

int window_start_step(int steps, double dt, double omega, double cycles) {
  std::vector<double> t(static_cast<std::size_t>(steps) + 1);
  for (int s = 0; s <= steps; ++s) t[static_cast<std::size_t>(s)] = s * dt;
  if (steps + 1 < 8) return 0;
  return std::max(0, window(t, kNaN, omega, cycles).first - 1);
}

bool ProtrusionStroke::strokes() const { return score >= kStrokeScore && area >= kStrokeArea; }

LocomotionMode classify_motion(const MotionFrames& frames, const IndexPairs& springs, double omega,
                               double cycles, bool bending, const StrokeBody* stroke) {
  const int n = frames.cells;
  const int nf_all = frames.frame_count();
  if (n < 0 ||
      frames.xy.size() != static_cast<std::size_t>(nf_all) * 2 * static_cast<std::size_t>(n))
    throw std::invalid_argument("classify_motion: " + std::to_string(frames.xy.size()) +
                                " coordinates for " + std::to_string(nf_all) + " frames of " +
                                std::to_string(n) + " cells (need frames × cells × 2)");
  if (nf_all < 8)
    throw std::invalid_argument("classify_motion: need at least 8 frames, got " +
                                std::to_string(nf_all));
  if (!std::isnan(frames.swim_start) && !(frames.swim_start <= frames.times.front()))
    throw std::invalid_argument("classify_motion: swim_start " + std::to_string(frames.swim_start) +
                                " is after the first frame's time " +
                                std::to_string(frames.times.front()));
  for (Eigen::Index s = 0; s < springs.rows(); ++s)
    for (int e = 0; e < 2; ++e)
      if (springs(s, e) < 0 || springs(s, e) >= n)
        throw std::invalid_argument("classify_motion: spring " + std::to_string(s) +
                                    " names cell " + std::to_string(springs(s, e)) + " of " +
                                    std::to_string(n));
  if (stroke) {
    for (int c : stroke->outline)
      if (c < 0 || c >= n)
        throw std::invalid_argument("classify_motion: outline names cell " + std::to_string(c) +
                                    " of " + std::to_string(n));
    if (stroke->rest_positions && stroke->rest_positions->rows() != n)
      throw std::invalid_argument(
          "classify_motion: " + std::to_string(stroke->rest_positions->rows()) +
          " rest positions for " + std::to_string(n) + " cells");
  }

  LocomotionMode out;
  out.omega = omega;
  const auto [first, k] = window(frames.times, frames.swim_start, omega, cycles);
  out.cycles = k;
  out.frames = nf_all - first;
  const int nf = out.frames;
  std::vector<Frame> w(static_cast<std::size_t>(nf));
  std::vector<double> tw(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    w[f] = Eigen::Map<const Frame>(frames.xy.data() + static_cast<std::size_t>(first + f) * 2 * n,
                                   n, 2);
    tw[f] = frames.times[static_cast<std::size_t>(first + f)];
  }
  const Aligned al = procrustes(w);
  const Frame centred = al.mean.rowwise() - al.mean.colwise().mean();
  const double size = n ? std::sqrt(centred.squaredNorm() / n) : 0.0;

  Eigen::Vector2d drift = Eigen::Vector2d::Zero();
  std::vector<Eigen::RowVector2d> com(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) com[f] = w[f].colwise().mean();
  for (int f = 0; f + 1 < nf; ++f) drift += ((com[f + 1] - com[f]) * al.rotation[f]).transpose();
  out.speed =
      tw.back() > tw.front() ? (com.back() - com.front()).norm() / (tw.back() - tw.front()) : 0.0;
  if (drift.norm() > 1e-9 * std::max(size, 1.0)) {
    out.direction = {drift(0) / drift.norm(), drift(1) / drift.norm()};
  } else if (n > 1) {
    out.direction = principal_axis(centred);
  }

  out.phases.assign(static_cast<std::size_t>(n), 0.0);
  out.amplitudes.assign(static_cast<std::size_t>(n), 0.0);
  if (omega <= 0 || !std::isfinite(omega) || size == 0) return out;  // no oscillation to analyse

  const Harmonic harmonic(tw, omega);
  Eigen::MatrixXd coords(nf, 2 * n);
  for (int f = 0; f < nf; ++f)
    coords.row(f) = Eigen::Map<const Eigen::RowVectorXd>(al.q[f].data(), 2 * n);
  const std::vector<Complex> disp = harmonic.fit(coords);
  std::vector<double> amp2(static_cast<std::size_t>(n));
  double amp2_sum = 0.0;
  for (int i = 0; i < n; ++i) {
    amp2[i] = std::norm(disp[2 * i]) + std::norm(disp[2 * i + 1]);
    amp2_sum += amp2[i];
  }
  out.deformation = std::sqrt(amp2_sum / n) / size;

  // Each cell's contraction: the mean strain (length over its window mean, minus 1) of its springs.
  Eigen::MatrixXd contraction_signal = Eigen::MatrixXd::Zero(nf, n);
  std::vector<double> degree(static_cast<std::size_t>(n), 0.0);
  for (Eigen::Index s = 0; s < springs.rows(); ++s) {
    const int i = springs(s, 0), j = springs(s, 1);
    Eigen::VectorXd length(nf);
    for (int f = 0; f < nf; ++f) length(f) = (al.q[f].row(i) - al.q[f].row(j)).norm();
    const Eigen::VectorXd strain = length / length.mean() - Eigen::VectorXd::Ones(nf);
    contraction_signal.col(i) += strain;
    contraction_signal.col(j) += strain;
    degree[i] += 1;
    degree[j] += 1;
  }
  for (int i = 0; i < n; ++i) contraction_signal.col(i) /= std::max(degree[i], 1.0);
  std::vector<Complex> contraction = harmonic.fit(contraction_signal);
  double cmax = 0.0;
  for (const Complex& c : contraction) cmax = std::max(cmax, std::abs(c));
  if (cmax < kContractionFloor) std::fill(contraction.begin(), contraction.end(), Complex(0.0));
  out.coherence = phase_coherence(contraction);
  out.travelling_index = travelling_index(contraction);
  const int n_top = std::max(1, static_cast<int>(std::ceil(kTopFraction * n - 1e-9)));
  out.top_cells = top_indices(amp2, n_top);
  double top_sum = 0.0;
  for (int c : out.top_cells) top_sum += amp2[c];
  out.concentration = amp2_sum > 0 ? top_sum / amp2_sum : 0.0;
  std::vector<double> ca(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    ca[i] = std::abs(contraction[i]);
    out.amplitudes[i] = ca[i];
    out.phases[i] = std::arg(contraction[i]);
  }
  if (out.deformation < kNoneDeformation) return out;

  out.has_wave = true;
  out.wave = wave_fit(contraction, centred, out.direction);
  if (bending) {
    out.has_bend = true;
    out.bend = bending_wave(al, harmonic, springs, out.direction);
  }
  const bool is_wave = out.wave.is_wave || (out.has_bend && out.bend.is_wave);
  const bool sync = out.coherence >= kSyncCoherence;
  const std::vector<int> c_top = top_indices(ca, n_top);
  const double mid = median(ca);
  double c_sq = 0.0;
  for (int c : c_top) c_sq += ca[c] * ca[c];
  out.contrast = mid > 0 ? std::sqrt(c_sq / n_top) / mid
                         : (c_sq > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  const bool local = out.contrast >= kLocalContrast;
  const bool prot = out.concentration >= kProtrusionConcentration || local;
  if (stroke && stroke->outline.size() >= 3) {
    out.has_stroke = true;
    out.stroke = stroke_motion(al, tw, harmonic, disp, omega, out.direction, *stroke, springs);
  }
  const std::vector<int>& cells = local ? c_top : out.top_cells;
  const int cell_groups = prot ? spring_groups(cells, springs) : 0;
  const bool one_appendage =
      prot && (cell_groups == 1 || (out.has_stroke && out.stroke.protrusions.size() == 1));
  if (out.has_stroke && out.stroke.strokes()) {
    // A symmetric pair rows: protrusions, or with a travelling wave its corners row with it.
    out.groups = static_cast<int>(out.stroke.protrusions.size());
    if (is_wave) {
      out.mode = Locomotion::undulation;
      out.mixed.push_back(Locomotion::protrusions);
    } else {
      out.mode = Locomotion::protrusions;
    }
  } else if (prot && (!out.has_stroke || one_appendage)) {
    out.groups = cell_groups;
    out.mode = out.groups >= 2 && !out.has_stroke ? Locomotion::protrusions : Locomotion::tail;
    if (is_wave) out.mixed.push_back(Locomotion::undulation);
  } else if (is_wave) {
    out.mode = Locomotion::undulation;
    if (sync) out.mixed.push_back(Locomotion::synchronous_contraction);
  } else if (sync) {
    out.mode = Locomotion::synchronous_contraction;
  } else {
    out.mode = Locomotion::other;
  }
  return out;
}

LocomotionMode classify_body_motion(const MotionFrames& frames, const Body& body, double cycles,
                                    const Points* rest_positions) {
  StrokeBody stroke;
  if (!body.skin_loops.empty()) stroke.outline = body.skin_loops[0];
  stroke.rest_positions = rest_positions ? rest_positions : &body.positions;
  // As classify_locomotion: the bending wave with an outline only.
  return classify_motion(frames, body.springs, dominant_frequency(body.amplitude, body.frequency),
                         cycles, stroke.outline.size() >= 3, &stroke);
}

}  // namespace animat
