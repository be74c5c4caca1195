#include "rcm/calib/stereo_calibration.h"

#include "air_calibration.h"
#include "board_bundle_adjustment.h"

namespace rcm::calib {

Status StereoCalibrationOptions::Check() const {
  if (static_cast<int>(model) < 0 ||
      static_cast<int>(model) >= kNumLensModels) {
    return Status::Error("lens model must be one of " + LensModelNameList());
  }
  return internal::CheckSharedFitSettings(
      {huber_px, outlier_sigmas, min_outlier_threshold_px, max_outlier_rounds,
       max_num_iterations, min_corners_per_view, num_threads});
}

StatusOr<StereoCalibration> CalibrateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibrationOptions& options) {
  return internal::CalibrateInAir(target, views, {cam0_size, cam1_size},
                                  options);
}

}  // namespace rcm::calib
