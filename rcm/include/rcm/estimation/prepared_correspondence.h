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
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct PreparedCorrespondence {
  // Lens-undistorted normalized coordinates (x_bar, y_bar) of each pixel.
  double left_normalized[2] = {0.0, 0.0};
  double right_normalized[2] = {0.0, 0.0};
  // d normalized / d pixel of each camera at its pixel, row-major 2x2: the
  // inverse of Camera::ImageFromNormalizedJacobian.
  double left_normalized_from_pixel[4] = {0.0, 0.0, 0.0, 0.0};
  double right_normalized_from_pixel[4] = {0.0, 0.0, 0.0, 0.0};
  // d normalized / d e of each camera at its pixel, for a change of the
  // camera's focal lengths by the factor (1 + e) (the focal drift of
  // calibration_uncertainty.h): every lens model maps u = fx x_d + cx,
  // v = fy y_d + cy, so the pixel of a fixed normalized point moves by
  // (u - cx, v - cy) de and the normalized point of a fixed pixel by
  //
  //   d(x, y)/de = -(d(x, y)/d(u, v)) (u - cx, v - cy).
  double left_focal_direction[2] = {0.0, 0.0};
  double right_focal_direction[2] = {0.0, 0.0};
  // d/de of each camera's d normalized / d pixel above, row-major: for a
  // lens without distortion -d(x, y)/d(u, v) (it scales with 1 / (1 + e));
  // PrepareFocalDerivatives gives it for any lens.
  double left_normalized_from_pixel_focal[4] = {0.0, 0.0, 0.0, 0.0};
  double right_normalized_from_pixel_focal[4] = {0.0, 0.0, 0.0, 0.0};
};

// nullopt when a pixel cannot be undistorted or the lens map is not
// invertible there (non-finite inputs included).
std::optional<PreparedCorrespondence> PrepareCorrespondence(
    const StereoRig& rig, const StereoCorrespondence& correspondence);

// One camera's half of PrepareCorrespondence (side 0: left, 1: right),
// written into `prepared`, the other half untouched: the lens columns of
// the propagation move one camera's parameters at a time
// (calibration_propagation.h). False, `prepared` partly written, where
// PrepareCorrespondence would give nullopt for this side.
bool PrepareCorrespondenceSide(const Camera& camera,
                               const Eigen::Vector2d& pixel, int side,
                               PreparedCorrespondence* prepared);

// The same for a camera whose lens differs by a small step h from the one
// `prepared`'s side was made with (the propagation's central differences):
// one Newton step from that side's normalized point x_0,
//
//   x_1 = x_0 + (d pixel / d x)^-1 (pixel - pixel(x_0)),
//
// instead of the undistortion from scratch. Its error is the Newton step's,
// quadratic in x - x_0 = +-h x' + O(h^2): the same for +h and -h to O(h^3),
// so a central difference of what it prepares keeps its O(h^2) error.
bool PrepareCorrespondenceSideNear(const Camera& camera,
                                   const Eigen::Vector2d& pixel, int side,
                                   PreparedCorrespondence* prepared);

// The derivatives in e of `prepared`'s inverse lens Jacobians for any lens
// model, by central differences of the preparation on `rig` with the focal
// lengths scaled by 1 +- kFocalStep (the undistortion converges to ~1e-14,
// so their error is ~1e-8 relative, ample for the Sampson normalization's
// derivative). False (and `prepared` unchanged) where a moved pixel does
// not prepare.
bool PrepareFocalDerivatives(const StereoRig& rig,
                             const StereoCorrespondence& correspondence,
                             PreparedCorrespondence* prepared);

// The rig with both cameras' focal lengths scaled by 1 +- kStep, made once
// for many PrepareFocalDerivatives (making a camera checks its lens, which
// costs more than preparing a match).
struct FocalStepRigs {
  static constexpr double kStep = 1e-6;
  static StatusOr<FocalStepRigs> Of(const StereoRig& rig);
  StereoRig plus;
  StereoRig minus;
};
bool PrepareFocalDerivatives(const FocalStepRigs& rigs,
                             const StereoCorrespondence& correspondence,
                             PreparedCorrespondence* prepared);

// The correspondences that could be prepared, with the index of each in the
// input, in input order; the matches prepared on up to `num_threads`
// threads (each match's preparation is its own, so the result does not
// depend on them).
struct PreparedCorrespondences {
  std::vector<PreparedCorrespondence> prepared;
  std::vector<int64_t> source_index;
};
PreparedCorrespondences PrepareCorrespondences(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    int num_threads = 1);

}  // namespace rcm

#endif  // RCM_ESTIMATION_PREPARED_CORRESPONDENCE_H_
