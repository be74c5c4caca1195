#include "rcm/calib/calibration_initialization.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "rcm/calib/board_reprojection_error.h"

namespace rcm::calib {
namespace {

// Single-camera bundle adjustment of the lens parameters and the poses of
// the posed views, robust (Huber at 1 px). Updates `lens` and `poses`;
// returns the final cost, nullopt when the solve is unusable.
std::optional<double> RefineCamera(LensModelId model,
                  const std::vector<Eigen::Vector3d>& target_points,
                  const std::vector<const TargetObservation*>& observations,
                  std::array<double, kMaxLensParams>* lens,
                  std::vector<std::array<double, 6>>* poses,
                  const std::vector<bool>& posed) {
  ceres::Problem problem;
  for (size_t v = 0; v < observations.size(); ++v) {
    if (!posed[v]) continue;
    for (int k = 0; k < observations[v]->size(); ++k) {
      const Eigen::Vector3d& point =
          target_points[observations[v]->point_ids[k]];
      const Eigen::Vector2d& pixel = observations[v]->pixels[k];
      ceres::CostFunction* cost = nullptr;
      RCM_LENS_MODEL_SWITCH(
          model,
          cost = Cam0BoardReprojectionError<LensModel>::Create(point, pixel);
          break;)
      problem.AddResidualBlock(cost, new ceres::HuberLoss(1.0), lens->data(),
                               (*poses)[v].data());
    }
  }
  if (!problem.HasParameterBlock(lens->data())) return std::nullopt;
  for (const DistortionBound& bound : DistortionBounds(model)) {
    problem.SetParameterLowerBound(lens->data(), 4 + bound.index, bound.lower);
    problem.SetParameterUpperBound(lens->data(), 4 + bound.index, bound.upper);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 100;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return std::nullopt;
  return summary.final_cost;
}

// The starts of step 3 for the double sphere: xi from -0.4 to 0.6 with the
// focal length f (1 + xi), which keeps the near-axis focal length f / (1 +
// xi) at the closed form's f. Near the axis the model is f / (1 + xi) r,
// so f and xi trade against each other along a long, curved valley of the
// cost that only the off-axis shape closes; from the single basalt start
// (xi = 0) the solver stopped in it far from the minimum (noise-free
// corners of a xi = -0.18 lens: xi 0.42 and f 73 % high at an RMS of 7e-4
// px). The start with the lowest cost is kept.
constexpr std::array<double, 6> kDoubleSphereStartXi = {-0.4, -0.2, 0.0,
                                                       0.2,  0.4,  0.6};

}  // namespace

std::vector<double> StartingDistortion(LensModelId model) {
  switch (model) {
    case LensModelId::kDoubleSphere:
      return {0.0, 0.5};  // xi, alpha
    case LensModelId::kEucm:
      return {0.5, 1.0};  // alpha, beta
    default:
      return std::vector<double>(NumDistortionParams(model), 0.0);
  }
}

StatusOr<Camera> InitializeCamera(
    LensModelId model, int width, int height,
    const std::vector<Eigen::Vector3d>& target_points,
    const std::vector<const TargetObservation*>& observations) {
  CHECK_GE(observations.size(), 1u);
  // 1. Closed form (OpenCV wants float points here).
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const TargetObservation* observation : observations) {
    object.emplace_back();
    image.emplace_back();
    for (int k = 0; k < observation->size(); ++k) {
      const Eigen::Vector3d& x = target_points[observation->point_ids[k]];
      object.back().emplace_back(x.x(), x.y(), x.z());
      image.back().emplace_back(observation->pixels[k].x(),
                                observation->pixels[k].y());
    }
  }
  cv::Matx33d k;
  try {
    k = cv::Matx33d(cv::initCameraMatrix2D(object, image,
                                           cv::Size(width, height),
                                           /*aspectRatio=*/0.0));
  } catch (const cv::Exception& e) {
    return Status::Error("OpenCV's closed-form intrinsics failed: " +
                         std::string(e.err));
  }
  StatusOr<Camera> start =
      Camera::Create(model, width, height, {k(0, 0), k(1, 1), k(0, 2), k(1, 2)},
                     StartingDistortion(model));
  if (!start.ok()) {
    return Status::Error(
        "OpenCV's closed-form intrinsics are not a camera (" +
        start.status().message() +
        "); the views may all be nearly fronto-parallel: tilt the target");
  }

  // 2. Poses.
  std::vector<std::array<double, 6>> poses(observations.size());
  std::vector<bool> posed(observations.size(), false);
  int num_posed = 0;
  for (size_t v = 0; v < observations.size(); ++v) {
    const std::optional<Rigid3d> pose =
        InitializeTargetPose(*start, target_points, *observations[v]);
    if (!pose) continue;
    const Eigen::Matrix3d r = pose->rotation;
    ceres::RotationMatrixToAngleAxis(r.data(), poses[v].data());
    for (int i = 0; i < 3; ++i) poses[v][3 + i] = pose->translation[i];
    posed[v] = true;
    ++num_posed;
  }
  constexpr int kMinPosedViews = 3;
  if (num_posed < kMinPosedViews) {
    return Status::Error("only " + std::to_string(num_posed) +
                         " view(s) could be posed from the closed-form "
                         "intrinsics; at least 3 are needed");
  }

