// Reprojection errors of planar-target corners, the residuals of the
// stereo bundle adjustment (stereo_calibration.h). Written as Ceres'
// examples/snavely_reprojection_error.h: const measurement members, a
// templated operator(), a static Create().
//
// Parameter blocks (raw arrays):
//   lens            [fx, fy, cx, cy, d0, d1, d2, d3]   (lens_models.h order,
//                                                      LensModel::kNumParams)
//   cam0_from_target [w0, w1, w2, t0, t1, t2]          rotation vector
//                                                      (angle-axis, rad) and
//                                                      translation (m)
//   cam1_from_cam0   [w0, w1, w2, t0, t1, t2]          the same convention
//
// Residuals (pixels), for a corner X (target frame, z = 0) seen at u:
//   cam0:  e = pi(lens, R(w_v) X + t_v) - u
//   cam1:  e = pi(lens, R(w_10) (R(w_v) X + t_v) + t_10) - u
// with pi(lens, P) = LensModel::ImgFromCam(lens, P_x / P_z, P_y / P_z).
// A point at or behind the camera plane (P_z <= 1e-9 m) makes the residual
// undefined: operator() returns false and Ceres rejects the step.
//
// The bowed-board variants (Cam0/Cam1WarpedBoardReprojectionError) take one
// more block, the board's warp (board_warp.h),
//   board_warp       [warp_x, warp_y]                  meters
// and replace X by the point on the bowed board,
//   X(warp) = (X_x, X_y, warp_x b_x + warp_y b_y),
// b = (4 xr (1 - xr), 4 yr (1 - yr)) the point's warp basis (a constant
// of the functor, BoardWarpBasis).
#ifndef RCM_CALIB_BOARD_REPROJECTION_ERROR_H_
#define RCM_CALIB_BOARD_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

namespace rcm::calib {

// Depth [m] below which a point counts as behind the camera.
inline constexpr double kMinBoardPointDepth = 1e-9;

namespace board_internal {

// LensModel::ImgFromCam(lens, x, y) - pixel for a normalized point.
template <typename LensModel, typename T>
void NormalizedPointResidual(const T* lens, const T& x, const T& y,
                             const Eigen::Vector2d& pixel, T* residuals) {
  T u;
  T v;
  LensModel::ImgFromCam(lens, x, y, &u, &v);
  residuals[0] = u - T(pixel.x());
  residuals[1] = v - T(pixel.y());
}

// pi(lens, P) for a point in the camera frame; false behind the camera.
template <typename LensModel, typename T>
bool ProjectCameraPoint(const T* lens, const T point[3], T* residuals,
                        const Eigen::Vector2d& pixel) {
  if (!(point[2] > T(kMinBoardPointDepth))) return false;
  NormalizedPointResidual<LensModel>(lens, point[0] / point[2],
                                     point[1] / point[2], pixel, residuals);
  return true;
}

// R(w) X + t for a pose block [w, t].
template <typename T>
void TransformPoint(const T* pose, const T point[3], T out[3]) {
  ceres::AngleAxisRotatePoint(pose, point, out);
  out[0] += pose[3];
  out[1] += pose[4];
  out[2] += pose[5];
}

// X(warp) = (X_x, X_y, X_z + warp . basis).
template <typename T>
void WarpedPoint(const Eigen::Vector3d& point, const Eigen::Vector2d& basis,
                 const T* warp, T out[3]) {
  out[0] = T(point.x());
  out[1] = T(point.y());
  out[2] = T(point.z()) + warp[0] * basis.x() + warp[1] * basis.y();
}

// The bowed board's point in cam0: R_v X(warp) + t_v.
template <typename T>
void WarpedPointInCam0(const Eigen::Vector3d& point,
                       const Eigen::Vector2d& basis, const T* warp,
                       const T* cam0_from_target, T out[3]) {
  T warped[3];
  WarpedPoint(point, basis, warp, warped);
  TransformPoint(cam0_from_target, warped, out);
}

// ... and in cam1: R_10 (R_v X(warp) + t_v) + t_10.
template <typename T>
void WarpedPointInCam1(const Eigen::Vector3d& point,
                       const Eigen::Vector2d& basis, const T* warp,
                       const T* cam0_from_target, const T* cam1_from_cam0,
                       T out[3]) {
  T in_cam0[3];
  WarpedPointInCam0(point, basis, warp, cam0_from_target, in_cam0);
  TransformPoint(cam1_from_cam0, in_cam0, out);
}

}  // namespace board_internal

// A corner seen by cam0: blocks (lens, cam0_from_target).
template <typename LensModel>
struct Cam0BoardReprojectionError {
  Cam0BoardReprojectionError(const Eigen::Vector3d& point_in_target,
                             const Eigen::Vector2d& pixel)
      : point_in_target(point_in_target), pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* cam0_from_target,
                  T* residuals) const {
    const T point[3] = {T(point_in_target.x()), T(point_in_target.y()),
                        T(point_in_target.z())};
    T point_in_cam0[3];
    board_internal::TransformPoint(cam0_from_target, point, point_in_cam0);
    return board_internal::ProjectCameraPoint<LensModel>(lens, point_in_cam0,
                                                         residuals, pixel);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam0BoardReprojectionError, 2,
                                           LensModel::kNumParams, 6>(
        new Cam0BoardReprojectionError(point_in_target, pixel));
  }

  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d pixel;
};

