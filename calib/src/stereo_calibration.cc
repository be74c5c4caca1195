#include "rcm/calib/stereo_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "rcm/calib/board_reprojection_error.h"
#include "rcm/calib/calibration_initialization.h"
#include "rcm/io/number_format.h"

namespace rcm::calib {
namespace {

// Median of the Rayleigh distribution of |e| for a 2-D residual with
// independent N(0, sigma^2) components, in units of sigma: sqrt(2 ln 2).
constexpr double kRayleighMedian = 1.1774100225154747;

using Pose = std::array<double, 6>;  // [rotation vector, translation]

Pose PoseFromRigid(const Rigid3d& rigid) {
  Pose pose{};
  const Eigen::Matrix3d r = rigid.rotation;  // column-major, as Ceres reads
  ceres::RotationMatrixToAngleAxis(r.data(), pose.data());
  for (int i = 0; i < 3; ++i) pose[3 + i] = rigid.translation[i];
  return pose;
}

Rigid3d RigidFromPose(const double* pose) {
  Rigid3d rigid;
  ceres::AngleAxisToRotationMatrix(pose, rigid.rotation.data());
  rigid.translation = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return rigid;
}

// One corner of the problem.
struct Corner {
  int view;
  int camera;
  int point_id;
  Eigen::Vector2d pixel;
  bool inlier = true;
};

// The unknowns, as Ceres sees them.
struct Parameters {
  std::array<std::array<double, kMaxLensParams>, 2> lens{};
  Pose cam1_from_cam0{};
  std::vector<Pose> cam0_from_target;  // per view (unused views ignored)
};

template <typename LensModel>
ceres::CostFunction* MakeCost(const Corner& corner,
                              const Eigen::Vector3d& point) {
  if (corner.camera == 0) {
    return Cam0BoardReprojectionError<LensModel>::Create(point, corner.pixel);
  }
  return Cam1BoardReprojectionError<LensModel>::Create(point, corner.pixel);
}

ceres::CostFunction* CostFor(LensModelId model, const Corner& corner,
                             const Eigen::Vector3d& point) {
  RCM_LENS_MODEL_SWITCH(model, return MakeCost<LensModel>(corner, point);)
  LOG(FATAL) << "unknown lens model";
  return nullptr;
}

// Adds the residuals of the inliers (every corner when `all`) to `problem`.
void AddResiduals(LensModelId model, const std::vector<Corner>& corners,
                  const std::vector<Eigen::Vector3d>& target_points,
                  double huber_px, bool all, Parameters* parameters,
                  ceres::Problem* problem) {
  for (const Corner& corner : corners) {
    if (!all && !corner.inlier) continue;
    ceres::LossFunction* loss =
        huber_px > 0.0 ? new ceres::HuberLoss(huber_px) : nullptr;
    double* lens = parameters->lens[corner.camera].data();
    double* pose = parameters->cam0_from_target[corner.view].data();
    ceres::CostFunction* cost =
        CostFor(model, corner, target_points[corner.point_id]);
    if (corner.camera == 0) {
      problem->AddResidualBlock(cost, loss, lens, pose);
    } else {
      problem->AddResidualBlock(cost, loss, lens, pose,
                                parameters->cam1_from_cam0.data());
    }
  }
}

// The residual of one corner at the current parameters; NaN when the
// corner is behind its camera.
Eigen::Vector2d Residual(LensModelId model, const Corner& corner,
                         const std::vector<Eigen::Vector3d>& target_points,
                         const Parameters& parameters) {
  const Eigen::Vector3d& point = target_points[corner.point_id];
  const double* lens = parameters.lens[corner.camera].data();
  const double* pose = parameters.cam0_from_target[corner.view].data();
  Eigen::Vector2d residual;
  bool ok = false;
  RCM_LENS_MODEL_SWITCH(
      model,
      if (corner.camera == 0) {
        ok = Cam0BoardReprojectionError<LensModel>(point, corner.pixel)(
            lens, pose, residual.data());
      } else {
        ok = Cam1BoardReprojectionError<LensModel>(point, corner.pixel)(
            lens, pose, parameters.cam1_from_cam0.data(), residual.data());
      } break;)
  if (!ok) residual.setConstant(std::numeric_limits<double>::quiet_NaN());
  return residual;
}

ceres::Solver::Summary Solve(const StereoCalibrationOptions& options,
                             ceres::Problem* problem) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.num_threads = options.num_threads;
  // The exact (noise-free) case must converge to 1e-9 in the parameters:
  // its cost falls toward 0 with large relative decreases, so only the
  // parameter tolerance (relative step) stops it, and 1e-14 of a 500 px
  // focal length is 5e-12 px. With noise, the function tolerance (relative
  // cost decrease 1e-10) stops the solve within a few iterations of the
  // minimum.
  solver_options.function_tolerance = 1e-10;
  solver_options.gradient_tolerance = 1e-12;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  return summary;
}

// d w / d a: how the left-perturbation rotation vector w (R = exp([w]x)
// R(a)) moves with the angle-axis parameters a, by central differences
// (the step is far above the rounding of the log map and far below the
// curvature of the map at any angle we meet).
Eigen::Matrix3d LeftPerturbationFromAngleAxis(const double* angle_axis) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix3d rotation;
  ceres::AngleAxisToRotationMatrix(angle_axis, rotation.data());
  Eigen::Matrix3d jacobian;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d w[2];
    for (int s = 0; s < 2; ++s) {
      double a[3] = {angle_axis[0], angle_axis[1], angle_axis[2]};
      a[i] += s == 0 ? kStep : -kStep;
      Eigen::Matrix3d moved;
      ceres::AngleAxisToRotationMatrix(a, moved.data());
      const Eigen::Matrix3d delta = moved * rotation.transpose();
      ceres::RotationMatrixToAngleAxis(delta.data(), w[s].data());
    }
    jacobian.col(i) = (w[0] - w[1]) / (2.0 * kStep);
  }
  return jacobian;
}

