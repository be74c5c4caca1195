#include "rcm/estimation/refinement_options.h"

#include <ceres/normal_prior.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rcm {

std::string_view RobustLossName(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
  }
  return "none";
}

std::optional<RobustLoss> RobustLossFromName(std::string_view name) {
  for (const RobustLoss loss :
       {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    if (RobustLossName(loss) == name) return loss;
  }
  return std::nullopt;
}

double RobustLossRho(RobustLoss loss, double scale, double squared_residual) {
  const double c2 = scale * scale;
  switch (loss) {
    case RobustLoss::kNone:
      return squared_residual;
    case RobustLoss::kHuber:
      return squared_residual <= c2
                 ? squared_residual
                 : 2.0 * scale * std::sqrt(squared_residual) - c2;
    case RobustLoss::kCauchy:
      return c2 * std::log1p(squared_residual / c2);
  }
  return squared_residual;
}

void RobustLossRoot(RobustLoss loss, double scale, double residual,
                    double* root, double* slope) {
  switch (loss) {
    case RobustLoss::kNone:
      break;
    case RobustLoss::kHuber: {
      const double magnitude = std::abs(residual);
      if (magnitude <= scale) break;
      const double root_magnitude =
          std::sqrt(2.0 * scale * magnitude - scale * scale);
      *root = std::copysign(root_magnitude, residual);
      *slope = scale / root_magnitude;
      return;
    }
    case RobustLoss::kCauchy: {
      const double x = residual * residual / (scale * scale);
      // log(1 + x) / x = 1 - x / 2 + x^2 / 3 - ...: below 1e-10 the first
      // two terms are exact to rounding, and 0 / 0 is avoided.
      const double h = x < 1e-10 ? 1.0 - 0.5 * x : std::log1p(x) / x;
      const double root_h = std::sqrt(h);
      *root = residual * root_h;
      *slope = 1.0 / ((1.0 + x) * root_h);
      return;
    }
  }
  *root = residual;
  *slope = 1.0;
}

Status RefinementOptions::Check() const {
  std::ostringstream error;
  if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px)) {
    error << "loss scale must be a positive number of pixels, got "
          << loss_scale_px;
  } else if (!(inlier_threshold_px > 0.0)) {
    error << "inlier threshold must be positive (inf keeps every match), got "
          << inlier_threshold_px;
  } else if (num_scan_points < 3) {
    error << "the scan of [1, 2] needs at least 3 points, got "
          << num_scan_points;
  } else if (min_inliers < (refine_rotation ? 5 : 2)) {
    error << "at least " << (refine_rotation ? 5 : 2)
          << " inliers are needed to estimate "
          << (refine_rotation ? "n, the rotation" : "n")
          << " and the pixel noise, got min_inliers = " << min_inliers;
  } else if (!(max_crlb_per_px > 0.0)) {
    error << "max_crlb_per_px must be positive, got " << max_crlb_per_px;
  } else if (max_num_iterations < 1) {
    error << "max_num_iterations must be at least 1, got "
          << max_num_iterations;
  } else if (!(systematic_px >= 0.0) || !std::isfinite(systematic_px)) {
    error << "systematic_px must be >= 0 pixels, got " << systematic_px;
  } else if (n_prior &&
             (!(n_prior->n >= 1.0 && n_prior->n <= 2.0) ||
              !(n_prior->sigma > 0.0) || !std::isfinite(n_prior->sigma))) {
    error << "the prior on n needs n in [1, 2] and a positive sigma, got "
          << n_prior->n << " +- " << n_prior->sigma;
  } else if (rows_at_rotation && !rows_at_rotation->allFinite()) {
    error << "rows_at_rotation must be finite";
  } else if (num_threads < 1) {
    error << "num_threads must be at least 1, got " << num_threads;
  } else {
    return Status::Ok();
  }
  return Status::Error(error.str());
}

Status CheckNotPinnedAtUpperBound(double n, double sigma_n) {
  constexpr double kUpperBound = 2.0;
  constexpr double kPinnedTolerance = 1e-6;
  // Further from 2 than this, n itself is not at the bound.
  constexpr double kWideOfTheBound = 0.05;
  if (!(n >= kUpperBound - std::max(kPinnedTolerance, sigma_n))) {
    return Status::Ok();
  }
  std::ostringstream message;
  message.setf(std::ios::fixed);
  message.precision(4);
  if (n < kUpperBound - kWideOfTheBound) {
    // Not at the bound: a sigma that reaches it.
    message << "n = " << n << " +- " << sigma_n
            << " reaches the upper bound 2 within one sigma: these data "
               "cannot pin n, its uncertainty is mostly the calibration's (a "
               "turn of cam1, or a change of a lens's focal length, since the "
               "calibration that these data cannot tell from n); calibrate "
               "in the water (rcm calibrate --underwater) and estimate with "
               "that camchain";
    return Status::Error(message.str());
  }
  message << "n = " << n
          << " is at the upper bound of [1, 2], which no medium reaches: the "
             "rig has likely moved since its calibration (cam1 turned by a "
             "few tenths of a degree, or a lens's focal length changed) or "
             "the rig file is not this rig's; calibrate in the water (rcm "
             "calibrate --underwater) or estimate the rotation with n "
             "(--refine-rotation)";
  return Status::Error(message.str());
}

ceres::Solver::Options RefinementSolverOptions(
    const RefinementOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.function_tolerance = 1e-14;
  solver_options.gradient_tolerance = 1e-16;
  solver_options.parameter_tolerance = 1e-12;
  solver_options.logging_type = ceres::SILENT;
  // No projected line search after each step of a problem with bounds (n's
  // [1, 2]): Ceres runs one by default, an evaluation of the cost and its
  // gradient per step that accepts the whole step in practice (the steps
  // and the solution are the same without it, and a minimum on the bound is
  // bounded_index_solve.h's), a third of the solve's time.
  solver_options.max_num_line_search_step_size_iterations = 0;
  return solver_options;
}

ceres::LossFunction* NewLossFunction(RobustLoss loss, double scale_px) {
  switch (loss) {
    case RobustLoss::kNone:
      return nullptr;
    case RobustLoss::kHuber:
      return new ceres::HuberLoss(scale_px);
    case RobustLoss::kCauchy:
      return new ceres::CauchyLoss(scale_px);
  }
  return nullptr;
}

ceres::CostFunction* NewRotationPrior(const Eigen::Matrix3d& covariance,
                                      double sigma_px) {
  const Eigen::Matrix3d lower = covariance.llt().matrixL();
  const ceres::Matrix root_information =
      sigma_px *
      lower.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
  return new ceres::NormalPrior(root_information, ceres::Vector::Zero(3));
}

}  // namespace rcm
