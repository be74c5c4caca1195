// Reprojection error of a planar-target corner seen under water through a
// dome port, the residual of the dome calibration (dome_calibration.h).
// Written as Ceres' examples/snavely_reprojection_error.h: const members,
// a templated operator(), a static Create(). The air calibration's lens
// and the dome's glass are constants of the functor, so the Jets carry
// only the underwater unknowns.
//
// Parameter blocks (raw arrays):
//   n                 [n]                       refractive index of the water
//   cam0_from_target  [w0, w1, w2, t0, t1, t2]  rotation vector (rad) and
//                                               translation (m)
//   cam_from_cam0     [w0, w1, w2, t0, t1, t2]  this camera from cam0 (the
//                                               air calibration's, held;
//                                               zero for cam0 itself)
//   decentering       [Cx, Cy, Cz]              the dome's centre in this
//                                               camera's frame, meters
//   board_warp        [warp_x, warp_y]          the board's bow, meters
//                                               (board_warp.h)
//
// Residual (pixels), for a corner X (target frame; on the bowed board
// X = (X_x, X_y, warp . b), b the point's warp basis) seen at u:
//   e = pi(lens, dome(n, C, R_c (R_v X + t_v) + t_c)) - u
// with dome(.) the normalized point in air of a point in the medium
// through the dome (rcm/camera/dome_port_refraction.h) and
// pi(lens, x) = LensModel::ImgFromCam. A point the dome cannot image
// (inside the dome, behind the camera, totally reflected) makes the
// residual undefined: operator() returns false and Ceres rejects the step.
#ifndef RCM_CALIB_DOME_REPROJECTION_ERROR_H_
#define RCM_CALIB_DOME_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <array>

#include "rcm/calib/board_reprojection_error.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/dome_port_refraction.h"
#include "rcm/camera/lens_models.h"

namespace rcm::calib {

// The joint calibration of air and water through the dome
// (dome_calibration.h, air views) estimates the lens too: the same
// residual with the lens as the first block, [fx, fy, cx, cy, d...]
// (lens_models.h order, LensModel::kNumParams). The air views are traced
// through the same dome at n = 1 (a held block): the glass shell in air
// is a weak meniscus lens whose bending an air calibration made through
// the dome holds in its lens.
template <typename LensModel>
struct DomeLensReprojectionError {
  DomeLensReprojectionError(const DomePort& dome,
                            const Eigen::Vector3d& point_in_target,
                            const Eigen::Vector2d& warp_basis,
                            const Eigen::Vector2d& pixel)
      : dome(dome),
        point_in_target(point_in_target),
        warp_basis(warp_basis),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* lens, const T* n, const T* cam0_from_target,
                  const T* cam_from_cam0, const T* decentering,
                  const T* board_warp, T* residuals) const {
    T point_in_camera[3];
    board_internal::WarpedPointInCam1(point_in_target, warp_basis, board_warp,
                                      cam0_from_target, cam_from_cam0,
                                      point_in_camera);
    T normalized[2];
    if (!DomePortRefraction::NormalizedFromPoint(n[0], decentering, dome,
                                                 point_in_camera, normalized)) {
      return false;
    }
    board_internal::NormalizedPointResidual<LensModel>(
        lens, normalized[0], normalized[1], pixel, residuals);
    return true;
  }

  static ceres::CostFunction* Create(const DomePort& dome,
                                     const Eigen::Vector3d& point_in_target,
                                     const Eigen::Vector2d& warp_basis,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<
        DomeLensReprojectionError, 2, LensModel::kNumParams, 1, 6, 6, 3, 2>(
        new DomeLensReprojectionError(dome, point_in_target, warp_basis,
                                      pixel));
  }

  const DomePort dome;  // its decentering is not read (a parameter block)
  const Eigen::Vector3d point_in_target;
  const Eigen::Vector2d warp_basis;
  const Eigen::Vector2d pixel;
};

// The residual with the air calibration's lens held: the same as
// DomeLensReprojectionError's with the lens a constant.
template <typename LensModel>
struct DomeReprojectionError {
  DomeReprojectionError(const std::array<double, kMaxLensParams>& lens,
                        const DomePort& dome,
                        const Eigen::Vector3d& point_in_target,
                        const Eigen::Vector2d& warp_basis,
                        const Eigen::Vector2d& pixel)
      : lens(lens), with_lens(dome, point_in_target, warp_basis, pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_target, const T* cam_from_cam0,
                  const T* decentering, const T* board_warp,
                  T* residuals) const {
    T lens_params[LensModel::kNumParams];
    for (int i = 0; i < LensModel::kNumParams; ++i) {
      lens_params[i] = T(lens[i]);
    }
    return with_lens(lens_params, n, cam0_from_target, cam_from_cam0,
                     decentering, board_warp, residuals);
  }

  static ceres::CostFunction* Create(
      const std::array<double, kMaxLensParams>& lens, const DomePort& dome,
      const Eigen::Vector3d& point_in_target, const Eigen::Vector2d& warp_basis,
      const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<DomeReprojectionError, 2, 1, 6, 6, 3,
                                           2>(new DomeReprojectionError(
        lens, dome, point_in_target, warp_basis, pixel));
  }

  const std::array<double, kMaxLensParams> lens;
  const DomeLensReprojectionError<LensModel> with_lens;
};

}  // namespace rcm::calib

#endif  // RCM_CALIB_DOME_REPROJECTION_ERROR_H_
