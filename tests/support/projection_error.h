// How far apart two lenses of one image are: for tests of calibrations
// whose coefficients are not identifiable one by one but whose lens is.
#ifndef RCM_TESTS_SUPPORT_PROJECTION_ERROR_H_
#define RCM_TESTS_SUPPORT_PROJECTION_ERROR_H_

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <optional>

#include "rcm/camera/camera.h"

namespace rcm::test {

// The largest distance between the pixels of `estimate` and of `truth`
// over the truth's image (a grid of `step_px`), corners included where no
// target was seen; infinity where the estimate does not image a ray the
// truth sees.
inline double MaxProjectionErrorPx(const Camera& estimate, const Camera& truth,
                                   double step_px) {
  double worst = 0.0;
  for (double v = -0.5; v <= truth.height() - 0.5; v += step_px) {
    for (double u = -0.5; u <= truth.width() - 0.5; u += step_px) {
      const std::optional<Eigen::Vector2d> ray =
          truth.NormalizedFromImage(Eigen::Vector2d(u, v));
      if (!ray) continue;
      const std::optional<Eigen::Vector2d> pixel =
          estimate.ProjectNormalized(*ray);
      if (!pixel) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, (*pixel - Eigen::Vector2d(u, v)).norm());
    }
  }
  return worst;
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_PROJECTION_ERROR_H_
