// One camera from a calibration file of either format rcm reads: a Kalibr
// camchain (camchain.h; the camera is chosen by name, "cam0", "cam1", ...)
// or a ROS camera_info YAML (camera_info.h; describes one camera). The
// format is recognised by the top-level keys: `cam0` for a camchain,
// `camera_matrix` for a camera_info.
#ifndef RCM_IO_CAMERA_FILE_H_
#define RCM_IO_CAMERA_FILE_H_

#include <string>

#include "rcm/camera/camera.h"
#include "rcm/util/status.h"

namespace rcm {

enum class CalibrationFileFormat { kCamchain, kCameraInfo };

// The format of calibration file text. Empty text and YAML syntax errors
// count as a camchain, so that the camchain parser's message describes the
// problem. Errors: a YAML map with neither key ("PATH: neither a Kalibr
// camchain (no 'cam0') nor a ROS camera_info (no 'camera_matrix')").
StatusOr<CalibrationFileFormat> DetectCalibrationFileFormat(
    const std::string& path, const std::string& text);

// Reads camera `camera_name` of a camchain, or the camera of a camera_info
// (which has one camera; `camera_name` is not used). Errors: the file's
// own (missing, unreadable, malformed; one line naming the file), an
// unknown camera name in a camchain (listing the camchain's cameras).
StatusOr<Camera> ReadCameraFile(const std::string& path,
                                const std::string& camera_name = "cam0");

}  // namespace rcm

#endif  // RCM_IO_CAMERA_FILE_H_
