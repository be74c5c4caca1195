#include "rcm/estimation/image_sample_grid.h"

#include <cmath>
#include <optional>
#include <sstream>

namespace rcm {

Status CheckGridStep(std::string_view what, double grid_step) {
  if (grid_step > 0.0 && std::isfinite(grid_step)) return Status::Ok();
  std::ostringstream message;
  message << what << ": grid_step " << grid_step << " is not positive";
  return Status::Error(message.str());
}

Status CheckInsetFraction(std::string_view what, std::string_view name,
                          double inset) {
  if (inset >= 0.0 && inset <= kMaxInsetFraction) return Status::Ok();
  std::ostringstream message;
  message << what << ": " << name << " " << inset << " is outside [0, "
          << kMaxInsetFraction << "]";
  return Status::Error(message.str());
}

ImageErrorField CenteredSampleGrid(int width, int height, double step) {
  ImageErrorField grid;
  grid.image_width = width;
  grid.image_height = height;
  grid.cols = static_cast<int>(std::floor((width - 1) / step)) + 1;
  grid.rows = static_cast<int>(std::floor((height - 1) / step)) + 1;
  grid.step = step;
  grid.origin = 0.5 * Eigen::Vector2d((width - 1) - (grid.cols - 1) * step,
                                      (height - 1) - (grid.rows - 1) * step);
  grid.errors.assign(static_cast<size_t>(grid.cols) * grid.rows, std::nullopt);
  return grid;
}

Eigen::Vector4d InsetRegion(int width, int height, double inset) {
  return Eigen::Vector4d(inset * width - 0.5, inset * height - 0.5,
                         (1.0 - inset) * width - 0.5,
                         (1.0 - inset) * height - 0.5);
}

}  // namespace rcm
