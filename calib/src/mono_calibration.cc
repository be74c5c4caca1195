#include "rcm/calib/mono_calibration.h"

#include <string>
#include <utility>

#include "air_calibration.h"

namespace rcm::calib {

StatusOr<StereoCalibration> CalibrateMono(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& size, const StereoCalibrationOptions& options) {
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].right.has_value()) {
      return Status::Error(
          "view " + std::to_string(v) +
          " has a right observation: a one-camera calibration takes the left "
          "observations only (CalibrateStereo calibrates a pair)");
    }
  }
  return internal::CalibrateInAir(target, views, {size}, options);
}

std::vector<StereoView> MonoViews(
    const std::vector<std::optional<TargetObservation>>& observations) {
  std::vector<StereoView> views(observations.size());
  for (size_t v = 0; v < observations.size(); ++v) {
    views[v].left_name = "view " + std::to_string(v);
    views[v].left = observations[v];
  }
  return views;
}

}  // namespace rcm::calib
