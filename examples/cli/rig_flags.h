// Flags that name the in-air calibrated rig, shared by the subcommands that
// read one (estimate, simulate).
#ifndef RCM_EXAMPLES_CLI_RIG_FLAGS_H_
#define RCM_EXAMPLES_CLI_RIG_FLAGS_H_

#include <gflags/gflags.h>

DECLARE_string(calib);
DECLARE_string(left_camera);
DECLARE_string(right_camera);

namespace rcm::cli {

// __FILE__ of rig_flags.cc, for Subcommand::flag_sources.
extern const char kRigFlagsSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_RIG_FLAGS_H_
