#include "rcm/estimation/batch_refinement.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "rcm/estimation/bounded_index_solve.h"
#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/cramer_rao_bound.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/robust_locus_fit.h"
#include "rcm/estimation/sampson_coplanarity_cost_function.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

// The paper's mask threshold, for the closed-form seed.
constexpr double kSeedMaskEta = 0.3;

// The median of eq. 14 over the matches that pass the paper's mask.
std::optional<double> ClosedFormSeed(
    const std::vector<PreparedCorrespondence>& matches) {
  std::vector<double> values;
  values.reserve(matches.size());
  for (const PreparedCorrespondence& match : matches) {
    NormalizedCorrespondence normalized;
    normalized.left =
        Eigen::Vector2d(match.left_normalized[0], match.left_normalized[1]);
    normalized.right =
        Eigen::Vector2d(match.right_normalized[0], match.right_normalized[1]);
    if (!PassesObservabilityMask(normalized.left, kSeedMaskEta)) continue;
    if (const std::optional<double> n = ClosedFormN(normalized)) {
      values.push_back(*n);
    }
  }
  if (values.empty()) return std::nullopt;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  if (values.size() % 2 == 1) return values[middle];
  const double upper = values[middle];
  const double lower =
      *std::max_element(values.begin(), values.begin() + middle);
  return 0.5 * (lower + upper);
}

// The unknowns: n, the rotation correction when it is refined, and the
// focal scales' step from the scales the matches were prepared with
// (FocalScales).
struct Parameters {
  double n = 1.0;
  double rotation[3] = {0.0, 0.0, 0.0};
  double focal[2] = {0.0, 0.0};
};

// With the focal scales estimated: the scales e0 the matches are prepared
// with (the rig's lenses scaled by 1 + e0) and the focal drift prior s_f.
// A step d on top of them is the scale e = (1 + e0)(1 + d) - 1 =
// e0 + (1 + e0) d, whose prior N(0, s_f^2) is, in pixels of residual,
//
//   sigma_px (1 + e0) / s_f (d - (-e0 / (1 + e0))).
struct FocalScales {
  Eigen::Vector2d prepared_with = Eigen::Vector2d::Zero();
  double prior_sigma = 0.0;

  Eigen::Vector2d Total(const double* step) const {
    return prepared_with + (Eigen::Vector2d::Ones() + prepared_with)
                               .cwiseProduct(Eigen::Vector2d(step[0], step[1]));
  }
  ceres::CostFunction* NewPrior(double sigma_px) const {
    ceres::Matrix root_information = ceres::Matrix::Zero(2, 2);
    ceres::Vector mean(2);
    for (int c = 0; c < 2; ++c) {
      root_information(c, c) =
          sigma_px * (1.0 + prepared_with[c]) / prior_sigma;
      mean[c] = -prepared_with[c] / (1.0 + prepared_with[c]);
    }
    return new ceres::NormalPrior(root_information, mean);
  }
};

