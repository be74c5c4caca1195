// The --reference-depth flag: the depth at which the tools that need a
// central camera in the water (undistort, export) make a thick port's
// camera exact (RefractiveCamera::CreateWithPort).
#ifndef RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_
#define RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_

#include <gflags/gflags.h>

#include <string>

#include "rcm/stereo/stereo_rig.h"

DECLARE_double(reference_depth);

namespace rcm::cli {

// __FILE__ of reference_depth_flag.cc, for Subcommand::flag_sources.
extern const char kReferenceDepthFlagSource[];

// One line for the report when the rig has a thick port ("thick port:
// exact for points 2 m in front of the cameras, ..."); empty otherwise.
std::string ThickPortNote(const StereoRig& rig);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_
