// Air stereo calibration by bundle adjustment over planar-target views.
//
// Unknowns: the lens parameters of each camera (lens_models.h order,
//   p_c = [fx, fy, cx, cy, d...], any of the six lens models), the
//   extrinsics cam1_from_cam0 = (R_10, t_10) and one pose
//   cam0_from_target_v = (R_v, t_v) per view, and (estimate_board_warp)
//   the board's warp w = [warp_x, warp_y] shared by all views. Target
//   corners X_j lie on the target plane z = 0 (calibration_target.h) or,
//   with the warp, on the bowed board of board_warp.h (mrcal's
//   calobject_warp):
//     X_j(w) = (x_j, y_j, warp_x 4 xr (1 - xr) + warp_y 4 yr (1 - yr)),
//   (xr, yr) the corner's position normalized over the target's extent.
//
// Residuals, for every corner j that camera c saw in view v at pixel u:
//   e = pi(p_0, R_v X_j + t_v) - u                          (cam0)
//   e = pi(p_1, R_10 (R_v X_j + t_v) + t_10) - u            (cam1)
// with pi the lens projection of lens_models.h. The cost is
// sum rho(|e|^2) with Huber's rho at `huber_px`, followed by rounds that
// drop corners whose residual exceeds `outlier_sigmas` robust standard
// deviations and re-solve. The robust sigma is median|e| / sqrt(2 ln 2):
// |e| of a 2-D residual with N(0, sigma^2) components is Rayleigh
// distributed, with median sigma sqrt(2 ln 2). The threshold is floored at
// `min_outlier_threshold_px`. The last solve is plain least squares over the
// inliers, so that the covariance below is that of the least-squares estimate.
//
// Initialization (OpenCV closed forms): per camera, cv::calibrateCamera
// (Zhang's homography method + LM) with k3 fixed to 0 for radtan; for
// equidistant, cv::fisheye::calibrate, falling back to a pinhole start
// from cv::calibrateCamera with zero distortion when it fails. Board poses
// from cv::solvePnP; cam1_from_cam0 from the stereo views' relative poses
// (chordal mean of rotations, mean of translations).
//
// Uncertainty: the covariance of all camera and extrinsic parameters is
// (J^T J)^-1 sigma^2 at the solution (ceres::Covariance), with the pixel
// noise sigma^2 = SSR / (2 m - p) estimated from the m inlier corners and
// the p unknowns, board poses (and the warp) included; the warp's 2x2
// block likewise. The covariance of every unknown together (lenses,
// extrinsics, board poses, warp), sigma^2 (J^T J)^-1 of the whole problem
// (dense: ~40 poses of 6), is kept too (StereoCalibration::
// full_covariance) for the projection uncertainty through the board poses
// (projection_uncertainty.h).
//
// One camera (CalibrateMono, mono_calibration.h) is this problem without
// cam1 and the extrinsics; its result is a StereoCalibration with
// num_cameras 1.
#ifndef RCM_CALIB_STEREO_CALIBRATION_H_
#define RCM_CALIB_STEREO_CALIBRATION_H_

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_observation.h"
#include "rcm/camera/camera.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm::calib {

struct ImageSize {
  int width = 0;
  int height = 0;
};

struct StereoCalibrationOptions {
  // Lens model of both cameras: any LensModelId (none, radtan,
  // equidistant, rational, ds, eucm).
  LensModelId model = LensModelId::kRadTan;
  // Huber loss scale [px] for the robust solves.
  double huber_px = 1.0;
  // Corners whose residual exceeds outlier_sigmas robust standard
  // deviations of the residual norms are dropped.
  double outlier_sigmas = 5.0;
  // Floor of that threshold [px]. Outliers are detector failures (a
  // corner on the wrong grid point, a reflection): several pixels. On real
  // images the residuals have a continuous tail to ~1.5 px from lens-model
  // error and blur (OpenCV's sample stereo pairs: 36 of 1404 corners at
  // 0.73-1.5 px exceed 5 sigma); those are data, not outliers.
  double min_outlier_threshold_px = 2.0;
  // Rounds of outlier rejection (0 = keep every corner).
  int max_outlier_rounds = 3;
  // Ceres iterations per solve.
  int max_num_iterations = 200;
  // Views where only one camera saw the target also constrain that
  // camera's intrinsics.
  bool use_single_camera_views = true;
  // Fewest corners a camera must see in a view for it to be used (a
  // board pose needs at least 4 points; fewer is noise).
  int min_corners_per_view = 6;
  // Compute the parameter covariance (cheap: dense over the cameras and
  // extrinsics only).
  bool compute_covariance = true;
  // Estimate the board's flatness (board_warp.h): two parameters shared by
  // all views. A printed board is rarely flat to a tenth of a millimetre,
  // and a bow of 0.7 mm moves the focal lengths by ~1 % (measured on real
  // images against mrcal, which estimates it by default). Off (a flat
  // board) reproduces cv::stereoCalibrate's model.
  bool estimate_board_warp = true;
  // Threads for Ceres.
  int num_threads = 2;

  // Fails on an unsupported model or a non-positive / non-finite value.
  Status Check() const;
};

