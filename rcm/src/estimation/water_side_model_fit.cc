#include "rcm/estimation/water_side_model_fit.h"

#include <ceres/ceres.h>

#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "rcm/estimation/image_sample_grid.h"
#include "rcm/estimation/water_side_projection_error.h"

namespace rcm {
namespace {

// A sample of the grid: its raw pixel and the normalized point (x/z, y/z)
// of its ray in the medium.
struct RaySample {
  int index = 0;  // into the grid
  Eigen::Vector2d pixel;
  Eigen::Vector2d normalized;
};

// Rays this close to 90 degrees from the axis have no normalized point
// that a lens model could take (z ~ 0).
constexpr double kMinRayZ = 1e-6;

template <typename LensModel>
ceres::Solver::Summary Solve(const std::vector<RaySample>& samples,
                             const Eigen::Vector4d& fit_region,
                             int max_iterations, double* params) {
  ceres::Problem problem;
  for (const RaySample& sample : samples) {
    if (!InRegion(sample.pixel, fit_region)) continue;
    problem.AddResidualBlock(WaterSideProjectionError<LensModel>::Create(
                                 sample.normalized, sample.pixel),
                             nullptr, params);
  }
  if (problem.HasParameterBlock(params)) {
    for (const DistortionBound& bound :
         DistortionBounds(LensModel::kModelId)) {
      problem.SetParameterLowerBound(params, 4 + bound.index, bound.lower);
      problem.SetParameterUpperBound(params, 4 + bound.index, bound.upper);
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_iterations;
  // The exact case (n = 1) converges to zero residual; tight tolerances
  // let it reach the 1e-9 the tests ask for.
  solver_options.function_tolerance = 1e-15;
  solver_options.gradient_tolerance = 1e-15;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

}  // namespace

Status WaterSideModelFitOptions::Check() const {
  constexpr std::string_view kWhat = "water-side model fit";
  RCM_RETURN_IF_ERROR(CheckGridStep(kWhat, grid_step));
  RCM_RETURN_IF_ERROR(CheckInsetFraction(kWhat, "fit_inset", fit_inset));
  RCM_RETURN_IF_ERROR(CheckInsetFraction(kWhat, "report_inset", report_inset));
  if (max_iterations <= 0) {
    return Status::Error("water-side model fit: max_iterations " +
                         std::to_string(max_iterations) + " is not positive");
  }
  return Status::Ok();
}

StatusOr<WaterSideModelFit> FitWaterSideModel(
    const RefractiveCamera& camera, const WaterSideModelFitOptions& options) {
  if (Status status = options.Check(); !status.ok()) return status;
  const Camera& lens = camera.camera();

  ImageErrorField errors =
      CenteredSampleGrid(lens.width(), lens.height(), options.grid_step);
  const Eigen::Vector4d fit_region = InsetRegion(lens.width(), lens.height(), options.fit_inset);

  std::vector<RaySample> samples;
  samples.reserve(errors.errors.size());
  int64_t num_fitted = 0;
  for (int row = 0; row < errors.rows; ++row) {
    for (int col = 0; col < errors.cols; ++col) {
      const Eigen::Vector2d pixel = errors.Pixel(col, row);
      const std::optional<Eigen::Vector3d> ray =
          camera.BearingInWaterFromImage(pixel);
      if (!ray.has_value() || !((*ray)[2] > kMinRayZ)) continue;
      samples.push_back({row * errors.cols + col, pixel,
                         ray->head<2>() / (*ray)[2]});
      if (InRegion(pixel, fit_region)) ++num_fitted;
    }
  }

  std::array<double, kMaxLensParams> params{};
  params[0] = camera.VirtualFocalScale() * lens.fx();
  params[1] = camera.VirtualFocalScale() * lens.fy();
  params[2] = lens.cx();
  params[3] = lens.cy();
  // Zero distortion, the virtual pinhole; the EUCM's pinhole is alpha = 0
  // with any beta (beta = 0 is outside its range).
  if (options.model == LensModelId::kEucm) params[5] = 1.0;
  const int num_params = 4 + NumDistortionParams(options.model);
  if (num_fitted < 2 * num_params) {
    std::ostringstream message;
    message << "water-side model fit: " << num_fitted
            << " usable samples in the fit region, fewer than twice the "
            << num_params << " parameters";
    return Status::Error(message.str());
  }

  ceres::Solver::Summary summary;
  RCM_LENS_MODEL_SWITCH(options.model,
                        summary = Solve<LensModel>(samples, fit_region,
                                                   options.max_iterations,
                                                   params.data());
                        break;)
  StatusOr<Camera> fitted = Camera::Create(
      options.model, lens.width(), lens.height(),
      {params[0], params[1], params[2], params[3]},
      std::vector<double>(params.begin() + 4, params.begin() + num_params));
  if (!fitted.ok()) {
    return fitted.status().WithContext(
        "water-side model fit left the valid parameters");
  }
  WaterSideModelFit fit{std::move(fitted).value(),
                        {},
                        {},
                        InsetRegion(lens.width(), lens.height(), options.report_inset),
                        std::move(errors)};
  fit.num_iterations = static_cast<int>(summary.iterations.size());
  fit.converged = summary.termination_type == ceres::CONVERGENCE;

  std::vector<double> full_errors;
  std::vector<double> inset_errors;
  full_errors.reserve(samples.size());
  inset_errors.reserve(samples.size());
  for (const RaySample& sample : samples) {
    const Eigen::Vector2d error =
        fit.camera.ImageFromNormalized(sample.normalized) - sample.pixel;
    fit.errors.errors[sample.index] = error;
    full_errors.push_back(error.norm());
    if (InRegion(sample.pixel, fit.inset_region)) {
      inset_errors.push_back(error.norm());
    }
    if (!fit.camera.LensInvertibleAt(sample.normalized)) {
      ++fit.num_not_invertible;
    }
  }
  fit.full = ComputePixelErrorStats(std::move(full_errors));
  fit.inset = ComputePixelErrorStats(std::move(inset_errors));
  return fit;
}

}  // namespace rcm
