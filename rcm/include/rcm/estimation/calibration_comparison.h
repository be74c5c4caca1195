// The refractive index implied by an air and an underwater calibration of
// the same camera (rcm compare): users who already hold a conventional
// underwater calibration check the refractive model on their own data,
// and read off the n of their water.
//
// The underwater calibration W is a conventional central camera in the
// medium: its pixel p sees the ray d_W(p) = (x, y, 1) with
// (x, y) = W.NormalizedFromImage(p). The air calibration A behind a thin
// flat port (paper Sec. III-A, eqs. 1-5) images a ray d of the medium at
// pi_A(n, s; d): the ray refracted into air (refracted_projection_error.h),
// through A's lens with its principal point shifted by s = (sx, sy). n and,
// when asked, s minimize, in pixels,
//
//   sum_i | pi_A(n, s; d_i) - p_i |^2
//
// over samples (p_i, d_i). CompareCalibrations takes the samples on a grid
// over W's image, d_i = d_W(p_i); EstimateIndexFromRays takes any samples
// (e.g. board corners observed under water with their rays).
//
// Why a principal-point shift: two calibrations of one camera rarely
// agree on the principal point to better than a pixel (it is the least
// well determined intrinsic, and a housing may sit the port off center).
// Left free, a shift is not confused with n, whose signature is radial:
// a change of n scales the image about the principal point.
//
// Uncertainty, with m samples, p parameters and residual r:
//   s^2 = sum |r_i|^2 / (2m - p),  cov = s^2 (J^T J)^-1   (Ceres covariance)
// honest when the p_i carry independent pixel noise (tested by Monte
// Carlo). Between two calibrations the residual is model error,
// correlated over the image, and the sigma is a lower bound ("formal").
#ifndef RCM_ESTIMATION_CALIBRATION_COMPARISON_H_
#define RCM_ESTIMATION_CALIBRATION_COMPARISON_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/estimation/image_error_field.h"
#include "rcm/estimation/pixel_error_stats.h"
#include "rcm/util/status.h"

namespace rcm {

struct CalibrationComparisonOptions {
  // Estimate the principal-point shift s (otherwise s = 0).
  bool estimate_principal_point_shift = false;
  // CompareCalibrations: spacing of the sample grid over W's image in
  // pixels (4 px: 24300 samples on 720x540). > 0.
  double grid_step = 4.0;
  // CompareCalibrations: fraction of the width and height left out at
  // each side, where the underwater calibration had no board corners and
  // its polynomial extrapolates (rcm export's default fit region). In
  // [0, 0.45].
  double inset = 0.05;
  // Levenberg-Marquardt iterations. > 0.
  int max_iterations = 100;

  Status Check() const;
};

// An observation: a pixel of the air-calibrated camera and the ray in the
// medium (camera frame, any length, z > 0) that it sees.
struct PixelRay {
  Eigen::Vector2d pixel;
  Eigen::Vector3d ray_in_water;
};

struct IndexFromRays {
  double n = 0.0;
  double sigma_n = 0.0;
  // Zero unless estimated.
  Eigen::Vector2d principal_point_shift = Eigen::Vector2d::Zero();
  Eigen::Vector2d sigma_principal_point_shift = Eigen::Vector2d::Zero();
  // Correlation of n with sx and sy (zero unless the shift is estimated).
  Eigen::Vector2d correlation_n_shift = Eigen::Vector2d::Zero();
  // s of the header: the residual's standard deviation per coordinate.
  double sigma_px = 0.0;
  // pi_A(n, s; d_i) - p_i at the solution, one per sample used.
  std::vector<Eigen::Vector2d> residuals;
  // Indices of the samples used; the others are past total internal
  // reflection or outside the air lens' invertible region at the start.
  std::vector<int64_t> used;
  int num_iterations = 0;
  bool converged = false;
};

// Errors: options.Check(); a sample that is not finite or has z <= 0;
// fewer usable samples than 10 (a parameter per sample is not a fit); a
// solve that fails or does not observe n (singular covariance).
StatusOr<IndexFromRays> EstimateIndexFromRays(
    const Camera& air_camera, const std::vector<PixelRay>& samples,
    const CalibrationComparisonOptions& options);

struct CalibrationComparison {
  IndexFromRays fit;
  // |pi_A(n, s; d_W(p_i)) - p_i| over the samples.
  PixelErrorStats residual_stats;
  // The residuals on the sample grid (for DrawImageErrorMap); absent
  // outside the inset and where a sample was not usable.
  ImageErrorField residual_field;
  // The region sampled, [x0, y0, x1, y1] in pixels.
  Eigen::Vector4d region = Eigen::Vector4d::Zero();
  // Grid pixels in the region that were not usable (W cannot undistort
  // them, or the ray is past total internal reflection for A).
  int64_t num_unusable = 0;
};

// Errors: options.Check(); the two cameras' image sizes differ; those of
// EstimateIndexFromRays.
StatusOr<CalibrationComparison> CompareCalibrations(
    const Camera& air_camera, const Camera& water_camera,
    const CalibrationComparisonOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_CALIBRATION_COMPARISON_H_
