#include "rcm/geometry/trajectory_error.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace rcm {

StatusOr<TrajectoryError> CompareTrajectories(
    const std::vector<Rigid3d>& estimated_world_from_cam,
    const std::vector<Rigid3d>& true_world_from_cam) {
  const size_t count = true_world_from_cam.size();
  if (estimated_world_from_cam.size() != count) {
    return Status::Error("the estimated trajectory has " +
                         std::to_string(estimated_world_from_cam.size()) +
                         " poses, the true one " + std::to_string(count));
  }
  if (count < 2) {
    return Status::Error("a trajectory error needs 2 poses at least, not " +
                         std::to_string(count));
  }
  Eigen::Matrix3Xd estimated(3, count);
  Eigen::Matrix3Xd truth(3, count);
  for (size_t f = 0; f < count; ++f) {
    const Rigid3d& e = estimated_world_from_cam[f];
    const Rigid3d& t = true_world_from_cam[f];
    if (!e.rotation.allFinite() || !e.translation.allFinite() ||
        !t.rotation.allFinite() || !t.translation.allFinite()) {
      return Status::Error("pose " + std::to_string(f) +
                           " of a trajectory is not finite");
    }
    estimated.col(f) = e.translation;
    truth.col(f) = t.translation;
  }
  // Rigid, no scale (Umeyama 1991): truth ~ R estimated + t.
  const Eigen::Matrix4d alignment =
      Eigen::umeyama(estimated, truth, /*with_scaling=*/false);
  const Eigen::Matrix3d r = alignment.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = alignment.topRightCorner<3, 1>();
  TrajectoryError error;
  error.frames = static_cast<int>(count);
  double squared = 0.0;
  for (size_t f = 0; f < count; ++f) {
    squared += (truth.col(f) - (r * estimated.col(f) + t)).squaredNorm();
    if (f > 0) error.path_length_m += (truth.col(f) - truth.col(f - 1)).norm();
    const Eigen::Matrix3d difference =
        true_world_from_cam[f].rotation.transpose() * r *
        estimated_world_from_cam[f].rotation;
    error.max_rotation_error_deg =
        std::max(error.max_rotation_error_deg,
                 Eigen::AngleAxisd(difference).angle() * 180.0 / M_PI);
  }
  error.ate_m = std::sqrt(squared / static_cast<double>(count));
  const auto end = [count](const std::vector<Rigid3d>& poses) {
    return Eigen::Vector3d(
        poses[0].rotation.transpose() *
        (poses[count - 1].translation - poses[0].translation));
  };
  const Eigen::Vector3d true_end = end(true_world_from_cam);
  error.true_end_distance_m = true_end.norm();
  error.end_drift_m = (end(estimated_world_from_cam) - true_end).norm();
  return error;
}

}  // namespace rcm
