// The files that describe a corrected rig (rcm/stereo/virtual_pinhole_rig.h)
// to the tools downstream: its Kalibr camchain, for VIO that reads one
// (OpenVINS, VINS, ORB-SLAM3 via Kalibr's format), and the ROS camera_info
// of its two corrected cameras, for nodes that subscribe to one.
#ifndef RCM_IO_CORRECTED_RIG_FILES_H_
#define RCM_IO_CORRECTED_RIG_FILES_H_

#include <string>
#include <utility>

#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// The Kalibr camchain of the corrected rig: cam0 the corrected left camera,
// cam1 the corrected right one (camera_model pinhole, distortion_model
// none, T_cn_cnm1 = right_view_from_left_view), each listing the other as
// overlap.
Camchain CorrectedCamchain(const VirtualPinholeRig& rig);

// The same, keeping what `source` (the camchain the raw rig was read from,
// cameras cam<left_index> and cam<right_index>) says of the two cameras
// (CopyCamchainImuAndTopics, camchain.h):
//   T_cam_imu          composed with the view rotation:
//                      view_from_imu = (R^T, 0) * camera_from_imu;
//   timeshift_cam_imu  unchanged (remapping moves no image in time);
//   rostopic           unchanged.
// Errors: an index out of range, equal indices, and a source whose two
// cameras are not the raw rig's (compared exactly).
StatusOr<Camchain> CorrectedCamchain(const VirtualPinholeRig& rig,
                                     const Camchain& source, int left_index,
                                     int right_index);

// ROS camera_info of the two corrected cameras (named left_name and
// right_name): K = K', no distortion, R = I. Unrectified: P = [K' | 0]
// for each (two monocular cameras). Rectified: the stereo pair's
// P_left = [K' | 0], P_right = [K' | (-fx' b, 0, 0)], from which
// StereoRigFromCameraInfo gives back the corrected rig.
std::pair<CameraInfo, CameraInfo> CorrectedCameraInfos(
    const VirtualPinholeRig& rig, const std::string& left_name,
    const std::string& right_name);

}  // namespace rcm

#endif  // RCM_IO_CORRECTED_RIG_FILES_H_
