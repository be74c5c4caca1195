#include "rcm/calib/board_warp.h"

#include <glog/logging.h>

#include <algorithm>

namespace rcm::calib {

BoardWarpSurface BoardWarpSurfaceOf(const CalibrationTarget& target,
                                    const Eigen::Vector2d& warp) {
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  CHECK(!points.empty());
  Eigen::Vector2d low = points[0].head<2>();
  Eigen::Vector2d high = low;
  for (const Eigen::Vector3d& point : points) {
    low = low.cwiseMin(point.head<2>());
    high = high.cwiseMax(point.head<2>());
  }
  BoardWarpSurface surface;
  surface.origin = low;
  surface.extent = high - low;
  // Every accepted target has at least 2 points along each axis.
  CHECK(surface.extent.minCoeff() > 0.0);
  surface.warp = warp;
  return surface;
}

std::vector<Eigen::Vector2d> BoardWarpBasis(const CalibrationTarget& target) {
  const BoardWarpSurface surface =
      BoardWarpSurfaceOf(target, Eigen::Vector2d::Zero());
  std::vector<Eigen::Vector2d> basis;
  for (const Eigen::Vector3d& point : TargetPoints(target)) {
    basis.push_back(surface.Basis(point.x(), point.y()));
  }
  return basis;
}

std::vector<Eigen::Vector3d> WarpedTargetPoints(const CalibrationTarget& target,
                                                const Eigen::Vector2d& warp) {
  const BoardWarpSurface surface = BoardWarpSurfaceOf(target, warp);
  std::vector<Eigen::Vector3d> points = TargetPoints(target);
  for (Eigen::Vector3d& point : points) {
    point.z() = surface.Height(point.x(), point.y());
  }
  return points;
}

}  // namespace rcm::calib
