// A picture of a 2-D error field over a camera image: how far one camera
// model lands from another at each pixel (the fit error of an exported
// model, the residual of an air calibration's refractive model against an
// underwater calibration). Where a person would rather look than read a
// table of numbers.
//
// The figure: the image frame to scale, the error magnitude as a heat map
// (each sample colours the cell of the sample grid around it; cells
// without a sample are light grey), a colour bar in the error's units, the
// error vectors as arrows from a subsample of the samples, magnified by a
// stated factor, an optional dashed rectangle (e.g. the region a figure of
// merit is computed on), a title and one line of statistics (RMS, median,
// max over the samples).
#ifndef RCM_VIZ_IMAGE_ERROR_MAP_H_
#define RCM_VIZ_IMAGE_ERROR_MAP_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/image_error_field.h"
#include "rcm/util/status.h"

namespace rcm {

struct ImageErrorMapOptions {
  // Title line above the image, e.g. "cam0: equidistant fit to the
  // refractive model, n = 1.333".
  std::string title;
  // Units of the error, shown on the colour bar and in the statistics.
  std::string units = "px";
  // Width of the drawn image frame in pixels (the figure adds margins and
  // the colour bar); the height follows the aspect ratio. >= 100.
  int frame_width = 720;
  // Top of the colour scale; <= 0 chooses the maximum error rounded up to
  // a 1-2-5 step.
  double color_max = 0.0;
  // Arrows: about this many along the image width (0: none). Each arrow is
  // the error vector times a magnification chosen so that the largest
  // arrow is about one arrow spacing long, stated in the legend
  // ("arrows x 50").
  int arrows_across = 16;
  // Optional dashed rectangle [x0, y0, x1, y1] in image pixels.
  std::optional<Eigen::Vector4d> region;
  // Label of the region in the legend, e.g. "5 % inset".
  std::string region_label;

  // frame_width >= 100, color_max finite, arrows_across >= 0, region
  // finite with x0 < x1 and y0 < y1 when present.
  Status Check() const;
};

// The figure, CV_8UC3 BGR. Errors: field.Check(), options.Check(), a field
// without any present error.
StatusOr<cv::Mat> DrawImageErrorMap(const ImageErrorField& field,
                                    const ImageErrorMapOptions& options);

}  // namespace rcm

#endif  // RCM_VIZ_IMAGE_ERROR_MAP_H_
