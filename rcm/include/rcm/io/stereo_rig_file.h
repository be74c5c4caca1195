// The stereo rig of a command line: one argument that names either rig
// file format rcm reads.
//
//   rig.yaml                 a Kalibr camchain (camchain.h); `left` and
//                            `right` name two of its cameras ("cam0",
//                            "cam1", ...), cam0/cam1 by default; a
//                            camchain of one camera (rcm calibrate
//                            --left alone) is an error that says so;
//   left.yaml,right.yaml     the ROS camera_info files of the left and the
//                            right camera (camera_info.h), in that order;
//                            `left` and `right` must keep their defaults.
//
// The format of each file is recognised by its top-level keys: `cam0` for a
// camchain, `camera_matrix` for a camera_info. A path that contains a comma
// is always taken as a pair.
//
// The rig comes with its CalibrationUncertainty (calibration_uncertainty.h):
// a camchain's covariance sidecar (rig-covariance.yaml next to rig.yaml,
// calibration_covariance_file.h, written by rcm calibrate) with its drift
// prior when the sidecar exists; otherwise, and for camera_info files, the
// default drift prior (0.1 degree, 0.1 mm per axis) and the default focal
// drift prior of an air calibration (0.3 %, calibration_uncertainty.h).
// `drift_prior` replaces the drift prior by (rotation sigma in radians,
// translation sigma in meters), `focal_drift` the focal drift prior
// (relative sigma), in either case.
#ifndef RCM_IO_STEREO_RIG_FILE_H_
#define RCM_IO_STEREO_RIG_FILE_H_

#include <array>
#include <optional>
#include <string>
#include <utility>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct RigFileOptions {
  std::optional<std::pair<double, double>> drift_prior;
  std::optional<double> focal_drift;
  // Read a camchain whose cameras have dome port blocks (the tools that
  // model domes, which take them from ReadStereoRigDomes): the rig is the
  // cameras' without them. Otherwise such a camchain is an error
  // (StereoRigFromCamchain).
  bool domes_allowed = false;
};

// `rig` with what ReadStereoRig gives a rig file without a sidecar: the
// default drift prior and the default focal drift prior, or those of
// `options`.
StatusOr<StereoRig> WithDefaultCalibrationUncertainty(
    const StereoRig& rig, const RigFileOptions& options = {});

StatusOr<StereoRig> ReadStereoRig(const std::string& spec,
                                  const std::string& left = "cam0",
                                  const std::string& right = "cam1",
                                  const RigFileOptions& options = {});

// The dome port blocks of the rig's two cameras (camchain.h), left then
// right: nullopt when neither has one (or the spec is a camera_info pair).
// Errors: those of reading the camchain, an unknown camera name, and only
// one of the two cameras with a dome ("cam1 has no dome port block, cam0
// has one: give both cameras one").
StatusOr<std::optional<std::array<DomePort, 2>>> ReadStereoRigDomes(
    const std::string& spec, const std::string& left = "cam0",
    const std::string& right = "cam1");

}  // namespace rcm

#endif  // RCM_IO_STEREO_RIG_FILE_H_
