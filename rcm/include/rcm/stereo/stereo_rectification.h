// Stereo rectification of two central cameras: the rotations that turn
// each camera into a view whose x axis is the baseline, so that the two
// views form the ideal rectified pair (R = I, t = [-b, 0, 0]) in which a
// scene point has the same image row in both (given one K for both).
//
// Underwater the refractive camera is not central in air, but its virtual
// pinhole in the medium is (thin port, paper Sec. III-B): rectified
// virtual pinhole views (virtual_pinhole_remap.h) are what stereo matchers
// and VIO built for pinhole pairs consume.
//
// Construction (in the left camera frame; c = the right camera's center,
// -R^T t for right_from_left = (R, t), and z_l, z_r the optical axes):
//   x_rect = c / |c|
//   y_rect = normalize((z_l + z_r) x x_rect)    (averaged optical axis)
//   z_rect = x_rect x y_rect
//   left_camera_from_rect  = [x_rect y_rect z_rect]
//   right_camera_from_rect = R left_camera_from_rect
// so both views look along the same direction, the average of the two
// optical axes made perpendicular to the baseline (the smallest rotation
// of each camera for a pair that is nearly rectified already).
#ifndef RCM_STEREO_STEREO_RECTIFICATION_H_
#define RCM_STEREO_STEREO_RECTIFICATION_H_

#include <Eigen/Core>

#include "rcm/stereo/stereo_rig.h"

namespace rcm {

struct StereoRectification {
  Eigen::Matrix3d left_camera_from_rect = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d right_camera_from_rect = Eigen::Matrix3d::Identity();
};

// The rig's baseline is nonzero (StereoRig guarantees it); a baseline
// along the averaged optical axis (cameras one behind the other) has no
// rectification and is a programmer error of the caller (CHECK).
StereoRectification RectifyStereoRig(const StereoRig& rig);

}  // namespace rcm

#endif  // RCM_STEREO_STEREO_RECTIFICATION_H_
