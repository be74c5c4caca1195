// Reprojection errors of planar-target corners seen under water through a
// flat port, the residuals of the underwater refinement
// (underwater_calibration.h). Written as Ceres'
// examples/snavely_reprojection_error.h: const members, a templated
// operator(), a static Create(). The air calibration's lens is a constant
// of the functor (it is never estimated here), so the Jets carry only the
// underwater unknowns.
//
// Parameter blocks (raw arrays):
//   n                 [n]                       refractive index of the water
//   cam0_from_target  [w0, w1, w2, t0, t1, t2]  rotation vector (rad) and
//                                               translation (m)
//   cam1_from_cam0    [w0, w1, w2, t0, t1, t2]  the same convention
//   air_gap           [d]                       the camera's port, meters
//   port_tilt         [a, b]                    the port normal
//                                               N = (a, b, 1) / |(a, b, 1)|,
//                                               i.e. a = N_x / N_z,
//                                               b = N_y / N_z
//   board_warp        [warp_x, warp_y]          the board's bow, meters
//                                               (board_warp.h)
//
// Residuals (pixels), for a corner X (target frame, z = 0; on the bowed
// board X = (X_x, X_y, warp . b), b the point's warp basis, a constant of
// the functor, board_reprojection_error.h) seen at u:
//   cam0:  e = pi(lens, port(n, d_0, N_0, R(w_v) X + t_v)) - u
//   cam1:  e = pi(lens, port(n, d_1, N_1,
//                            R(w_10) (R(w_v) X + t_v) + t_10)) - u
// with port(.) the normalized point in air of a point in the medium through
// the flat port (rcm/camera/flat_port_projection.h; the glass thickness and
// index are constants of the functor) and pi(lens, x) =
// LensModel::ImgFromCam. A point the port cannot image (behind the glass,
// past the critical angle) makes the residual undefined: operator()
// returns false and Ceres rejects the step.
#ifndef RCM_CALIB_UNDERWATER_REPROJECTION_ERROR_H_
#define RCM_CALIB_UNDERWATER_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "rcm/calib/board_reprojection_error.h"
#include "rcm/camera/flat_port_projection.h"
#include "rcm/camera/lens_models.h"

namespace rcm::calib {

// What the residual holds fixed: the air calibration's lens parameters
// (lens_models.h order) and the port's glass.
struct UnderwaterCameraConstants {
  std::array<double, kMaxLensParams> lens{};
  double glass_thickness = 0.0;  // meters
  double glass_index = 1.49;
};

namespace underwater_internal {

// pi(lens, port(n, d, N(tilt), P)) - pixel for a point P in the camera
// frame; false where the port cannot image P.
template <typename LensModel, typename T>
bool ProjectThroughPort(const UnderwaterCameraConstants& constants,
                        const T* lens, const T& n, const T& air_gap,
                        const T* port_tilt, const T point[3],
                        const Eigen::Vector2d& pixel, T* residuals) {
  using std::sqrt;
  const T norm =
      sqrt(port_tilt[0] * port_tilt[0] + port_tilt[1] * port_tilt[1] + T(1.0));
  const T normal[3] = {port_tilt[0] / norm, port_tilt[1] / norm, T(1.0) / norm};
  T normalized[2];
  if (!FlatPortProjection::NormalizedFromPoint(
          n, air_gap, T(constants.glass_thickness), T(constants.glass_index),
          normal, point, normalized)) {
    return false;
  }
  board_internal::NormalizedPointResidual<LensModel>(
      lens, normalized[0], normalized[1], pixel, residuals);
  return true;
}

// The same with the constants' lens.
template <typename LensModel, typename T>
bool ProjectThroughPort(const UnderwaterCameraConstants& constants, const T& n,
                        const T& air_gap, const T* port_tilt, const T point[3],
                        const Eigen::Vector2d& pixel, T* residuals) {
  T lens[LensModel::kNumParams];
  for (int i = 0; i < LensModel::kNumParams; ++i) {
    lens[i] = T(constants.lens[i]);
  }
  return ProjectThroughPort<LensModel>(constants, lens, n, air_gap, port_tilt,
                                       point, pixel, residuals);
}

}  // namespace underwater_internal

// A corner seen by cam0: blocks (n, cam0_from_target, air_gap, port_tilt,
// board_warp).
template <typename LensModel>
struct Cam0UnderwaterReprojectionError {
  Cam0UnderwaterReprojectionError(const UnderwaterCameraConstants& constants,
                                  const Eigen::Vector3d& point_in_target,
                                  const Eigen::Vector2d& warp_basis,
                                  const Eigen::Vector2d& pixel)
      : constants(constants),
        point_in_target(point_in_target),
        warp_basis(warp_basis),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_target, const T* air_gap,
                  const T* port_tilt, const T* board_warp, T* residuals) const {
    T point_in_cam0[3];
    board_internal::WarpedPointInCam0(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, point_in_cam0);
    return underwater_internal::ProjectThroughPort<LensModel>(
        constants, n[0], air_gap[0], port_tilt, point_in_cam0, pixel,
        residuals);
  }