// Covariance blocks of the cameras and the extrinsics, unscaled
// ((J^T J)^-1); false when J is rank deficient.
bool ComputeCovariance(Parameters* parameters, int num_lens_params,
                       ceres::Problem* problem,
                       Eigen::Matrix<double, 8, 8> lens_covariance[2],
                       Eigen::Matrix<double, 6, 6>* extrinsics_covariance,
                       int num_threads) {
  double* blocks[3] = {parameters->lens[0].data(), parameters->lens[1].data(),
                       parameters->cam1_from_cam0.data()};
  std::vector<std::pair<const double*, const double*>> pairs;
  for (double* block : blocks) pairs.emplace_back(block, block);
  for (ceres::CovarianceAlgorithmType algorithm :
       {ceres::SPARSE_QR, ceres::DENSE_SVD}) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = algorithm;
    covariance_options.num_threads = num_threads;
    ceres::Covariance covariance(covariance_options);
    if (!covariance.Compute(pairs, problem)) continue;
    for (int c = 0; c < 2; ++c) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
          block(num_lens_params, num_lens_params);
      if (!covariance.GetCovarianceBlock(blocks[c], blocks[c], block.data())) {
        return false;
      }
      lens_covariance[c].setZero();
      lens_covariance[c].topLeftCorner(num_lens_params, num_lens_params) =
          block;
    }
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> extrinsics;
    if (!covariance.GetCovarianceBlock(blocks[2], blocks[2],
                                       extrinsics.data())) {
      return false;
    }
    *extrinsics_covariance = extrinsics;
    return extrinsics_covariance->allFinite() &&
           lens_covariance[0].allFinite() && lens_covariance[1].allFinite();
  }
  return false;
}

}  // namespace

Status StereoCalibrationOptions::Check() const {
  if (model != LensModelId::kRadTan && model != LensModelId::kEquidistant &&
      model != LensModelId::kPinhole) {
    return Status::Error("lens model must be radtan, equidistant or none");
  }
  if (!(huber_px > 0.0) || !std::isfinite(huber_px)) {
    return Status::Error("huber_px must be positive and finite");
  }
  if (!(outlier_sigmas > 0.0) || !std::isfinite(outlier_sigmas)) {
    return Status::Error("outlier_sigmas must be positive and finite");
  }
  if (!(min_outlier_threshold_px >= 0.0) ||
      !std::isfinite(min_outlier_threshold_px)) {
    return Status::Error("min_outlier_threshold_px must be >= 0 and finite");
  }
  if (max_outlier_rounds < 0) {
    return Status::Error("max_outlier_rounds must be >= 0");
  }
  if (max_num_iterations <= 0) {
    return Status::Error("max_num_iterations must be positive");
  }
  if (min_corners_per_view < 4) {
    return Status::Error("min_corners_per_view must be at least 4");
  }
  if (num_threads <= 0) return Status::Error("num_threads must be positive");
  return Status::Ok();
}

