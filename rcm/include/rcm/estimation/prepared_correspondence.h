// A correspondence made ready for the locus residual: both pixels
// lens-undistorted once, and the inverse lens Jacobians that carry pixel
// noise into normalized coordinates. Refinement evaluates the residual many
// times per correspondence (scan, solver iterations, covariance); the lens
// undistortion, an iterative solve, is done here only once.
#ifndef RCM_ESTIMATION_PREPARED_CORRESPONDENCE_H_
#define RCM_ESTIMATION_PREPARED_CORRESPONDENCE_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/geometry/stereo_rig.h"

namespace rcm {

struct PreparedCorrespondence {
  // Lens-undistorted normalized coordinates (x_bar, y_bar) of each pixel.
  double left_normalized[2] = {0.0, 0.0};
  double right_normalized[2] = {0.0, 0.0};
  // d normalized / d pixel of each camera at its pixel, row-major 2x2: the
  // inverse of Camera::ImageFromNormalizedJacobian.
  double left_normalized_from_pixel[4] = {0.0, 0.0, 0.0, 0.0};
  double right_normalized_from_pixel[4] = {0.0, 0.0, 0.0, 0.0};
};

// nullopt when a pixel cannot be undistorted or the lens map is not
// invertible there (non-finite inputs included).
std::optional<PreparedCorrespondence> PrepareCorrespondence(
    const StereoRig& rig, const StereoCorrespondence& correspondence);

// The correspondences that could be prepared, with the index of each in the
// input, in input order.
struct PreparedCorrespondences {
  std::vector<PreparedCorrespondence> prepared;
  std::vector<int64_t> source_index;
};
PreparedCorrespondences PrepareCorrespondences(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences);

}  // namespace rcm

#endif  // RCM_ESTIMATION_PREPARED_CORRESPONDENCE_H_
