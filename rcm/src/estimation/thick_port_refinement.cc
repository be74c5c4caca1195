#include "rcm/estimation/thick_port_refinement.h"

#include <ceres/ceres.h>

#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "rcm/estimation/bounded_index_solve.h"
#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/generalized_epipolar_error.h"
#include "rcm/estimation/prepared_correspondence.h"

namespace rcm {
namespace {

struct Parameters {
  double n = 1.0;
  double gap_delta = 0.0;
  double rotation[3] = {0.0, 0.0, 0.0};  // cam1's correction, angle-axis
};

// sum_i rho(r_i^2) at (n, 0), unusable matches at the loss' value of a
// large residual, for the seed scan.
double RobustCost(const ThickPortStereo& stereo,
                  const std::vector<PreparedCorrespondence>& matches, double n,
                  const RefinementOptions& options) {
  std::unique_ptr<ceres::LossFunction> loss(
      NewLossFunction(options.loss, options.loss_scale_px));
  constexpr double kUnusablePx = 1e3;
  double cost = 0.0;
  for (const PreparedCorrespondence& match : matches) {
    double r = kUnusablePx;
    if (!GeneralizedEpipolarResidual(stereo, match, n, 0.0, &r) ||
        !std::isfinite(r)) {
      r = kUnusablePx;
    }
    double rho[3] = {r * r, 1.0, 0.0};
    if (loss != nullptr) loss->Evaluate(r * r, rho);
    cost += rho[0];
  }
  return cost;
}

// One Ceres problem over `indices` of `matches`; with `rotation_prior`
// (NewRotationPrior) cam1's rotation correction is estimated under it.
ceres::Solver::Summary Solve(const ThickPortStereo& stereo,
                             const std::vector<PreparedCorrespondence>& matches,
                             const std::vector<int64_t>& indices,
                             RobustLoss loss,
                             const ThickPortRefinementOptions& options,
                             ceres::CostFunction* rotation_prior,
                             Parameters* parameters, ceres::Problem* problem) {
  ceres::LossFunction* loss_function =
      NewLossFunction(loss, options.base.loss_scale_px);
  if (rotation_prior != nullptr) {
    problem->AddResidualBlock(rotation_prior, nullptr, parameters->rotation);
  }
  for (const int64_t i : indices) {
    if (rotation_prior != nullptr) {
      problem->AddResidualBlock(
          GeneralizedEpipolarError::CreateWithRotation(stereo, matches[i]),
          loss_function, &parameters->n, &parameters->gap_delta,
          parameters->rotation);
    } else {
      problem->AddResidualBlock(
          GeneralizedEpipolarError::Create(stereo, matches[i]), loss_function,
          &parameters->n, &parameters->gap_delta);
    }
  }
  problem->SetParameterLowerBound(&parameters->n, 0, 1.0);
  problem->SetParameterUpperBound(&parameters->n, 0, 2.0);
  if (!options.estimate_air_gap) {
    problem->SetParameterBlockConstant(&parameters->gap_delta);
  } else {
    // A gap cannot be negative.
    const double smallest_gap =
        std::min(stereo.left_port.air_gap, stereo.right_port.air_gap);
    problem->SetParameterLowerBound(&parameters->gap_delta, 0, -smallest_gap);
  }
  const ceres::Solver::Options solver_options =
      RefinementSolverOptions(options.base);
  return SolveWithBoundedIndex(solver_options, problem, &parameters->n, 1.0,
                               2.0);
}

}  // namespace

Status ThickPortRefinementOptions::Check() const {
  RCM_RETURN_IF_ERROR(base.Check());
  if (base.refine_rotation) {
    return Status::Error(
        "the rotation correction is not available with a thick port");
  }
  return Status::Ok();
}

StatusOr<ThickPortRefinementSummary> RefineRefractiveIndexThickPort(
    const StereoRig& rig, const FlatPort& left_port, const FlatPort& right_port,
    const std::vector<StereoCorrespondence>& correspondences,
    const ThickPortRefinementOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  RCM_RETURN_IF_ERROR(left_port.Check().WithContext("left camera"));
  RCM_RETURN_IF_ERROR(right_port.Check().WithContext("right camera"));
  ThickPortStereo stereo{left_port, right_port, rig.right_from_left()};
  stereo.left_port.normal.normalize();
  stereo.right_port.normal.normalize();

  ThickPortRefinementSummary result;
  RefinementSummary& summary = result.refinement;
  summary.num_correspondences = static_cast<int64_t>(correspondences.size());
  const PreparedCorrespondences prepared =
      PrepareCorrespondences(rig, correspondences);
  const std::vector<PreparedCorrespondence>& matches = prepared.prepared;
  summary.num_invalid =
      summary.num_correspondences - static_cast<int64_t>(matches.size());
  const int min_inliers = options.base.min_inliers;
  if (static_cast<int>(matches.size()) < min_inliers) {
    std::ostringstream message;
    message << "too few correspondences: " << matches.size() << " usable of "
            << correspondences.size() << ", at least " << min_inliers
            << " needed";
    return Status::Error(message.str());
  }

  // How cam1's rotation is treated (batch_refinement.h): estimated with
  // the calibration's rotation covariance as prior (self-calibration)
  // when there is one, as for the thin port, unless the air gap is
  // estimated too; otherwise held, its uncertainty propagated.
  const CalibrationUncertainty uncertainty =
      rig.calibration_uncertainty().value_or(CalibrationUncertainty());
  const RotationMode mode =
      options.base.self_calibrate_rotation && !options.estimate_air_gap &&
              !uncertainty.RotationCovariance().isZero(0.0)
          ? RotationMode::kPrior
          : RotationMode::kHeld;
  const bool with_rotation = mode == RotationMode::kPrior;
  // The prior in pixels of residual for the pixel noise sigma_px.
  const auto rotation_prior = [&](double sigma_px) -> ceres::CostFunction* {
    return with_rotation
               ? NewRotationPrior(uncertainty.RotationPriorCovariance(),
                                  std::max(sigma_px, 1e-6))
               : nullptr;
  };
  const auto residual = [&](const Parameters& at, size_t i, double* r) {
    return GeneralizedEpipolarResidual(stereo, matches[i], at.n, at.gap_delta,
                                       with_rotation ? at.rotation : nullptr,
                                       r);
  };

  // Seed: the robust cost's minimum over a scan of [1, 2].
  Parameters parameters;
  double best_cost = std::numeric_limits<double>::infinity();
  const int points = options.base.num_scan_points;
  for (int k = 0; k < points; ++k) {
    const double n = 1.0 + static_cast<double>(k) / (points - 1);
    const double cost = RobustCost(stereo, matches, n, options.base);
    if (cost < best_cost) {
      best_cost = cost;
      parameters.n = n;
    }
  }
  summary.n_seed = parameters.n;

  // Stage 1: robust, all matches. The prior's weight needs the pixel
  // noise, unknown before stage 2: half the loss scale, which the options
  // call about twice the noise.
  std::vector<int64_t> all(matches.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int64_t>(i);
  {
    ceres::Problem problem;
    const ceres::Solver::Summary stage1 =
        Solve(stereo, matches, all, options.base.loss, options,
              rotation_prior(0.5 * options.base.loss_scale_px), &parameters,
              &problem);
    if (!stage1.IsSolutionUsable()) {
      return Status::Error("the robust refinement failed: " + stage1.message);
    }
    summary.robust_cost = stage1.final_cost;
    summary.num_iterations += static_cast<int>(stage1.iterations.size());
  }
  summary.n_robust = parameters.n;

  // Inliers at the robust estimate.
  std::vector<int64_t> inliers;
  for (size_t i = 0; i < matches.size(); ++i) {
    double r = 0.0;
    if (residual(parameters, i, &r) &&
        std::abs(r) <= options.base.inlier_threshold_px) {
      inliers.push_back(static_cast<int64_t>(i));
    }
  }
  if (static_cast<int>(inliers.size()) < min_inliers) {
    std::ostringstream message;
    message << "too few inliers: " << inliers.size() << " of " << matches.size()
            << " within " << options.base.inlier_threshold_px
            << " px of the thick-port loci, at least " << min_inliers
            << " needed";
    return Status::Error(message.str());
  }

  // Stage 2: least squares on the inliers, and its covariance. With the
  // rotation's prior, its weight sigma_px^2 comes from the inliers'
  // residuals, refined until it settles (two or three solves).
  const int num_parameters =
      1 + (options.estimate_air_gap ? 1 : 0) + (with_rotation ? 3 : 0);
  const int64_t dof = static_cast<int64_t>(inliers.size()) - num_parameters;
  const auto data_sigma_px = [&](const Parameters& at) {
    double sum = 0.0;
    for (const int64_t i : inliers) {
      double r = 0.0;
      if (residual(at, static_cast<size_t>(i), &r) && std::isfinite(r)) {
        sum += r * r;
      }
    }
    return std::sqrt(sum / static_cast<double>(dof));
  };
  std::unique_ptr<ceres::Problem> problem;
  RCM_RETURN_IF_ERROR(SolveUntilThePriorWeightSettles(
      with_rotation,
      [&](double prior_sigma_px) {
        problem = std::make_unique<ceres::Problem>();
        const ceres::Solver::Summary stage2 =
            Solve(stereo, matches, inliers, RobustLoss::kNone, options,
                  rotation_prior(prior_sigma_px), &parameters, problem.get());
        if (!stage2.IsSolutionUsable()) {
          return Status::Error("the least-squares refinement failed: " +
                               stage2.message);
        }
        summary.num_iterations += static_cast<int>(stage2.iterations.size());
        return Status::Ok();
      },
      [&] { return data_sigma_px(parameters); }, &summary.sigma_px));
  summary.n = parameters.n;
  summary.cost =
      0.5 * summary.sigma_px * summary.sigma_px * static_cast<double>(dof);

  // The information on n alone (port and rotation known): sum (dr/dn)^2.
  double information = 0.0;
  for (const int64_t i : inliers) {
    using Jet = ceres::Jet<double, 1>;
    Jet r;
    const Jet rotation[3] = {Jet(parameters.rotation[0]),
                             Jet(parameters.rotation[1]),
                             Jet(parameters.rotation[2])};
    if (GeneralizedEpipolarResidual(stereo, matches[i], Jet(parameters.n, 0),
                                    Jet(parameters.gap_delta),
                                    with_rotation ? rotation : nullptr, &r)) {
      information += r.v[0] * r.v[0];
    }
  }
  if (!(information > 0.0) ||
      1.0 / std::sqrt(information) > options.base.max_crlb_per_px) {
    return Status::Error(
        "the correspondences do not observe n (Cramer-Rao bound at 1 px "
        "above the limit)");
  }
  summary.crlb = summary.sigma_px / std::sqrt(information);

  // Without the rotation, n's (and the gap's) covariance from Ceres; with
  // it, from the propagation below, which splits the prior's share from
  // the pixel noise's.
  if (!with_rotation) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.num_threads = options.base.num_threads;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> blocks = {
        {&parameters.n, &parameters.n}};
    if (options.estimate_air_gap) {
      blocks.emplace_back(&parameters.n, &parameters.gap_delta);
      blocks.emplace_back(&parameters.gap_delta, &parameters.gap_delta);
    }
    if (!covariance.Compute(blocks, problem.get())) {
      return Status::Error(
          options.estimate_air_gap
              ? "the air gap cannot be separated from n with these "
                "correspondences (singular covariance); give the gap instead"
              : "the covariance of n is singular: the correspondences do not "
                "observe n");
    }
    const double variance_scale = summary.sigma_px * summary.sigma_px;
    double n_variance = 0.0;
    covariance.GetCovarianceBlock(&parameters.n, &parameters.n, &n_variance);
    summary.sigma_n = std::sqrt(n_variance * variance_scale);
    if (options.estimate_air_gap) {
      double n_gap = 0.0;
      double gap_variance = 0.0;
      covariance.GetCovarianceBlock(&parameters.n, &parameters.gap_delta,
                                    &n_gap);
      covariance.GetCovarianceBlock(&parameters.gap_delta,
                                    &parameters.gap_delta, &gap_variance);
      AirGapEstimate gap;
      gap.left_air_gap = left_port.air_gap + parameters.gap_delta;
      gap.right_air_gap = right_port.air_gap + parameters.gap_delta;
      gap.sigma = std::sqrt(gap_variance * variance_scale);
      gap.correlation_with_n = n_gap / std::sqrt(n_variance * gap_variance);
      result.air_gap = gap;
    }
    summary.sigma_n_noise = summary.sigma_n;
  }

  // The frames' consistency and the calibration's uncertainty
  // (calibration_propagation.h), with the ports held at the solution's
  // and cam1's rotation at the solution's correction.
  StatusOr<StereoRig> at = rig.WithPorts(
      [&] {
        FlatPort port = stereo.left_port;
        port.air_gap += parameters.gap_delta;
        return port;
      }(),
      [&] {
        FlatPort port = stereo.right_port;
        port.air_gap += parameters.gap_delta;
        return port;
      }());
  if (!at.ok()) return at.status();
  std::vector<StereoCorrespondence> raw;
  raw.reserve(matches.size());
  for (const int64_t i : prepared.source_index)
    raw.push_back(correspondences[i]);
  const CalibrationParameterLayout layout = CalibrationParameterLayout::Of(
      *at, options.base.systematic_px, false, options.base.detect_systematic);
  LocusNormalEquations equations(layout.Size());
  std::vector<LocusNormalEquations> per_frame;
  const Eigen::Vector3d rotation(parameters.rotation[0], parameters.rotation[1],
                                 parameters.rotation[2]);
  AccumulateLocusNormalEquations(*at, layout, raw, matches, inliers,
                                 parameters.n, rotation,
                                 Eigen::Vector2d::Zero(), &equations,
                                 &per_frame, options.base.num_threads);
  summary.consistency = FrameConsistencyOf(per_frame, summary.sigma_px);
  const double inflation =
      summary.consistency ? summary.consistency->inflation : 1.0;
  if (with_rotation) {
    StatusOr<CalibrationPropagation> propagation = PropagateCalibration(
        equations, layout, uncertainty, mode, summary.sigma_px, inflation);
    if (!propagation.ok()) return propagation.status();
    summary.sigma_n_noise = propagation->sigma_n_noise;
    summary.sigma_n_calibration = propagation->sigma_n_calibration;
    summary.sigma_n_systematic = propagation->sigma_n_systematic;
    const StatusOr<StereoRig> turned = rig.WithCam1Moved(rotation);
    if (!turned.ok()) return turned.status();
    summary.rotation = RotationCorrectionOf(*propagation, rotation, true,
                                            turned->right_from_left());
    summary.calibration = *propagation;
  } else {
    summary.sigma_n_noise *= inflation;
    if (at->calibration_uncertainty() || layout.systematic_px > 0.0 ||
        options.base.detect_systematic) {
      StatusOr<CalibrationPropagation> propagation = PropagateCalibration(
          equations, layout,
          at->calibration_uncertainty().value_or(CalibrationUncertainty()),
          RotationMode::kHeld, summary.sigma_px);
      if (!propagation.ok()) return propagation.status();
      summary.sigma_n_calibration = propagation->sigma_n_calibration;
      summary.sigma_n_systematic = propagation->sigma_n_systematic;
      // (A rig made in code is exact: no calibration report unless a floor
      // or a field the residuals show.)
      if (at->calibration_uncertainty() || layout.systematic_px > 0.0 ||
          propagation->systematic_detected_px > 0.0) {
        summary.calibration = *propagation;
      }
    }
  }
  summary.sigma_n =
      std::sqrt(summary.sigma_n_noise * summary.sigma_n_noise +
                summary.sigma_n_calibration * summary.sigma_n_calibration +
                summary.sigma_n_systematic * summary.sigma_n_systematic);
  RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(summary.n, summary.sigma_n));

  summary.inliers.reserve(inliers.size());
  for (const int64_t i : inliers) {
    summary.inliers.push_back(prepared.source_index[i]);
  }
  return result;
}

}  // namespace rcm
