// The air views of rcm calibrate --underwater's joint calibration: the
// target in air seen by the same cameras, as images (--air-left DIR
// --air-right DIR) or a corners file (--air-corners FILE, its rows named
// by --air-left/--air-right patterns as --corners' are by --left/--right),
// and whether the air board is the water board (--same-board) or another
// (--air-target FILE).
#ifndef RCM_EXAMPLES_CLI_AIR_VIEWS_FLAGS_H_
#define RCM_EXAMPLES_CLI_AIR_VIEWS_FLAGS_H_

#include <gflags/gflags.h>

#include <optional>
#include <string>

#include "rcm/calib/underwater_calibration.h"
#include "rcm/util/status.h"

DECLARE_string(air_left);
DECLARE_string(air_right);
DECLARE_string(air_corners);
DECLARE_string(air_target);
DECLARE_bool(same_board);

namespace rcm::cli {

extern const char kAirViewsFlagsSource[];

// Any of the air views' flags is given.
bool AirViewsGiven();

struct AirViewsInput {
  calib::AirTargetViews views;
  // "air folders L and R: 32 pairs", "air corners file F: 64 images".
  std::string description;
  std::vector<std::string> warnings;
};

// The air views, detected in the images or read from the corners file,
// with the air board: --air-target's, else `water_target`. Errors (one
// line): --air-left without --air-right (or the reverse), --same-board
// or --air-target without air views, --same-board with an --air-target
// that is another board, a detection or file that fails, no air view
// that shows the target. `estimate_board_warp`: the air board's warp is
// estimated (not under --flat-board).
// `allow_left_only`: --air-left without --air-right gives one camera's air
// views (the dome calibration of one camera).
StatusOr<AirViewsInput> ReadAirViews(
    const calib::CalibrationTarget& water_target, bool estimate_board_warp,
    bool allow_left_only = false);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_AIR_VIEWS_FLAGS_H_
