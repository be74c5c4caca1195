#include "board_bundle_adjustment.h"

#include <ceres/rotation.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace rcm::calib::internal {

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

// By central differences: the step is far above the rounding of the log
// map and far below the curvature of the map at any angle we meet.
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

StatusOr<UsedObservations> SelectObservations(
    const std::vector<StereoView>& views, int num_points, int min_corners,
    bool use_single_camera_views) {
  const int num_views = static_cast<int>(views.size());
  UsedObservations used(num_views, {nullptr, nullptr});
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
      if (observation.size() >= min_corners) used[v][c] = &observation;
    }
    if (!use_single_camera_views &&
        (used[v][0] == nullptr || used[v][1] == nullptr)) {
      used[v] = {nullptr, nullptr};
    }
  }
  return used;
}

ceres::Solver::Options BoardSolverOptions(int max_num_iterations,
                                          int num_threads) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.max_num_iterations = max_num_iterations;
  solver_options.num_threads = num_threads;
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
  // A step whose reduced camera matrix is too ill-conditioned for dense
  // Cholesky (a model with many distortion terms, e.g. the rational one's
  // k3..k6 near 0, at a small LM damping) is an invalid step, after which
  // Levenberg-Marquardt raises the damping. Ceres gives up after 5 in a
  // row; with two threads the Schur complement's sums are added in a
  // varying order, so whether a step fails can differ from run to run, and
  // 5 halvings of the trust region were once not enough (CI, the OpenCV
  // sample pairs with the rational model). 20 allow a damping 2^20 times
  // larger, which makes any such matrix positive definite; solves that
  // meet no failure are unchanged.
  solver_options.max_num_consecutive_invalid_steps = 20;
  return solver_options;
}

Status CheckSharedFitSettings(const SharedFitSettings& settings) {
  if (!(settings.huber_px > 0.0) || !std::isfinite(settings.huber_px)) {
    return Status::Error("huber_px must be positive and finite");
  }
  if (!(settings.outlier_sigmas > 0.0) ||
      !std::isfinite(settings.outlier_sigmas)) {
    return Status::Error("outlier_sigmas must be positive and finite");
  }
  if (!(settings.min_outlier_threshold_px >= 0.0) ||
      !std::isfinite(settings.min_outlier_threshold_px)) {
    return Status::Error("min_outlier_threshold_px must be >= 0 and finite");
  }
  if (settings.max_outlier_rounds < 0) {
    return Status::Error("max_outlier_rounds must be >= 0");
  }
  if (settings.max_num_iterations <= 0) {
    return Status::Error("max_num_iterations must be positive");
  }
  if (settings.min_corners_per_view < 4) {
    return Status::Error("min_corners_per_view must be at least 4");
  }
  if (settings.num_threads <= 0) {
    return Status::Error("num_threads must be positive");
  }
  return Status::Ok();
}

namespace {

Status Solve(const ceres::Solver::Options& solver_options,
             ceres::Problem* problem) {
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  if (summary.termination_type == ceres::FAILURE) {
    return Status::Error("bundle adjustment failed: " + summary.message);
  }
  return Status::Ok();
}

}  // namespace

Status FitWithOutlierRejection(
    const OutlierRejectionOptions& options,
    const ceres::Solver::Options& solver_options,
    const std::function<void(double, ceres::Problem*)>& add_residuals,
    const std::function<Eigen::Vector2d(const Corner&)>& residual,
    std::vector<Corner>* corners, ceres::Problem* final_problem) {
  for (int round = 0; round < options.max_outlier_rounds; ++round) {
    ceres::Problem problem;
    add_residuals(options.huber_px, &problem);
    RCM_RETURN_IF_ERROR(Solve(solver_options, &problem));
    std::vector<double> norms;
    std::vector<double> finite;  // the median skips corners that do not
                                 // project (NaN): they are outliers
    for (const Corner& corner : *corners) {
      norms.push_back(residual(corner).norm());
      if (std::isfinite(norms.back())) finite.push_back(norms.back());
    }
    if (finite.empty()) {
      return Status::Error(
          "bundle adjustment failed: no corner projects at the solution");
    }
    std::nth_element(finite.begin(), finite.begin() + finite.size() / 2,
                     finite.end());
    const double sigma = finite[finite.size() / 2] / kRayleighMedian;
    const double threshold = std::max(options.outlier_sigmas * sigma,
                                      options.min_outlier_threshold_px);
    bool changed = false;
    for (size_t i = 0; i < corners->size(); ++i) {
      const bool inlier = norms[i] <= threshold;  // NaN -> outlier
      changed |= inlier != (*corners)[i].inlier;
      (*corners)[i].inlier = inlier;
    }
    if (!changed) break;
  }
  add_residuals(/*huber_px=*/0.0, final_problem);
  return Solve(solver_options, final_problem);
}

