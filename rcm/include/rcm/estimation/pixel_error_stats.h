// Summary statistics of pixel errors (lengths of 2-D error vectors): how
// far one camera model lands from another over an image (the water-side
// model fit, the air vs underwater calibration comparison).
#ifndef RCM_ESTIMATION_PIXEL_ERROR_STATS_H_
#define RCM_ESTIMATION_PIXEL_ERROR_STATS_H_

#include <cstdint>
#include <vector>

namespace rcm {

struct PixelErrorStats {
  double rms_px = 0.0;
  double median_px = 0.0;
  double max_px = 0.0;
  int64_t num_samples = 0;
};

// Statistics of `errors` (non-negative lengths); all zero when empty.
PixelErrorStats ComputePixelErrorStats(std::vector<double> errors);

}  // namespace rcm

#endif  // RCM_ESTIMATION_PIXEL_ERROR_STATS_H_
