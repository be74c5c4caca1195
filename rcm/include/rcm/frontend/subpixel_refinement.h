// Subpixel positions of matched keypoints. Detectors localize keypoints to
// about a pixel (FAST on the pixel grid, SIFT by a parabola through its
// scale space), and the left and right detections of one corner need not
// agree to better than that. n is observed through shifts of a fraction of
// a pixel (the locus bends by ~1 px at the image border for n = 1.333), so
// the right pixel of each match is refined against the left window T
// around the left pixel by minimizing
//
//   sum_{w in window} (g I_r(x_r + t + (I + D) w) + b - T(w))^2
//
// over the translation t and the 2x2 D of an affine warp (g = 1, b = 0
// unless normalize_exposure, which solves them in closed form at each step
// by matching the warped patch's mean and contrast to T's). The refined
// right pixel is x_r + t, the image of the window's center. Method:
// inverse compositional Gauss-Newton (Baker and Matthews 2004): T's
// steepest-descent images and Hessian are computed once per match; the
// translation alone is fitted first, until its step is below 0.1 px, and
// the warp from there.
//
// Why affine: the two views of a slanted surface (the pool floor, seen 16
// degrees down) differ by a warp across the window, since disparity grows
// toward the near side. A translation-only fit (Lucas-Kanade) returns the
// displacement of the window's gradient-weighted centroid, not of its
// center; at a corner keypoint the gradient energy is off center, and the
// error is systematic. Measured on rendered pairs of the simulated pool
// (n = 1.333, ORB keypoints): translation-only windows of 7, 11, 15, 21 px
// biased n by +4.8e-4, +8.4e-4, +1.0e-3, +1.5e-3 over frames 50-57 (sigma
// 1.1e-4); the affine fit with the default 11 px window gives +1.7e-4 +-
// 1.2e-4 there and +5e-5 +- 5e-5 over frames 0-39. What remains is not
// zero: frames 0-3 read -7.8e-4 +- 1.8e-4 (windows of 9 and 13 px: -7e-4,
// -4.7e-4), a scene-dependent error of a few thousandths of a pixel per
// match (windows across depth edges, view-dependent texture filtering)
// that averages out over a longer run but that sigma_n does not count. The price: two more
// degrees of freedom per axis make a single match noisier on smooth
// texture (a subpixel shift of blurred blobs: median error 0.057 px at ORB
// corners, against 0.025 px for the translation alone).
#ifndef RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_
#define RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_

#include <opencv2/core.hpp>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

struct SubpixelOptions {
  bool enabled = true;
  // Side of the square window, pixels; odd, >= 5.
  int window = 11;
  // Gauss-Newton iterations per match, and the translation step (pixels)
  // below which they stop; >= 1 and > 0.
  int max_iterations = 30;
  double min_step_px = 0.005;
  // A match whose right pixel moves farther than this is dropped: the
  // alignment found another patch than the detector did; > 0.
  double max_shift_px = 2.0;
  // A fit whose warp strays further from the identity (any entry of
  // A - I) is dropped: the two patches do not show one surface; > 0.
  double max_warp = 0.3;
  // Windows whose weaker gradient direction (the smaller eigenvalue of the
  // 2x2 structure tensor per pixel, gray levels^2 / px^2) is below this are
  // dropped: along an edge or in a flat area the position is not
  // determined; >= 0. 4 is a gradient of 2 levels per pixel.
  double min_texture = 4.0;
  // Fit the affine warp (true) or the translation alone (false: faster,
  // and less noisy on smooth texture, but biased on slanted surfaces; see
  // above).
  bool affine = true;
  // Fit a gain and bias between the two patches (cameras whose exposures
  // differ). Off by default: on smooth texture (blurred blobs, where the
  // window's intensity is nearly linear) a shift and an intensity change
  // look alike, and the fitted position drifts by tenths of a pixel.
  bool normalize_exposure = false;
  // Threads over the matches; >= 1.
  int num_threads = 2;

  Status Check() const;
};

// Refines `right[i]` for each pair (left[i], right[i]) of pixels (pixel
// centers at integers) in the 8-bit gray images; `kept[i]` is 1 where the
// refinement converged within max_shift_px and max_warp, 0 where the match
// should be dropped (also: a window leaving the image, a textureless
// patch). With options.enabled false, right is unchanged and all are kept.
void RefineRightPixels(const cv::Mat& left_gray, const cv::Mat& right_gray,
                       const std::vector<cv::Point2f>& left,
                       std::vector<cv::Point2f>* right,
                       std::vector<unsigned char>* kept,
                       const SubpixelOptions& options);

}  // namespace rcm

#endif  // RCM_FRONTEND_SUBPIXEL_REFINEMENT_H_
