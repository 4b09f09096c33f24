// The centroids of a CVT archive (search.hpp): Lloyd's k-means of uniform samples of the unit cube,
// as animat.qd.CVTArchive computes them.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "animat/errors.hpp"
#include "animat/random.hpp"
#include "animat/search.hpp"

namespace animat {

std::size_t nearest_centroid(std::span<const double> point,
                             const std::vector<std::vector<double>>& centroids) {
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < centroids.size(); ++c) {
    double d = 0.0;
    for (std::size_t j = 0; j < point.size(); ++j) {
      const double x = point[j] - centroids[c][j];
      d += x * x;
    }
    if (d < best_d) {  // strictly: the lowest index among equals
      best_d = d;
      best = c;
    }
  }
  return best;
}

std::size_t cvt_samples(std::size_t cells, std::size_t samples) {
  return samples > 0 ? samples : std::max<std::size_t>(1000, 20 * cells);
}

void check_cvt_size(std::size_t dims, std::size_t cells, std::size_t samples,
                    std::string_view cells_key, std::string_view samples_key) {
  if (dims < 1) throw ConfigError(fmt::format("{}: a CVT archive needs a descriptor", cells_key));
  if (cells < 1 || cells > static_cast<std::size_t>(kMaxArchiveCells))
    throw ConfigError(fmt::format("{} = {}: a CVT archive has 1 to {} cells", cells_key, cells,
                                  kMaxArchiveCells));
  const std::size_t n = cvt_samples(cells, samples);
  if (n < cells)
    throw ConfigError(fmt::format("{} = {}: fewer samples than the {} cells of {}", samples_key, n,
                                  cells, cells_key));
  // Each Lloyd iteration measures every sample against every centroid.
  const double work = static_cast<double>(n) * static_cast<double>(cells);
  if (work > static_cast<double>(kMaxCvtWork))
    throw ConfigError(
        fmt::format("{} = {} with {} = {} samples makes {:.3g} distances per Lloyd iteration, more "
                    "than {:.3g}: "
                    "fewer cells or samples",
                    cells_key, cells, samples_key, n, work, static_cast<double>(kMaxCvtWork)));
}

std::vector<std::vector<double>> cvt_centroids(std::size_t dims, std::size_t cells,
                                               std::uint64_t seed, std::size_t samples,
                                               int iterations) {
  check_cvt_size(dims, cells, samples, "cells", "samples");
  const std::size_t n = cvt_samples(cells, samples);
  Rng rng = Rng::derive(seed, kCvtSamplesKey, 0);
  std::vector<std::vector<double>> points(n, std::vector<double>(dims));
  for (auto& p : points)
    for (double& x : p) x = rng.uniform();
  std::vector<std::vector<double>> centroids(points.begin(),
                                             points.begin() + static_cast<std::ptrdiff_t>(cells));
  std::vector<std::size_t> labels(n), previous;
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) labels[i] = nearest_centroid(points[i], centroids);
    if (labels == previous) break;
    // the mean of each centroid's samples, summed in sample order (numpy.bincount's weights)
    std::vector<std::size_t> counts(cells, 0);
    std::vector<std::vector<double>> sums(cells, std::vector<double>(dims, 0.0));
    for (std::size_t i = 0; i < n; ++i) {
      ++counts[labels[i]];
      for (std::size_t j = 0; j < dims; ++j) sums[labels[i]][j] += points[i][j];
    }
    for (std::size_t c = 0; c < cells; ++c)
      if (counts[c] > 0)  // a centroid without samples stays
        for (std::size_t j = 0; j < dims; ++j)
          centroids[c][j] = sums[c][j] / static_cast<double>(counts[c]);
    previous = labels;
  }
  return centroids;
}

}  // namespace animat
