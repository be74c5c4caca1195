// ImageErrorField: a 2-D error field over a camera image, sampled on a
// regular grid: how far one camera model lands from another at each pixel
// (the fit error of an exported model, the residual of an air
// calibration's refractive model against an underwater calibration). The
// estimators fill it; rcm/viz/image_error_map.h draws it.
#ifndef RCM_ESTIMATION_IMAGE_ERROR_FIELD_H_
#define RCM_ESTIMATION_IMAGE_ERROR_FIELD_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

// Samples on a regular grid over the image (row-major: sample
// row * cols + col at pixel origin + (col, row) * step).
struct ImageErrorField {
  int image_width = 0;
  int image_height = 0;
  int cols = 0;
  int rows = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double step = 1.0;
  // cols * rows error vectors in pixels; nullopt where there is no value
  // (the model does not reach that pixel).
  std::vector<std::optional<Eigen::Vector2d>> errors;

  // Image size positive, grid at least 1 x 1 with step > 0 and finite
  // origin, errors.size() == cols * rows, every present error finite.
  Status Check() const;
  Eigen::Vector2d Pixel(int col, int row) const {
    return origin + step * Eigen::Vector2d(col, row);
  }
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_IMAGE_ERROR_FIELD_H_
