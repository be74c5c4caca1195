// One camera's calibration in air by bundle adjustment over planar-target
// views (`rcm calibrate --left DIR` without --right): the stereo
// calibration (stereo_calibration.h) without cam1 and the extrinsics, by
// the same solver.
//
// Unknowns: the lens parameters p = [fx, fy, cx, cy, d...] (lens_models.h
//   order, any of the six lens models), one pose cam_from_target_v =
//   (R_v, t_v) per view, and (estimate_board_warp) the board's warp
//   w = [warp_x, warp_y] shared by all views, the corners on the bowed
//   board of board_warp.h:
//     X_j(w) = (x_j, y_j, warp_x 4 xr (1 - xr) + warp_y 4 yr (1 - yr)).
//
// Residuals, for every corner j seen in view v at pixel u:
//   e = pi(p, R_v X_j(w) + t_v) - u.
// The cost is sum rho(|e|^2), Huber's rho at huber_px, with rounds that
// drop the corners beyond outlier_sigmas robust standard deviations
// (median|e| / sqrt(2 ln 2), floored at min_outlier_threshold_px), then
// plain least squares over the inliers (the covariance's problem).
//
// Initialization: cv::calibrateCamera (cv::fisheye::calibrate for
// equidistant; calibration_initialization.h), board poses by
// cv::solvePnP. With a flat board (estimate_board_warp off), radtan and
// no outlier, the minimum is cv::calibrateCamera's with CALIB_FIX_K3 on
// the same corners: the same model, residuals and cost.
//
// Uncertainty: Cov(p) = sigma^2 [(J^T J)^-1]_pp (CameraCalibration::
// covariance, sigma), sigma^2 = SSR / (2 m - q) from the m inlier corners
// and the q = n_p + 6 V (+ 2 with the warp) unknowns; the warp's 2x2
// block likewise; and sigma^2 (J^T J)^-1 of every unknown (lens, poses,
// warp; StereoCalibration::full_covariance) for the projection
// uncertainty through the board poses (projection_uncertainty.h).
#ifndef RCM_CALIB_MONO_CALIBRATION_H_
#define RCM_CALIB_MONO_CALIBRATION_H_

#include <optional>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/util/status.h"

namespace rcm::calib {

// Calibrates one camera from the views' left observations (a view's right
// observation must be absent). The options are the pair's
// (use_single_camera_views does not apply). The result has
// num_cameras == 1: cam0 is the camera, cam0_from_target the poses;
// rms_px, inlier_rms_px, pixel_sigma, initial_rms_px, corners and the
// counts are those of the camera's corners. The report
// (calibration_report.h), the cross-validation (cross_validation.h), the
// projection uncertainty and the covariance sidecar
// (calibration_covariance.h) take it as a pair's and cover cam0 alone.
// Fails with one line when the options or the image size are invalid, a
// view has a right observation, fewer than 3 views show the target with
// min_corners_per_view corners, initialization fails, or the solve does
// not reach a usable solution.
StatusOr<StereoCalibration> CalibrateMono(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& size, const StereoCalibrationOptions& options = {});

// The views CalibrateMono takes for one camera's observations (nullopt: the
// target was not seen), named "view 0", "view 1", ...
std::vector<StereoView> MonoViews(
    const std::vector<std::optional<TargetObservation>>& observations);

}  // namespace rcm::calib

#endif  // RCM_CALIB_MONO_CALIBRATION_H_
