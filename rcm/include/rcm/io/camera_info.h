// ROS camera_info YAML, as written by camera_calibration_parsers (the ROS
// camera calibrator's ost.yaml, camera_info_manager's files):
//
//   image_width: 720
//   image_height: 540
//   camera_name: left                      # optional
//   camera_matrix:                         # K, row-major
//     rows: 3
//     cols: 3
//     data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]
//   distortion_model: plumb_bob            # see below
//   distortion_coefficients:
//     rows: 1
//     cols: 5
//     data: [k1, k2, p1, p2, k3]
//   rectification_matrix:                  # optional, R (default identity)
//     rows: 3
//     cols: 3
//     data: [...]
//   projection_matrix:                     # optional, P (default [K | 0])
//     rows: 3
//     cols: 4
//     data: [fx', 0, cx', Tx, 0, fy', cy', Ty, 0, 0, 1, 0]
//
// `rows` and `cols` are optional; when present they must match the shape.
// Distortion models:
//   plumb_bob, radtan  -> rcm radtan (k1, k2, p1, p2); a fifth coefficient
//                         k3 is accepted only when it is exactly 0, since
//                         rcm's radtan model has no k3; an absent
//                         distortion_model means plumb_bob, as in ROS;
//   equidistant        -> rcm equidistant (k1..k4, OpenCV fisheye);
//   rational_polynomial -> rcm rational (k1, k2, p1, p2, k3, k4, k5, k6);
//   none, ""           -> pinhole; the coefficients must be absent, an
//                         empty list or all zero.
// Other ROS models are rejected. K must have zero
// skew and last row [0, 0, 1]; R must be a rotation.
//
// Errors are one line, "SOURCE[:LINE]: KEY: message", as for camchain.h.
#ifndef RCM_IO_CAMERA_INFO_H_
#define RCM_IO_CAMERA_INFO_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct CameraInfo {
  std::string camera_name;
  Camera camera;
  // R: rotates this camera's frame into its rectified frame,
  // point_in_rectified = rectification * point_in_camera.
  Eigen::Matrix3d rectification;
  // P: projects points given in the rectified frame of the *left* camera of
  // the stereo pair to rectified pixels of this camera.
  Eigen::Matrix<double, 3, 4> projection;
};

// Parses camera_info text; `source_name` (usually the path) prefixes every
// error message.
StatusOr<CameraInfo> ParseCameraInfo(const std::string& text,
                                     const std::string& source_name);
StatusOr<CameraInfo> ReadCameraInfo(const std::string& path);

// The camera_info of a camera used on its own, unrectified: R = I and
// P = [K | 0].
CameraInfo CameraInfoFromCamera(const std::string& camera_name,
                                const Camera& camera);

// The distortion_model and coefficients D that ROS tools expect of
// `camera`, as FormatCameraInfo and camera_info messages write them:
//   radtan       -> plumb_bob [k1, k2, p1, p2, 0] (ROS's k3 held at 0);
//   equidistant  -> equidistant [k1, k2, k3, k4];
//   rational     -> rational_polynomial [k1, k2, p1, p2, k3, k4, k5, k6];
//   pinhole      -> plumb_bob [0, 0, 0, 0, 0] (some ROS tools reject
//                   "none"; zero coefficients read as undistorted).
// ROS has no double-sphere or EUCM model: for those cameras
// CheckCameraInfoModel fails (one line) and RosDistortionOf and
// FormatCameraInfo must not be called.
struct RosDistortion {
  std::string model;
  std::vector<double> coefficients;
};
Status CheckCameraInfoModel(const Camera& camera);
RosDistortion RosDistortionOf(const Camera& camera);

// The text camera_calibration_parsers writes (keys in its order:
// image_width, image_height, camera_name, camera_matrix, distortion_model,
// distortion_coefficients, rectification_matrix, projection_matrix, each
// matrix with rows, cols and a flow list `data`), numbers in their
// shortest round-trip form (number_format.h), so that ParseCameraInfo
// reads back exactly the numbers written. Distortion models written:
//   radtan       -> plumb_bob [k1, k2, p1, p2, 0];
//   equidistant  -> equidistant [k1, k2, k3, k4];
//   rational     -> rational_polynomial [k1, k2, p1, p2, k3, k4, k5, k6]
//                   (read back as rational);
//   pinhole      -> plumb_bob [0, 0, 0, 0, 0], what ROS tools expect of an
//                   undistorted camera (it reads back as radtan with zero
//                   coefficients: the same projection).
std::string FormatCameraInfo(const CameraInfo& info);
// Writes atomically (WriteFileAtomically): on failure `path` is untouched.
// Fails with CheckCameraInfoModel's message for ds and eucm cameras.
Status WriteCameraInfo(const std::string& path, const CameraInfo& info);

// The stereo rig described by the camera_info files of the left and right
// cameras of a pair calibrated by ROS (stereo_calibrate / stereoRectify).
//
// ROS convention: both cameras are rotated into a common rectified frame,
//   X_rect_left  = R_l X_left,        X_rect_right = R_r X_right,
// and each P projects points of the *left* rectified frame, P_l = [K' | 0]
// and P_r = [K' | (Tx, Ty, 0)^T] with K' = [fx' 0 cx'; 0 fy' cy'; 0 0 1],
// Tx = -fx' * B for a horizontal baseline B. P_r = K'_r [I | t_rect] with
// t_rect = K'_r^-1 (Tx, Ty, 0)^T = (Tx / fx', Ty / fy', 0) (no skew), so
//   X_rect_right = X_rect_left + t_rect.
// Substituting the rotations, X_right = R_r^T (R_l X_left + t_rect):
//   right_from_left = [R_r^T R_l | R_r^T (Tx / fx', Ty / fy', 0)].
// Both P must have the form above (zero skew, last row [0 0 1 0], positive
// fx', fy'), and the left P a zero 4th column; otherwise an error says what
// is wrong (e.g. the two files given in the wrong order).
StatusOr<StereoRig> StereoRigFromCameraInfo(const CameraInfo& left,
                                            const CameraInfo& right);

}  // namespace rcm

#endif  // RCM_IO_CAMERA_INFO_H_
