// Flags that name a calibration target (board): a Kalibr target YAML
// (--target), or --board with its sizes. Shared by the subcommands that
// see boards: rcm calibrate detects them, rcm simulate renders them.
#ifndef RCM_EXAMPLES_CLI_TARGET_FLAGS_H_
#define RCM_EXAMPLES_CLI_TARGET_FLAGS_H_

#include <gflags/gflags.h>

#include "rcm/calib/calibration_target.h"
#include "rcm/util/status.h"

DECLARE_string(target);
DECLARE_string(board);
DECLARE_int32(cols);
DECLARE_int32(rows);
DECLARE_double(square);
DECLARE_double(tag_size);
DECLARE_double(tag_spacing);
DECLARE_double(marker);
DECLARE_string(dictionary);

namespace rcm::cli {

// __FILE__ of target_flags.cc, for Subcommand::flag_sources.
extern const char kTargetFlagsSource[];

// True when --target or --board is set.
bool TargetGiven();

// True when --board names a chessboard (chessboard or checkerboard).
bool BoardIsChessboard();

// The target the flags name. Errors (one line): neither or both of
// --target and --board, an unknown --board, and the readers' and makers'
// own errors (calibration_target.h), prefixed with the flag.
StatusOr<calib::CalibrationTarget> TargetFromFlags();

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_TARGET_FLAGS_H_
