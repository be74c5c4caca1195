#include "rcm/estimation/image_sample_grid.h"

#include <cmath>
#include <optional>

namespace rcm {

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
