#include "rcm/stereo/stereo_rectification.h"

#include <glog/logging.h>

#include <Eigen/Geometry>

namespace rcm {

StereoRectification RectifyStereoRig(const StereoRig& rig) {
  const Eigen::Matrix3d& rotation = rig.right_from_left().rotation;
  const Eigen::Vector3d right_center =
      -(rotation.transpose() * rig.right_from_left().translation);
  const Eigen::Vector3d x = right_center.normalized();
  const Eigen::Vector3d mean_axis =
      Eigen::Vector3d::UnitZ() + rotation.transpose().col(2);
  const Eigen::Vector3d y_unnormalized = mean_axis.cross(x);
  CHECK_GT(y_unnormalized.norm(), 1e-6)
      << "baseline along the optical axis: no rectification";
  const Eigen::Vector3d y = y_unnormalized.normalized();
  StereoRectification rectification;
  rectification.left_camera_from_rect.col(0) = x;
  rectification.left_camera_from_rect.col(1) = y;
  rectification.left_camera_from_rect.col(2) = x.cross(y);
  rectification.right_camera_from_rect =
      rotation * rectification.left_camera_from_rect;
  return rectification;
}

}  // namespace rcm