// One camera's calibration and its uncertainty.
struct CameraCalibration {
  explicit CameraCalibration(const Camera& camera) : camera(camera) {}

  Camera camera;
  // Covariance of camera.params() ([fx, fy, cx, cy, d...]; the first
  // camera.num_params() rows/cols are used) and their standard deviations.
  Eigen::Matrix<double, kMaxLensParams, kMaxLensParams> covariance =
      Eigen::Matrix<double, kMaxLensParams, kMaxLensParams>::Zero();
  std::array<double, kMaxLensParams> sigma{};
};

// The covariance of every unknown of the final least-squares problem,
// sigma^2 (J^T J)^-1, in the raw parameters Ceres estimates: the lenses
// ([fx, fy, cx, cy, d...], num_params each), cam1_from_cam0 and each used
// view's cam0_from_target as [angle-axis (rad), translation (m)], and the
// warp [m] when estimated. Empty when the covariance was not computed. One
// camera: lens_offset[1] and extrinsics_offset are -1 (no such block).
struct FullCovariance {
  Eigen::MatrixXd matrix;
  std::array<int, 2> lens_offset{};
  int num_lens_params = 0;
  int extrinsics_offset = 0;
  // Per input view; -1 for a view that was not used.
  std::vector<int> pose_offset;
  int warp_offset = -1;  // -1: the warp was not estimated
  int size() const { return static_cast<int>(matrix.rows()); }
};

// A corner as the final solve saw it.
struct CornerResidual {
  int view = 0;    // index into the input views
  int camera = 0;  // 0 = cam0 (left), 1 = cam1 (right)
  int point_id = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();     // measured
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();  // projected - measured
  bool inlier = true;
};

struct StereoCalibration {
  StereoCalibration(const Camera& cam0, const Camera& cam1)
      : cam0(cam0), cam1(cam1) {}

  // 2 for a pair (CalibrateStereo); 1 for one camera (CalibrateMono): then
  // cam1 is a copy of cam0, cam1_from_cam0 the identity, the baseline and
  // the extrinsics' covariance zero and num_stereo_views 0, none of them a
  // measurement, and every corner is cam0's.
  int num_cameras = 2;
  CameraCalibration cam0;
  CameraCalibration cam1;
  Rigid3d cam1_from_cam0;
  // Covariance of the extrinsics as [w; t]: w the rotation vector of the
  // left perturbation R_10 = exp([w]x) R_10_hat (radians), t = t_10 (m).
  Eigen::Matrix<double, 6, 6> extrinsics_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  // Baseline |t_10| [m] and its standard deviation.
  double baseline = 0.0;
  double baseline_sigma = 0.0;

  // The board's warp [warp_x, warp_y] (m, board_warp.h; zero when not
  // estimated), its covariance and standard deviations. The bowl at the
  // board's centre is warp_x + warp_y.
  bool board_warp_estimated = false;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();
  Eigen::Matrix2d board_warp_covariance = Eigen::Matrix2d::Zero();
  Eigen::Vector2d board_warp_sigma = Eigen::Vector2d::Zero();
  // The bowl at the centre, warp_x + warp_y [m], and its sigma.
  double BoardBowl() const { return board_warp.sum(); }
  double BoardBowlSigma() const {
    return std::sqrt(board_warp_covariance.sum());
  }

  // Per input view: cam0_from_target, nullopt when the view was not used
  // (no target, too few corners, or the pose failed to initialize).
  std::vector<std::optional<Rigid3d>> cam0_from_target;
  // The covariance of all unknowns together (above; empty without
  // compute_covariance), and the solution in its layout (the poses and
  // extrinsics as the angle-axis vectors the solver held).
  FullCovariance full_covariance;
  // Why full_covariance is empty although compute_covariance was on (it
  // could not be factored); empty otherwise.
  std::string full_covariance_note;
  Eigen::VectorXd full_parameters;
  // Every corner of every used view, inliers and outliers.
  std::vector<CornerResidual> corners;

  // sqrt(mean |e|^2) over all corners of used views (outliers included:
  // comparable with cv::stereoCalibrate's RMS on the same corners), and
  // over the inliers only.
  double rms_px = 0.0;
  double inlier_rms_px = 0.0;
  // Pixel noise estimated from the inliers, sqrt(SSR / (2 m - p)).
  double pixel_sigma = 0.0;
  // RMS of the OpenCV initialization over the same corners.
  double initial_rms_px = 0.0;

  int num_views_used = 0;    // views with a pose
  int num_stereo_views = 0;  // of which both cameras saw the target
  int num_inliers = 0;
  int num_outliers = 0;
  int num_parameters = 0;  // p above
};

// Calibrates the rig from the target's views. Fails with one line when the
// options are invalid, no view shows the target in both cameras (the
// extrinsics are unobservable), a camera has fewer than 3 usable views,
// initialization fails, or the solve does not converge to a usable
// solution.
StatusOr<StereoCalibration> CalibrateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibrationOptions& options = {});

}  // namespace rcm::calib

#endif  // RCM_CALIB_STEREO_CALIBRATION_H_
