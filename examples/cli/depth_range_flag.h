// The --depth-range flag, MIN,MAX in meters: the depths at which rcm
// simulate samples matches, and those rcm dome-check evaluates.
#ifndef RCM_EXAMPLES_CLI_DEPTH_RANGE_FLAG_H_
#define RCM_EXAMPLES_CLI_DEPTH_RANGE_FLAG_H_

#include <gflags/gflags.h>

DECLARE_string(depth_range);

namespace rcm::cli {

// __FILE__ of depth_range_flag.cc, for Subcommand::flag_sources.
extern const char kDepthRangeFlagSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_DEPTH_RANGE_FLAG_H_
