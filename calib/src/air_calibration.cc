#include "air_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "board_bundle_adjustment.h"
#include "rcm/calib/board_reprojection_error.h"
#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_initialization.h"
#include "rcm/util/number_format.h"

namespace rcm::calib {
namespace {

using internal::Corner;
using internal::Pose;
using internal::PoseFromRigid;
using internal::RigidFromPose;

// The unknowns, as Ceres sees them.
struct Parameters {
  std::array<std::array<double, kMaxLensParams>, 2> lens{};
  Pose cam1_from_cam0{};
  std::vector<Pose> cam0_from_target;  // per view (unused views ignored)
  std::array<double, 2> board_warp{};  // [warp_x, warp_y] (m), board_warp.h
};

// The target's corners and their warp basis.
struct Board {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> warp_basis;
};

template <typename LensModel>
ceres::CostFunction* MakeCost(const Corner& corner, const Board& board) {
  const Eigen::Vector3d& point = board.points[corner.point_id];
  const Eigen::Vector2d& basis = board.warp_basis[corner.point_id];
  if (corner.camera == 0) {
    return Cam0WarpedBoardReprojectionError<LensModel>::Create(point, basis,
                                                               corner.pixel);
  }
  return Cam1WarpedBoardReprojectionError<LensModel>::Create(point, basis,
                                                             corner.pixel);
}

ceres::CostFunction* CostFor(LensModelId model, const Corner& corner,
                             const Board& board) {
  RCM_LENS_MODEL_SWITCH(model, return MakeCost<LensModel>(corner, board);)
  LOG(FATAL) << "unknown lens model";
  return nullptr;
}

// Adds the residuals of the inliers to `problem`; the warp is held at its
// value (0) unless `estimate_warp`.
void AddResiduals(LensModelId model, const std::vector<Corner>& corners,
                  const Board& board, bool estimate_warp, double huber_px,
                  Parameters* parameters, ceres::Problem* problem) {
  double* warp = parameters->board_warp.data();
  for (const Corner& corner : corners) {
    if (!corner.inlier) continue;
    ceres::LossFunction* loss =
        huber_px > 0.0 ? new ceres::HuberLoss(huber_px) : nullptr;
    double* lens = parameters->lens[corner.camera].data();
    double* pose = parameters->cam0_from_target[corner.view].data();
    ceres::CostFunction* cost = CostFor(model, corner, board);
    if (corner.camera == 0) {
      problem->AddResidualBlock(cost, loss, lens, pose, warp);
    } else {
      problem->AddResidualBlock(cost, loss, lens, pose,
                                parameters->cam1_from_cam0.data(), warp);
    }
  }
  if (!estimate_warp && problem->HasParameterBlock(warp)) {
    problem->SetParameterBlockConstant(warp);
  }
  // The unified models' coefficients stay in their ranges.
  for (auto& lens : parameters->lens) {
    if (!problem->HasParameterBlock(lens.data())) continue;
    for (const DistortionBound& bound : DistortionBounds(model)) {
      problem->SetParameterLowerBound(lens.data(), 4 + bound.index,
                                      bound.lower);
      problem->SetParameterUpperBound(lens.data(), 4 + bound.index,
                                      bound.upper);
    }
  }
}

// A unified model's coefficient that ended at an end of its range (the
// solver's box, DistortionBounds) is an error, not a camera: the fit
// wanted to go beyond what the model can represent, so the lens it found
// is not a minimum of the corners' errors, and a covariance taken at an
// active bound means nothing. 1e-9 is far below any coefficient's sigma
// and far above the solver's projection onto the box, which lands on the
// bound itself.
Status CheckNotPinned(LensModelId model, int camera, const double* lens) {
  constexpr double kPinned = 1e-9;
  for (const DistortionBound& bound : DistortionBounds(model)) {
    const double value = lens[4 + bound.index];
    const bool at_lower = value <= bound.lower + kPinned;
    if (!at_lower && value < bound.upper - kPinned) continue;
    const std::string others = model == LensModelId::kEucm
                                   ? "ds or equidistant"
                                   : "eucm or equidistant";
    return Status::Error(
        "the calibration failed: cam" + std::to_string(camera) + "'s " +
        std::string(LensModelName(model)) + " " + bound.name + " ended at " +
        FormatDouble(at_lower ? bound.lower : bound.upper) +
        ", the end of its range, so the model does not fit these views " +
        "(try --model " + others + ", or views that reach the image corners)");
  }
  return Status::Ok();
}

// The residual of one corner at the current parameters; NaN when the
// corner is behind its camera.
Eigen::Vector2d Residual(LensModelId model, const Corner& corner,
                         const Board& board, const Parameters& parameters) {
  const Eigen::Vector3d& point = board.points[corner.point_id];
  const Eigen::Vector2d& basis = board.warp_basis[corner.point_id];
  const double* lens = parameters.lens[corner.camera].data();
  const double* pose = parameters.cam0_from_target[corner.view].data();
  const double* warp = parameters.board_warp.data();
  Eigen::Vector2d residual;
  bool ok = false;
  RCM_LENS_MODEL_SWITCH(
      model,
      if (corner.camera == 0) {
        ok = Cam0WarpedBoardReprojectionError<LensModel>(
            point, basis, corner.pixel)(lens, pose, warp, residual.data());
      } else {
        ok = Cam1WarpedBoardReprojectionError<LensModel>(
            point, basis, corner.pixel)(lens, pose,
                                        parameters.cam1_from_cam0.data(), warp,
                                        residual.data());
      } break;)
  if (!ok) residual.setConstant(std::numeric_limits<double>::quiet_NaN());
  return residual;
}

// sigma^2 (J^T J)^-1 of every unknown of `problem` (header), dense, with
// the layout of FullCovariance; false when J^T J is not positive definite.
// J^T J is scaled to unit diagonal before the Cholesky factorization
// (D^-1/2 J^T J D^-1/2), which keeps its condition number that of the
// geometry rather than of the parameters' units (px vs rad vs m).
bool ComputeFullCovariance(const std::vector<bool>& view_used, int num_cameras,
                           int num_lens_params, bool estimate_warp,
                           double variance, Parameters* parameters,
                           ceres::Problem* problem, FullCovariance* out,
                           Eigen::VectorXd* values) {
  std::vector<double*> blocks;
  std::vector<int> sizes;
  FullCovariance layout;
  layout.num_lens_params = num_lens_params;
  int total = 0;
  const auto add = [&](double* block, int size) {
    blocks.push_back(block);
    sizes.push_back(size);
    total += size;
    return total - size;
  };
  layout.lens_offset = {-1, -1};
  for (int c = 0; c < num_cameras; ++c) {
    layout.lens_offset[c] = add(parameters->lens[c].data(), num_lens_params);
  }
  layout.extrinsics_offset =
      num_cameras == 2 ? add(parameters->cam1_from_cam0.data(), 6) : -1;
  layout.pose_offset.assign(view_used.size(), -1);
  for (size_t v = 0; v < view_used.size(); ++v) {
    if (view_used[v] &&
        problem->HasParameterBlock(parameters->cam0_from_target[v].data())) {
      layout.pose_offset[v] = add(parameters->cam0_from_target[v].data(), 6);
    }
  }
  if (estimate_warp) layout.warp_offset = add(parameters->board_warp.data(), 2);
  for (double* block : blocks) {
    if (!problem->HasParameterBlock(block)) return false;
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.apply_loss_function = false;
  evaluate.num_threads = 1;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) {
    return false;
  }
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(total, total);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int a = crs.rows[r]; a < crs.rows[r + 1]; ++a) {
      for (int b = crs.rows[r]; b < crs.rows[r + 1]; ++b) {
        information(crs.cols[a], crs.cols[b]) += crs.values[a] * crs.values[b];
      }
    }
  }
  const Eigen::VectorXd diagonal = information.diagonal();
  if (!(diagonal.minCoeff() > 0.0)) return false;
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled =
      scale.asDiagonal() * information * scale.asDiagonal();
  Eigen::MatrixXd inverse;
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() == Eigen::Success) {
    inverse = llt.solve(Eigen::MatrixXd::Identity(total, total));
  } else {
    // Too ill-conditioned for the plain factorization in double precision
    // (the rational model's k1..k6 on views that do not reach the image
    // corners: its numerator and denominator nearly share a factor). The
    // pivoted LDL^T factors it when every pivot is positive; the
    // near-degenerate directions then get the large variances the data
    // leave them, and they do not move a projection.
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(scaled);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
        !(ldlt.vectorD().minCoeff() > 0.0)) {
      return false;
    }
    inverse = ldlt.solve(Eigen::MatrixXd::Identity(total, total));
  }
  layout.matrix = variance * scale.asDiagonal() * inverse * scale.asDiagonal();
  if (!layout.matrix.allFinite()) return false;
  values->resize(total);
  for (size_t b = 0, offset = 0; b < blocks.size(); offset += sizes[b], ++b) {
    for (int i = 0; i < sizes[b]; ++i) (*values)[offset + i] = blocks[b][i];
  }
  *out = std::move(layout);
  return true;
}

}  // namespace

