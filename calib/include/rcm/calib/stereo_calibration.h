// Air stereo calibration by bundle adjustment over planar-target views.
//
// Unknowns: the lens parameters of each camera (lens_models.h order,
//   p_c = [fx, fy, cx, cy, d0, d1, d2, d3], radtan or equidistant), the
//   extrinsics cam1_from_cam0 = (R_10, t_10) and one pose
//   cam0_from_target_v = (R_v, t_v) per view. Target corners X_j lie on
//   the target plane z = 0 (calibration_target.h).
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
// the p unknowns, board poses included.
#ifndef RCM_CALIB_STEREO_CALIBRATION_H_
#define RCM_CALIB_STEREO_CALIBRATION_H_

#include <Eigen/Core>
#include <array>
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

  // Per input view: cam0_from_target, nullopt when the view was not used
  // (no target, too few corners, or the pose failed to initialize).
  std::vector<std::optional<Rigid3d>> cam0_from_target;
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
