// The residual of the estimator of record (docs/design.md, "The estimator
// of record"): how far a correspondence lies from the refractive epipolar
// locus of a refractive index n, in pixels, for a general calibrated rig
// (no rectification).
//
// Coplanarity of the two water-side bearings (epipolar.h; the paper's
// eqs. 10-11 without the rectification of Sec. III-C):
//
//   e(n) = b_r(n)^T E b_l(n),   E = [t]x R (unit t),
//   b(n) = (x, y, m(n, r)),     m = sqrt(n^2 + (n^2 - 1) r^2)  (eq. 5),
//
// with (x, y) = lens-undistorted normalized coordinates, r^2 = x^2 + y^2.
// The Sampson normalization divides e by its gradient with respect to the
// four raw pixel coordinates p = (ul, vl, ur, vr):
//
//   r(n) = e(n) / |de/dp|,
//   de/d(x_l, y_l) = (E^T b_r)^T db_l/d(x_l, y_l),
//   de/d(x_r, y_r) = (E b_l)^T  db_r/d(x_r, y_r),
//   db/d(x, y) = [1, 0; 0, 1; (n^2 - 1) x / m, (n^2 - 1) y / m],
//   de/dp = de/d(x, y) d(x, y)/dp   (inverse lens Jacobian, per camera).
//
// r is the first-order distance of the measured pixels from the locus:
// with independent pixel noise of standard deviation sigma on the four
// coordinates, r ~ N(0, sigma^2) to first order, so sum r^2 / sigma^2 is
// the first-order negative log-likelihood of n. It is exactly 0 on exact
// correspondences and does not depend on the baseline length.
//
// Optional rotation correction: cam1 rotated about its own center by the
// small angle-axis delta (in the cam1 frame), i.e. cam1_from_cam0 becomes
// (R_delta R, R_delta t) and E becomes R_delta E; the camera centers stay.
//
// Optional focal scales (e_l, e_r): each camera's focal lengths scaled by
// (1 + e) since the calibration (calibration_uncertainty.h, focal drift),
// to first order in e on the prepared coordinates, and in the Sampson
// normalization, whose inverse lens Jacobian scales with 1 / (1 + e):
//
//   (x, y)       -> (x, y) + e d(x, y)/de     (prepared_correspondence.h),
//   d(x, y)/dp   -> d(x, y)/dp + e d/de (d(x, y)/dp).
//
// (The normalization matters: held at the calibration's, shrinking the
// coordinates would shrink the noise's residuals with them, and the focal
// scales would come out biased by the pixel noise, about +1 % for 0.3 px;
// so does its derivative on a fisheye lens, whose d(x, y)/dp changes
// across the image: without it, +0.7 %.) The batch refinement prepares the
// pixels again with the estimated scales until the step vanishes, so that
// its solution is the minimum of the exact residuals, for every lens.
#ifndef RCM_ESTIMATION_SAMPSON_COPLANARITY_ERROR_H_
#define RCM_ESTIMATION_SAMPSON_COPLANARITY_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/util/scalar.h"

