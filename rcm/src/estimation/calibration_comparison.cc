#include "rcm/estimation/calibration_comparison.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/image_sample_grid.h"
#include "rcm/estimation/refracted_projection_error.h"

namespace rcm {
namespace {

// Fewest usable samples for a fit of at most 3 parameters.
constexpr int64_t kMinSamples = 10;

// The start of n: the minimum over a scan of [1, 2] of the mean squared
// reprojection error with s = 0, each sample's error capped (a sample
// past total internal reflection at some n counts as the cap), so that
// the scan is not led by the few samples far off.
double ScanIndex(const Camera& air_camera,
                 const std::vector<PixelRay>& samples) {
  constexpr double kCapPx = 50.0;
  constexpr int kSteps = 200;  // 0.005 in n
  double best_n = 1.0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= kSteps; ++k) {
    const double n =
        RefractiveCamera::kMinIndex +
        (RefractiveCamera::kMaxIndex - RefractiveCamera::kMinIndex) * k / kSteps;
    const RefractiveCamera camera = RefractiveCamera::Create(air_camera, n).value();
    double cost = 0.0;
    for (const PixelRay& sample : samples) {
      const std::optional<Eigen::Vector2d> pixel =
          camera.ImageFromPointInWater(sample.ray_in_water);
      const double error =
          pixel.has_value() ? std::min((*pixel - sample.pixel).norm(), kCapPx)
                            : kCapPx;
      cost += error * error;
    }
    if (cost < best_cost) {
      best_cost = cost;
      best_n = n;
    }
  }
  return best_n;
}

// True when the ray is imaged by the air camera at index n: refracted
// below the critical angle, onto the invertible part of the lens.
bool UsableAt(const Camera& air_camera, double n, const Eigen::Vector3d& ray) {
  double xb;
  double yb;
  if (!FlatPortRefraction::NormalizedFromPointInWater(n, ray.data(), &xb,
                                                      &yb)) {
    return false;
  }
  return air_camera.LensInvertibleAt(Eigen::Vector2d(xb, yb));
}

Status CheckSamples(const std::vector<PixelRay>& samples) {
  for (size_t i = 0; i < samples.size(); ++i) {
    const PixelRay& sample = samples[i];
    if (!sample.pixel.allFinite() || !sample.ray_in_water.allFinite() ||
        !(sample.ray_in_water.z() > 0.0)) {
      std::ostringstream message;
      message << "sample " << i
              << ": pixel and ray must be finite with the ray in front of "
                 "the camera (z > 0)";
      return Status::Error(message.str());
    }
  }
  return Status::Ok();
}

}  // namespace

Status CalibrationComparisonOptions::Check() const {
  constexpr std::string_view kWhat = "calibration comparison";
  RCM_RETURN_IF_ERROR(CheckGridStep(kWhat, grid_step));
  RCM_RETURN_IF_ERROR(CheckInsetFraction(kWhat, "inset", inset));
  if (max_iterations <= 0) {
    return Status::Error("calibration comparison: max_iterations " +
                         std::to_string(max_iterations) + " is not positive");
  }
  return Status::Ok();
}

