#include "rcm/io/camera_file.h"

#include <yaml-cpp/yaml.h>

#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/yaml_fields.h"

namespace rcm {

StatusOr<CalibrationFileFormat> DetectCalibrationFileFormat(
    const std::string& path, const std::string& text) {
  const StatusOr<YAML::Node> root = YamlReader(path).Load(text);
  if (!root.ok() || root->IsNull()) return CalibrationFileFormat::kCamchain;
  bool has_cam0 = false;
  bool has_camera_matrix = false;
  if (root->IsMap()) {
    for (auto it = root->begin(); it != root->end(); ++it) {
      if (!it->first.IsScalar()) continue;
      has_cam0 = has_cam0 || it->first.Scalar() == "cam0";
      has_camera_matrix =
          has_camera_matrix || it->first.Scalar() == "camera_matrix";
    }
  }
  if (has_cam0) return CalibrationFileFormat::kCamchain;
  if (has_camera_matrix) return CalibrationFileFormat::kCameraInfo;
  return Status::Error(path +
                       ": neither a Kalibr camchain (no 'cam0') nor a ROS "
                       "camera_info (no 'camera_matrix')");
}

StatusOr<Camera> ReadCameraFile(const std::string& path,
                                const std::string& camera_name) {
  const StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  const StatusOr<CalibrationFileFormat> format =
      DetectCalibrationFileFormat(path, *text);
  if (!format.ok()) return format.status();

  if (*format == CalibrationFileFormat::kCameraInfo) {
    const StatusOr<CameraInfo> info = ParseCameraInfo(*text, path);
    if (!info.ok()) return info.status();
    return info->camera;
  }

  const StatusOr<Camchain> camchain = ParseCamchain(*text, path);
  if (!camchain.ok()) return camchain.status();
  const StatusOr<int> index = FindCamchainCamera(*camchain, camera_name);
  if (!index.ok()) return index.status().WithContext(path);
  return camchain->cameras[*index].camera;
}

}  // namespace rcm
