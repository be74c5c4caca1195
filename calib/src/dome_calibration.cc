#include "rcm/calib/dome_calibration.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

#include "board_bundle_adjustment.h"
#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_initialization.h"
#include "rcm/calib/cross_validation.h"
#include "rcm/calib/dome_reprojection_error.h"
#include "rcm/calib/mono_calibration.h"
#include "rcm/camera/refractive_camera.h"

namespace rcm::calib {
namespace {

using internal::Corner;
using internal::Pose;

// What the problem's corners refer to: water views [0, num_water_views),
// air views after them (traced at n = 1), each with its board's points.
struct DomeProblem {
  const std::vector<DomeCameraInput>* cameras = nullptr;
  std::vector<Eigen::Vector3d> water_points, air_points;
  std::vector<Eigen::Vector2d> water_basis, air_basis;
  int num_water_views = 0;
  int num_views = 0;  // water and air
  bool lenses_estimated = false;
  bool air_same_board = true;
  bool Air(const Corner& corner) const {
    return corner.view >= num_water_views;
  }
  const Eigen::Vector3d& Point(const Corner& corner) const {
    return Air(corner) ? air_points[corner.point_id]
                       : water_points[corner.point_id];
  }
  const Eigen::Vector2d& Basis(const Corner& corner) const {
    return Air(corner) ? air_basis[corner.point_id]
                       : water_basis[corner.point_id];
  }
};

// The unknowns of one candidate's problem.
struct DomeState {
  double n = 1.333;
  double n_air = 1.0;                         // held
  std::vector<Pose> poses;                    // per view, water then air
  std::vector<Pose> cam_from_cam0;            // per camera, held
  std::vector<std::array<double, 3>> centre;  // per camera
  std::vector<std::array<double, kMaxLensParams>> lens;  // per camera
  std::array<double, 2> warp{0.0, 0.0};
  std::array<double, 2> air_warp{0.0, 0.0};  // another air board's
};

// The fit of one candidate model, with its covariance.
struct DomeFit {
  DomeState state;
  std::vector<Corner> corners;
  internal::ResidualStatistics statistics;
  double pixel_sigma = 0.0;
  int num_parameters = 0;
  // Joint covariance of [n?, C_0, C_1?, warp?] scaled by sigma^2.
  Eigen::MatrixXd covariance;
  int n_offset = -1;
  std::vector<int> centre_offset;
  int warp_offset = -1;
  std::vector<double> view_ssr;  // per view, inliers, NaN when unused
  int num_outlier_views = 0;     // dropped whole (header)
  // Per view, the weight of its corners (1 unless options.weigh_views).
  std::vector<double> view_weight;
};

// A view whose inlier RMS exceeds this many times the median view's is an
// outlier view. With Gaussian corner noise a view's RMS over its ~50
// corners varies by about 10 % (a chi distribution on ~100 degrees of
// freedom), so noise alone never reaches it; a detector that failed on a
// view (a steep, far or crowded board: on a rendered dive one view's 49
// corners were 0.79 px RMS off against at most 0.11 px for the 13 others)
// does.
constexpr double kOutlierViewFactor = 4.0;

// The bounds of a view's weight, relative to the median view's: a view's
// variance estimate over its ~50 corners is good to ~15 %, and the
// outlier-view rule leaves views within 4^2 = 16 times the median's
// variance.
constexpr double kMaxViewWeightRatio = 16.0;

// Per view, the weight w_v = clamp(median_u s_u^2 / s_v^2, 1/16, 16) of
// its corners, with s_v^2 = SSR_v / (2 m_v - 6) its inliers' residual
// variance (m_v corners over the cameras, one pose, that project); 1 for
// views without inliers.
std::vector<double> ViewWeights(const std::vector<double>& view_ssr,
                                const std::vector<int>& view_corners) {
  const size_t num_views = view_ssr.size();
  std::vector<double> variance(num_views, std::nan(""));
  std::vector<double> used;
  for (size_t v = 0; v < num_views; ++v) {
    const int dof = 2 * view_corners[v] - 6;
    if (dof <= 0) continue;
    variance[v] = view_ssr[v] / dof;
    used.push_back(variance[v]);
  }
  std::vector<double> weights(num_views, 1.0);
  if (used.empty()) return weights;
  std::nth_element(used.begin(), used.begin() + used.size() / 2, used.end());
  const double median = used[used.size() / 2];
  if (!(median > 0.0)) return weights;
  for (size_t v = 0; v < num_views; ++v) {
    if (!std::isfinite(variance[v])) continue;
    weights[v] = variance[v] > 0.0 ? std::clamp(median / variance[v],
                                                1.0 / kMaxViewWeightRatio,
                                                kMaxViewWeightRatio)
                                   : kMaxViewWeightRatio;
  }
  return weights;
}

ceres::CostFunction* MakeDomeCost(const DomeProblem& problem,
                                  const DomeState& state,
                                  const Corner& corner) {
  const DomeCameraInput& input = (*problem.cameras)[corner.camera];
  const Eigen::Vector3d& point = problem.Point(corner);
  const Eigen::Vector2d& basis = problem.Basis(corner);
  if (problem.lenses_estimated) {
    RCM_LENS_MODEL_SWITCH(input.camera.model(),
                          return DomeLensReprojectionError<LensModel>::Create(
                              input.dome, point, basis, corner.pixel););
  }
  RCM_LENS_MODEL_SWITCH(
      input.camera.model(),
      return DomeReprojectionError<LensModel>::Create(
          state.lens[corner.camera], input.dome, point, basis, corner.pixel););
  return nullptr;
}

// The parameter blocks of a corner's residual, in the functor's order.
std::vector<double*> DomeBlocks(const DomeProblem& problem, DomeState* state,
                                const Corner& corner) {
  std::vector<double*> blocks;
  if (problem.lenses_estimated) {
    blocks.push_back(state->lens[corner.camera].data());
  }
  const bool air = problem.Air(corner);
  blocks.push_back(air ? &state->n_air : &state->n);
  blocks.push_back(state->poses[corner.view].data());
  blocks.push_back(state->cam_from_cam0[corner.camera].data());
  blocks.push_back(state->centre[corner.camera].data());
  blocks.push_back(air && !problem.air_same_board ? state->air_warp.data()
                                                  : state->warp.data());
  return blocks;
}

// `replicate_weights`, when given: a leave-out replicate with the full
// fit's view weights, refitted from the solution on its inliers (no
// outlier rounds, no outlier views, no new weights) without a covariance.
StatusOr<DomeFit> FitDomeCandidate(
    const DomeProblem& description, const std::vector<Corner>& start_corners,
    const DomeState& start, bool board_warp,
    const DomeCalibrationOptions& options,
    const std::vector<double>* replicate_weights = nullptr) {
  const bool replicate = replicate_weights != nullptr;
  DomeFit fit;
  fit.state = start;
  fit.corners = start_corners;
  fit.view_weight = replicate ? *replicate_weights
                              : std::vector<double>(description.num_views, 1.0);
  if (!board_warp) {
    fit.state.warp = {0.0, 0.0};
    fit.state.air_warp = {0.0, 0.0};
  }
  DomeState& state = fit.state;
  const std::vector<DomeCameraInput>& cameras = *description.cameras;
  const int num_cameras = static_cast<int>(cameras.size());
  const int num_views = description.num_views;
  std::vector<bool> view_used(num_views, false);
  for (const Corner& corner : fit.corners) view_used[corner.view] = true;

  const auto add_residuals = [&](double huber_px, ceres::Problem* problem) {
    for (const Corner& corner : fit.corners) {
      if (!corner.inlier) continue;
      ceres::LossFunction* loss =
          huber_px > 0.0 ? new ceres::HuberLoss(huber_px) : nullptr;
      const double weight = fit.view_weight[corner.view];
      if (weight != 1.0) {
        loss = new ceres::ScaledLoss(loss, weight, ceres::TAKE_OWNERSHIP);
      }
      problem->AddResidualBlock(MakeDomeCost(description, state, corner), loss,
                                DomeBlocks(description, &state, corner));
    }
    if (problem->HasParameterBlock(&state.n_air)) {
      problem->SetParameterBlockConstant(&state.n_air);
    }
    for (int c = 0; c < num_cameras && description.lenses_estimated; ++c) {
      double* lens = state.lens[c].data();
      if (!problem->HasParameterBlock(lens)) continue;
      for (const DistortionBound& bound :
           DistortionBounds(cameras[c].camera.model())) {
        problem->SetParameterLowerBound(lens, 4 + bound.index, bound.lower);
        problem->SetParameterUpperBound(lens, 4 + bound.index, bound.upper);
      }
    }
    if (problem->HasParameterBlock(&state.n)) {
      problem->SetParameterBlockConstant(&state.n);
    }
    if (options.estimate_n && problem->HasParameterBlock(&state.n)) {
      problem->SetParameterBlockVariable(&state.n);
      problem->SetParameterLowerBound(&state.n, 0, RefractiveCamera::kMinIndex);
      problem->SetParameterUpperBound(&state.n, 0, RefractiveCamera::kMaxIndex);
    }
    for (int c = 0; c < num_cameras; ++c) {
      if (problem->HasParameterBlock(state.cam_from_cam0[c].data())) {
        problem->SetParameterBlockConstant(state.cam_from_cam0[c].data());
      }
    }
    for (double* warp : {state.warp.data(), state.air_warp.data()}) {
      if (!board_warp && problem->HasParameterBlock(warp)) {
        problem->SetParameterBlockConstant(warp);
      }
    }
  };
  const auto residual = [&](const Corner& corner) -> Eigen::Vector2d {
    std::unique_ptr<ceres::CostFunction> cost(
        MakeDomeCost(description, state, corner));
    const std::vector<double*> blocks = DomeBlocks(description, &state, corner);
    Eigen::Vector2d e;
    if (!cost->Evaluate(blocks.data(), e.data(), nullptr)) {
      return Eigen::Vector2d::Constant(std::nan(""));
    }
    return e;
  };

  internal::OutlierRejectionOptions rejection;
  rejection.huber_px = options.huber_px;
  rejection.outlier_sigmas = options.outlier_sigmas;
  rejection.min_outlier_threshold_px = options.min_outlier_threshold_px;
  rejection.max_outlier_rounds = replicate ? 0 : options.max_outlier_rounds;
  auto problem = std::make_unique<ceres::Problem>();
  RCM_RETURN_IF_ERROR(internal::FitWithOutlierRejection(
      rejection,
      internal::BoardSolverOptions(options.max_num_iterations,
                                   options.num_threads),
      add_residuals, residual, &fit.corners, problem.get()));
  // Per view, the inliers' sum of squared residuals and their count (of
  // those that project).
  const auto view_sums = [&](std::vector<double>* squares,
                             std::vector<int>* counts) {
    squares->assign(num_views, 0.0);
    counts->assign(num_views, 0);
    for (const Corner& corner : fit.corners) {
      if (!corner.inlier) continue;
      const Eigen::Vector2d e = residual(corner);
      if (!e.allFinite()) continue;
      (*squares)[corner.view] += e.squaredNorm();
      ++(*counts)[corner.view];
    }
  };
  // The final least squares again, from the solution, without new
  // outlier rounds.
  const auto refit = [&]() -> Status {
    rejection.max_outlier_rounds = 0;
    problem = std::make_unique<ceres::Problem>();
    return internal::FitWithOutlierRejection(
        rejection,
        internal::BoardSolverOptions(options.max_num_iterations,
                                     options.num_threads),
        add_residuals, residual, &fit.corners, problem.get());
  };
  std::vector<double> squares;
  std::vector<int> counts;
  // Outlier views (header): a view whose inlier RMS exceeds
  // kOutlierViewFactor times the median view's is dropped whole, and the
  // rest refitted.
  if (!replicate) {
    view_sums(&squares, &counts);
    std::vector<double> view_rms(num_views, 0.0);
    std::vector<double> used_rms;
    for (int v = 0; v < num_views; ++v) {
      if (counts[v] == 0) continue;
      view_rms[v] = std::sqrt(squares[v] / counts[v]);
      used_rms.push_back(view_rms[v]);
    }
    if (used_rms.size() >= 4) {
      std::nth_element(used_rms.begin(), used_rms.begin() + used_rms.size() / 2,
                       used_rms.end());
      const double limit = kOutlierViewFactor * used_rms[used_rms.size() / 2];
      bool dropped = false;
      for (Corner& corner : fit.corners) {
        if (counts[corner.view] > 0 && view_rms[corner.view] > limit &&
            corner.inlier) {
          corner.inlier = false;
          dropped = true;
        }
      }
      for (int v = 0; v < num_views; ++v) {
        if (counts[v] > 0 && view_rms[v] > limit) ++fit.num_outlier_views;
      }
      if (dropped) RCM_RETURN_IF_ERROR(refit());
    }
  }
  // The views weighed by their own corner noise (options.weigh_views), and
  // the solution refitted from where it is.
  if (!replicate && options.weigh_views) {
    view_sums(&squares, &counts);
    fit.view_weight = ViewWeights(squares, counts);
    RCM_RETURN_IF_ERROR(refit());
  }
  if (options.estimate_n && (state.n <= RefractiveCamera::kMinIndex + 1e-9 ||
                             state.n >= RefractiveCamera::kMaxIndex - 1e-9)) {
    std::ostringstream message;
    message << "n = " << state.n
            << " went to a bound of [1, 2]: the views cannot separate n "
               "from the decentering (views at several distances would); "
               "hold n (no --estimate-n)";
    return Status::Error(message.str());
  }

  fit.statistics = internal::SummarizeResiduals(fit.corners, residual);
  int num_used_views = 0;
  for (bool used : view_used) num_used_views += used ? 1 : 0;
  fit.num_parameters = 6 * num_used_views + 3 * num_cameras +
                       (options.estimate_n ? 1 : 0) + (board_warp ? 2 : 0);
  if (description.lenses_estimated) {
    for (const DomeCameraInput& input : cameras) {
      fit.num_parameters += input.camera.num_params();
    }
    if (board_warp && !description.air_same_board) fit.num_parameters += 2;
  }
  const int dof = 2 * fit.statistics.num_inliers - fit.num_parameters;
  if (dof <= 0) {
    return Status::Error("too few corners (" +
                         std::to_string(fit.statistics.num_inliers) + ") for " +
                         std::to_string(fit.num_parameters) + " unknowns");
  }
  fit.pixel_sigma = std::sqrt(fit.statistics.inlier_ssr / dof);
  fit.view_ssr.assign(num_views, std::nan(""));
  for (size_t k = 0; k < fit.corners.size(); ++k) {
    const CornerResidual& corner = fit.statistics.corners[k];
    if (!corner.inlier) continue;
    double& ssr = fit.view_ssr[corner.view];
    ssr = (std::isnan(ssr) ? 0.0 : ssr) + corner.residual.squaredNorm();
  }

  if (replicate) return fit;
  // The covariance of the blocks reported.
  std::vector<internal::CovarianceBlockRef> blocks;
  int offset = 0;
  if (options.estimate_n) {
    blocks.push_back({&state.n, 1});
    fit.n_offset = offset;
    offset += 1;
  }
  for (int c = 0; c < num_cameras; ++c) {
    blocks.push_back({state.centre[c].data(), 3});
    fit.centre_offset.push_back(offset);
    offset += 3;
  }
  if (board_warp) {
    blocks.push_back({state.warp.data(), 2});
    fit.warp_offset = offset;
    offset += 2;
  }
  Eigen::MatrixXd covariance;
  if (!internal::JointCovariance(blocks, true, options.num_threads,
                                 problem.get(), &covariance)) {
    return Status::Error(
        "the decentering's covariance cannot be computed (the views do "
        "not determine it: add views at other distances and angles)");
  }
  // The covariance of the weighted problem scaled by its residual
  // variance sum_v w_v SSR_v / dof (the pixel variance without weights).
  double weighted_ssr = 0.0;
  for (const CornerResidual& corner : fit.statistics.corners) {
    if (corner.inlier && corner.residual.allFinite()) {
      weighted_ssr +=
          fit.view_weight[corner.view] * corner.residual.squaredNorm();
    }
  }
  fit.covariance = covariance * (weighted_ssr / dof);
  return fit;
}

DomeCandidate CandidateOf(const DomeFit& fit, bool board_warp,
                          int num_cameras) {
  DomeCandidate candidate;
  candidate.board_warp = board_warp;
  candidate.name = board_warp ? "bowed board" : "flat board";
  for (int c = 0; c < num_cameras; ++c) {
    const std::array<double, 3>& centre = fit.state.centre[c];
    candidate.decentering.emplace_back(centre[0], centre[1], centre[2]);
    const int o = fit.centre_offset[c];
    candidate.decentering_sigma.push_back(
        fit.covariance.block<3, 3>(o, o).diagonal().cwiseSqrt());
  }
  candidate.n = fit.state.n;
  candidate.sigma_n =
      fit.n_offset >= 0 ? std::sqrt(fit.covariance(fit.n_offset, fit.n_offset))
                        : 0.0;
  candidate.rms_px = fit.statistics.rms_px;
  candidate.pixel_sigma = fit.pixel_sigma;
  return candidate;
}

// The paired t statistic of ln(s_flat(v) / s_bowed(v)) over the views both
// fits used (0 with fewer than 2 views or no spread).
double BowEvidence(const DomeFit& flat, const DomeFit& bowed) {
  std::vector<double> d;
  for (size_t v = 0; v < flat.view_ssr.size(); ++v) {
    const double a = flat.view_ssr[v];
    const double b = bowed.view_ssr[v];
    if (std::isfinite(a) && std::isfinite(b) && a > 0.0 && b > 0.0) {
      d.push_back(std::log(a / b));
    }
  }
  if (d.size() < 2) return 0.0;
  double mean = 0.0;
  for (double x : d) mean += x;
  mean /= d.size();
  double variance = 0.0;
  for (double x : d) variance += (x - mean) * (x - mean);
  variance /= (d.size() - 1);
  if (!(variance > 0.0)) return mean > 0.0 ? HUGE_VAL : 0.0;
  return mean / std::sqrt(variance / d.size());
}

// max(0, (a - b)^2 - |sa^2 - sb^2|): the part of a difference between
// nested fits that their noises do not explain.
double SpreadSquared(double a, double b, double sigma_a, double sigma_b) {
  return std::max(
      0.0, (a - b) * (a - b) - std::abs(sigma_a * sigma_a - sigma_b * sigma_b));
}

}  // namespace

Status DomeCalibrationOptions::Check() const {
  RCM_RETURN_IF_ERROR(internal::CheckSharedFitSettings(
      {huber_px, outlier_sigmas, min_outlier_threshold_px, max_outlier_rounds,
       max_num_iterations, min_corners_per_view, num_threads}));
  if (!std::isfinite(n) || n < RefractiveCamera::kMinIndex ||
      n > RefractiveCamera::kMaxIndex) {
    std::ostringstream message;
    message << "n = " << n << " is outside [1, 2]";
    return Status::Error(message.str());
  }
  if (!(evidence_sigmas > 0.0) || !std::isfinite(evidence_sigmas)) {
    return Status::Error("evidence_sigmas must be positive and finite");
  }
  if (folds < 0 || folds == 1) {
    return Status::Error("folds = " + std::to_string(folds) +
                         " must be 0 (no leave-out) or at least 2");
  }
  return Status::Ok();
}

StatusOr<DomeCalibration> CalibrateDome(
    const std::vector<StereoView>& views,
    const std::vector<DomeCameraInput>& cameras, const Rigid3d& cam1_from_cam0,
    const CalibrationTarget& target, const DomeCalibrationOptions& options,
    const AirTargetViews* air_views) {
  RCM_RETURN_IF_ERROR(options.Check());
  const int num_cameras = static_cast<int>(cameras.size());
  if (num_cameras != 1 && num_cameras != 2) {
    return Status::Error("a dome calibration takes 1 or 2 cameras, not " +
                         std::to_string(num_cameras));
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (const Status status = cameras[c].dome.Check(); !status.ok()) {
      return Status::Error("cam" + std::to_string(c) + ": " + status.message());
    }
  }
  DomeProblem description;
  description.cameras = &cameras;
  description.water_points = TargetPoints(target);
  description.water_basis = BoardWarpBasis(target);
  description.lenses_estimated = air_views != nullptr;
  if (air_views != nullptr) {
    description.air_points = TargetPoints(air_views->target);
    description.air_basis = BoardWarpBasis(air_views->target);
    description.air_same_board = air_views->same_board;
  }
  const int num_water_views = static_cast<int>(views.size());
  description.num_water_views = num_water_views;
  description.num_views =
      num_water_views +
      (air_views != nullptr ? static_cast<int>(air_views->views.size()) : 0);

  // Start: poses from the air lenses (the dome ignored), one camera's pose
  // moved to cam0.
  DomeState start;
  start.n = options.n;
  start.poses.assign(description.num_views, Pose{});
  start.cam_from_cam0.push_back(internal::PoseFromRigid(Rigid3d()));
  if (num_cameras == 2) {
    start.cam_from_cam0.push_back(internal::PoseFromRigid(cam1_from_cam0));
  }
  for (const DomeCameraInput& input : cameras) {
    const Eigen::Vector3d& c = input.dome.decentering;
    start.centre.push_back({c.x(), c.y(), c.z()});
    std::array<double, kMaxLensParams> lens{};
    std::copy(input.camera.params(),
              input.camera.params() + input.camera.num_params(), lens.begin());
    start.lens.push_back(lens);
  }
  std::vector<Corner> corners;
  int num_views_used = 0;
  int num_air_views_used = 0;
  // The views of one medium, from view index `offset` on.
  const auto add_views = [&](const std::vector<StereoView>& medium_views,
                             const std::vector<Eigen::Vector3d>& points,
                             int offset, int* used_count) -> Status {
    StatusOr<internal::UsedObservations> used = internal::SelectObservations(
        medium_views, static_cast<int>(points.size()),
        options.min_corners_per_view, true);
    if (!used.ok()) return used.status();
    for (int v = 0; v < static_cast<int>(medium_views.size()); ++v) {
      if (num_cameras == 1) (*used)[v][1] = nullptr;
      std::optional<Rigid3d> pose;
      for (int c = 0; c < num_cameras && !pose; ++c) {
        if ((*used)[v][c] == nullptr) continue;
        const std::optional<Rigid3d> cam_from_target =
            InitializeTargetPose(cameras[c].camera, points, *(*used)[v][c]);
        if (!cam_from_target) continue;
        pose = c == 0 ? *cam_from_target
                      : cam1_from_cam0.Inverse() * *cam_from_target;
      }
      if (!pose) continue;
      ++*used_count;
      start.poses[offset + v] = internal::PoseFromRigid(*pose);
      for (int c = 0; c < num_cameras; ++c) {
        const TargetObservation* observation = (*used)[v][c];
        if (observation == nullptr) continue;
        for (int k = 0; k < observation->size(); ++k) {
          corners.push_back({offset + v, c, observation->point_ids[k],
                             observation->pixels[k], true});
        }
      }
    }
    return Status::Ok();
  };
  RCM_RETURN_IF_ERROR(
      add_views(views, description.water_points, 0, &num_views_used));
  if (num_views_used < 3) {
    return Status::Error("only " + std::to_string(num_views_used) +
                         " views show the target with at least " +
                         std::to_string(options.min_corners_per_view) +
                         " corners and a pose; a dome calibration needs 3");
  }
  if (air_views != nullptr) {
    if (const Status status =
            add_views(air_views->views, description.air_points, num_water_views,
                      &num_air_views_used);
        !status.ok()) {
      return Status::Error("air views: " + status.message());
    }
    if (num_air_views_used < 3) {
      return Status::Error(
          "only " + std::to_string(num_air_views_used) +
          " air views show the target with a pose; estimating the lenses "
          "with the dome needs 3");
    }
  }

  // The candidates: the flat board, then (estimate_board_warp) the bowed
  // one from the flat one's solution.
  StatusOr<DomeFit> flat =
      FitDomeCandidate(description, corners, start, false, options);
  if (!flat.ok()) return flat.status();
  std::optional<DomeFit> bowed;
  if (options.estimate_board_warp) {
    StatusOr<DomeFit> fit = FitDomeCandidate(description, flat->corners,
                                             flat->state, true, options);
    if (!fit.ok()) return fit.status();
    bowed = std::move(*fit);
  }

  DomeCalibration result;
  result.num_cameras = num_cameras;
  result.n_estimated = options.estimate_n;
  result.candidates.push_back(CandidateOf(*flat, false, num_cameras));
  if (bowed)
    result.candidates.push_back(CandidateOf(*bowed, true, num_cameras));
  const DomeFit* chosen = &*flat;
  std::ostringstream rule;
  if (bowed) {
    const double evidence = BowEvidence(*flat, *bowed);
    DomeCandidate& flat_candidate = result.candidates[0];
    flat_candidate.evidence = std::max(0.0, evidence);
    flat_candidate.plausible = !(evidence > options.evidence_sigmas);
    rule.precision(3);
    // The bowed board nests the flat one: it is unbiased whether or not
    // the board bows, so it is the answer; the flat board, when the views
    // cannot rule it out, widens the sigmas by what its answer differs
    // beyond the two fits' noises.
    chosen = &*bowed;
    result.chosen = 1;
    if (flat_candidate.plausible) {
      rule << "bowed board; the flat board stays plausible (evidence "
           << evidence << " <= " << options.evidence_sigmas
           << " sigmas) and its spread is in sigma";
    } else {
      rule << "bowed board; the views rule the flat board out (evidence "
           << evidence << " > " << options.evidence_sigmas << " sigmas)";
    }
  } else {
    rule << "flat board (the bow is not estimated)";
  }
  result.rule = rule.str();

  const DomeFit& fit = *chosen;
  const DomeCandidate& best = result.candidates[result.chosen];
  // The other candidate, when it stays plausible, widens the sigmas by
  // its spread weighted as underwater_model_selection.h weighs it:
  // w = exp(-evidence^2 / 2) beside the chosen one's 1.
  const DomeCandidate* other = nullptr;
  double weight = 0.0;
  if (result.candidates.size() == 2) {
    const DomeCandidate& candidate = result.candidates[1 - result.chosen];
    if (candidate.plausible) {
      other = &candidate;
      weight = std::exp(-0.5 * candidate.evidence * candidate.evidence);
    }
  }
  const double share = weight / (1.0 + weight);

  // The leave-views-out replicates of the chosen model: the used water
  // views in g = min(folds, V) groups (the k-th in group k mod g), each left
  // out in turn and the rest refitted from the solution on its inliers.
  std::vector<bool> water_view_used(num_water_views, false);
  for (const Corner& corner : fit.corners) {
    if (corner.view < num_water_views) water_view_used[corner.view] = true;
  }
  std::vector<int> used_views;
  for (int v = 0; v < num_water_views; ++v) {
    if (water_view_used[v]) used_views.push_back(v);
  }
  const int groups = std::min<int>(options.folds, used_views.size());
  // Per replicate: each camera's decentering, then n.
  std::vector<Eigen::VectorXd> replicates;
  if (options.folds >= 2 && groups >= 2) {
    for (int g = 0; g < groups; ++g) {
      std::vector<bool> left_out(description.num_views, false);
      for (size_t k = g; k < used_views.size(); k += groups) {
        left_out[used_views[k]] = true;
      }
      std::vector<Corner> kept;
      for (const Corner& corner : fit.corners) {
        if (corner.inlier && !left_out[corner.view]) kept.push_back(corner);
      }
      const StatusOr<DomeFit> refit = FitDomeCandidate(
          description, kept, fit.state, result.chosen == 1 && bowed, options,
          &fit.view_weight);
      if (!refit.ok()) {
        ++result.failed_folds;
        continue;
      }
      Eigen::VectorXd replicate(3 * num_cameras + 1);
      for (int c = 0; c < num_cameras; ++c) {
        const std::array<double, 3>& centre = refit->state.centre[c];
        replicate.segment<3>(3 * c) << centre[0], centre[1], centre[2];
      }
      replicate[3 * num_cameras] = refit->state.n;
      replicates.push_back(replicate);
    }
    result.folds = groups;
  }
  const int num_replicates = static_cast<int>(replicates.size());
  const bool leave_out = num_replicates >= 2;
  const Eigen::VectorXd jackknife_sigma =
      leave_out ? internal::JackknifeSigma(replicates)
                : Eigen::VectorXd::Zero(3 * num_cameras + 1);

  for (int c = 0; c < num_cameras; ++c) {
    result.decentering.push_back(best.decentering[c]);
    const int o = fit.centre_offset[c];
    result.decentering_covariance.push_back(fit.covariance.block<3, 3>(o, o));
    Eigen::Vector3d noise = best.decentering_sigma[c];
    const Eigen::Vector3d leave_out_sigma = jackknife_sigma.segment<3>(3 * c);
    for (int i = 0; leave_out && i < 3; ++i) {
      noise[i] =
          JackknifeNoiseSigma(noise[i], leave_out_sigma[i], num_replicates);
    }
    result.decentering_sigma_leave_out.push_back(leave_out_sigma);
    result.decentering_sigma_noise.push_back(noise);
    Eigen::Vector3d model = Eigen::Vector3d::Zero();
    if (other != nullptr) {
      for (int i = 0; i < 3; ++i) {
        model[i] =
            std::sqrt(share * SpreadSquared(other->decentering[c][i],
                                            best.decentering[c][i],
                                            other->decentering_sigma[c][i],
                                            best.decentering_sigma[c][i]));
      }
    }
    result.decentering_sigma_model.push_back(model);
    result.decentering_sigma.push_back(
        (noise.array().square() + model.array().square()).sqrt());
    Eigen::Vector3d correlation = Eigen::Vector3d::Zero();
    if (fit.n_offset >= 0) {
      for (int i = 0; i < 3; ++i) {
        const double denominator =
            std::sqrt(fit.covariance(fit.n_offset, fit.n_offset) *
                      fit.covariance(o + i, o + i));
        if (denominator > 0.0) {
          correlation[i] = fit.covariance(fit.n_offset, o + i) / denominator;
        }
      }
    }
    result.correlation_n_decentering.push_back(correlation);
  }
  result.n = best.n;
  if (options.estimate_n) {
    result.sigma_n_model =
        other != nullptr
            ? std::sqrt(share * SpreadSquared(other->n, best.n, other->sigma_n,
                                              best.sigma_n))
            : 0.0;
    double noise = best.sigma_n;
    if (leave_out) {
      result.sigma_n_leave_out = jackknife_sigma[3 * num_cameras];
      noise =
          JackknifeNoiseSigma(noise, result.sigma_n_leave_out, num_replicates);
    }
    result.sigma_n = std::hypot(noise, result.sigma_n_model);
  }
  if (fit.warp_offset >= 0) {
    result.board_warp_estimated = true;
    result.board_warp = Eigen::Vector2d(fit.state.warp[0], fit.state.warp[1]);
    result.board_warp_sigma =
        fit.covariance.block<2, 2>(fit.warp_offset, fit.warp_offset)
            .diagonal()
            .cwiseSqrt();
  }
  result.cam0_from_target = internal::UsedViewPoses(
      std::vector<Pose>(fit.state.poses.begin(),
                        fit.state.poses.begin() + num_water_views),
      water_view_used);
  result.num_views_used = num_views_used;
  result.num_air_views_used = num_air_views_used;
  // The water corners' statistics (the air views' apart).
  result.rms_px_per_camera.assign(num_cameras, 0.0);
  std::vector<int> counts(num_cameras, 0);
  double water_squares = 0.0, inlier_squares = 0.0, air_squares = 0.0;
  int water_count = 0, air_count = 0;
  for (const CornerResidual& corner : fit.statistics.corners) {
    const bool finite = corner.residual.allFinite();
    const double squared = finite ? corner.residual.squaredNorm() : 0.0;
    if (corner.view >= num_water_views) {
      air_squares += squared;
      air_count += finite ? 1 : 0;
      continue;
    }
    result.corners.push_back(corner);
    if (corner.inlier) {
      ++result.num_inliers;
      inlier_squares += squared;
    } else {
      ++result.num_outliers;
    }
    if (!finite) continue;
    water_squares += squared;
    ++water_count;
    result.rms_px_per_camera[corner.camera] += squared;
    ++counts[corner.camera];
  }
  for (int c = 0; c < num_cameras; ++c) {
    result.rms_px_per_camera[c] =
        counts[c] > 0 ? std::sqrt(result.rms_px_per_camera[c] / counts[c])
                      : 0.0;
  }
  result.rms_px =
      water_count > 0 ? std::sqrt(water_squares / water_count) : 0.0;
  result.inlier_rms_px = result.num_inliers > 0
                             ? std::sqrt(inlier_squares / result.num_inliers)
                             : 0.0;
  result.air_rms_px = air_count > 0 ? std::sqrt(air_squares / air_count) : 0.0;
  result.lenses_estimated = description.lenses_estimated;
  for (int c = 0; c < num_cameras; ++c) {
    StatusOr<Camera> lens =
        cameras[c].camera.WithParams(fit.state.lens[c].data());
    if (!lens.ok()) {
      return Status::Error(
          "cam" + std::to_string(c) +
          ": the estimated lens is invalid: " + lens.status().message());
    }
    result.cameras.push_back(*lens);
  }
  result.pixel_sigma = fit.pixel_sigma;
  result.num_parameters = fit.num_parameters;
  result.num_outlier_views = fit.num_outlier_views;
  result.view_weights.assign(num_water_views, 0.0);
  for (const Corner& corner : fit.corners) {
    if (corner.inlier && corner.view < num_water_views) {
      result.view_weights[corner.view] = fit.view_weight[corner.view];
    }
  }

  // The conventional model, the air lens model free, on the same corners.
  if (options.fit_conventional_model) {
    ConventionalFit& conventional = result.conventional;
    conventional.model = cameras[0].camera.model();
    const StereoCalibrationOptions free_fit = internal::ConventionalFitOptions(
        conventional.model, options, result.board_warp_estimated);
    const Camera& cam0 = cameras[0].camera;
    const auto fit_freely = [&]() -> StatusOr<StereoCalibration> {
      if (num_cameras == 1) {
        std::vector<StereoView> left_views = views;
        for (StereoView& view : left_views) view.right.reset();
        return CalibrateMono(target, left_views, {cam0.width(), cam0.height()},
                             free_fit);
      }
      const Camera& cam1 = cameras[1].camera;
      return CalibrateStereo(target, views, {cam0.width(), cam0.height()},
                             {cam1.width(), cam1.height()}, free_fit);
    };
    const StatusOr<StereoCalibration> calibration = fit_freely();
    if (calibration.ok()) {
      conventional.ok = true;
      conventional.rms_px = calibration->rms_px;
      conventional.inlier_rms_px = calibration->inlier_rms_px;
      conventional.pixel_sigma = calibration->pixel_sigma;
      conventional.num_parameters = calibration->num_parameters;
    } else {
      conventional.error = calibration.status().message();
    }
  }
  return result;
}

}  // namespace rcm::calib
