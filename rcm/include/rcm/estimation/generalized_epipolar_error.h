// The locus residual generalized to non-central cameras: a housing with an
// air gap and glass (flat_port.h, thick_port_refraction.h), where each
// pixel sees along its own ray in the medium that does not pass through
// the camera center, so the coplanarity of two bearings
// (sampson_coplanarity_error.h) no longer describes a correspondence.
//
// Two rays meet (or are parallel) exactly when their Pluecker coordinates
// satisfy the generalized epipolar constraint (Pless, CVPR 2003). With the
// left ray (o_l, d_l) in cam0 and the right ray (o_r, d_r) in cam1 brought
// into cam0 by cam1_from_cam0 = (R, t):
//
//   d_r' = R^T d_r,   o_r' = R^T (o_r - t),   m = o x d   (moment)
//   e(n) = d_l . m_r' + d_r' . m_l
//
// The Sampson normalization divides e by its gradient with respect to the
// four raw pixel coordinates p = (ul, vl, ur, vr):
//
//   r(n) = e(n) / |de/dp|,   de/dp = de/d(xl, yl, xr, yr) d(x, y)/dp
//
// with d(x, y)/dp the inverse lens Jacobians (prepared_correspondence.h).
// de/d(x, y) is taken by central differences of e in the scalar type T
// (step kNormalizedStep), so that a Jet carries the derivatives of the
// denominator in n and the air gap too; the difference is exact to
// O(h^2) ~ 1e-12 relative and rounding ~1e-10 relative, far below any
// pixel noise. As for the thin port, r is the first-order distance of the
// measured pixels from the locus of n, in pixels, and exactly 0 on exact
// correspondences.
//
// Parameters: n, gap_delta (meters) added to both cameras' air gaps, for
// the joint estimation of the air gap with n, and optionally the rotation
// correction w (angle-axis, radians) of cam1 about its center, the
// self-calibration of batch_refinement.h: cam1_from_cam0 becomes
// (exp([w]x) R, exp([w]x) t), so that in cam0
//
//   d_r' = R^T exp(-[w]x) d_r,   o_r' = R^T (exp(-[w]x) o_r - t).
#ifndef RCM_ESTIMATION_GENERALIZED_EPIPOLAR_ERROR_H_
#define RCM_ESTIMATION_GENERALIZED_EPIPOLAR_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/camera/thick_port_refraction.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/scalar.h"

