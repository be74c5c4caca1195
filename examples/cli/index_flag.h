// The --n flag: the refractive index of the medium, shared by the
// subcommands that take one (simulate, demo, undistort, export).
#ifndef RCM_EXAMPLES_CLI_INDEX_FLAG_H_
#define RCM_EXAMPLES_CLI_INDEX_FLAG_H_

#include <gflags/gflags.h>

#include "rcm/util/status.h"

DECLARE_double(n);

namespace rcm::cli {

// __FILE__ of index_flag.cc, for Subcommand::flag_sources.
extern const char kIndexFlagSource[];

// The value of --n. Errors: "--n is required" when `required` and the
// flag was not given; "--n 2.5 is outside [1, 2]" (also NaN, inf).
StatusOr<double> RefractiveIndexFromFlag(bool required);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_INDEX_FLAG_H_
