#pragma once
// Internal: a Verlet list of axis-aligned boxes, shared by the collisions effect's skin candidates
// (src/effects/collisions.cpp) and the embedding monitor's skin crossings (src/embedding.cpp).
//
// build() widens every box by a margin and keeps the pairs whose widened boxes overlap; until a
// box leaves its widened box, those pairs hold every pair whose boxes overlap. The proof: if box A
// lies within its widened box A' and box B within B', and A and B overlap (closed boxes), then A'
// and B' overlap, so the pair was kept. holds() checks the containment with comparisons of stored
// values only, so no rounding enters the bound: whatever the widened boxes' own rounding, a pair
// that overlaps now is in the list, and testing the listed pairs for overlap gives exactly the
// pairs a sweep over all boxes gives. A box with a non-finite bound fails holds() and build(); the
// caller then sweeps all boxes as before.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace animat::detail {

struct Box {
  double lo, hi, ylo, yhi;  // x extent, y extent
};

/// Whether two closed boxes overlap (touching counts).
inline bool boxes_overlap(const Box& a, const Box& b) {
  return a.lo <= b.hi && b.lo <= a.hi && a.ylo <= b.yhi && b.ylo <= a.yhi;
}

class BoxPairList {
 public:
  BoxPairList() = default;
  /// A copy keeps the room for max_pairs kept pairs, so that its build() allocates nothing either.
  BoxPairList(const BoxPairList& other) { *this = other; }
  BoxPairList& operator=(const BoxPairList& other) {
    if (this == &other) return *this;
    margin_ = other.margin_;
    max_pairs_ = other.max_pairs_;
    wide_ = other.wide_;
    order_ = other.order_;
    pairs_.reserve(max_pairs_);
    pairs_ = other.pairs_;
    built_ = other.built_;
    builds_ = other.builds_;
    return *this;
  }
  BoxPairList(BoxPairList&&) noexcept = default;
  BoxPairList& operator=(BoxPairList&&) noexcept = default;
  ~BoxPairList() = default;

  /// Sized for `count` boxes and at most `max_pairs` kept pairs: the only allocation.
  void reset(std::size_t count, double margin, std::size_t max_pairs) {
    margin_ = margin;
    max_pairs_ = max_pairs;
    wide_.assign(count, Box{0.0, 0.0, 0.0, 0.0});
    order_.clear();
    for (std::size_t k = 0; k < count; ++k) order_.push_back(static_cast<int>(k));
    pairs_.clear();
    pairs_.reserve(max_pairs);
    built_ = false;
  }

  /// Whether every box lies within its widened box of the last build (false before the first
  /// build, and for a box with a NaN bound).
  [[nodiscard]] bool holds(const Box* boxes) const {
    if (!built_) return false;
    for (std::size_t k = 0; k < wide_.size(); ++k)
      if (!contains(k, boxes[k])) return false;
    return true;
  }
  /// Whether box k, `b`, lies within its widened box (holds() is: built() and this for every box).
  [[nodiscard]] bool contains(std::size_t k, const Box& b) const {
    const Box& w = wide_[k];
    return b.lo >= w.lo && b.hi <= w.hi && b.ylo >= w.ylo && b.yhi <= w.yhi;
  }
  /// Whether the last build() succeeded.
  [[nodiscard]] bool built() const { return built_; }

  /// Widens every box by the margin and keeps the pairs (p, q), p < q, with eligible(p, q) whose
  /// widened boxes overlap, in no particular order. False (and no list) if a widened bound is
  /// not finite. Allocates nothing.
  template <class Eligible>
  bool build(const Box* boxes, Eligible eligible) {
    ++builds_;
    built_ = false;
    pairs_.clear();
    for (std::size_t k = 0; k < wide_.size(); ++k) {
      const Box& b = boxes[k];
      Box& w = wide_[k];
      w = {b.lo - margin_, b.hi + margin_, b.ylo - margin_, b.yhi + margin_};
      if (!(std::isfinite(w.lo) && std::isfinite(w.hi) && std::isfinite(w.ylo) &&
            std::isfinite(w.yhi)))
        return false;
    }
    // Sort and sweep along x (insertion sort: the order barely changes between builds).
    for (std::size_t q = 1; q < order_.size(); ++q)
      for (std::size_t r = q; r > 0 && wide_[at(order_[r])].lo < wide_[at(order_[r - 1])].lo; --r)
        std::swap(order_[r], order_[r - 1]);
    for (std::size_t q = 0; q < order_.size(); ++q) {
      const Box& p = wide_[at(order_[q])];
      for (std::size_t r = q + 1; r < order_.size(); ++r) {
        const Box& o = wide_[at(order_[r])];
        if (o.lo > p.hi) break;
        if (o.ylo > p.yhi || o.yhi < p.ylo) continue;
        const int a = std::min(order_[q], order_[r]), b = std::max(order_[q], order_[r]);
        if (eligible(a, b)) pairs_.emplace_back(a, b);
      }
    }
    built_ = true;
    return true;
  }

  [[nodiscard]] std::span<const std::pair<int, int>> pairs() const { return pairs_; }
  /// How many times build() ran.
  [[nodiscard]] long builds() const { return builds_; }

 private:
  static std::size_t at(int i) { return static_cast<std::size_t>(i); }

  double margin_ = 0.0;
  std::size_t max_pairs_ = 0;  // the room reserved in pairs_
  std::vector<Box> wide_;      // per box, the box at the last build widened by the margin
  std::vector<int> order_;     // boxes sorted by their widened lower x (kept between builds)
  std::vector<std::pair<int, int>> pairs_;
  bool built_ = false;
  long builds_ = 0;
};

}  // namespace animat::detail
