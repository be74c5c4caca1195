// rcm calibrate --underwater --port dome (calibrate_dome.cc): the
// decentering of each camera's dome, and n with --estimate-n, from views of
// a target in the water with the air calibration's lenses held, or with
// air views (--air-left / --air-corners) estimated from air and water
// together, the air views traced through the dome at n = 1
// (rcm/calib/dome_calibration.h).
#ifndef RCM_EXAMPLES_CLI_CALIBRATE_DOME_H_
#define RCM_EXAMPLES_CLI_CALIBRATE_DOME_H_

#include <gflags/gflags.h>

#include <string>

#include "calibrate_underwater.h"
#include "calibration_run.h"
#include "command.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/util/status.h"

DECLARE_bool(estimate_n);

namespace rcm::cli {

// __FILE__ of calibrate_dome.cc, for Subcommand::flag_sources.
extern const char kDomeCalibrationFlagsSource[];

// Fails when a dome flag (--port, --dome-*, --glass-index, --estimate-n,
// --n) was given to a run that is not a dome's (`where`: "an air
// calibration", "a flat port").
Status CheckNoDomeFlags(const std::string& where);

// True when --air names a camchain whose cameras have dome port blocks.
bool AirCamchainHasDomes();

// Runs rcm calibrate --underwater for a dome; returns the exit code.
// Writes the report folder (residuals, coverage, per-view RMS,
// underwater.json) and then the camchain: the air camchain with each
// camera's dome block (the estimated decentering).
int RunCalibrateDome(const Subcommand& command,
                     const calib::CalibrationTarget& target,
                     const CalibrationOutputPaths& paths,
                     const UnderwaterRunOptions& run);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_CALIBRATE_DOME_H_