namespace internal {

StatusOr<StereoCalibration> CalibrateInAir(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const std::vector<ImageSize>& sizes,
    const StereoCalibrationOptions& options) {
  if (Status status = options.Check(); !status.ok()) return status;
  const int num_cameras = static_cast<int>(sizes.size());
  CHECK(num_cameras == 1 || num_cameras == 2) << num_cameras;
  for (int c = 0; c < num_cameras; ++c) {
    if (Status status = Camera::CheckImageSize(sizes[c].width, sizes[c].height);
        !status.ok()) {
      return status.WithContext("cam" + std::to_string(c));
    }
  }
  const std::vector<Eigen::Vector3d> target_points = TargetPoints(target);
  const Board board{target_points, BoardWarpBasis(target)};
  const int num_points = static_cast<int>(target_points.size());
  const int num_views = static_cast<int>(views.size());

  // Which observations take part: enough corners, and (unless single-
  // camera views are wanted) both cameras.
  StatusOr<internal::UsedObservations> selected = internal::SelectObservations(
      views, num_points, options.min_corners_per_view,
      options.use_single_camera_views || num_cameras == 1);
  if (!selected.ok()) return selected.status();
  const internal::UsedObservations& used = *selected;

  // Intrinsics, per camera.
  std::optional<Camera> cameras[2];
  for (int c = 0; c < num_cameras; ++c) {
    std::vector<const TargetObservation*> observations;
    for (int v = 0; v < num_views; ++v) {
      if (used[v][c] != nullptr) observations.push_back(used[v][c]);
    }
    constexpr int kMinViews = 3;
    if (static_cast<int>(observations.size()) < kMinViews) {
      return Status::Error(
          "cam" + std::to_string(c) + " sees the target with at least " +
          std::to_string(options.min_corners_per_view) + " corners in " +
          std::to_string(observations.size()) + " view(s); at least " +
          std::to_string(kMinViews) + " are needed");
    }
    StatusOr<Camera> camera =
        InitializeCamera(options.model, sizes[c].width, sizes[c].height,
                         target_points, observations);
    if (!camera.ok()) {
      return camera.status().WithContext("cam" + std::to_string(c));
    }
    cameras[c] = *camera;
  }

  // Board poses per camera, then the extrinsics from the stereo views (a
  // pair only).
  std::vector<std::array<std::optional<Rigid3d>, 2>> camera_from_target(
      num_views);
  std::vector<Rigid3d> relative;
  for (int v = 0; v < num_views; ++v) {
    for (int c = 0; c < num_cameras; ++c) {
      if (used[v][c] == nullptr) continue;
      camera_from_target[v][c] =
          InitializeTargetPose(*cameras[c], target_points, *used[v][c]);
    }
    if (camera_from_target[v][0] && camera_from_target[v][1]) {
      relative.push_back(*camera_from_target[v][1] *
                         camera_from_target[v][0]->Inverse());
    }
  }
  Rigid3d cam1_from_cam0_start;
  if (num_cameras == 2) {
    if (relative.empty()) {
      return Status::Error(
          "no view shows the target in both images (with a pose in each), so "
          "the extrinsics cam1_from_cam0 cannot be calibrated");
    }
    cam1_from_cam0_start = MedianRigid(relative);
    if (!(cam1_from_cam0_start.translation.norm() > 0.0)) {
      return Status::Error("the initial extrinsics have a zero baseline");
    }
  }

  Parameters parameters;
  parameters.cam0_from_target.resize(num_views);
  for (int c = 0; c < num_cameras; ++c) {
    std::copy(cameras[c]->params(),
              cameras[c]->params() + cameras[c]->num_params(),
              parameters.lens[c].begin());
  }
  parameters.cam1_from_cam0 = PoseFromRigid(cam1_from_cam0_start);

  // Filled with the solution below. One camera: cam1 holds a copy of cam0
  // (StereoCalibration::num_cameras).
  StereoCalibration result(*cameras[0], *cameras[num_cameras - 1]);
  result.num_cameras = num_cameras;
  std::vector<Corner> corners;
  std::vector<bool> view_used(num_views, false);
  for (int v = 0; v < num_views; ++v) {
    std::optional<Rigid3d> cam0_from_target = camera_from_target[v][0];
    if (!cam0_from_target && camera_from_target[v][1]) {
      cam0_from_target =
          cam1_from_cam0_start.Inverse() * *camera_from_target[v][1];
    }
    if (!cam0_from_target) continue;
    view_used[v] = true;
    parameters.cam0_from_target[v] = PoseFromRigid(*cam0_from_target);
    for (int c = 0; c < num_cameras; ++c) {
      // A camera whose own pose failed still has a usable view when the
      // other camera posed the board.
      if (used[v][c] == nullptr) continue;
      for (int k = 0; k < used[v][c]->size(); ++k) {
        corners.push_back(
            {v, c, used[v][c]->point_ids[k], used[v][c]->pixels[k], true});
      }
    }
  }
  const int num_views_used =
      static_cast<int>(std::count(view_used.begin(), view_used.end(), true));
  const int num_lens_params = cameras[0]->num_params();
  const int num_warp_params = options.estimate_board_warp ? 2 : 0;
  const int num_extrinsics_params = num_cameras == 2 ? 6 : 0;
  const int num_parameters = num_cameras * num_lens_params +
                             num_extrinsics_params + 6 * num_views_used +
                             num_warp_params;

  double initial_sum = 0.0;
  for (const Corner& corner : corners) {
    initial_sum +=
        Residual(options.model, corner, board, parameters).squaredNorm();
  }
  result.initial_rms_px =
      corners.empty() ? 0.0 : std::sqrt(initial_sum / corners.size());

  // Robust solves with outlier rejection, then least squares on the inliers.
  const auto residual = [&](const Corner& corner) {
    return Residual(options.model, corner, board, parameters);
  };
  const ceres::Solver::Options solver_options = internal::BoardSolverOptions(
      options.max_num_iterations, options.num_threads);
  ceres::Problem problem;
  RCM_RETURN_IF_ERROR(internal::FitWithOutlierRejection(
      {options.huber_px, options.outlier_sigmas,
       options.min_outlier_threshold_px, options.max_outlier_rounds},
      solver_options,
      [&](double huber_px, ceres::Problem* problem) {
        AddResiduals(options.model, corners, board, options.estimate_board_warp,
                     huber_px, &parameters, problem);
      },
      residual, &corners, &problem));

  // The result.
  for (int c = 0; c < num_cameras; ++c) {
    const double* lens = parameters.lens[c].data();
    RCM_RETURN_IF_ERROR(CheckNotPinned(options.model, c, lens));
    const std::vector<double> distortion(lens + 4, lens + num_lens_params);
    StatusOr<Camera> camera =
        Camera::Create(options.model, sizes[c].width, sizes[c].height,
                       {lens[0], lens[1], lens[2], lens[3]}, distortion);
    if (!camera.ok()) {
      return Status::Error("bundle adjustment diverged: cam" +
                           std::to_string(c) + ": " +
                           camera.status().message());
    }
    (c == 0 ? result.cam0 : result.cam1) = CameraCalibration(*camera);
  }
  if (num_cameras == 1) result.cam1 = result.cam0;
  result.board_warp_estimated = options.estimate_board_warp;
  result.board_warp =
      Eigen::Vector2d(parameters.board_warp[0], parameters.board_warp[1]);
  if (num_cameras == 2) {
    result.cam1_from_cam0 = RigidFromPose(parameters.cam1_from_cam0.data());
    result.baseline = result.cam1_from_cam0.translation.norm();
    if (!(result.baseline > 0.0) || !std::isfinite(result.baseline)) {
      return Status::Error("bundle adjustment diverged: the baseline is " +
                           FormatDouble(result.baseline));
    }
  }
  result.cam0_from_target =
      internal::UsedViewPoses(parameters.cam0_from_target, view_used);
  // Each corner's final residual, evaluated once.
  internal::ResidualStatistics statistics =
      internal::SummarizeResiduals(corners, residual);
  const double inlier_sum = statistics.inlier_ssr;
  internal::StoreResidualStatistics(std::move(statistics), &result);
  result.num_views_used = num_views_used;
  for (int v = 0; v < num_views; ++v) {
    if (num_cameras == 2 && view_used[v] && used[v][0] != nullptr &&
        used[v][1] != nullptr) {
      ++result.num_stereo_views;
    }
  }
  result.num_parameters = num_parameters;
  const int redundancy = 2 * result.num_inliers - num_parameters;
  if (redundancy <= 0) {
    return Status::Error(
        "too few corners: " + std::to_string(result.num_inliers) +
        " inlier corners for " + std::to_string(num_parameters) + " unknowns");
  }
  result.pixel_sigma = std::sqrt(inlier_sum / redundancy);

  if (options.compute_covariance) {
    // The lenses, the extrinsics (a pair) and the warp, in this order.
    std::vector<internal::CovarianceBlockRef> blocks;
    for (int c = 0; c < num_cameras; ++c) {
      blocks.push_back({parameters.lens[c].data(), num_lens_params});
    }
    if (num_cameras == 2) {
      blocks.push_back({parameters.cam1_from_cam0.data(), 6});
    }
    if (options.estimate_board_warp) {
      blocks.push_back({parameters.board_warp.data(), 2});
    }
    Eigen::MatrixXd covariance;
    if (!internal::JointCovariance(blocks, /*cross_blocks=*/false,
                                   options.num_threads, &problem,
                                   &covariance)) {
      return Status::Error(
          "the calibration is degenerate: its covariance cannot be computed "
          "(the views do not constrain every parameter; add views with the "
          "target tilted and near the image corners)");
    }
    const double variance = result.pixel_sigma * result.pixel_sigma;
    CameraCalibration* out[2] = {&result.cam0, &result.cam1};
    for (int c = 0; c < num_cameras; ++c) {
      out[c]->covariance.setZero();
      out[c]->covariance.topLeftCorner(num_lens_params, num_lens_params) =
          variance * covariance.block(c * num_lens_params, c * num_lens_params,
                                      num_lens_params, num_lens_params);
      for (int i = 0; i < kMaxLensParams; ++i) {
        out[c]->sigma[i] = std::sqrt(out[c]->covariance(i, i));
      }
    }
    if (num_cameras == 1) result.cam1 = result.cam0;
    if (options.estimate_board_warp) {
      result.board_warp_covariance =
          variance * covariance.bottomRightCorner<2, 2>();
      result.board_warp_sigma =
          result.board_warp_covariance.diagonal().cwiseSqrt();
    }
    if (num_cameras == 2) {
      Eigen::Matrix<double, 6, 6> jacobian =
          Eigen::Matrix<double, 6, 6>::Identity();
      jacobian.topLeftCorner<3, 3>() = internal::LeftPerturbationFromAngleAxis(
          parameters.cam1_from_cam0.data());
      const Eigen::Matrix<double, 6, 6> extrinsics =
          covariance.block<6, 6>(2 * num_lens_params, 2 * num_lens_params);
      result.extrinsics_covariance =
          variance * jacobian * extrinsics * jacobian.transpose();
      const Eigen::Vector3d direction =
          result.cam1_from_cam0.translation / result.baseline;
      result.baseline_sigma = std::sqrt(direction.dot(
          result.extrinsics_covariance.bottomRightCorner<3, 3>() * direction));
    }
    // The joint covariance of every unknown, board poses included, is
    // only for mrcal's projection uncertainty: when it cannot be factored
    // the calibration stands (its lens covariance is above) and the
    // report says the uncertainty is not available.
    if (!ComputeFullCovariance(view_used, num_cameras, num_lens_params,
                               options.estimate_board_warp, variance,
                               &parameters, &problem, &result.full_covariance,
                               &result.full_parameters)) {
      result.full_covariance = FullCovariance{};
      result.full_parameters.resize(0);
      result.full_covariance_note =
          "the covariance of all unknowns together (board poses included) "
          "is numerically singular, so the projection uncertainty through "
          "the board poses is not available (the lens model has more "
          "freedom than these views constrain: try fewer coefficients, or "
          "views that reach the image corners)";
    }
  }
  return result;
}

}  // namespace internal
}  // namespace rcm::calib
