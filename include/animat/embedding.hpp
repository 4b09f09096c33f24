#pragma once
// The body's planar embedding as an invariant of the swim (paper §4: a cell may not penetrate an
// edge; regions oppose compression): every region keeps the sign of its rest area, and the skin
// stays a simple polygon (no two skin edges that share no end intersect). EmbeddingMonitor checks
// both on a sequence of frames, independently of the effect that is meant to guarantee them.
#include <memory>
#include <span>
#include <vector>

namespace animat {

struct Body;

class EmbeddingMonitor {
 public:
  EmbeddingMonitor();
  explicit EmbeddingMonitor(const Body& body);
  EmbeddingMonitor(const EmbeddingMonitor& other);
  EmbeddingMonitor& operator=(const EmbeddingMonitor& other);
  EmbeddingMonitor(EmbeddingMonitor&&) noexcept;
  EmbeddingMonitor& operator=(EmbeddingMonitor&&) noexcept;
  ~EmbeddingMonitor();

  /// Checks one frame (positions, n each); adds to the totals. Returns whether the embedding is
  /// intact in this frame. Allocates nothing.
  bool observe(std::span<const double> x, std::span<const double> y);

  [[nodiscard]] long frames() const { return frames_; }
  /// Smallest S/S0 of any region over the frames seen (1 with no regions or no frames).
  [[nodiscard]] double min_area_ratio() const { return min_ratio_; }
  /// (region, frame) pairs whose signed area had lost the sign of its rest area (S/S0 <= 0).
  [[nodiscard]] long inverted_region_frames() const { return inverted_; }
  /// Frames in which some pair of skin edges intersected, and such pairs summed over frames.
  [[nodiscard]] long skin_crossing_frames() const { return crossing_frames_; }
  [[nodiscard]] long skin_crossings() const { return crossings_; }
  [[nodiscard]] bool intact() const { return inverted_ == 0 && crossings_ == 0; }

  /// Number of pairs of skin edges (sharing no end) that intersect in this frame (brute force over
  /// the sweep's candidates; exposed for tests).
  [[nodiscard]] int count_skin_crossings(std::span<const double> x, std::span<const double> y);

 private:
  /// count_skin_crossings() from the pairs kept between frames (what observe() uses).
  int skin_crossings_now(std::span<const double> x, std::span<const double> y);

  // the vertices of every region with a rest area, one after another
  std::vector<int> region_nodes_;
  std::vector<int> region_start_;   // where each such region starts in region_nodes_ (and the end)
  std::vector<double> rest_twice_;  // 2·S0 per such region
  std::vector<int> sa_, sb_;        // skin edges
  std::vector<int> order_;          // skin edges sorted by their smallest x (kept between frames)
  std::vector<double> lo_, hi_;     // per skin edge, x extent of this frame
  // the skin edge pairs that can cross, kept between frames (src/box_pair_list.hpp); a copy
  // copies them
  struct SkinPairs;
  std::unique_ptr<SkinPairs> pairs_;
  long frames_ = 0;
  double min_ratio_ = 1.0;
  long inverted_ = 0;
  long crossing_frames_ = 0;
  long crossings_ = 0;
};

/// Whether closed segments ab and cd intersect (touching counts), in double arithmetic.
[[nodiscard]] bool segments_intersect(double ax, double ay, double bx, double by, double cx,
                                      double cy, double dx, double dy);

}  // namespace animat