bool JointCovariance(const std::vector<CovarianceBlockRef>& blocks,
                     bool cross_blocks, int num_threads,
                     ceres::Problem* problem, Eigen::MatrixXd* covariance) {
  std::vector<std::pair<size_t, size_t>> indices;
  std::vector<std::pair<const double*, const double*>> pairs;
  for (size_t i = 0; i < blocks.size(); ++i) {
    for (size_t j = i; j < (cross_blocks ? blocks.size() : i + 1); ++j) {
      indices.emplace_back(i, j);
      pairs.emplace_back(blocks[i].block, blocks[j].block);
    }
  }
  std::vector<int> offsets;
  int total = 0;
  for (const CovarianceBlockRef& block : blocks) {
    offsets.push_back(total);
    total += block.size;
  }
  for (ceres::CovarianceAlgorithmType algorithm :
       {ceres::SPARSE_QR, ceres::DENSE_SVD}) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = algorithm;
    covariance_options.num_threads = num_threads;
    ceres::Covariance solver(covariance_options);
    if (!solver.Compute(pairs, problem)) continue;
    covariance->setZero(total, total);
    for (const auto& [i, j] : indices) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
          block(blocks[i].size, blocks[j].size);
      if (!solver.GetCovarianceBlock(blocks[i].block, blocks[j].block,
                                     block.data())) {
        return false;
      }
      covariance->block(offsets[i], offsets[j], blocks[i].size,
                        blocks[j].size) = block;
      covariance->block(offsets[j], offsets[i], blocks[j].size,
                        blocks[i].size) = block.transpose();
    }
    return covariance->allFinite();
  }
  return false;
}

ResidualStatistics SummarizeResiduals(
    const std::vector<Corner>& corners,
    const std::function<Eigen::Vector2d(const Corner&)>& residual) {
  ResidualStatistics statistics;
  double sum = 0.0;
  for (const Corner& corner : corners) {
    CornerResidual out;
    out.view = corner.view;
    out.camera = corner.camera;
    out.point_id = corner.point_id;
    out.pixel = corner.pixel;
    out.residual = residual(corner);
    out.inlier = corner.inlier;
    if (!out.residual.allFinite()) {
      ++statistics.num_unprojected;
    } else {
      sum += out.residual.squaredNorm();
    }
    if (corner.inlier) {
      ++statistics.num_inliers;
      statistics.inlier_ssr += out.residual.squaredNorm();
    } else {
      ++statistics.num_outliers;
    }
    statistics.corners.push_back(out);
  }
  const int num_projected =
      static_cast<int>(corners.size()) - statistics.num_unprojected;
  statistics.rms_px = num_projected == 0 ? 0.0 : std::sqrt(sum / num_projected);
  statistics.inlier_rms_px =
      statistics.num_inliers == 0
          ? 0.0
          : std::sqrt(statistics.inlier_ssr / statistics.num_inliers);
  return statistics;
}

std::vector<std::optional<Rigid3d>> UsedViewPoses(
    const std::vector<Pose>& poses, const std::vector<bool>& used) {
  CHECK_EQ(poses.size(), used.size());
  std::vector<std::optional<Rigid3d>> out(poses.size());
  for (size_t v = 0; v < poses.size(); ++v) {
    if (used[v]) out[v] = RigidFromPose(poses[v].data());
  }
  return out;
}

Eigen::MatrixXd JackknifeCovariance(
    const std::vector<Eigen::VectorXd>& samples) {
  const int g = static_cast<int>(samples.size());
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(samples[0].size());
  for (const Eigen::VectorXd& x : samples) mean += x;
  mean /= g;
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(mean.size(), mean.size());
  for (const Eigen::VectorXd& x : samples) {
    sum += (x - mean) * (x - mean).transpose();
  }
  return (g - 1.0) / g * sum;
}

Eigen::VectorXd JackknifeSigma(const std::vector<Eigen::VectorXd>& samples) {
  return JackknifeCovariance(samples).diagonal().cwiseSqrt();
}

namespace {

// The one-sided 95 % quantile of chi-square with `dof` degrees of freedom
// (Wilson-Hilferty).
double ChiSquare95(double dof) {
  constexpr double kZ95 = 1.6448536269514722;
  const double a = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - a + kZ95 * std::sqrt(a), 3);
}

}  // namespace

double LeaveOutOrCovarianceSigma(double covariance_sigma,
                                 double leave_out_sigma, int replicates) {
  if (!(covariance_sigma > 0.0)) return leave_out_sigma;
  const double dof = replicates - 1.0;
  if (dof < 1.0 || !std::isfinite(leave_out_sigma)) return covariance_sigma;
  const double ratio = leave_out_sigma / covariance_sigma;
  return ratio * ratio * dof > ChiSquare95(dof) ? leave_out_sigma
                                                : covariance_sigma;
}

}  // namespace rcm::calib::internal
