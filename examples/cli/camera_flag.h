// The --camera flag: which camera of a camchain a one-camera subcommand
// reads (rcm compare, rcm dome-check).
#ifndef RCM_EXAMPLES_CLI_CAMERA_FLAG_H_
#define RCM_EXAMPLES_CLI_CAMERA_FLAG_H_

#include <gflags/gflags.h>

DECLARE_string(camera);

namespace rcm::cli {

// __FILE__ of camera_flag.cc, for Subcommand::flag_sources.
extern const char kCameraFlagSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_CAMERA_FLAG_H_
