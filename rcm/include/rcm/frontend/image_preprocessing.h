// The first stage of the stereo front end: checks that two images form a
// pair, converts them to 8-bit gray, and optionally equalizes their
// contrast with CLAHE (contrast-limited adaptive histogram equalization,
// Zuiderveld 1994), which the paper uses for the low, uneven light under
// water: it stretches the histogram of each tile of the image, clipped so
// that noise in flat regions is not amplified without bound.
#ifndef RCM_FRONTEND_IMAGE_PREPROCESSING_H_
#define RCM_FRONTEND_IMAGE_PREPROCESSING_H_

#include <opencv2/core.hpp>

#include "rcm/util/status.h"

namespace rcm {

struct ClaheOptions {
  // Off by default: the simulator's and most pool images have enough
  // contrast, and CLAHE raises the noise the matcher sees in flat areas.
  bool enabled = false;
  // Histogram clip, in multiples of the mean bin count; > 0. 2 is OpenCV's
  // and the common choice for feature detection.
  double clip_limit = 2.0;
  // Tiles per image side; >= 1. 8 x 8 tiles of 90 x 68 px at 720 x 540.
  int tiles = 8;

  Status Check() const;
};

// Errors unless `left` and `right` are non-empty 8-bit images with 1 (gray),
// 3 (BGR) or 4 (BGRA) channels and one size ("left image is 720 x 540,
// right image 640 x 480: a stereo pair needs images of one size").
Status CheckStereoImages(const cv::Mat& left, const cv::Mat& right);

// The 8-bit gray image the detectors see: `image` converted to gray (no
// copy when it is gray already and CLAHE is off), then CLAHE when enabled.
// `image` must pass CheckStereoImages; `options` must pass Check().
cv::Mat PreprocessImage(const cv::Mat& image, const ClaheOptions& options);

}  // namespace rcm

#endif  // RCM_FRONTEND_IMAGE_PREPROCESSING_H_
