#include "rcm/calib/calibration_covariance.h"

#include <Eigen/Core>
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

Eigen::Matrix<double, 6, 1> ExtrinsicsLeaveOutScales(
    const ExtrinsicChange& change) {
  Eigen::Matrix<double, 6, 1> scales = Eigen::Matrix<double, 6, 1>::Ones();
  const auto ratio = [](double leave_out, double covariance) {
    return covariance > 0.0 ? std::max(1.0, leave_out / covariance) : 1.0;
  };
  for (int k = 0; k < 3; ++k) {
    if (change.rotation_leave_out_sigma_deg) {
      scales[k] = ratio((*change.rotation_leave_out_sigma_deg)[k],
                        change.rotation_sigma_deg[k]);
    }
    if (change.translation_leave_out_sigma_mm) {
      scales[3 + k] = ratio((*change.translation_leave_out_sigma_mm)[k],
                            change.translation_sigma_mm[k]);
    }
  }
  return scales;
}

CalibrationCovarianceFile UnderwaterCalibrationCovariance(
    const UnderwaterCalibration& result, const StereoRig& air_rig) {
  CalibrationCovarianceFile file;
  file.medium = "water";
  file.cameras.resize(2);
  if (result.lenses_estimated) {
    // The joint fit's lenses and their covariance (it counts the air views
    // and the water's).
    file.cameras[0].intrinsics_covariance = result.lens_covariance[0];
    file.cameras[1].intrinsics_covariance = result.lens_covariance[1];
    file.cameras[1].previous_intrinsics_covariance =
        result.lens_cross_covariance;
  } else if (const std::optional<CalibrationUncertainty>& air =
                 air_rig.calibration_uncertainty()) {
    file.cameras[0].intrinsics_covariance = air->left_lens_covariance;
    file.cameras[1].intrinsics_covariance = air->right_lens_covariance;
    if (!result.extrinsics_estimated) {
      file.cameras[1].from_previous_covariance = air->extrinsics_covariance;
    }
  }
  if (result.extrinsics_estimated) {
    const Eigen::DiagonalMatrix<double, 6> scales(
        ExtrinsicsLeaveOutScales(result.extrinsic_change));
    Eigen::Matrix<double, 6, 6> extrinsics = result.extrinsic_change.covariance;
    // The extrinsics were fitted through the lenses: their covariance with
    // the lenses, X, and the lenses' share of their own.
    const int lens_size =
        static_cast<int>(file.cameras[0].intrinsics_covariance.rows() +
                         file.cameras[1].intrinsics_covariance.rows());
    if (file.cameras[0].intrinsics_covariance.size() > 0 &&
        file.cameras[1].intrinsics_covariance.size() > 0 &&
        result.extrinsics_lens_covariance.cols() == lens_size) {
      extrinsics += result.extrinsics_covariance_from_lenses;
      file.cameras[1].from_previous_intrinsics_covariance =
          result.extrinsics_lens_covariance;
      // Only the part the water views measured with the lenses given is
      // widened to the leave-out spread (which holds the lenses too); the
      // response to a lens error stays as the fit has it: a scaled X would
      // claim a response the rig does not have, which a target-free
      // estimate then counts as an error of n.
      CalibrationUncertainty joint;
      joint.extrinsics_covariance = extrinsics;
      joint.left_lens_covariance = file.cameras[0].intrinsics_covariance;
      joint.right_lens_covariance = file.cameras[1].intrinsics_covariance;
      joint.extrinsics_lens_covariance = result.extrinsics_lens_covariance;
      joint.lens_cross_covariance =
          file.cameras[1].previous_intrinsics_covariance;
      const Eigen::Matrix<double, 6, 6> given_lenses =
          ConditionalCovariance(joint.JointCovariance(), 6);
      file.cameras[1].from_previous_covariance =
          scales * given_lenses * scales + (extrinsics - given_lenses);
    } else {
      file.cameras[1].from_previous_covariance = scales * extrinsics * scales;
    }
  }
  return file;
}

}  // namespace rcm::calib
