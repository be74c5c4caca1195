#include "rcm/calib/calibration_covariance.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace rcm::calib {

double LeaveOutScale(const std::optional<CrossValidation>& cross_validation,
                     int camera) {
  double scale = 1.0;
  if (!cross_validation) return scale;
  const std::string prefix =
      camera == 2 ? "baseline" : "cam" + std::to_string(camera) + " ";
  for (const ParameterSpread& spread : cross_validation->parameters) {
    if (spread.name.rfind(prefix, 0) != 0 || !(spread.reported_sigma > 0.0)) {
      continue;
    }
    scale = std::max(scale, spread.jackknife_sigma / spread.reported_sigma);
  }
  return scale;
}

CalibrationCovarianceFile AirCalibrationCovariance(
    const StereoCalibration& calibration,
    const std::optional<CrossValidation>& cross_validation) {
  CalibrationCovarianceFile file;
  file.medium = "air";
  file.drift_rotation_sigma =
      CalibrationUncertainty::kDefaultDriftDegrees * M_PI / 180.0;
  file.drift_translation_sigma =
      1e-3 * CalibrationUncertainty::kDefaultDriftMillimeters;
  // The lenses may change between the air and the water.
  file.drift_focal_sigma =
      1e-2 * CalibrationUncertainty::kDefaultFocalDriftPercent;
  file.cameras.resize(2);
  const CameraCalibration* cameras[2] = {&calibration.cam0, &calibration.cam1};
  for (int c = 0; c < 2; ++c) {
    const int size = cameras[c]->camera.num_params();
    const double scale = LeaveOutScale(cross_validation, c);
    file.cameras[c].intrinsics_covariance =
        scale * scale * cameras[c]->covariance.topLeftCorner(size, size);
  }
  const double scale = LeaveOutScale(cross_validation, 2);
  file.cameras[1].from_previous_covariance =
      scale * scale * calibration.extrinsics_covariance;
  return file;
}

}  // namespace rcm::calib
