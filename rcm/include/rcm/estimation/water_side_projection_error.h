// Cost functor of the water-side model fit (water_side_model_fit.h): the
// pixel at which a conventional lens model (lens_models.h), with free
// parameters, images a fixed ray in the medium, minus the pixel at which
// the refractive camera images it.
//
//   r = pi_M(theta; x, y) - p          (pixels)
//
// with (x, y) = (d_x / d_z, d_y / d_z) the normalized point of the ray d
// (d_z > 0), theta = [fx, fy, cx, cy, d...] the model's parameters and p
// the refractive camera's raw pixel of the ray.
#ifndef RCM_ESTIMATION_WATER_SIDE_PROJECTION_ERROR_H_
#define RCM_ESTIMATION_WATER_SIDE_PROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

namespace rcm {

template <typename LensModel>
struct WaterSideProjectionError {
  WaterSideProjectionError(const Eigen::Vector2d& normalized_in_water,
                           const Eigen::Vector2d& pixel)
      : x(normalized_in_water.x()),
        y(normalized_in_water.y()),
        u(pixel.x()),
        v(pixel.y()) {}

  template <typename T>
  bool operator()(const T* params, T* residual) const {
    T projected_u;
    T projected_v;
    LensModel::ImgFromCam(params, T(x), T(y), &projected_u, &projected_v);
    residual[0] = projected_u - T(u);
    residual[1] = projected_v - T(v);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& normalized_in_water,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<WaterSideProjectionError, 2,
                                           LensModel::kNumParams>(
        new WaterSideProjectionError(normalized_in_water, pixel));
  }

  const double x;
  const double y;
  const double u;
  const double v;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_WATER_SIDE_PROJECTION_ERROR_H_
