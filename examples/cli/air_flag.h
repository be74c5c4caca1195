// The --air flag: the in-air calibration a subcommand compares with or
// refines (rcm compare, rcm calibrate --underwater).
#ifndef RCM_EXAMPLES_CLI_AIR_FLAG_H_
#define RCM_EXAMPLES_CLI_AIR_FLAG_H_

#include <gflags/gflags.h>

DECLARE_string(air);

namespace rcm::cli {

// __FILE__ of air_flag.cc, for Subcommand::flag_sources.
extern const char kAirFlagSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_AIR_FLAG_H_