// `matches` (prepared for `rig`, from correspondences[source_index[i]])
// prepared again with the rig's lenses scaled by `scale`; with
// `derivatives`, the inverse lens Jacobians' derivatives in e too
// (PrepareFocalDerivatives, two more preparations), else those of the
// previous preparation kept (the refinement computes them once, after the
// robust stage: the scale then moves by a fraction of a percent, which
// changes them by as small a fraction; the coordinates and the residuals,
// which set the solution, are always prepared anew). A match that no
// longer prepares keeps its old preparation (a change of a few tenths of a
// percent moves no pixel off the lens's domain in practice).
void PrepareWithFocalScale(
    const StereoRig& rig, const Eigen::Vector2d& scale,
    const std::vector<StereoCorrespondence>& correspondences,
    const std::vector<int64_t>& source_index, bool derivatives, int num_threads,
    std::vector<PreparedCorrespondence>* matches) {
  const StatusOr<StereoRig> scaled = rig.WithFocalScaled(scale[0], scale[1]);
  if (!scaled.ok()) return;
  std::optional<FocalStepRigs> steps;  // made once, not per match
  if (derivatives) {
    StatusOr<FocalStepRigs> made = FocalStepRigs::Of(*scaled);
    if (!made.ok()) return;
    steps = *std::move(made);
  }
  // Each match's own: on the threads in chunks, the result independent of
  // them.
  constexpr int64_t kMatchesPerChunk = 256;
  const int64_t count = static_cast<int64_t>(matches->size());
  ParallelForChunks(
      count, count >= 2 * kMatchesPerChunk ? num_threads : 1, kMatchesPerChunk,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          const StereoCorrespondence& correspondence =
              correspondences[source_index[i]];
          std::optional<PreparedCorrespondence> prepared =
              PrepareCorrespondence(*scaled, correspondence);
          if (!prepared) continue;
          PreparedCorrespondence& match = (*matches)[i];
          if (derivatives) {
            if (!PrepareFocalDerivatives(*steps, correspondence, &*prepared)) {
              continue;
            }
          } else {
            std::copy_n(match.left_normalized_from_pixel_focal, 4,
                        prepared->left_normalized_from_pixel_focal);
            std::copy_n(match.right_normalized_from_pixel_focal, 4,
                        prepared->right_normalized_from_pixel_focal);
          }
          match = *prepared;
        }
      });
}

// The prior on n (RefinementOptions::n_prior) in pixels of residual:
// sigma_px (n - mean) / sigma, as NewRotationPrior's.
ceres::CostFunction* NewIndexPrior(const IndexPrior& prior, double sigma_px) {
  ceres::Matrix root_information(1, 1);
  root_information(0, 0) = sigma_px / prior.sigma;
  ceres::Vector mean(1);
  mean[0] = prior.n;
  return new ceres::NormalPrior(root_information, mean);
}

// One Ceres problem over `indices` of `matches`, with the rotation
// correction when `with_rotation` and its prior when `prior` is not null
// (NewRotationPrior), the prior on n when `n_prior` is not null
// (NewIndexPrior), and the focal scales' step with its prior when
// `focal_prior` is not null (FocalScales::NewPrior; the rotation then held
// at zero unless `with_rotation`); returns the summary.
ceres::Solver::Summary Solve(const Eigen::Matrix3d& essential,
                             const std::vector<PreparedCorrespondence>& matches,
                             const std::vector<int64_t>& indices,
                             RobustLoss loss, const RefinementOptions& options,
                             bool with_rotation, ceres::CostFunction* prior,
                             ceres::CostFunction* n_prior,
                             ceres::CostFunction* focal_prior,
                             Parameters* parameters, ceres::Problem* problem) {
  if (prior != nullptr) {
    problem->AddResidualBlock(prior, nullptr, parameters->rotation);
  }
  if (n_prior != nullptr) {
    problem->AddResidualBlock(n_prior, nullptr, &parameters->n);
  }
  if (focal_prior != nullptr) {
    problem->AddResidualBlock(focal_prior, nullptr, parameters->focal);
  }
  // The matches in blocks of kSampsonBlockMatches, the loss inside each
  // (sampson_coplanarity_cost_function.h); the Jacobian written out.
  const SampsonParameters blocks =
      focal_prior != nullptr ? SampsonParameters::kIndexRotationFocal
      : with_rotation        ? SampsonParameters::kIndexRotation
                             : SampsonParameters::kIndex;
  std::vector<double*> parameter_blocks = {&parameters->n};
  if (blocks != SampsonParameters::kIndex) {
    parameter_blocks.push_back(parameters->rotation);
  }
  if (blocks == SampsonParameters::kIndexRotationFocal) {
    parameter_blocks.push_back(parameters->focal);
  }
  for (size_t begin = 0; begin < indices.size();
       begin += kSampsonBlockMatches) {
    const size_t end =
        std::min(indices.size(), begin + size_t{kSampsonBlockMatches});
    std::vector<PreparedCorrespondence> block;
    block.reserve(end - begin);
    for (size_t k = begin; k < end; ++k) block.push_back(matches[indices[k]]);
    problem->AddResidualBlock(
        SampsonCoplanarityCostFunction::Create(
            essential, std::move(block), blocks, loss, options.loss_scale_px),
        nullptr, parameter_blocks);
  }
  if (focal_prior != nullptr && !with_rotation) {
    problem->SetParameterBlockConstant(parameters->rotation);
  }
  problem->SetParameterLowerBound(&parameters->n, 0, 1.0);
  problem->SetParameterUpperBound(&parameters->n, 0, 2.0);

  const ceres::Solver::Options solver_options =
      RefinementSolverOptions(options);
  return SolveWithBoundedIndex(solver_options, problem, &parameters->n, 1.0,
                               2.0);
}

