// Subpixel positions of matched keypoints. Detectors localize keypoints to
// about a pixel (FAST on the pixel grid, SIFT by a parabola through its
// scale space), and the left and right detections of one corner need not
// agree to better than that. n is observed through shifts of a fraction of
// a pixel (the locus bends by ~1 px at the image border for n = 1.333), so
// the right pixel of each match is refined against the left patch by
// Lucas-Kanade alignment (OpenCV calcOpticalFlowPyrLK on the full-resolution
// images, starting at the matched keypoint): it minimizes
//
//   sum_{w in window} (I_r(x_r + w) - I_l(x_l + w))^2       over x_r,
//
// so the two pixels of a match describe the same scene point to the
// precision of the image texture (measured on the simulated pool: 0.05 px
// of locus distance after refinement, 0.5 px before).
#ifndef RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_
#define RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_

#include <opencv2/core.hpp>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

struct SubpixelOptions {
  bool enabled = true;
  // Side of the square window, pixels; odd, >= 5. Larger windows average
  // more noise but mix more of the surface's slant: on the pool floor seen
  // 16 degrees down, 11 was the best of 7, 11, 15, 21, 31.
  int window = 11;
  // Gauss-Newton iterations per match and the step that stops them.
  int max_iterations = 30;
  double min_step_px = 0.01;
  // A match whose right pixel moves farther than this is dropped: the
  // alignment found another patch than the detector did; > 0.
  double max_shift_px = 2.0;

  Status Check() const;
};

// Refines `right[i]` for each pair (left[i], right[i]) of pixels (pixel
// centers at integers) in the 8-bit gray images; `kept[i]` is 1 where the
// refinement converged within max_shift_px, 0 where the match should be
// dropped. With options.enabled false, right is unchanged and all are kept.
void RefineRightPixels(const cv::Mat& left_gray, const cv::Mat& right_gray,
                       const std::vector<cv::Point2f>& left,
                       std::vector<cv::Point2f>* right,
                       std::vector<unsigned char>* kept,
                       const SubpixelOptions& options);

}  // namespace rcm

#endif  // RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_