  static ceres::CostFunction* Create(const UnderwaterCameraConstants& constants,
                                     const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam0UnderwaterReprojectionError, 2,
                                           1, 6, 1, 2, 2>(
        new Cam0UnderwaterReprojectionError(constants, point_in_target,
                                            warp_basis, pixel));
  }

  const UnderwaterCameraConstants constants;
  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

// A corner seen by cam1: blocks (n, cam0_from_target, cam1_from_cam0,
// air_gap, port_tilt, board_warp).
template <typename LensModel>
struct Cam1UnderwaterReprojectionError {
  Cam1UnderwaterReprojectionError(const UnderwaterCameraConstants& constants,
                                  const Eigen::Vector3d& point_in_target,
                                  const Eigen::Vector2d& warp_basis,
                                  const Eigen::Vector2d& pixel)
      : constants(constants),
        point_in_target(point_in_target),
        warp_basis(warp_basis),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_target,
                  const T* cam1_from_cam0, const T* air_gap, const T* port_tilt,
                  const T* board_warp, T* residuals) const {
    T point_in_cam1[3];
    board_internal::WarpedPointInCam1(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, cam1_from_cam0,
                                      point_in_cam1);
    return underwater_internal::ProjectThroughPort<LensModel>(
        constants, n[0], air_gap[0], port_tilt, point_in_cam1, pixel,
        residuals);
  }

  static ceres::CostFunction* Create(const UnderwaterCameraConstants& constants,
                                     const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam1UnderwaterReprojectionError, 2,
                                           1, 6, 6, 1, 2, 2>(
        new Cam1UnderwaterReprojectionError(constants, point_in_target,
                                            warp_basis, pixel));
  }

  const UnderwaterCameraConstants constants;
  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

// The joint calibration of air and water (underwater_calibration.h,
// AirTargetViews) estimates the lenses too: the same residuals with the
// lens as the first block, [fx, fy, cx, cy, d...] (lens_models.h order,
// LensModel::kNumParams); constants.lens is not used.

// A corner seen by cam0: blocks (lens, n, cam0_from_target, air_gap,
// port_tilt, board_warp).
template <typename LensModel>
struct Cam0UnderwaterLensReprojectionError {
  Cam0UnderwaterLensReprojectionError(
      const UnderwaterCameraConstants& constants,
      const Eigen::Vector3d& point_in_target, const Eigen::Vector2d& warp_basis,
      const Eigen::Vector2d& pixel)
      : constants(constants),
        point_in_target(point_in_target),
        warp_basis(warp_basis),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* n, const T* cam0_from_target,
                  const T* air_gap, const T* port_tilt, const T* board_warp,
                  T* residuals) const {
    T point_in_cam0[3];
    board_internal::WarpedPointInCam0(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, point_in_cam0);
    return underwater_internal::ProjectThroughPort<LensModel>(
        constants, lens, n[0], air_gap[0], port_tilt, point_in_cam0, pixel,
        residuals);
  }

  static ceres::CostFunction* Create(const UnderwaterCameraConstants& constants,
                                     const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam0UnderwaterLensReprojectionError,
                                           2, LensModel::kNumParams, 1, 6, 1, 2,
                                           2>(
        new Cam0UnderwaterLensReprojectionError(constants, point_in_target,
                                                warp_basis, pixel));
  }

  const UnderwaterCameraConstants constants;
  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

// A corner seen by cam1: blocks (lens, n, cam0_from_target, cam1_from_cam0,
// air_gap, port_tilt, board_warp).
template <typename LensModel>
struct Cam1UnderwaterLensReprojectionError {
  Cam1UnderwaterLensReprojectionError(
      const UnderwaterCameraConstants& constants,
      const Eigen::Vector3d& point_in_target, const Eigen::Vector2d& warp_basis,
      const Eigen::Vector2d& pixel)
      : constants(constants),
        point_in_target(point_in_target),
        warp_basis(warp_basis),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* n, const T* cam0_from_target,
                  const T* cam1_from_cam0, const T* air_gap, const T* port_tilt,
                  const T* board_warp, T* residuals) const {
    T point_in_cam1[3];
    board_internal::WarpedPointInCam1(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, cam1_from_cam0,
                                      point_in_cam1);
    return underwater_internal::ProjectThroughPort<LensModel>(
        constants, lens, n[0], air_gap[0], port_tilt, point_in_cam1, pixel,
        residuals);
  }

  static ceres::CostFunction* Create(const UnderwaterCameraConstants& constants,
                                     const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam1UnderwaterLensReprojectionError,
                                           2, LensModel::kNumParams, 1, 6, 6, 1,
                                           2, 2>(
        new Cam1UnderwaterLensReprojectionError(constants, point_in_target,
                                                warp_basis, pixel));
  }

  const UnderwaterCameraConstants constants;
  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

}  // namespace rcm::calib

#endif  // RCM_CALIB_UNDERWATER_REPROJECTION_ERROR_H_