// cam1_from_cam0 with cam1 rotated about its center by `rotation`
// (angle-axis): (R_delta R, R_delta t), whose essential matrix is R_delta E.
Rigid3d CorrectedExtrinsics(const Rigid3d& right_from_left,
                            const double* rotation) {
  Eigen::Matrix3d delta;
  ceres::AngleAxisToRotationMatrix(rotation,
                                   ceres::ColumnMajorAdapter3x3(delta.data()));
  Rigid3d corrected;
  corrected.rotation = delta * right_from_left.rotation;
  corrected.translation = delta * right_from_left.translation;
  return corrected;
}

std::string Count(int64_t count, const char* singular, const char* plural) {
  return std::to_string(count) + " " + (count == 1 ? singular : plural);
}

}  // namespace

RotationCorrection RotationCorrectionOf(
    const CalibrationPropagation& propagation,
    const Eigen::Vector3d& angle_axis, bool with_prior,
    const Rigid3d& cam1_from_cam0) {
  RotationCorrection correction;
  correction.angle_axis = angle_axis;
  for (int k = 0; k < 3; ++k) {
    correction.sigma[k] =
        std::sqrt(std::max(0.0, propagation.rotation_covariance(k, k)));
  }
  correction.correlation_with_n = propagation.rotation_correlation_with_n;
  correction.multiple_correlation_with_n =
      propagation.rotation_multiple_correlation;
  correction.with_prior = with_prior;
  correction.cam1_from_cam0 = cam1_from_cam0;
  return correction;
}

