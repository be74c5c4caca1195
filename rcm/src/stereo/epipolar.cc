#include "rcm/stereo/epipolar.h"

#include <glog/logging.h>

namespace rcm {

Eigen::Matrix3d EssentialMatrix(const Rigid3d& right_from_left) {
  const double baseline = right_from_left.translation.norm();
  CHECK_GT(baseline, 0.0) << "EssentialMatrix of a zero-baseline rig";
  const Eigen::Vector3d t = right_from_left.translation / baseline;
  Eigen::Matrix3d cross;
  cross << 0.0, -t.z(), t.y(),  //
      t.z(), 0.0, -t.x(),       //
      -t.y(), t.x(), 0.0;
  return cross * right_from_left.rotation;
}

}  // namespace rcm
