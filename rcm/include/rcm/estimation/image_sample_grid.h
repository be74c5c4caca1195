// The regular grid of pixels on which two camera models are compared over
// an image (water_side_model_fit.h, calibration_comparison.h), and the
// inset regions their figures are computed on.
#ifndef RCM_ESTIMATION_IMAGE_SAMPLE_GRID_H_
#define RCM_ESTIMATION_IMAGE_SAMPLE_GRID_H_

#include <Eigen/Core>
#include <string_view>

#include "rcm/estimation/image_error_field.h"
#include "rcm/util/status.h"

namespace rcm {

// The largest inset fraction at each side: 0.45 leaves the central 10 %.
inline constexpr double kMaxInsetFraction = 0.45;

// Checks of the settings of a fit on a sample grid, their messages
// prefixed by `what` ("water-side model fit: grid_step 0 is not
// positive", "...: inset 0.6 is outside [0, 0.45]"; `name` names the
// inset's option).
Status CheckGridStep(std::string_view what, double grid_step);
Status CheckInsetFraction(std::string_view what, std::string_view name,
                          double inset);

// A grid every `step` (> 0) pixels over a width x height image, centered
// (the same margin on both sides), with every error absent.
ImageErrorField CenteredSampleGrid(int width, int height, double step);

// [x0, y0, x1, y1] of the sensor [-0.5, w - 0.5] x [-0.5, h - 0.5]
// without `inset` of its width and height at each side.
Eigen::Vector4d InsetRegion(int width, int height, double inset);

// True when `pixel` lies in `region` (boundary included).
inline bool InRegion(const Eigen::Vector2d& pixel,
                     const Eigen::Vector4d& region) {
  return pixel.x() >= region[0] && pixel.x() <= region[2] &&
         pixel.y() >= region[1] && pixel.y() <= region[3];
}

}  // namespace rcm

#endif  // RCM_ESTIMATION_IMAGE_SAMPLE_GRID_H_
