#pragma once
// Internal: a uniform grid over the cells of a development step, for its pair loops (contact
// forces, and the morphogen field when it has a cut-off). It hands out every pair (i, j), i < j,
// whose points may be closer than a given reach, in the order of the all-pairs loop (i ascending,
// then j ascending): a loop that adds per-pair terms to per-cell sums therefore adds the same terms
// in the same order, and gives bit for bit the all-pairs sums. It is a conservative filter only;
// the caller keeps its own exact distance test. Nothing is allocated once reserve() has seen the
// most points.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace animat::detail {

class NeighbourGrid {
 public:
  void reserve(std::size_t most) {
    bucket_.reserve(most);
    sorted_.reserve(most);
    marks_.reserve((most + 63) / 64);
    start_.reserve(kBucketsPerPoint * most + 2);
    next_.reserve(kBucketsPerPoint * most + 2);
  }

  /// Buckets the n >= 1 points for pairs closer than `reach`. Points it cannot bucket (a non-finite
  /// coordinate, an extent beyond double range, a reach that is not a positive number) all go to
  /// one bucket: every pair is then handed out.
  void build(const double* x, const double* y, std::size_t n, double reach) {
    double x0 = x[0], x1 = x[0], y0 = y[0], y1 = y[0];
    for (std::size_t i = 1; i < n; ++i) {
      x0 = std::min(x0, x[i]);
      x1 = std::max(x1, x[i]);
      y0 = std::min(y0, y[i]);
      y1 = std::max(y1, y[i]);
    }
    // The margin keeps two points closer than `reach` at most one bucket apart whatever the
    // rounding of their bucket coordinates; a spread-out set gets larger buckets, not more of them.
    double size = reach * (1.0 + 1e-6);
    const double most = static_cast<double>(kBucketsPerPoint * n + 1);
    const bool finite =
        std::isfinite(x1 - x0) && std::isfinite(y1 - y0) && std::isfinite(size) && size > 0.0;
    for (std::size_t i = 0; finite && i < n; ++i)
      // every pair, as all-pairs would
      if (!std::isfinite(x[i]) || !std::isfinite(y[i])) return single_bucket(n);
    if (!finite) return single_bucket(n);
    for (;;) {
      const double fx = std::floor((x1 - x0) / size) + 1.0, fy = std::floor((y1 - y0) / size) + 1.0;
      if (fx * fy <= most) {
        nx_ = static_cast<long>(fx);
        ny_ = static_cast<long>(fy);
        break;
      }
      size *= 2.0;
    }
    x0_ = x0;
    y0_ = y0;
    inv_ = 1.0 / size;
    const auto buckets = static_cast<std::size_t>(nx_ * ny_);
    start_.assign(buckets + 1, 0);
    bucket_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const long bx = std::min(nx_ - 1, static_cast<long>((x[i] - x0_) * inv_));
      const long by = std::min(ny_ - 1, static_cast<long>((y[i] - y0_) * inv_));
      bucket_[i] = bx + nx_ * by;
      ++start_[static_cast<std::size_t>(bucket_[i]) + 1];
    }
    for (std::size_t b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
    // Counting sort in ascending point order: every bucket lists its points ascending.
    sorted_.resize(n);
    next_.assign(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      sorted_[static_cast<std::size_t>(next_[static_cast<std::size_t>(bucket_[i])]++)] =
          static_cast<long>(i);
  }

  /// visit(i, j) for every pair i < j in the same or adjacent buckets: i ascending, then j
  /// ascending. A point's later neighbours are marked in a bit set and read back in index order (no
  /// sort): one word test per 64 points between the first and the last neighbour.
  template <class Visit>
  void for_each_pair(std::size_t n, Visit&& visit) {
    marks_.assign((n + 63) / 64, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const long bx = bucket_[i] % nx_, by = bucket_[i] / nx_;
      std::size_t lo = marks_.size(), hi = 0;
      for (long cy = std::max(0L, by - 1); cy <= std::min(ny_ - 1, by + 1); ++cy)
        for (long cx = std::max(0L, bx - 1); cx <= std::min(nx_ - 1, bx + 1); ++cx) {
          const auto b = static_cast<std::size_t>(cx + nx_ * cy);
          // Each bucket is ascending: its points after i only.
          const auto end = sorted_.begin() + start_[b + 1];
          for (auto it = std::upper_bound(sorted_.begin() + start_[b], end, static_cast<long>(i));
               it != end; ++it) {
            const auto j = static_cast<std::size_t>(*it);
            marks_[j / 64] |= std::uint64_t{1} << (j % 64);
            lo = std::min(lo, j / 64);
            hi = std::max(hi, j / 64);
          }
        }
      for (std::size_t w = lo; w <= hi && w < marks_.size(); ++w) {
        std::uint64_t bits = marks_[w];
        marks_[w] = 0;
        while (bits != 0) {
          visit(i, w * 64 + static_cast<std::size_t>(std::countr_zero(bits)));
          bits &= bits - 1;
        }
      }
    }
  }

 private:
  static constexpr std::size_t kBucketsPerPoint = 4;

  /// Every point in one bucket: for_each_pair() then hands out every pair.
  void single_bucket(std::size_t n) {
    x0_ = y0_ = 0.0;
    inv_ = 0.0;
    nx_ = ny_ = 1;
    start_.assign({0, static_cast<long>(n)});
    bucket_.assign(n, 0);
    sorted_.resize(n);
    for (std::size_t i = 0; i < n; ++i) sorted_[i] = static_cast<long>(i);
  }

  double x0_ = 0.0, y0_ = 0.0, inv_ = 1.0;
  long nx_ = 1, ny_ = 1;
  std::vector<long> bucket_;  ///< per point: its bucket
  /// per bucket: where its points start in sorted_ (one more entry at the end)
  std::vector<long> start_;
  std::vector<long> sorted_;  ///< points by bucket, ascending within each
  std::vector<long> next_;    ///< scratch of build(): the next free slot of every bucket
  /// scratch of for_each_pair(): one point's later neighbours, a bit each
  std::vector<std::uint64_t> marks_;
};

}  // namespace animat::detail