StatusOr<IndexFromRays> EstimateIndexFromRays(
    const Camera& air_camera, const std::vector<PixelRay>& samples,
    const CalibrationComparisonOptions& options) {
  if (Status status = options.Check(); !status.ok()) return status;
  if (Status status = CheckSamples(samples); !status.ok()) return status;

  IndexFromRays result;
  double n = ScanIndex(air_camera, samples);
  for (size_t i = 0; i < samples.size(); ++i) {
    if (UsableAt(air_camera, n, samples[i].ray_in_water)) {
      result.used.push_back(static_cast<int64_t>(i));
    }
  }
  const int64_t num_used = static_cast<int64_t>(result.used.size());
  if (num_used < kMinSamples) {
    std::ostringstream message;
    message << "only " << num_used << " of " << samples.size()
            << " samples are imaged by the air camera behind a flat port "
               "(at least "
            << kMinSamples << " needed)";
    return Status::Error(message.str());
  }

  double shift[2] = {0.0, 0.0};
  ceres::Problem problem;
  for (const int64_t i : result.used) {
    ceres::CostFunction* cost = nullptr;
    RCM_LENS_MODEL_SWITCH(
        air_camera.model(),
        cost = RefractedProjectionError<LensModel>::Create(
            air_camera, samples[i].ray_in_water, samples[i].pixel);
        break;)
    problem.AddResidualBlock(cost, nullptr, &n, shift);
  }
  problem.SetParameterLowerBound(&n, 0, RefractiveCamera::kMinIndex);
  problem.SetParameterUpperBound(&n, 0, RefractiveCamera::kMaxIndex);
  if (!options.estimate_principal_point_shift) {
    problem.SetParameterBlockConstant(shift);
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  // Tight: the exact case is asked to 1e-9 in n.
  solver_options.function_tolerance = 1e-15;
  solver_options.gradient_tolerance = 1e-15;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    return Status::Error("the refractive index fit failed: " +
                         summary.message);
  }
  result.n = n;
  result.principal_point_shift = Eigen::Vector2d(shift[0], shift[1]);
  result.num_iterations = static_cast<int>(summary.iterations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;

  // Residuals at the solution.
  double sum_squares = 0.0;
  result.residuals.reserve(result.used.size());
  ceres::Problem::EvaluateOptions evaluate_options;
  std::vector<double> residuals;
  problem.Evaluate(evaluate_options, nullptr, &residuals, nullptr, nullptr);
  for (size_t k = 0; k + 1 < residuals.size(); k += 2) {
    result.residuals.emplace_back(residuals[k], residuals[k + 1]);
    sum_squares += residuals[k] * residuals[k] + residuals[k + 1] * residuals[k + 1];
  }
  const int num_params = options.estimate_principal_point_shift ? 3 : 1;
  result.sigma_px =
      std::sqrt(sum_squares / static_cast<double>(2 * num_used - num_params));

  // cov = s^2 (J^T J)^-1 (Ceres' covariance is (J^T J)^-1).
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  // Fails (null_space_rank 0) when the reciprocal condition number of
  // J^T J is below the floor: n unobservable (e.g. every sample on the
  // optical axis) makes J^T J singular.
  covariance_options.min_reciprocal_condition_number = 1e-14;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {{&n, &n}};
  if (options.estimate_principal_point_shift) {
    blocks.push_back({shift, shift});
    blocks.push_back({&n, shift});
  }
  double var_n = 0.0;
  // An all-zero J^T J (every sample on the axis) has no condition number
  // to test (0 / 0), and Ceres returns 0: a variance that is not positive
  // and finite is the same failure.
  if (!covariance.Compute(blocks, &problem) ||
      !covariance.GetCovarianceBlock(&n, &n, &var_n) || !(var_n > 0.0) ||
      !std::isfinite(var_n)) {
    return Status::Error(
        "the samples do not determine the refractive index (singular "
        "covariance): spread them over the image, away from its center");
  }
  const double variance_scale = result.sigma_px * result.sigma_px;
  result.sigma_n = std::sqrt(var_n * variance_scale);
  if (options.estimate_principal_point_shift) {
    double cov_shift[4];
    double cov_n_shift[2];
    covariance.GetCovarianceBlock(shift, shift, cov_shift);
    covariance.GetCovarianceBlock(&n, shift, cov_n_shift);
    result.sigma_principal_point_shift =
        Eigen::Vector2d(std::sqrt(cov_shift[0] * variance_scale),
                        std::sqrt(cov_shift[3] * variance_scale));
    for (int k = 0; k < 2; ++k) {
      const double denominator = std::sqrt(var_n * cov_shift[3 * k]);
      result.correlation_n_shift[k] =
          denominator > 0.0 ? cov_n_shift[k] / denominator : 0.0;
    }
  }
  return result;
}

StatusOr<CalibrationComparison> CompareCalibrations(
    const Camera& air_camera, const Camera& water_camera,
    const CalibrationComparisonOptions& options) {
  if (Status status = options.Check(); !status.ok()) return status;
  if (air_camera.width() != water_camera.width() ||
      air_camera.height() != water_camera.height()) {
    std::ostringstream message;
    message << "the air calibration is for " << air_camera.width() << " x "
            << air_camera.height() << " images and the underwater one for "
            << water_camera.width() << " x " << water_camera.height()
            << ": not the same camera";
    return Status::Error(message.str());
  }

  ImageErrorField field = CenteredSampleGrid(
      water_camera.width(), water_camera.height(), options.grid_step);
  const Eigen::Vector4d region =
      InsetRegion(water_camera.width(), water_camera.height(), options.inset);
  std::vector<PixelRay> samples;
  std::vector<int> grid_index;
  int64_t num_in_region = 0;
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      const Eigen::Vector2d pixel = field.Pixel(col, row);
      if (!InRegion(pixel, region)) continue;
      ++num_in_region;
      const std::optional<Eigen::Vector2d> normalized =
          water_camera.NormalizedFromImage(pixel);
      if (!normalized.has_value() || !normalized->allFinite()) continue;
      samples.push_back({pixel, normalized->homogeneous()});
      grid_index.push_back(row * field.cols + col);
    }
  }

  StatusOr<IndexFromRays> fit =
      EstimateIndexFromRays(air_camera, samples, options);
  if (!fit.ok()) return fit.status();

  CalibrationComparison comparison;
  std::vector<double> lengths;
  lengths.reserve(fit->used.size());
  for (size_t k = 0; k < fit->used.size(); ++k) {
    const Eigen::Vector2d& residual = fit->residuals[k];
    field.errors[grid_index[fit->used[k]]] = residual;
    lengths.push_back(residual.norm());
  }
  comparison.residual_stats = ComputePixelErrorStats(std::move(lengths));
  comparison.num_unusable =
      num_in_region - static_cast<int64_t>(fit->used.size());
  comparison.residual_field = std::move(field);
  comparison.region = region;
  comparison.fit = std::move(fit).value();
  return comparison;
}

}  // namespace rcm
