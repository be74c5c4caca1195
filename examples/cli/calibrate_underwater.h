// rcm calibrate --underwater (calibrate_underwater.cc): the part of
// rcm calibrate that refines an air calibration on views of a target in
// the water.
#ifndef RCM_EXAMPLES_CLI_CALIBRATE_UNDERWATER_H_
#define RCM_EXAMPLES_CLI_CALIBRATE_UNDERWATER_H_

#include <gflags/gflags.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "air_views_flags.h"
#include "calibration_input.h"
#include "calibration_run.h"
#include "command.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"

DECLARE_bool(underwater);
DECLARE_bool(estimate_port_tilt);
DECLARE_bool(thin_port);

namespace rcm::cli {

// __FILE__ of calibrate_underwater.cc, for Subcommand::flag_sources.
extern const char kUnderwaterFlagsSource[];

// The flags rcm calibrate shares between air and water.
struct UnderwaterRunOptions {
  double huber_px = 1.0;
  double outlier_sigmas = 5.0;
  int min_corners = 6;
  int folds = 10;
  bool estimate_board_warp = true;  // not --flat-board
};

// Runs rcm calibrate --underwater once the common flags are checked
// (--out, the images given, the target); returns the exit code.
int RunCalibrateUnderwater(const Subcommand& command,
                           const calib::CalibrationTarget& target,
                           const CalibrationOutputPaths& paths,
                           const UnderwaterRunOptions& options);

// The report folder of an underwater calibration: the residual fields and
// coverage of each camera, the per-view RMS plot and CSV, from `drawing`
// (the result's lenses, poses and corners as a calibration's).
Status WriteUnderwaterReport(const std::string& folder,
                             const calib::StereoCalibration& drawing,
                             const std::vector<calib::StereoView>& views,
                             const calib::ImageSize sizes[2], bool one_camera,
                             calib::CalibrationReport* report);

// A 3-vector as the JSON writes it: [x, y, z].
nlohmann::json Vector3Json(const Eigen::Vector3d& v);

// What an underwater calibration reads, before anything is written: the
// air views of a joint calibration (when --air-left, --air-corners,
// --same-board or --air-target are given; --air-left alone for one camera
// when `allow_left_only_air`) and the water views. `banner` starts the
// lines that say what is read ("rcm calibrate --underwater"), `air_note`
// ends the air views' line.
struct UnderwaterInputs {
  std::optional<AirViewsInput> air_views;
  CalibrationInput input;
};
StatusOr<UnderwaterInputs> ReadUnderwaterInputs(
    const calib::CalibrationTarget& target, const CalibrationOutputPaths& paths,
    bool estimate_board_warp, bool allow_left_only_air,
    const std::string& banner, const std::string& air_note);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_CALIBRATE_UNDERWATER_H_