namespace rcm {

// The two ports of a stereo rig and its extrinsics: what the generalized
// residual needs besides the correspondence. Normals are unit length.
struct ThickPortStereo {
  FlatPort left_port;
  FlatPort right_port;
  Rigid3d cam1_from_cam0;
};

// Central-difference step in normalized coordinates (1e-6 ~ 3e-4 px at a
// 350 px focal length).
inline constexpr double kNormalizedStep = 1e-6;

// e of the header for the normalized points (xl, yl) and (xr, yr), with
// the rotation correction `rotation` (3, angle-axis) or none (nullptr);
// false when a ray misses its port.
template <typename T>
bool GeneralizedEpipolarValue(const ThickPortStereo& stereo, const T& n,
                              const T& gap_delta, const T* rotation,
                              const T& xl, const T& yl, const T& xr,
                              const T& yr, T* e) {
  T origin_l[3];
  T direction_l[3];
  T origin_r[3];
  T direction_r[3];
  const FlatPort& left = stereo.left_port;
  const FlatPort& right = stereo.right_port;
  if (!ThickPortRefraction::RayInMedium(
          n, T(left.air_gap) + gap_delta, T(left.glass_thickness),
          T(left.glass_index), left.normal, xl, yl, origin_l, direction_l) ||
      !ThickPortRefraction::RayInMedium(
          n, T(right.air_gap) + gap_delta, T(right.glass_thickness),
          T(right.glass_index), right.normal, xr, yr, origin_r, direction_r)) {
    return false;
  }
  if (rotation != nullptr) {
    // exp(-[w]x) of the right ray: cam1 turned back by the correction.
    const T inverse[3] = {-rotation[0], -rotation[1], -rotation[2]};
    T turned[3];
    ceres::AngleAxisRotatePoint(inverse, direction_r, turned);
    for (int i = 0; i < 3; ++i) direction_r[i] = turned[i];
    ceres::AngleAxisRotatePoint(inverse, origin_r, turned);
    for (int i = 0; i < 3; ++i) origin_r[i] = turned[i];
  }
  // The right ray in cam0: R^T d_r and R^T (o_r - t).
  const Eigen::Matrix3d& r = stereo.cam1_from_cam0.rotation;
  const Eigen::Vector3d& t = stereo.cam1_from_cam0.translation;
  T d_r[3];
  T o_r[3];
  for (int i = 0; i < 3; ++i) {
    d_r[i] = T(r(0, i)) * direction_r[0] + T(r(1, i)) * direction_r[1] +
             T(r(2, i)) * direction_r[2];
    o_r[i] = T(r(0, i)) * (origin_r[0] - T(t[0])) +
             T(r(1, i)) * (origin_r[1] - T(t[1])) +
             T(r(2, i)) * (origin_r[2] - T(t[2]));
  }
  const auto cross = [](const T* a, const T* b, T* c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  };
  T moment_l[3];
  T moment_r[3];
  cross(origin_l, direction_l, moment_l);
  cross(o_r, d_r, moment_r);
  *e = direction_l[0] * moment_r[0] + direction_l[1] * moment_r[1] +
       direction_l[2] * moment_r[2] + d_r[0] * moment_l[0] +
       d_r[1] * moment_l[1] + d_r[2] * moment_l[2];
  return true;
}

// r(n) of the header, with the rotation correction `rotation` (3,
// angle-axis) or none (nullptr). False when a ray misses its port or the
// gradient vanishes.
template <typename T>
bool GeneralizedEpipolarResidual(const ThickPortStereo& stereo,
                                 const PreparedCorrespondence& match,
                                 const T& n, const T& gap_delta,
                                 const T* rotation, T* residual) {
  using std::sqrt;
  T x[4] = {T(match.left_normalized[0]), T(match.left_normalized[1]),
            T(match.right_normalized[0]), T(match.right_normalized[1])};
  T e;
  if (!GeneralizedEpipolarValue(stereo, n, gap_delta, rotation, x[0], x[1],
                                x[2], x[3], &e)) {
    return false;
  }
  // de/d(xl, yl, xr, yr) by central differences.
  T gradient[4];
  for (int k = 0; k < 4; ++k) {
    T plus[4] = {x[0], x[1], x[2], x[3]};
    T minus[4] = {x[0], x[1], x[2], x[3]};
    plus[k] += T(kNormalizedStep);
    minus[k] -= T(kNormalizedStep);
    T e_plus;
    T e_minus;
    if (!GeneralizedEpipolarValue(stereo, n, gap_delta, rotation, plus[0],
                                  plus[1], plus[2], plus[3], &e_plus) ||
        !GeneralizedEpipolarValue(stereo, n, gap_delta, rotation, minus[0],
                                  minus[1], minus[2], minus[3], &e_minus)) {
      return false;
    }
    gradient[k] = (e_plus - e_minus) / T(2.0 * kNormalizedStep);
  }
  // Chain through the inverse lens Jacobians (row-major 2x2 each).
  const double* jl = match.left_normalized_from_pixel;
  const double* jr = match.right_normalized_from_pixel;
  const T g[4] = {gradient[0] * T(jl[0]) + gradient[1] * T(jl[2]),
                  gradient[0] * T(jl[1]) + gradient[1] * T(jl[3]),
                  gradient[2] * T(jr[0]) + gradient[3] * T(jr[2]),
                  gradient[2] * T(jr[1]) + gradient[3] * T(jr[3])};
  const T norm_squared = g[0] * g[0] + g[1] * g[1] + g[2] * g[2] + g[3] * g[3];
  if (!(ScalarPart(norm_squared) > 0.0)) return false;
  *residual = e / sqrt(norm_squared);
  return true;
}

// Without a rotation correction.
template <typename T>
bool GeneralizedEpipolarResidual(const ThickPortStereo& stereo,
                                 const PreparedCorrespondence& match,
                                 const T& n, const T& gap_delta, T* residual) {
  return GeneralizedEpipolarResidual<T>(stereo, match, n, gap_delta, nullptr,
                                        residual);
}

// Ceres functor: parameter blocks n (1) and gap_delta (1) and, for
// CreateWithRotation, the rotation correction (angle-axis, 3).
class GeneralizedEpipolarError {
 public:
  GeneralizedEpipolarError(const ThickPortStereo& stereo,
                           const PreparedCorrespondence& match)
      : stereo_(stereo), match_(match) {}

  template <typename T>
  bool operator()(const T* n, const T* gap_delta, T* residual) const {
    return GeneralizedEpipolarResidual<T>(stereo_, match_, n[0], gap_delta[0],
                                          nullptr, residual);
  }

  template <typename T>
  bool operator()(const T* n, const T* gap_delta, const T* rotation,
                  T* residual) const {
    return GeneralizedEpipolarResidual<T>(stereo_, match_, n[0], gap_delta[0],
                                          rotation, residual);
  }

  static ceres::CostFunction* Create(const ThickPortStereo& stereo,
                                     const PreparedCorrespondence& match) {
    return new ceres::AutoDiffCostFunction<GeneralizedEpipolarError, 1, 1, 1>(
        new GeneralizedEpipolarError(stereo, match));
  }

  static ceres::CostFunction* CreateWithRotation(
      const ThickPortStereo& stereo, const PreparedCorrespondence& match) {
    return new ceres::AutoDiffCostFunction<GeneralizedEpipolarError, 1, 1, 1,
                                           3>(
        new GeneralizedEpipolarError(stereo, match));
  }

 private:
  const ThickPortStereo stereo_;
  const PreparedCorrespondence match_;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_GENERALIZED_EPIPOLAR_ERROR_H_
