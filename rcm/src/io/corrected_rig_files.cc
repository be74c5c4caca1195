#include "rcm/io/corrected_rig_files.h"

#include <Eigen/Core>
#include <optional>
#include <string>

#include "rcm/geometry/rigid3d.h"

namespace rcm {

Camchain CorrectedCamchain(const VirtualPinholeRig& rig) {
  return CamchainFromStereoRig(rig.corrected_rig());
}

StatusOr<Camchain> CorrectedCamchain(const VirtualPinholeRig& rig,
                                     const Camchain& source, int left_index,
                                     int right_index) {
  Camchain camchain = CorrectedCamchain(rig);
  if (Status status =
          CopyCamchainImuAndTopics(source, left_index, right_index, &camchain);
      !status.ok()) {
    return status;
  }
  if (source.cameras[left_index].camera != rig.raw_rig().left() ||
      source.cameras[right_index].camera != rig.raw_rig().right()) {
    return Status::Error("cam" + std::to_string(left_index) + " and cam" +
                         std::to_string(right_index) +
                         " of the camchain are not the cameras of the rig");
  }
  // A rotated view sees the IMU through its rotation:
  // view_from_imu = (R^T, 0) * camera_from_imu.
  const VirtualPinholeCamera* corrected[2] = {&rig.left(), &rig.right()};
  for (int k = 0; k < 2; ++k) {
    std::optional<Rigid3d>& cam_from_imu = camchain.cameras[k].cam_from_imu;
    if (!cam_from_imu) continue;
    const Rigid3d view_from_camera{
        corrected[k]->view.camera_from_view.transpose(),
        Eigen::Vector3d::Zero()};
    cam_from_imu = view_from_camera * *cam_from_imu;
  }
  return camchain;
}

std::pair<CameraInfo, CameraInfo> CorrectedCameraInfos(
    const VirtualPinholeRig& rig, const std::string& left_name,
    const std::string& right_name) {
  const auto info = [](const std::string& name, const Camera& pinhole,
                       double tx) {
    Eigen::Matrix<double, 3, 4> projection =
        Eigen::Matrix<double, 3, 4>::Zero();
    projection(0, 0) = pinhole.fx();
    projection(0, 2) = pinhole.cx();
    projection(1, 1) = pinhole.fy();
    projection(1, 2) = pinhole.cy();
    projection(2, 2) = 1.0;
    projection(0, 3) = tx;
    return CameraInfo{name, pinhole, Eigen::Matrix3d::Identity(), projection};
  };
  const Camera& right = rig.right().pinhole;
  const double tx =
      rig.options().rectify
          ? right.fx() * rig.corrected_rig().right_from_left().translation.x()
          : 0.0;
  return {info(left_name, rig.left().pinhole, 0.0),
          info(right_name, right, tx)};
}

}  // namespace rcm
