#include "rcm/estimation/batch_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/cramer_rao_bound.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/robust_locus_fit.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/geometry/epipolar.h"

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

// The unknowns: n, and the rotation correction when it is refined.
struct Parameters {
  double n = 1.0;
  double rotation[3] = {0.0, 0.0, 0.0};
};

// One Ceres problem over `indices` of `matches`; returns the summary.
ceres::Solver::Summary Solve(const Eigen::Matrix3d& essential,
                             const std::vector<PreparedCorrespondence>& matches,
                             const std::vector<int64_t>& indices,
                             RobustLoss loss, const RefinementOptions& options,
                             Parameters* parameters, ceres::Problem* problem) {
  ceres::LossFunction* loss_function = NewLossFunction(loss, options.loss_scale_px);
  for (const int64_t i : indices) {
    if (options.refine_rotation) {
      problem->AddResidualBlock(
          SampsonCoplanarityError::CreateWithRotation(essential, matches[i]),
          loss_function, &parameters->n, parameters->rotation);
    } else {
      problem->AddResidualBlock(
          SampsonCoplanarityError::Create(essential, matches[i]), loss_function,
          &parameters->n);
    }
  }
  problem->SetParameterLowerBound(&parameters->n, 0, 1.0);
  problem->SetParameterUpperBound(&parameters->n, 0, 2.0);

  const ceres::Solver::Options solver_options =
      RefinementSolverOptions(options);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  return summary;
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

StatusOr<RefinementSummary> RefineRefractiveIndex(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    const RefinementOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (rig.HasThickPort()) {
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
      PrepareCorrespondences(rig, correspondences);
  const std::vector<PreparedCorrespondence>& matches = prepared.prepared;
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

  // Seed and stage 1 (robust, all usable matches).
  summary.n_closed_form = ClosedFormSeed(matches);
  std::optional<double> candidate;
  if (summary.n_closed_form) {
    candidate = std::clamp(*summary.n_closed_form, 1.0, 2.0);
  }
  Parameters parameters;
  if (!options.refine_rotation) {
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
    const ceres::Solver::Summary stage1 = Solve(
        essential, matches, all, options.loss, options, &parameters, &problem);
    if (!stage1.IsSolutionUsable()) {
      return Status::Error("the robust refinement failed: " + stage1.message);
    }
    summary.robust_cost = stage1.final_cost;
    summary.num_iterations += static_cast<int>(stage1.iterations.size());
  }
  summary.n_robust = parameters.n;

  // Inliers at the robust estimate.
  const Rigid3d robust_extrinsics =
      options.refine_rotation
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
  std::vector<PreparedCorrespondence> inlier_matches;
  inlier_matches.reserve(inliers.size());
  for (const int64_t i : inliers) inlier_matches.push_back(matches[i]);
  const double information_per_px =
      LocusInformation(robust_essential, inlier_matches, parameters.n);
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

  // Stage 2: least squares on the inliers, and its covariance.
  ceres::Problem problem;
  const ceres::Solver::Summary stage2 =
      Solve(essential, matches, inliers, RobustLoss::kNone, options,
            &parameters, &problem);
  if (!stage2.IsSolutionUsable()) {
    return Status::Error("the least-squares refinement failed: " +
                         stage2.message);
  }
  summary.num_iterations += static_cast<int>(stage2.iterations.size());
  summary.n = parameters.n;
  summary.cost = stage2.final_cost;
  const int num_parameters = options.refine_rotation ? 4 : 1;
  const int64_t dof = static_cast<int64_t>(inliers.size()) - num_parameters;
  summary.sigma_px = std::sqrt(2.0 * summary.cost / static_cast<double>(dof));

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = options.num_threads;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {&parameters.n, &parameters.n}};
  if (options.refine_rotation) {
    blocks.emplace_back(&parameters.n, parameters.rotation);
    blocks.emplace_back(parameters.rotation, parameters.rotation);
  }
  if (!covariance.Compute(blocks, &problem)) {
    return Status::Error(
        options.refine_rotation
            ? "the rotation correction cannot be separated from n with these "
              "correspondences (singular covariance); refine n alone"
            : "the covariance of n is singular: the correspondences do not "
              "observe n");
  }
  const double variance_scale = summary.sigma_px * summary.sigma_px;
  double n_variance = 0.0;
  covariance.GetCovarianceBlock(&parameters.n, &parameters.n, &n_variance);
  summary.sigma_n = std::sqrt(n_variance * variance_scale);

  const Rigid3d final_extrinsics =
      options.refine_rotation
          ? CorrectedExtrinsics(rig.right_from_left(), parameters.rotation)
          : rig.right_from_left();
  const Eigen::Matrix3d final_essential = EssentialMatrix(final_extrinsics);
  summary.crlb =
      summary.sigma_px / std::sqrt(LocusInformation(
                             final_essential, inlier_matches, parameters.n));

  if (options.refine_rotation) {
    double n_rotation[3];
    double rotation_rotation[9];
    covariance.GetCovarianceBlock(&parameters.n, parameters.rotation,
                                  n_rotation);
    covariance.GetCovarianceBlock(parameters.rotation, parameters.rotation,
                                  rotation_rotation);
    RotationCorrection correction;
    for (int k = 0; k < 3; ++k) {
      correction.angle_axis[k] = parameters.rotation[k];
      const double variance = rotation_rotation[4 * k];
      correction.sigma[k] = std::sqrt(variance * variance_scale);
      correction.correlation_with_n[k] =
          n_rotation[k] / std::sqrt(n_variance * variance);
    }
    correction.cam1_from_cam0 = final_extrinsics;
    const double bound_ratio = summary.crlb / summary.sigma_n;
    correction.multiple_correlation_with_n =
        std::sqrt(std::max(0.0, 1.0 - bound_ratio * bound_ratio));
    summary.rotation = correction;
  }

  summary.inliers.reserve(inliers.size());
  for (const int64_t i : inliers) {
    summary.inliers.push_back(prepared.source_index[i]);
  }
  return summary;
}

}  // namespace rcm
