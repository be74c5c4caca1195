#include "rcm/calib/dome_calibration.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "board_bundle_adjustment.h"
#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_initialization.h"
#include "rcm/calib/dome_reprojection_error.h"
#include "rcm/calib/mono_calibration.h"
#include "rcm/camera/refractive_camera.h"

namespace rcm::calib {
namespace {

using internal::Corner;
using internal::Pose;

// The unknowns of one candidate's problem.
struct DomeState {
  double n = 1.333;
  std::vector<Pose> poses;                    // per view
  std::vector<Pose> cam_from_cam0;            // per camera, held
  std::vector<std::array<double, 3>> centre;  // per camera
  std::array<double, 2> warp{0.0, 0.0};
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
};

ceres::CostFunction* MakeDomeCost(const Camera& camera, const DomePort& dome,
                                  const Eigen::Vector3d& point,
                                  const Eigen::Vector2d& basis,
                                  const Eigen::Vector2d& pixel) {
  std::array<double, kMaxLensParams> lens{};
  std::copy(camera.params(), camera.params() + camera.num_params(),
            lens.begin());
  RCM_LENS_MODEL_SWITCH(camera.model(),
                        return DomeReprojectionError<LensModel>::Create(
                            lens, dome, point, basis, pixel););
  return nullptr;
}

StatusOr<DomeFit> FitDomeCandidate(const std::vector<DomeCameraInput>& cameras,
                                   const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector2d>& basis,
                                   const std::vector<Corner>& start_corners,
                                   const DomeState& start, bool board_warp,
                                   int num_views,
                                   const DomeCalibrationOptions& options) {
  DomeFit fit;
  fit.state = start;
  fit.corners = start_corners;
  if (!board_warp) fit.state.warp = {0.0, 0.0};
  DomeState& state = fit.state;
  const int num_cameras = static_cast<int>(cameras.size());
  std::vector<bool> view_used(num_views, false);
  for (const Corner& corner : fit.corners) view_used[corner.view] = true;

  const auto add_residuals = [&](double huber_px, ceres::Problem* problem) {
    for (const Corner& corner : fit.corners) {
      if (!corner.inlier) continue;
      problem->AddResidualBlock(
          MakeDomeCost(cameras[corner.camera].camera,
                       cameras[corner.camera].dome, points[corner.point_id],
                       basis[corner.point_id], corner.pixel),
          huber_px > 0.0 ? new ceres::HuberLoss(huber_px) : nullptr, &state.n,
          state.poses[corner.view].data(),
          state.cam_from_cam0[corner.camera].data(),
          state.centre[corner.camera].data(), state.warp.data());
    }
    problem->SetParameterBlockConstant(&state.n);
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
    if (!board_warp && problem->HasParameterBlock(state.warp.data())) {
      problem->SetParameterBlockConstant(state.warp.data());
    }
  };
  const auto residual = [&](const Corner& corner) -> Eigen::Vector2d {
    std::unique_ptr<ceres::CostFunction> cost(MakeDomeCost(
        cameras[corner.camera].camera, cameras[corner.camera].dome,
        points[corner.point_id], basis[corner.point_id], corner.pixel));
    const double* blocks[5] = {&state.n, state.poses[corner.view].data(),
                               state.cam_from_cam0[corner.camera].data(),
                               state.centre[corner.camera].data(),
                               state.warp.data()};
    Eigen::Vector2d e;
    if (!cost->Evaluate(blocks, e.data(), nullptr)) {
      return Eigen::Vector2d::Constant(std::nan(""));
    }
    return e;
  };

  internal::OutlierRejectionOptions rejection;
  rejection.huber_px = options.huber_px;
  rejection.outlier_sigmas = options.outlier_sigmas;
  rejection.min_outlier_threshold_px = options.min_outlier_threshold_px;
  rejection.max_outlier_rounds = options.max_outlier_rounds;
  ceres::Problem problem;
  RCM_RETURN_IF_ERROR(internal::FitWithOutlierRejection(
      rejection,
      internal::BoardSolverOptions(options.max_num_iterations,
                                   options.num_threads),
      add_residuals, residual, &fit.corners, &problem));
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
  if (!internal::JointCovariance(blocks, true, options.num_threads, &problem,
                                 &covariance)) {
    return Status::Error(
        "the decentering's covariance cannot be computed (the views do "
        "not determine it: add views at other distances and angles)");
  }
  fit.covariance = covariance * (fit.pixel_sigma * fit.pixel_sigma);
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
  return Status::Ok();
}

StatusOr<DomeCalibration> CalibrateDome(
    const std::vector<StereoView>& views,
    const std::vector<DomeCameraInput>& cameras, const Rigid3d& cam1_from_cam0,
    const CalibrationTarget& target, const DomeCalibrationOptions& options) {
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
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  const std::vector<Eigen::Vector2d> basis = BoardWarpBasis(target);
  const int num_points = static_cast<int>(points.size());
  StatusOr<internal::UsedObservations> used = internal::SelectObservations(
      views, num_points, options.min_corners_per_view, true);
  if (!used.ok()) return used.status();
  const int num_views = static_cast<int>(views.size());
  if (num_cameras == 1) {
    for (auto& sides : *used) sides[1] = nullptr;
  }

  // Start: poses from the air cameras (the dome ignored), then one camera's
  // pose moved to cam0.
  DomeState start;
  start.n = options.n;
  start.poses.assign(num_views, Pose{});
  start.cam_from_cam0.push_back(internal::PoseFromRigid(Rigid3d()));
  if (num_cameras == 2) {
    start.cam_from_cam0.push_back(internal::PoseFromRigid(cam1_from_cam0));
  }
  for (const DomeCameraInput& input : cameras) {
    const Eigen::Vector3d& c = input.dome.decentering;
    start.centre.push_back({c.x(), c.y(), c.z()});
  }
  std::vector<Corner> corners;
  int num_views_used = 0;
  for (int v = 0; v < num_views; ++v) {
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
    ++num_views_used;
    start.poses[v] = internal::PoseFromRigid(*pose);
    for (int c = 0; c < num_cameras; ++c) {
      const TargetObservation* observation = (*used)[v][c];
      if (observation == nullptr) continue;
      for (int k = 0; k < observation->size(); ++k) {
        corners.push_back(
            {v, c, observation->point_ids[k], observation->pixels[k], true});
      }
    }
  }
  if (num_views_used < 3) {
    return Status::Error("only " + std::to_string(num_views_used) +
                         " views show the target with at least " +
                         std::to_string(options.min_corners_per_view) +
                         " corners and a pose; a dome calibration needs 3");
  }

  // The candidates: the flat board, then (estimate_board_warp) the bowed
  // one from the flat one's solution.
  StatusOr<DomeFit> flat = FitDomeCandidate(cameras, points, basis, corners,
                                            start, false, num_views, options);
  if (!flat.ok()) return flat.status();
  std::optional<DomeFit> bowed;
  if (options.estimate_board_warp) {
    StatusOr<DomeFit> fit =
        FitDomeCandidate(cameras, points, basis, flat->corners, flat->state,
                         true, num_views, options);
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
  for (int c = 0; c < num_cameras; ++c) {
    result.decentering.push_back(best.decentering[c]);
    const int o = fit.centre_offset[c];
    result.decentering_covariance.push_back(fit.covariance.block<3, 3>(o, o));
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
        (best.decentering_sigma[c].array().square() + model.array().square())
            .sqrt());
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
    result.sigma_n = std::hypot(best.sigma_n, result.sigma_n_model);
  }
  if (fit.warp_offset >= 0) {
    result.board_warp_estimated = true;
    result.board_warp = Eigen::Vector2d(fit.state.warp[0], fit.state.warp[1]);
    result.board_warp_sigma =
        fit.covariance.block<2, 2>(fit.warp_offset, fit.warp_offset)
            .diagonal()
            .cwiseSqrt();
  }
  std::vector<bool> view_used(num_views, false);
  for (const Corner& corner : fit.corners) view_used[corner.view] = true;
  result.cam0_from_target = internal::UsedViewPoses(fit.state.poses, view_used);
  result.num_views_used = num_views_used;
  internal::ResidualStatistics statistics = fit.statistics;
  result.rms_px_per_camera.assign(num_cameras, 0.0);
  std::vector<int> counts(num_cameras, 0);
  for (const CornerResidual& corner : statistics.corners) {
    if (!corner.residual.allFinite()) continue;
    result.rms_px_per_camera[corner.camera] += corner.residual.squaredNorm();
    ++counts[corner.camera];
  }
  for (int c = 0; c < num_cameras; ++c) {
    result.rms_px_per_camera[c] =
        counts[c] > 0 ? std::sqrt(result.rms_px_per_camera[c] / counts[c])
                      : 0.0;
  }
  internal::StoreResidualStatistics(std::move(statistics), &result);
  result.pixel_sigma = fit.pixel_sigma;
  result.num_parameters = fit.num_parameters;

  // The conventional model, the air lens model free, on the same corners.
  if (options.fit_conventional_model) {
    ConventionalFit& conventional = result.conventional;
    conventional.model = cameras[0].camera.model();
    StereoCalibrationOptions free_fit;
    free_fit.model = conventional.model;
    free_fit.huber_px = options.huber_px;
    free_fit.outlier_sigmas = options.outlier_sigmas;
    free_fit.min_outlier_threshold_px = options.min_outlier_threshold_px;
    free_fit.max_outlier_rounds = options.max_outlier_rounds;
    free_fit.max_num_iterations = options.max_num_iterations;
    free_fit.min_corners_per_view = options.min_corners_per_view;
    free_fit.compute_covariance = false;
    free_fit.estimate_board_warp = result.board_warp_estimated;
    free_fit.num_threads = options.num_threads;
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
