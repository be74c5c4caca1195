// Kalibr camchain YAML: the rig file every rcm tool reads and writes.
//
// Format (one top-level key per camera, cam0, cam1, ..., consecutive):
//
//   cam0:
//     T_cam_imu:                  # optional, IMU points into cam0 (4x4)
//     - [r00, r01, r02, t0]
//     - [r10, r11, r12, t1]
//     - [r20, r21, r22, t2]
//     - [0.0, 0.0, 0.0, 1.0]
//     cam_overlaps: [1]           # optional, indices of overlapping cameras
//     camera_model: pinhole       # or ds (double sphere), eucm
//     distortion_coeffs: [k1, k2, k3, k4]
//     distortion_model: equidistant   # none | radtan | equidistant |
//                                     # rational (none for ds, eucm)
//     intrinsics: [fu, fv, pu, pv]    # fx, fy, cx, cy in pixels
//     resolution: [720, 540]          # width, height
//     rostopic: /cam0/image_raw       # optional
//     timeshift_cam_imu: 0.0012       # optional, seconds
//     port:                           # optional (rcm), the housing's flat
//       air_gap: 0.008                #   port in front of the camera, in
//       glass_index: 1.49             #   meters (flat_port_geometry.h);
//       glass_thickness: 0.006        #   normal optional, default [0, 0, 1],
//       normal: [0.0, 0.0, 1.0]       #   glass_index optional, default 1.49
//     port:                           # or a dome port (dome_port_geometry.h):
//       decentering: [0.0, 0.0, 0.0072]  # the dome's centre in the camera
//       glass_index: 1.495            #   frame, meters (default 0: centred)
//       inner_radius: 0.04355         #   meters
//       thickness: 0.00375            #   or outer_radius: 0.0473 (or both,
//       type: dome                    #   when they agree to 1 micrometre)
//   cam1:
//     T_cn_cnm1:                  # required on cam1 and later, absent on
//     - [...]                     # cam0: maps cam(n-1) points into cam(n),
//     ...                         # i.e. T_cn_cnm1 = camn_from_camnm1
//
// `distortion_coeffs` has as many entries as the model takes (4 for radtan
// and equidistant, 8 for rational: OpenCV's k1, k2, p1, p2, k3, k4, k5,
// k6); with `none` it is an empty list or absent. The unified models ds
// and eucm put their two parameters (xi, alpha; alpha, beta) before fu, fv,
// pu, pv in `intrinsics`, as Kalibr does. Keys rcm does
// not know are ignored when reading (and therefore not written back).
//
// Reading never throws: every problem is reported as one line,
// "SOURCE[:LINE]: cam1.intrinsics: expected 4 numbers, got 3", with the
// 1-based line of the offending YAML node when there is one.
//
// Writing reproduces the bytes Kalibr writes (Python's yaml.dump with
// sorted keys and leaf lists in flow style): keys in sorted order, 4x4
// matrices as block lists of flow rows, numbers as Python prints them (see
// number_format.h; PyYAML adds ".0" to a bare mantissa, so 1e-05 is written
// 1.0e-05), flow lists wrapped after column 80 with a four-space
// continuation indent, cameras in Python's string order (cam10 sorts before
// cam2). A file Kalibr wrote is therefore reproduced byte for byte, and a
// file rcm wrote reads back bit-exactly.
#ifndef RCM_IO_CAMCHAIN_H_
#define RCM_IO_CAMCHAIN_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port_geometry.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct CamchainCamera {
  Camera camera;
  // T_cn_cnm1: this camera from the previous one (cam(n-1) points into
  // cam(n)). Present on every camera but cam0.
  std::optional<Rigid3d> cam_from_previous;
  // T_cam_imu: IMU points into this camera.
  std::optional<Rigid3d> cam_from_imu;
  // timeshift_cam_imu in seconds (t_imu = t_cam + shift, as in Kalibr).
  std::optional<double> timeshift_cam_imu;
  std::vector<int> cam_overlaps;
  // Empty means the key is absent.
  std::string rostopic;
  // The housing's flat port in front of this camera (rcm's extension of
  // Kalibr's format, see above); absent = the paper's thin port.
  std::optional<FlatPort> port = std::nullopt;
  // The dome port in front of this camera (a `port` block of type dome);
  // never set together with `port`.
  std::optional<DomePort> dome = std::nullopt;
};

struct Camchain {
  // cameras[k] is camk.
  std::vector<CamchainCamera> cameras;
};

// The index N of a camchain camera name "camN" (N a decimal without sign or
// leading zero that fits an int); nullopt for any other name.
std::optional<int> CamchainCameraIndex(std::string_view name);

// The index of camera `name` in `camchain`. Error (without a source
// prefix): "unknown camera 'cam2' (the camchain has cam0, cam1)".
StatusOr<int> FindCamchainCamera(const Camchain& camchain,
                                 std::string_view name);

// Parses camchain text. `source_name` (usually the path) prefixes every
// error message.
StatusOr<Camchain> ParseCamchain(const std::string& text,
                                 const std::string& source_name);
StatusOr<Camchain> ReadCamchain(const std::string& path);

// The file contents, as Kalibr would write them. Formats the camchain as
// given; WriteCamchain additionally checks that cam0 has no T_cn_cnm1 and
// every other camera has one, so that the file can be read back.
std::string FormatCamchain(const Camchain& camchain);
// Writes atomically (WriteFileAtomically): on failure `path` is untouched.
Status WriteCamchain(const std::string& path, const Camchain& camchain);

// The stereo pair (cam<left_index>, cam<right_index>), with right_from_left
// chained through the T_cn_cnm1 of the cameras in between; any two distinct
// cameras, in either order (left 1, right 0 gives the inverse of left 0,
// right 1). The cameras' port blocks become the rig's ports (a camera
// without one has the thin port). Fails on an index out of range, equal
// indices, a camera behind a dome port (the stereo rig models flat ports),
// a missing T_cn_cnm1 and a zero baseline.
StatusOr<StereoRig> StereoRigFromCamchain(const Camchain& camchain,
                                          int left_index, int right_index);

// The two-camera camchain of a rig: cam0 the left camera, cam1 the right
// one with T_cn_cnm1 = right_from_left, each listing the other as overlap,
// and the rig's ports as port blocks.
Camchain CamchainFromStereoRig(const StereoRig& rig);

// Copies what `source` says of its cameras cam<left_index> and
// cam<right_index> beyond their intrinsics and extrinsics to cameras 0 and
// 1 of `pair` (a CamchainFromStereoRig of a rig derived from them, e.g.
// the water-side models): T_cam_imu, timeshift_cam_imu and rostopic, so
// that a VIO keeps its IMU calibration. Errors: an index out of range,
// equal indices, a `pair` without two cameras.
Status CopyCamchainImuAndTopics(const Camchain& source, int left_index,
                                int right_index, Camchain* pair);

}  // namespace rcm

#endif  // RCM_IO_CAMCHAIN_H_
