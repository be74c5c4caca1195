#include "rcm/estimation/pixel_error_stats.h"

#include <algorithm>
#include <cmath>

namespace rcm {

PixelErrorStats ComputePixelErrorStats(std::vector<double> errors) {
  PixelErrorStats stats;
  stats.num_samples = static_cast<int64_t>(errors.size());
  if (errors.empty()) return stats;
  double sum_squares = 0.0;
  for (const double e : errors) {
    sum_squares += e * e;
    stats.max_px = std::max(stats.max_px, e);
  }
  stats.rms_px = std::sqrt(sum_squares / errors.size());
  // The upper median for an even count: a sample value, not a mean.
  const size_t middle = errors.size() / 2;
  std::nth_element(errors.begin(), errors.begin() + middle, errors.end());
  stats.median_px = errors[middle];
  return stats;
}

}  // namespace rcm