// A corner seen by cam1: blocks (lens, cam0_from_target, cam1_from_cam0).
template <typename LensModel>
struct Cam1BoardReprojectionError {
  Cam1BoardReprojectionError(const Eigen::Vector3d& point_in_target,
                             const Eigen::Vector2d& pixel)
      : point_in_target(point_in_target), pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* cam0_from_target,
                  const T* cam1_from_cam0, T* residuals) const {
    const T point[3] = {T(point_in_target.x()), T(point_in_target.y()),
                        T(point_in_target.z())};
    T point_in_cam0[3];
    board_internal::TransformPoint(cam0_from_target, point, point_in_cam0);
    T point_in_cam1[3];
    board_internal::TransformPoint(cam1_from_cam0, point_in_cam0,
                                   point_in_cam1);
    return board_internal::ProjectCameraPoint<LensModel>(lens, point_in_cam1,
                                                         residuals, pixel);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam1BoardReprojectionError, 2,
                                           LensModel::kNumParams, 6, 6>(
        new Cam1BoardReprojectionError(point_in_target, pixel));
  }

  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d pixel;
};

// A corner of the bowed board seen by cam0: blocks (lens, cam0_from_target,
// board_warp).
template <typename LensModel>
struct Cam0WarpedBoardReprojectionError {
  Cam0WarpedBoardReprojectionError(const Eigen::Vector3d& point_in_target,
                                   const Eigen::Vector2d& warp_basis,
                                   const Eigen::Vector2d& pixel)
      : point_in_target(point_in_target), warp_basis(warp_basis), pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* cam0_from_target,
                  const T* board_warp, T* residuals) const {
    T point_in_cam0[3];
    board_internal::WarpedPointInCam0(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, point_in_cam0);
    return board_internal::ProjectCameraPoint<LensModel>(lens, point_in_cam0,
                                                         residuals, pixel);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam0WarpedBoardReprojectionError, 2,
                                           LensModel::kNumParams, 6, 2>(
        new Cam0WarpedBoardReprojectionError(point_in_target, warp_basis,
                                             pixel));
  }

  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

// A corner of the bowed board seen by cam1: blocks (lens, cam0_from_target,
// cam1_from_cam0, board_warp).
template <typename LensModel>
struct Cam1WarpedBoardReprojectionError {
  Cam1WarpedBoardReprojectionError(const Eigen::Vector3d& point_in_target,
                                   const Eigen::Vector2d& warp_basis,
                                   const Eigen::Vector2d& pixel)
      : point_in_target(point_in_target), warp_basis(warp_basis), pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* cam0_from_target,
                  const T* cam1_from_cam0, const T* board_warp,
                  T* residuals) const {
    T point_in_cam1[3];
    board_internal::WarpedPointInCam1(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, cam1_from_cam0,
                                      point_in_cam1);
    return board_internal::ProjectCameraPoint<LensModel>(lens, point_in_cam1,
                                                         residuals, pixel);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam1WarpedBoardReprojectionError, 2,
                                           LensModel::kNumParams, 6, 6, 2>(
        new Cam1WarpedBoardReprojectionError(point_in_target, warp_basis,
                                             pixel));
  }

  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

}  // namespace rcm::calib

#endif  // RCM_CALIB_BOARD_REPROJECTION_ERROR_H_
