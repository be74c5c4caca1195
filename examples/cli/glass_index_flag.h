// The --glass-index flag: the index of a port's glass, flat (rcm simulate's
// thick port, simulation_flags.h) or dome (dome_port_flags.h).
#ifndef RCM_EXAMPLES_CLI_GLASS_INDEX_FLAG_H_
#define RCM_EXAMPLES_CLI_GLASS_INDEX_FLAG_H_

#include <gflags/gflags.h>

DECLARE_double(glass_index);

namespace rcm::cli {

// __FILE__ of glass_index_flag.cc, for Subcommand::flag_sources.
extern const char kGlassIndexFlagSource[];

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_GLASS_INDEX_FLAG_H_
