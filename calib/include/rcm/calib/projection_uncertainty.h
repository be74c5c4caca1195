// Projection uncertainty of a calibrated camera the way mrcal 2.2 computes
// it ("mean-frames"), through the board poses, at a stated distance, so that
// rcm's numbers compare with mrcal's.
//
// For a pixel q0 of camera c and a distance d (infinity by default), with
// the solved parameters b* (both lenses, cam1_from_cam0, every board pose,
// the warp; StereoCalibration::full_parameters):
//
//   v      = unproject(lens_c*, q0)          the ray (x, y, 1)
//   p_cam  = d v / |v|                       (at infinity the direction
//                                             (v, 0): translations drop out)
//   p_ref  = T_ref_cam* p_cam                ref = cam0; T_cam1_ref =
//                                             cam1_from_cam0
//   p_i    = T_board_i_ref* p_ref            for each used view i
//                                             (cam0_from_target_i^-1)
//
// and for parameters b:
//
//   p_ref(b) = mean_i T_ref_board_i(b) p_i
//   q(b)     = project(lens_c(b), T_cam_ref(b) p_ref(b))
//
// Var(q) = J Var(b) J^T, J = dq/db at b* (autodiff: dq/dp_ref chained with
// dp_ref/dpose_i, which is all the poses enter through), Var(b) =
// StereoCalibration::full_covariance (sigma^2 (J^T J)^-1 of the whole
// problem, board poses and warp included, sigma from the residuals). The
// figure reported is the worst-direction standard deviation
// sqrt(lambda_max(Var(q))) [px].
//
// What it means: where the camera would project a point seen at q0 at
// distance d, in a calibration redone with new noise, the point held fixed
// relative to the mean of the boards (the frame the calibration data pin
// down). The intrinsics-only figure (calibration_report.h,
// ProjectionUncertainty) holds the ray fixed in the camera frame and
// ignores the poses and extrinsics: it is a different quantity (on one
// real set 0.80 px median against mrcal's 0.26 px at infinity).
#ifndef RCM_CALIB_PROJECTION_UNCERTAINTY_H_
#define RCM_CALIB_PROJECTION_UNCERTAINTY_H_

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

#include "rcm/calib/stereo_calibration.h"

namespace rcm::calib {

inline constexpr double kInfiniteDistance =
    std::numeric_limits<double>::infinity();

// The points the mean-frames method holds fixed for pixel q0 of `camera`
// (0 or 1; 0 of one camera) at `distance` [m] (> 0, or kInfiniteDistance): p_i per used
// view, homogeneous (w = 0 at infinity), in the layout of the views of
// calibration.full_covariance.pose_offset.
struct MeanFramesPoint {
  int camera = 0;
  double distance = kInfiniteDistance;
  std::vector<int> pose_offset;                 // of the used views
  std::vector<Eigen::Vector4d> point_in_board;  // p_i, per used view
};

// nullopt when q0 cannot be unprojected, the calibration has no full
// covariance (compute_covariance was off), or the distance is not > 0.
std::optional<MeanFramesPoint> MeanFramesPointOf(
    const StereoCalibration& calibration, int camera,
    const Eigen::Vector2d& pixel, double distance = kInfiniteDistance);

// q(b) for parameters b in the layout of calibration.full_covariance (the
// lens model and layout are calibration's); nullopt where the point is
// behind the camera. q(full_parameters) is q0 up to the unprojection.
std::optional<Eigen::Vector2d> MeanFramesPixel(
    const StereoCalibration& calibration, const MeanFramesPoint& point,
    const Eigen::VectorXd& parameters);

// dq/db at calibration.full_parameters (2 x full_covariance.size()),
// automatic differentiation; nullopt as MeanFramesPixel.
std::optional<Eigen::MatrixXd> MeanFramesJacobian(
    const StereoCalibration& calibration, const MeanFramesPoint& point);

// Var(q) = J Var(b) J^T [px^2]; nullopt as MeanFramesPointOf.
std::optional<Eigen::Matrix2d> MeanFramesProjectionCovariance(
    const StereoCalibration& calibration, int camera,
    const Eigen::Vector2d& pixel, double distance = kInfiniteDistance);

// sqrt(lambda_max(Var(q))) [px]; NaN where there is none.
double MeanFramesProjectionUncertainty(const StereoCalibration& calibration,
                                       int camera, const Eigen::Vector2d& pixel,
                                       double distance = kInfiniteDistance);

// sqrt of the largest eigenvalue of a 2x2 covariance (0 for a slightly
// indefinite one from round-off).
double WorstDirectionSigma(const Eigen::Matrix2d& covariance);

}  // namespace rcm::calib

#endif  // RCM_CALIB_PROJECTION_UNCERTAINTY_H_