namespace rcm {

// r(n) above. `rotation_correction` is the angle-axis delta, or nullptr for
// none; `focal_scale` (e_l, e_r), or nullptr for none. False when the
// gradient vanishes (no defined distance), which does not happen for n in
// [1, 2] away from the epipoles.
template <typename T>
bool SampsonCoplanarityResidual(const Eigen::Matrix3d& essential,
                                const PreparedCorrespondence& match, const T& n,
                                const T* rotation_correction,
                                const T* focal_scale, T* residual) {
  using std::sqrt;
  const T excess = n * n - T(1.0);
  T xl(match.left_normalized[0]);
  T yl(match.left_normalized[1]);
  T xr(match.right_normalized[0]);
  T yr(match.right_normalized[1]);
  if (focal_scale != nullptr) {
    xl += focal_scale[0] * match.left_focal_direction[0];
    yl += focal_scale[0] * match.left_focal_direction[1];
    xr += focal_scale[1] * match.right_focal_direction[0];
    yr += focal_scale[1] * match.right_focal_direction[1];
  }
  const T left[3] = {xl, yl, sqrt(n * n + excess * (xl * xl + yl * yl))};
  T right[3] = {xr, yr, sqrt(n * n + excess * (xr * xr + yr * yr))};

  // E b_l, then R_delta E b_l; and E^T R_delta^T b_r.
  T essential_left[3];
  for (int i = 0; i < 3; ++i) {
    essential_left[i] = T(essential(i, 0)) * left[0] +
                        T(essential(i, 1)) * left[1] +
                        T(essential(i, 2)) * left[2];
  }
  T right_rotated[3] = {right[0], right[1], right[2]};
  if (rotation_correction != nullptr) {
    T rotated[3];
    ceres::AngleAxisRotatePoint(rotation_correction, essential_left, rotated);
    for (int i = 0; i < 3; ++i) essential_left[i] = rotated[i];
    const T inverse[3] = {-rotation_correction[0], -rotation_correction[1],
                          -rotation_correction[2]};
    ceres::AngleAxisRotatePoint(inverse, right, right_rotated);
  }
  T essential_t_right[3];
  for (int j = 0; j < 3; ++j) {
    essential_t_right[j] = T(essential(0, j)) * right_rotated[0] +
                           T(essential(1, j)) * right_rotated[1] +
                           T(essential(2, j)) * right_rotated[2];
  }
  const T e = right[0] * essential_left[0] + right[1] * essential_left[1] +
              right[2] * essential_left[2];

  // de/d(x, y) in each camera.
  const T left_scale = excess / left[2];
  const T right_scale = excess / right[2];
  const T de_dxl =
      essential_t_right[0] + essential_t_right[2] * left_scale * xl;
  const T de_dyl =
      essential_t_right[1] + essential_t_right[2] * left_scale * yl;
  const T de_dxr = essential_left[0] + essential_left[2] * right_scale * xr;
  const T de_dyr = essential_left[1] + essential_left[2] * right_scale * yr;

  // Chained to pixels: row vector times d(x, y)/d(u, v) (with a focal
  // scale, to first order in it).
  T jl[4];
  T jr[4];
  for (int k = 0; k < 4; ++k) {
    jl[k] = T(match.left_normalized_from_pixel[k]);
    jr[k] = T(match.right_normalized_from_pixel[k]);
    if (focal_scale != nullptr) {
      jl[k] += focal_scale[0] * match.left_normalized_from_pixel_focal[k];
      jr[k] += focal_scale[1] * match.right_normalized_from_pixel_focal[k];
    }
  }
  const T de_dul = de_dxl * jl[0] + de_dyl * jl[2];
  const T de_dvl = de_dxl * jl[1] + de_dyl * jl[3];
  const T de_dur = de_dxr * jr[0] + de_dyr * jr[2];
  const T de_dvr = de_dxr * jr[1] + de_dyr * jr[3];
  const T gradient_squared =
      de_dul * de_dul + de_dvl * de_dvl + de_dur * de_dur + de_dvr * de_dvr;
  if (!(ScalarPart(gradient_squared) > 0.0)) return false;
  *residual = e / sqrt(gradient_squared);
  return true;
}

template <typename T>
bool SampsonCoplanarityResidual(const Eigen::Matrix3d& essential,
                                const PreparedCorrespondence& match, const T& n,
                                const T* rotation_correction, T* residual) {
  return SampsonCoplanarityResidual<T>(essential, match, n, rotation_correction,
                                       nullptr, residual);
}

// Ceres cost functor of r(n), one per correspondence (after Ceres'
// examples/snavely_reprojection_error.h). Parameter blocks: n (size 1) and,
// for CreateWithRotation, the rotation correction (angle-axis, size 3), and
// for CreateWithRotationAndFocal also the focal scales (e_l, e_r). The batch
// refinement solves with the same residual's Jacobian written out, many
// matches per block (sampson_coplanarity_cost_function.h), which is tested
// against these.
class SampsonCoplanarityError {
 public:
  SampsonCoplanarityError(const Eigen::Matrix3d& essential,
                          const PreparedCorrespondence& match)
      : essential_(essential), match_(match) {}

  template <typename T>
  bool operator()(const T* n, T* residual) const {
    return SampsonCoplanarityResidual<T>(essential_, match_, n[0], nullptr,
                                         residual);
  }

  template <typename T>
  bool operator()(const T* n, const T* rotation_correction, T* residual) const {
    return SampsonCoplanarityResidual<T>(essential_, match_, n[0],
                                         rotation_correction, residual);
  }

  template <typename T>
  bool operator()(const T* n, const T* rotation_correction,
                  const T* focal_scale, T* residual) const {
    return SampsonCoplanarityResidual<T>(
        essential_, match_, n[0], rotation_correction, focal_scale, residual);
  }

  static ceres::CostFunction* Create(const Eigen::Matrix3d& essential,
                                     const PreparedCorrespondence& match) {
    return new ceres::AutoDiffCostFunction<SampsonCoplanarityError, 1, 1>(
        new SampsonCoplanarityError(essential, match));
  }

  static ceres::CostFunction* CreateWithRotation(
      const Eigen::Matrix3d& essential, const PreparedCorrespondence& match) {
    return new ceres::AutoDiffCostFunction<SampsonCoplanarityError, 1, 1, 3>(
        new SampsonCoplanarityError(essential, match));
  }

  static ceres::CostFunction* CreateWithRotationAndFocal(
      const Eigen::Matrix3d& essential, const PreparedCorrespondence& match) {
    return new ceres::AutoDiffCostFunction<SampsonCoplanarityError, 1, 1, 3, 2>(
        new SampsonCoplanarityError(essential, match));
  }

 private:
  const Eigen::Matrix3d essential_;
  const PreparedCorrespondence match_;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_SAMPSON_COPLANARITY_ERROR_H_