  // 3. Single-camera bundle adjustment, from one start (several for the
  // double sphere), keeping the lowest cost.
  std::vector<std::array<double, kMaxLensParams>> starts;
  std::array<double, kMaxLensParams> lens{};
  std::copy(start->params(), start->params() + start->num_params(),
            lens.begin());
  if (model == LensModelId::kDoubleSphere) {
    for (double xi : kDoubleSphereStartXi) {
      std::array<double, kMaxLensParams> shifted = lens;
      shifted[0] *= 1.0 + xi;
      shifted[1] *= 1.0 + xi;
      shifted[4] = xi;
      starts.push_back(shifted);
    }
  } else {
    starts.push_back(lens);
  }
  std::optional<double> best_cost;
  for (std::array<double, kMaxLensParams> candidate : starts) {
    std::vector<std::array<double, 6>> candidate_poses = poses;
    const std::optional<double> cost = RefineCamera(
        model, target_points, observations, &candidate, &candidate_poses,
        posed);
    if (cost && (!best_cost || *cost < *best_cost)) {
      best_cost = cost;
      lens = candidate;
    }
  }
  if (!best_cost) return *start;
  StatusOr<Camera> refined =
      Camera::Create(model, width, height, {lens[0], lens[1], lens[2], lens[3]},
                     std::vector<double>(lens.begin() + 4,
                                         lens.begin() + start->num_params()));
  return refined.ok() ? *refined : *start;
}

std::optional<Rigid3d> InitializeTargetPose(
    const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
    const TargetObservation& observation) {
  std::vector<std::optional<Eigen::Vector2d>> normalized;
  for (const Eigen::Vector2d& pixel : observation.pixels) {
    normalized.push_back(camera.NormalizedFromImage(pixel));
  }
  return TargetPoseFromNormalized(target_points, observation, normalized);
}

std::optional<Rigid3d> TargetPoseFromNormalized(
    const std::vector<Eigen::Vector3d>& target_points,
    const TargetObservation& observation,
    const std::vector<std::optional<Eigen::Vector2d>>& rays) {
  CHECK_EQ(rays.size(), observation.pixels.size());
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> normalized;
  for (int k = 0; k < observation.size(); ++k) {
    const std::optional<Eigen::Vector2d>& xy = rays[k];
    if (!xy || !xy->allFinite()) continue;
    const Eigen::Vector3d& x = target_points[observation.point_ids[k]];
    object.emplace_back(x.x(), x.y(), x.z());
    normalized.emplace_back(xy->x(), xy->y());
  }
  if (object.size() < 4) return std::nullopt;
  cv::Vec3d rvec;
  cv::Vec3d tvec;
  try {
    if (!cv::solvePnP(object, normalized, cv::Matx33d::eye(), cv::noArray(),
                      rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
      return std::nullopt;
    }
    cv::solvePnPRefineLM(object, normalized, cv::Matx33d::eye(), cv::noArray(),
                         rvec, tvec);
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Rigid3d pose;
  cv::cv2eigen(rotation, pose.rotation);
  pose.translation = Eigen::Vector3d(tvec[0], tvec[1], tvec[2]);
  if (!pose.rotation.allFinite() || !pose.translation.allFinite()) {
    return std::nullopt;
  }
  for (const cv::Point3d& x : object) {
    if (!((pose * Eigen::Vector3d(x.x, x.y, x.z)).z() > 0.0)) {
      return std::nullopt;
    }
  }
  return pose;
}

Rigid3d MedianRigid(const std::vector<Rigid3d>& transforms) {
  CHECK(!transforms.empty());
  const int n = static_cast<int>(transforms.size());
  int medoid = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (int j = 0; j < n; ++j) {
      sum +=
          Rigid3d{transforms[i].rotation.transpose() * transforms[j].rotation,
                  Eigen::Vector3d::Zero()}
              .RotationAngle();
    }
    if (sum < best) {
      best = sum;
      medoid = i;
    }
  }
  Rigid3d center;
  center.rotation = transforms[medoid].rotation;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Rigid3d& t : transforms) values.push_back(t.translation[axis]);
    std::nth_element(values.begin(), values.begin() + n / 2, values.end());
    double median = values[n / 2];
    if (n % 2 == 0) {
      median = 0.5 * (median + *std::max_element(values.begin(),
                                                 values.begin() + n / 2));
    }
    center.translation[axis] = median;
  }
  return center;
}

double ReprojectionRms(
    const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
    const std::vector<const TargetObservation*>& observations,
    const std::vector<std::optional<Rigid3d>>& poses) {
  CHECK_EQ(observations.size(), poses.size());
  double sum = 0.0;
  int count = 0;
  for (size_t v = 0; v < observations.size(); ++v) {
    if (!poses[v]) continue;
    const TargetObservation& observation = *observations[v];
    for (int k = 0; k < observation.size(); ++k) {
      const Eigen::Vector3d point =
          *poses[v] * target_points[observation.point_ids[k]];
      if (!(point.z() > 0.0)) return std::numeric_limits<double>::infinity();
      const std::optional<Eigen::Vector2d> pixel =
          camera.ProjectNormalized(point.head<2>() / point.z());
      if (!pixel) return std::numeric_limits<double>::infinity();
      sum += (*pixel - observation.pixels[k]).squaredNorm();
      ++count;
    }
  }
  return count == 0 ? std::numeric_limits<double>::infinity()
                    : std::sqrt(sum / count);
}

}  // namespace rcm::calib
