// Cost functor of the calibration comparison (calibration_comparison.h):
// the pixel at which an in-air calibrated camera behind a thin flat port
// (paper Sec. III-A) images a fixed ray in the medium, for a free
// refractive index n and a free shift s of its principal point, minus the
// pixel the ray was observed at.
//
//   (xb, yb) = n (X, Y) / sqrt(Z^2 - (n^2 - 1)(X^2 + Y^2))   (refraction,
//                                                    refractive_model.h)
//   r        = pi_A(fx, fy, cx + sx, cy + sy, d; xb, yb) - p   (pixels)
//
// with d = (X, Y, Z) the ray and pi_A the air lens model (lens_models.h).
// False behind the camera and past total internal reflection.
#ifndef RCM_ESTIMATION_REFRACTED_PROJECTION_ERROR_H_
#define RCM_ESTIMATION_REFRACTED_PROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <array>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_model.h"

namespace rcm {

template <typename LensModel>
struct RefractedProjectionError {
  RefractedProjectionError(const Camera& air_camera,
                           const Eigen::Vector3d& ray_in_water,
                           const Eigen::Vector2d& pixel)
      : ray(ray_in_water), observed(pixel) {
    for (int i = 0; i < LensModel::kNumParams; ++i) {
      air_params[i] = air_camera.params()[i];
    }
  }

  // n: 1 value; principal_point_shift: 2 values (sx, sy), pixels.
  template <typename T>
  bool operator()(const T* n, const T* principal_point_shift,
                  T* residual) const {
    const T point[3] = {T(ray[0]), T(ray[1]), T(ray[2])};
    T xb;
    T yb;
    if (!FlatPortRefraction::NormalizedFromPointInWater(n[0], point, &xb,
                                                        &yb)) {
      return false;
    }
    T params[LensModel::kNumParams];
    for (int i = 0; i < LensModel::kNumParams; ++i) params[i] = T(air_params[i]);
    params[2] += principal_point_shift[0];
    params[3] += principal_point_shift[1];
    T u;
    T v;
    LensModel::ImgFromCam(params, xb, yb, &u, &v);
    residual[0] = u - T(observed[0]);
    residual[1] = v - T(observed[1]);
    return true;
  }

  static ceres::CostFunction* Create(const Camera& air_camera,
                                     const Eigen::Vector3d& ray_in_water,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<RefractedProjectionError, 2, 1, 2>(
        new RefractedProjectionError(air_camera, ray_in_water, pixel));
  }

  std::array<double, LensModel::kNumParams> air_params{};
  const Eigen::Vector3d ray;
  const Eigen::Vector2d observed;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_REFRACTED_PROJECTION_ERROR_H_
