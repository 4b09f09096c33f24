// EmbeddingMonitor: region signs and skin simplicity, frame by frame (see embedding.hpp).
#include "animat/embedding.hpp"

#include <algorithm>
#include <cstddef>

#include "animat/body.hpp"
#include "box_pair_list.hpp"
#include "effects/effect_support.hpp"

namespace animat {
namespace {

inline double orient(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

inline bool within(double a, double b, double c) {
  return std::min(a, b) <= c && c <= std::max(a, b);
}

}  // namespace

bool segments_intersect(double ax, double ay, double bx, double by, double cx, double cy, double dx,
                        double dy) {
  const double o1 = orient(ax, ay, bx, by, cx, cy), o2 = orient(ax, ay, bx, by, dx, dy);
  const double o3 = orient(cx, cy, dx, dy, ax, ay), o4 = orient(cx, cy, dx, dy, bx, by);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  // Touching or collinear overlap: an end lies on the other segment.
  if (o1 == 0 && within(ax, bx, cx) && within(ay, by, cy)) return true;
  if (o2 == 0 && within(ax, bx, dx) && within(ay, by, dy)) return true;
  if (o3 == 0 && within(cx, dx, ax) && within(cy, dy, ay)) return true;
  if (o4 == 0 && within(cx, dx, bx) && within(cy, dy, by)) return true;
  return false;
}

/// The skin edges' boxes of the current frame and the pairs of edges sharing no end whose boxes
/// can overlap while every box stays within its box of the last build widened by kMargin.
struct EmbeddingMonitor::SkinPairs {
  /// length units; measured on the evolved bests of data/paper_100_generations
  /// (docs/performance.md)
  static constexpr double kMargin = 0.5;
  std::vector<detail::Box> boxes;
  detail::BoxPairList list;
};

EmbeddingMonitor::EmbeddingMonitor() : pairs_(std::make_unique<SkinPairs>()) {}
EmbeddingMonitor::EmbeddingMonitor(const EmbeddingMonitor& other)
    : region_nodes_(other.region_nodes_),
      region_start_(other.region_start_),
      rest_twice_(other.rest_twice_),
      sa_(other.sa_),
      sb_(other.sb_),
      order_(other.order_),
      lo_(other.lo_),
      hi_(other.hi_),
      pairs_(std::make_unique<SkinPairs>(*other.pairs_)),
      frames_(other.frames_),
      min_ratio_(other.min_ratio_),
      inverted_(other.inverted_),
      crossing_frames_(other.crossing_frames_),
      crossings_(other.crossings_) {}
EmbeddingMonitor& EmbeddingMonitor::operator=(const EmbeddingMonitor& other) {
  if (this != &other) *this = EmbeddingMonitor(other);
  return *this;
}
EmbeddingMonitor::EmbeddingMonitor(EmbeddingMonitor&&) noexcept = default;
EmbeddingMonitor& EmbeddingMonitor::operator=(EmbeddingMonitor&&) noexcept = default;
EmbeddingMonitor::~EmbeddingMonitor() = default;

EmbeddingMonitor::EmbeddingMonitor(const Body& body) : pairs_(std::make_unique<SkinPairs>()) {
  // Regions with a rest area, flattened (their vertices one after another), in the body's order.
  region_start_.push_back(0);
  for (int r = 0; r < body.region_count(); ++r) {
    const double rest_twice = 2.0 * body.rest_areas(r);
    if (!(rest_twice != 0.0)) continue;
    const auto& loop = body.regions[effects::at(r)];
    region_nodes_.insert(region_nodes_.end(), loop.begin(), loop.end());
    region_start_.push_back(static_cast<int>(region_nodes_.size()));
    rest_twice_.push_back(rest_twice);
  }
  for (int e = 0; e < static_cast<int>(body.skin.rows()); ++e) {
    sa_.push_back(body.skin(e, 0));
    sb_.push_back(body.skin(e, 1));
    order_.push_back(e);
  }
  lo_.assign(sa_.size(), 0.0);
  hi_.assign(sa_.size(), 0.0);
  pairs_->boxes.assign(sa_.size(), detail::Box{0.0, 0.0, 0.0, 0.0});
  const std::size_t m = sa_.size();
  pairs_->list.reset(m, SkinPairs::kMargin, m > 1 ? m * (m - 1) / 2 : 0);
}

int EmbeddingMonitor::skin_crossings_now(std::span<const double> x, std::span<const double> y) {
  // The pairs count_skin_crossings() tests are those sharing no end whose closed boxes overlap
  // (its sweep finds every such pair once; the order does not matter to a count, and
  // segments_intersect(ab, cd) is segments_intersect(cd, ab)). While every box is finite and
  // within its widened box, the list holds every such pair (src/box_pair_list.hpp).
  SkinPairs& sp = *pairs_;
  const std::size_t m = sa_.size();
  for (std::size_t e = 0; e < m; ++e) {
    const double xa = x[effects::at(sa_[e])], xb = x[effects::at(sb_[e])];
    const double ya = y[effects::at(sa_[e])], yb = y[effects::at(sb_[e])];
    sp.boxes[e] = {std::min(xa, xb), std::max(xa, xb), std::min(ya, yb), std::max(ya, yb)};
  }
  auto share_no_end = [&](int e, int f) {
    const auto ue = effects::at(e), uf = effects::at(f);
    return sa_[uf] != sa_[ue] && sa_[uf] != sb_[ue] && sb_[uf] != sa_[ue] && sb_[uf] != sb_[ue];
  };
  if (!sp.list.holds(sp.boxes.data()) && !sp.list.build(sp.boxes.data(), share_no_end))
    return count_skin_crossings(x, y);
  int count = 0;
  for (const auto& [e, f] : sp.list.pairs()) {
    const auto ue = effects::at(e), uf = effects::at(f);
    if (!detail::boxes_overlap(sp.boxes[ue], sp.boxes[uf])) continue;
    const auto a = effects::at(sa_[ue]), b = effects::at(sb_[ue]);
    const auto c = effects::at(sa_[uf]), d = effects::at(sb_[uf]);
    if (segments_intersect(x[a], y[a], x[b], y[b], x[c], y[c], x[d], y[d])) ++count;
  }
  return count;
}

int EmbeddingMonitor::count_skin_crossings(std::span<const double> x, std::span<const double> y) {
  const std::size_t m = sa_.size();
  for (std::size_t e = 0; e < m; ++e) {
    lo_[e] = std::min(x[effects::at(sa_[e])], x[effects::at(sb_[e])]);
    hi_[e] = std::max(x[effects::at(sa_[e])], x[effects::at(sb_[e])]);
  }
  // Insertion sort by the smallest x: the order barely changes between frames, so this is ~O(m).
  for (std::size_t q = 1; q < m; ++q)
    for (std::size_t r = q; r > 0 && lo_[effects::at(order_[r])] < lo_[effects::at(order_[r - 1])];
         --r)
      std::swap(order_[r], order_[r - 1]);
  int count = 0;
  for (std::size_t q = 0; q < m; ++q) {
    const auto e = effects::at(order_[q]);
    const int a = sa_[e], b = sb_[e];
    const double ymin = std::min(y[effects::at(a)], y[effects::at(b)]),
                 ymax = std::max(y[effects::at(a)], y[effects::at(b)]);
    for (std::size_t r = q + 1; r < m && lo_[effects::at(order_[r])] <= hi_[e]; ++r) {
      const auto f = effects::at(order_[r]);
      const int c = sa_[f], d = sb_[f];
      if (c == a || c == b || d == a || d == b) continue;
      if (std::max(y[effects::at(c)], y[effects::at(d)]) < ymin ||
          std::min(y[effects::at(c)], y[effects::at(d)]) > ymax)
        continue;
      if (segments_intersect(x[effects::at(a)], y[effects::at(a)], x[effects::at(b)],
                             y[effects::at(b)], x[effects::at(c)], y[effects::at(c)],
                             x[effects::at(d)], y[effects::at(d)]))
        ++count;
    }
  }
  return count;
}

bool EmbeddingMonitor::observe(std::span<const double> x, std::span<const double> y) {
  ++frames_;
  bool ok = true;
  const double* px = x.data();
  const double* py = y.data();
  const int* nodes = region_nodes_.data();
  for (std::size_t r = 0; r < rest_twice_.size(); ++r) {
    // Doubled signed area, as effects::twice_area computes it (the same operations, so the same
    // bits).
    const int* loop = nodes + region_start_[r];
    const auto k = static_cast<std::size_t>(region_start_[r + 1] - region_start_[r]);
    double twice = 0.0;
    if (k == 3) {
      const int a = loop[0], b = loop[1], c = loop[2];
      twice = (px[b] - px[a]) * (py[c] - py[a]) - (px[c] - px[a]) * (py[b] - py[a]);
    } else {
      for (std::size_t q = 0; q < k; ++q)
        twice += px[loop[q]] * (py[loop[(q + 1) % k]] - py[loop[(q + k - 1) % k]]);
    }
    const double ratio = twice / rest_twice_[r];
    min_ratio_ = std::min(min_ratio_, ratio);
    if (!(ratio > 0.0)) {
      ++inverted_;
      ok = false;
    }
  }
  const int c = skin_crossings_now(x, y);
  if (c > 0) {
    ++crossing_frames_;
    crossings_ += c;
    ok = false;
  }
  return ok;
}

}  // namespace animat
