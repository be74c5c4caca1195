// What `rcm calibrate` does the same in air and under water: where its
// outputs go, the check that they can be written, and the detection pass
// over the images.
#ifndef RCM_EXAMPLES_CLI_CALIBRATION_RUN_H_
#define RCM_EXAMPLES_CLI_CALIBRATION_RUN_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/stereo_image_source.h"
#include "rcm/util/status.h"

namespace rcm::cli {

// Where the outputs go: `out` FILE.yaml -> FILE.yaml + FILE-report/;
// `out` DIR -> DIR/camchain.yaml + DIR/report/. A non-empty `report`
// overrides the report folder.
struct CalibrationOutputPaths {
  std::string camchain;
  std::string report;
};
CalibrationOutputPaths CalibrationOutputPathsFor(const std::string& out,
                                                 const std::string& report);

// The outputs before the detection, so that a calibration is not wasted
// on a camchain or report that cannot be written: the camchain is not a
// folder, and both folders exist or can be created (nothing is created).
Status CheckCalibrationOutputPaths(const CalibrationOutputPaths& paths);

// "fx 532.69 +- 0.37" with the leave-out sigma in parentheses when given.
std::string WithSigma(double value, double sigma, int digits,
                      std::optional<double> leave_out);

// The board's flatness as rcm calibrate prints it: "board flatness: bowl
// 0.74 +- 0.05 mm at the centre (x 0.40 +- 0.03, y 0.34 +- 0.03 mm)", or
// "board flatness: assumed flat (--flat-board)" when not estimated. warp
// [m], covariance [m^2] (board_warp.h); the bowl's leave-out sigma [m],
// when the folds ran, in parentheses after its covariance sigma as the
// other quantities' ("0.74 +- 0.05 (0.21) mm").
std::string BoardFlatnessText(
    bool estimated, const Eigen::Vector2d& warp,
    const Eigen::Matrix2d& covariance,
    std::optional<double> bowl_leave_out_sigma = std::nullopt);

// Its JSON: {"estimated", "board_warp_mm": [x, y], "board_warp_sigma_mm":
// [sx, sy], "bowl_mm", "bowl_sigma_mm"[, "bowl_leave_out_sigma_mm"]} (the
// bowl at the centre is warp_x + warp_y); {"estimated": false} when not
// estimated.
nlohmann::json BoardFlatnessJson(
    bool estimated, const Eigen::Vector2d& warp,
    const Eigen::Matrix2d& covariance,
    std::optional<double> bowl_leave_out_sigma = std::nullopt);

// The detection pass over every pair (a progress bar on a terminal). Its
// warnings wait until the pass is over, so that a run that fails says one
// thing, its error. A source of one camera (empty right images) gives
// views with the left observation only and no right size.
struct Detections {
  std::vector<calib::StereoView> views;
  std::optional<calib::ImageSize> sizes[2];
  int unreadable = 0;
  std::string first_unreadable;  // why the first unreadable pair was skipped
  std::vector<std::string> warnings;
  // Views with the target in both images, in the left or the right only.
  int stereo = 0;
  int left_only = 0;
  int right_only = 0;
};
// Sets the stereo / left_only / right_only counts from the views.
void CountViews(Detections* detections);
// Fails (one line) when one camera's images differ in size.
StatusOr<Detections> DetectTargets(StereoImageSource* source,
                                   const calib::CalibrationTarget& target);

// Writes the covariance sidecar (rcm/io/calibration_covariance_file.h)
// and then the camchain, the product, last; the sidecar is removed again
// if the camchain cannot be written, so that an older camchain never gets
// this calibration's sidecar.
Status WriteCamchainWithCovariance(const std::string& camchain_path,
                                   const Camchain& camchain,
                                   const CalibrationCovarianceFile& covariance);

// The error of a run where no pair could be read, or none showed the
// target (in both images, or with `one_camera` in the left one); Ok when
// the detections can be calibrated from.
Status CheckDetections(const Detections& detections, bool one_camera);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_CALIBRATION_RUN_H_