StatusOr<RefinementSummary> RefineRefractiveIndex(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    const RefinementOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (rig.HasThickPort()) {
    if (options.n_prior) {
      return Status::Error(
          "the prior on n (the medium) is available for thin ports only");
    }
    // The thick-port model (thick_port_refinement.h); a rig without ports
    // or with thin ones takes the paper's model below, unchanged.
    ThickPortRefinementOptions thick_options;
    thick_options.base = options;
    StatusOr<ThickPortRefinementSummary> thick = RefineRefractiveIndexThickPort(
        rig, rig.ports()->left, rig.ports()->right, correspondences,
        thick_options);
    if (!thick.ok()) return thick.status();
    return std::move(thick->refinement);
  }
  RefinementSummary summary;
  summary.num_correspondences = static_cast<int64_t>(correspondences.size());
  const PreparedCorrespondences prepared =
      PrepareCorrespondences(rig, correspondences, options.num_threads);
  // Prepared with the calibration's lenses; with the focal scales
  // estimated, prepared again with each estimate of them.
  std::vector<PreparedCorrespondence> matches = prepared.prepared;
  summary.num_invalid =
      summary.num_correspondences - static_cast<int64_t>(matches.size());
  if (static_cast<int>(matches.size()) < options.min_inliers) {
    std::ostringstream message;
    message << "too few correspondences: "
            << Count(static_cast<int64_t>(matches.size()), "usable match",
                     "usable matches")
            << " of " << correspondences.size() << ", at least "
            << options.min_inliers << " needed";
    return Status::Error(message.str());
  }
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());

  // How cam1's rotation is treated: free (refine_rotation), estimated with
  // the calibration's rotation covariance as prior (self-calibration), or
  // held at the calibration's.
  const CalibrationUncertainty uncertainty =
      rig.calibration_uncertainty().value_or(CalibrationUncertainty());
  const bool rotation_uncertain = !uncertainty.RotationCovariance().isZero(0.0);
  const RotationMode mode =
      options.refine_rotation ? RotationMode::kFree
      : options.self_calibrate_rotation && rotation_uncertain
          ? RotationMode::kPrior
          : RotationMode::kHeld;
  const bool with_rotation = mode != RotationMode::kHeld;
  // The focal scales, estimated under the focal drift prior.
  const CalibrationParameterLayout layout = CalibrationParameterLayout::Of(
      rig, options.systematic_px, options.self_calibrate_focal,
      options.detect_systematic);
  const bool with_focal = layout.focal;
  FocalScales focal;
  focal.prior_sigma = uncertainty.focal_drift_sigma;
  const auto new_focal_prior = [&](double sigma_px) {
    return with_focal ? focal.NewPrior(sigma_px) : nullptr;
  };
  // Takes the solved focal step into the preparation of the matches. The
  // robust stage takes the inverse lens Jacobians' derivatives of a lens
  // without distortion (PrepareCorrespondence's); the first preparation
  // after it gives every lens its own.
  int focal_preparations = 0;
  const auto prepare_with_focal_step = [&](Parameters* at) {
    focal.prepared_with = focal.Total(at->focal);
    at->focal[0] = at->focal[1] = 0.0;
    PrepareWithFocalScale(rig, focal.prepared_with, correspondences,
                          prepared.source_index, focal_preparations++ == 0,
                          options.num_threads, &matches);
  };

  // Seed and stage 1 (robust, all usable matches).
  summary.n_closed_form = ClosedFormSeed(matches);
  std::optional<double> candidate;
  if (summary.n_closed_form) {
    candidate = std::clamp(*summary.n_closed_form, 1.0, 2.0);
  }
  Parameters parameters;
  if (!with_rotation && !with_focal) {
    // n alone: a 1-D search is exact and several times faster than a
    // Ceres solve of the robust cost, whose Gauss-Newton model converges
    // only linearly on it.
    parameters.n = MinimizeRobustLocusCost(essential, matches, options,
                                           candidate, &summary.n_seed);
    summary.robust_cost =
        0.5 * RobustLocusCost(essential, matches, parameters.n, options);
  } else {
    summary.n_seed =
        ScanRobustLocusCost(essential, matches, options, candidate);
    parameters.n = summary.n_seed;
    std::vector<int64_t> all(matches.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int64_t>(i);
    ceres::Problem problem;
    // The prior's weight needs the pixel noise, unknown before stage 2:
    // half the loss scale, which the options call about twice the noise.
    const double prior_sigma_px = 0.5 * options.loss_scale_px;
    ceres::CostFunction* prior =
        mode == RotationMode::kPrior
            ? NewRotationPrior(uncertainty.RotationPriorCovariance(),
                               prior_sigma_px)
            : nullptr;
    const ceres::Solver::Summary stage1 = Solve(
        essential, matches, all, options.loss, options, with_rotation, prior,
        options.n_prior ? NewIndexPrior(*options.n_prior, prior_sigma_px)
                        : nullptr,
        new_focal_prior(prior_sigma_px), &parameters, &problem);
    if (!stage1.IsSolutionUsable()) {
      return Status::Error("the robust refinement failed: " + stage1.message);
    }
    summary.robust_cost = stage1.final_cost;
    summary.num_iterations += static_cast<int>(stage1.iterations.size());
    if (with_focal) prepare_with_focal_step(&parameters);
  }
  summary.n_robust = parameters.n;

  // Inliers at the robust estimate.
  const Rigid3d robust_extrinsics =
      with_rotation
          ? CorrectedExtrinsics(rig.right_from_left(), parameters.rotation)
          : rig.right_from_left();
  const Eigen::Matrix3d robust_essential = EssentialMatrix(robust_extrinsics);
  const std::vector<int64_t> inliers =
      ClassifyLocusInliers(robust_extrinsics, matches, parameters.n, options);
  if (static_cast<int>(inliers.size()) < options.min_inliers) {
    std::ostringstream message;
    message << "too few inliers: "
            << Count(static_cast<int64_t>(inliers.size()), "match", "matches")
            << " of " << matches.size() << " within "
            << options.inlier_threshold_px
            << " px of the refractive epipolar loci and in front of both "
               "cameras, at least "
            << options.min_inliers << " needed";
    return Status::Error(message.str());
  }
  const auto inlier_matches = [&] {
    std::vector<PreparedCorrespondence> subset;
    subset.reserve(inliers.size());
    for (const int64_t i : inliers) subset.push_back(matches[i]);
    return subset;
  };
  const double information_per_px =
      LocusInformation(robust_essential, inlier_matches(), parameters.n);
  if (!(information_per_px > 0.0) ||
      1.0 / std::sqrt(information_per_px) > options.max_crlb_per_px) {
    std::ostringstream message;
    message << "the correspondences do not observe n: at 1 px of noise its "
               "uncertainty would be "
            << (information_per_px > 0.0 ? 1.0 / std::sqrt(information_per_px)
                                         : INFINITY)
            << " (limit " << options.max_crlb_per_px
            << "); matches on the image axes or far away carry no "
               "information on n";
    return Status::Error(message.str());
  }

  // Stage 2: least squares on the inliers. With the prior, its weight
  // sigma_px^2 comes from the inliers' residuals, refined until it settles
  // (two or three solves). With the focal scales, the matches are prepared
  // again at each solution's scales and stage 2 repeated until the step
  // vanishes (the first-order model of sampson_coplanarity_error.h is then
  // exact at the solution; two or three passes).
  const int num_parameters = 1 + (with_rotation ? 3 : 0) + (with_focal ? 2 : 0);
  const int64_t dof = static_cast<int64_t>(inliers.size()) - num_parameters;
  const auto data_sigma_px = [&](const Parameters& at) {
    const Rigid3d extrinsics =
        with_rotation ? CorrectedExtrinsics(rig.right_from_left(), at.rotation)
                      : rig.right_from_left();
    const Eigen::Matrix3d corrected = EssentialMatrix(extrinsics);
    double sum = 0.0;
    for (const int64_t i : inliers) {
      double r = 0.0;
      if (SampsonCoplanarityResidual<double>(
              corrected, matches[i], at.n, nullptr,
              with_focal ? at.focal : nullptr, &r) &&
          std::isfinite(r)) {
        sum += r * r;
      }
    }
    return std::sqrt(sum / static_cast<double>(dof));
  };
  const bool with_prior =
      mode == RotationMode::kPrior || options.n_prior || with_focal;
  // The passes stop when the step is a thousandth of the prior's sigma
  // (3e-6 for the default 0.3 %), or after two: the robust stage leaves the
  // scales off by the square of the change (~1e-5), the first pass's step
  // takes that out and leaves its square (~1e-10), and on exact data the
  // second's is ~1e-20. With noise, later passes would only follow the
  // prior's weight, re-estimated each pass, by ~1e-6, far inside sigma.
  constexpr int kMaxFocalPasses = 2;
  const double focal_step_tolerance = 1e-3 * focal.prior_sigma;
  for (int pass = 0; pass < (with_focal ? kMaxFocalPasses : 1); ++pass) {
    RCM_RETURN_IF_ERROR(SolveUntilThePriorWeightSettles(
        with_prior,
        [&](double prior_sigma_px) {
          ceres::Problem problem;
          const double weight_px = std::max(prior_sigma_px, 1e-6);
          ceres::CostFunction* prior =
              mode == RotationMode::kPrior
                  ? NewRotationPrior(uncertainty.RotationPriorCovariance(),
                                     weight_px)
                  : nullptr;
          const ceres::Solver::Summary stage2 =
              Solve(essential, matches, inliers, RobustLoss::kNone, options,
                    with_rotation, prior,
                    options.n_prior ? NewIndexPrior(*options.n_prior, weight_px)
                                    : nullptr,
                    new_focal_prior(weight_px), &parameters, &problem);
          if (!stage2.IsSolutionUsable()) {
            return Status::Error("the least-squares refinement failed: " +
                                 stage2.message);
          }
          summary.num_iterations += static_cast<int>(stage2.iterations.size());
          return Status::Ok();
        },
        [&] { return data_sigma_px(parameters); }, &summary.sigma_px));
    if (!with_focal) break;
    const double step =
        std::max(std::abs(parameters.focal[0]), std::abs(parameters.focal[1]));
    prepare_with_focal_step(&parameters);
    if (step <= focal_step_tolerance) break;
  }
  summary.cost =
      0.5 * summary.sigma_px * summary.sigma_px * static_cast<double>(dof);
  summary.n = parameters.n;

  // Uncertainty (calibration_propagation.h): the normal equations at the
  // solution, the frames' consistency, and the propagation of the pixel
  // noise and the calibration's uncertainty into n.
  const Eigen::Vector3d rotation(parameters.rotation[0], parameters.rotation[1],
                                 parameters.rotation[2]);
  const Rigid3d final_extrinsics =
      with_rotation
          ? CorrectedExtrinsics(rig.right_from_left(), parameters.rotation)
          : rig.right_from_left();
  const Eigen::Matrix3d final_essential = EssentialMatrix(final_extrinsics);
  std::vector<StereoCorrespondence> raw;
  raw.reserve(matches.size());
  for (const int64_t i : prepared.source_index)
    raw.push_back(correspondences[i]);
  // With the focal scales, the rows are taken on the rig with the
  // estimated lenses (what `matches` are now prepared with).
  StereoRig solved_rig = rig;
  if (with_focal) {
    StatusOr<StereoRig> scaled =
        rig.WithFocalScaled(focal.prepared_with[0], focal.prepared_with[1]);
    if (!scaled.ok()) return scaled.status();
    solved_rig = *std::move(scaled);
  }
  // The rows at the solution's rotation, or at the caller's.
  const Eigen::Vector3d rows_rotation =
      with_rotation ? options.rows_at_rotation.value_or(rotation) : rotation;
  LocusNormalEquations equations(layout.Size());
  std::vector<LocusNormalEquations> per_frame;
  AccumulateLocusNormalEquations(
      solved_rig, layout, raw, matches, inliers, parameters.n, rows_rotation,
      focal.prepared_with, &equations, &per_frame, options.num_threads);
  summary.consistency = FrameConsistencyOf(per_frame, summary.sigma_px);
  const double inflation =
      summary.consistency ? summary.consistency->inflation : 1.0;
  StatusOr<CalibrationPropagation> propagation = PropagateCalibration(
      equations, layout, uncertainty, mode, summary.sigma_px, inflation,
      options.n_prior ? options.n_prior->sigma : 0.0);
  if (!propagation.ok()) return propagation.status();
  summary.sigma_n = propagation->sigma_n;
  summary.sigma_n_noise = propagation->sigma_n_noise;
  summary.sigma_n_calibration = propagation->sigma_n_calibration;
  summary.sigma_n_systematic = propagation->sigma_n_systematic;
  summary.crlb =
      summary.sigma_px / std::sqrt(LocusInformation(
                             final_essential, inlier_matches(), parameters.n));

  if (with_rotation) {
    summary.rotation = RotationCorrectionOf(
        *propagation, rotation, mode == RotationMode::kPrior, final_extrinsics);
  }
  if (with_focal) {
    FocalScaleCorrection correction;
    correction.scale = focal.prepared_with;
    for (int c = 0; c < 2; ++c) {
      correction.sigma[c] =
          std::sqrt(std::max(0.0, propagation->focal_scale_covariance(c, c)));
    }
    correction.correlation_with_n = propagation->focal_scale_correlation_with_n;
    summary.focal = correction;
  }
  // (A rig made in code is exact: no calibration report unless a floor,
  // a prior on n or a field the residuals show.)
  if (rig.calibration_uncertainty() || layout.systematic_px > 0.0 ||
      propagation->systematic_detected_px > 0.0 || options.n_prior) {
    summary.calibration = *propagation;
  }
  summary.normal_equations = std::move(equations);
  summary.rows_rotation = rows_rotation;

  // An estimate pinned at the upper bound is a failure, not a number.
  RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(summary.n, summary.sigma_n));

  summary.inliers.reserve(inliers.size());
  for (const int64_t i : inliers) {
    summary.inliers.push_back(prepared.source_index[i]);
  }
  return summary;
}

}  // namespace rcm