StatusOr<StereoCalibration> CalibrateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibrationOptions& options) {
  if (Status status = options.Check(); !status.ok()) return status;
  const ImageSize sizes[2] = {cam0_size, cam1_size};
  for (int c = 0; c < 2; ++c) {
    if (Status status = Camera::CheckImageSize(sizes[c].width, sizes[c].height);
        !status.ok()) {
      return status.WithContext("cam" + std::to_string(c));
    }
  }
  const std::vector<Eigen::Vector3d> target_points = TargetPoints(target);
  const int num_points = static_cast<int>(target_points.size());
  const int num_views = static_cast<int>(views.size());

  // Which observations take part: enough corners, and (unless single-
  // camera views are wanted) both cameras.
  std::vector<std::array<const TargetObservation*, 2>> used(num_views,
                                                            {nullptr, nullptr});
  for (int v = 0; v < num_views; ++v) {
    const std::optional<TargetObservation>* sides[2] = {&views[v].left,
                                                        &views[v].right};
    for (int c = 0; c < 2; ++c) {
      if (!sides[c]->has_value()) continue;
      const TargetObservation& observation = **sides[c];
      if (observation.point_ids.size() != observation.pixels.size()) {
        return Status::Error("view " + std::to_string(v) +
                             ": point ids and pixels differ in number");
      }
      for (int k = 0; k < observation.size(); ++k) {
        const int id = observation.point_ids[k];
        if (id < 0 || id >= num_points) {
          return Status::Error("view " + std::to_string(v) + ": point id " +
                               std::to_string(id) + " is not on the target");
        }
        if (!observation.pixels[k].allFinite()) {
          return Status::Error("view " + std::to_string(v) +
                               ": a corner pixel is not finite");
        }
      }
      if (observation.size() >= options.min_corners_per_view) {
        used[v][c] = &observation;
      }
    }
    if (!options.use_single_camera_views &&
        (used[v][0] == nullptr || used[v][1] == nullptr)) {
      used[v] = {nullptr, nullptr};
    }
  }

  // Intrinsics, per camera.
  std::optional<Camera> cameras[2];
  for (int c = 0; c < 2; ++c) {
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

  // Board poses per camera, then the extrinsics from the stereo views.
  std::vector<std::array<std::optional<Rigid3d>, 2>> camera_from_target(
      num_views);
  std::vector<Rigid3d> relative;
  for (int v = 0; v < num_views; ++v) {
    for (int c = 0; c < 2; ++c) {
      if (used[v][c] == nullptr) continue;
      camera_from_target[v][c] =
          InitializeTargetPose(*cameras[c], target_points, *used[v][c]);
    }
    if (camera_from_target[v][0] && camera_from_target[v][1]) {
      relative.push_back(*camera_from_target[v][1] *
                         camera_from_target[v][0]->Inverse());
    }
  }
  if (relative.empty()) {
    return Status::Error(
        "no view shows the target in both images (with a pose in each), so "
        "the extrinsics cam1_from_cam0 cannot be calibrated");
  }
  const Rigid3d cam1_from_cam0_start = MedianRigid(relative);
  if (!(cam1_from_cam0_start.translation.norm() > 0.0)) {
    return Status::Error("the initial extrinsics have a zero baseline");
  }

  Parameters parameters;
  parameters.cam0_from_target.resize(num_views);
  for (int c = 0; c < 2; ++c) {
    std::copy(cameras[c]->params(),
              cameras[c]->params() + cameras[c]->num_params(),
              parameters.lens[c].begin());
  }
  parameters.cam1_from_cam0 = PoseFromRigid(cam1_from_cam0_start);

  // Filled with the solution below.
  StereoCalibration result(*cameras[0], *cameras[1]);
  result.cam0_from_target.resize(num_views);
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
    for (int c = 0; c < 2; ++c) {
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
  const int num_parameters = 2 * num_lens_params + 6 + 6 * num_views_used;

  double initial_sum = 0.0;
  for (const Corner& corner : corners) {
    initial_sum += Residual(options.model, corner, target_points, parameters)
                       .squaredNorm();
  }
  result.initial_rms_px =
      corners.empty() ? 0.0 : std::sqrt(initial_sum / corners.size());

  // Robust solves with outlier rejection, then least squares on the inliers.
  for (int round = 0; round < options.max_outlier_rounds; ++round) {
    ceres::Problem problem;
    AddResiduals(options.model, corners, target_points, options.huber_px,
                 /*all=*/false, &parameters, &problem);
    const ceres::Solver::Summary summary = Solve(options, &problem);
    if (summary.termination_type == ceres::FAILURE) {
      return Status::Error("bundle adjustment failed: " + summary.message);
    }
    std::vector<double> norms;
    for (const Corner& corner : corners) {
      norms.push_back(
          Residual(options.model, corner, target_points, parameters).norm());
    }
    std::vector<double> sorted = norms;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2,
                     sorted.end());
    const double sigma = sorted[sorted.size() / 2] / kRayleighMedian;
    const double threshold = std::max(options.outlier_sigmas * sigma,
                                      options.min_outlier_threshold_px);
    bool changed = false;
    for (size_t i = 0; i < corners.size(); ++i) {
      const bool inlier = norms[i] <= threshold;  // NaN -> outlier
      changed |= inlier != corners[i].inlier;
      corners[i].inlier = inlier;
    }
    if (!changed) break;
  }
  ceres::Problem problem;
  AddResiduals(options.model, corners, target_points, /*huber_px=*/0.0,
               /*all=*/false, &parameters, &problem);
  const ceres::Solver::Summary summary = Solve(options, &problem);
  if (summary.termination_type == ceres::FAILURE) {
    return Status::Error("bundle adjustment failed: " + summary.message);
  }

  // The result.
  for (int c = 0; c < 2; ++c) {
    const double* lens = parameters.lens[c].data();
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
  result.cam1_from_cam0 = RigidFromPose(parameters.cam1_from_cam0.data());
  result.baseline = result.cam1_from_cam0.translation.norm();
  if (!(result.baseline > 0.0) || !std::isfinite(result.baseline)) {
    return Status::Error("bundle adjustment diverged: the baseline is " +
                         FormatDouble(result.baseline));
  }
  for (int v = 0; v < num_views; ++v) {
    if (view_used[v]) {
      result.cam0_from_target[v] =
          RigidFromPose(parameters.cam0_from_target[v].data());
    }
  }
  // Each corner's final residual, evaluated once.
  double sum = 0.0;
  double inlier_sum = 0.0;
  for (const Corner& corner : corners) {
    CornerResidual out;
    out.view = corner.view;
    out.camera = corner.camera;
    out.point_id = corner.point_id;
    out.pixel = corner.pixel;
    out.residual = Residual(options.model, corner, target_points, parameters);
    out.inlier = corner.inlier;
    sum += out.residual.squaredNorm();
    if (corner.inlier) {
      ++result.num_inliers;
      inlier_sum += out.residual.squaredNorm();
    } else {
      ++result.num_outliers;
    }
    result.corners.push_back(out);
  }
  result.rms_px = corners.empty() ? 0.0 : std::sqrt(sum / corners.size());
  result.inlier_rms_px = result.num_inliers == 0
                             ? 0.0
                             : std::sqrt(inlier_sum / result.num_inliers);
  result.num_views_used = num_views_used;
  for (int v = 0; v < num_views; ++v) {
    if (view_used[v] && used[v][0] != nullptr && used[v][1] != nullptr) {
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
    Eigen::Matrix<double, 8, 8> lens_covariance[2];
    Eigen::Matrix<double, 6, 6> extrinsics;
    if (!ComputeCovariance(&parameters, num_lens_params, &problem,
                           lens_covariance, &extrinsics, options.num_threads)) {
      return Status::Error(
          "the calibration is degenerate: its covariance cannot be computed "
          "(the views do not constrain every parameter; add views with the "
          "target tilted and near the image corners)");
    }
    const double variance = result.pixel_sigma * result.pixel_sigma;
    CameraCalibration* out[2] = {&result.cam0, &result.cam1};
    for (int c = 0; c < 2; ++c) {
      out[c]->covariance = variance * lens_covariance[c];
      for (int i = 0; i < 8; ++i) {
        out[c]->sigma[i] = std::sqrt(out[c]->covariance(i, i));
      }
    }
    Eigen::Matrix<double, 6, 6> jacobian =
        Eigen::Matrix<double, 6, 6>::Identity();
    jacobian.topLeftCorner<3, 3>() =
        LeftPerturbationFromAngleAxis(parameters.cam1_from_cam0.data());
    result.extrinsics_covariance =
        variance * jacobian * extrinsics * jacobian.transpose();
    const Eigen::Vector3d direction =
        result.cam1_from_cam0.translation / result.baseline;
    result.baseline_sigma = std::sqrt(direction.dot(
        result.extrinsics_covariance.bottomRightCorner<3, 3>() * direction));
  }
  return result;
}

}  // namespace rcm::calib
