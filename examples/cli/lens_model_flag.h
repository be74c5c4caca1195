// The --model flag: a lens model by its Kalibr name, shared by the
// subcommands that produce a calibration (calibrate, export), each with
// its own default.
#ifndef RCM_EXAMPLES_CLI_LENS_MODEL_FLAG_H_
#define RCM_EXAMPLES_CLI_LENS_MODEL_FLAG_H_

#include <gflags/gflags.h>

#include "rcm/camera/lens_models.h"
#include "rcm/util/status.h"

DECLARE_string(model);

namespace rcm::cli {

// __FILE__ of lens_model_flag.cc, for Subcommand::flag_sources.
extern const char kLensModelFlagSource[];

// The model --model names, `default_model` when it is not given. Error:
// "unknown --model 'fisheye' (available: none, radtan, equidistant,
// rational, ds, eucm)".
StatusOr<LensModelId> LensModelFromFlag(LensModelId default_model);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_LENS_MODEL_FLAG_H_
