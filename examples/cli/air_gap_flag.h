// The --estimate-air-gap flag, shared by the subcommands that can estimate
// the ports' air gap with n: rcm estimate (from matches) and rcm
// calibrate --underwater (from a target).
#ifndef RCM_EXAMPLES_CLI_AIR_GAP_FLAG_H_
#define RCM_EXAMPLES_CLI_AIR_GAP_FLAG_H_

#include <gflags/gflags.h>

DECLARE_bool(estimate_air_gap);

namespace rcm::cli {

// __FILE__ of air_gap_flag.cc, for Subcommand::flag_sources.
extern const char kAirGapFlagSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_AIR_GAP_FLAG_H_
