// The --reference-depth flag: the depth at which the tools that need a
// central camera in the water (undistort, export) make a thick port's or a
// dome's camera exact (RefractiveCamera::CreateWithPort, CreateWithDome).
#ifndef RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_
#define RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_

#include <gflags/gflags.h>

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

DECLARE_double(reference_depth);

namespace rcm::cli {

// __FILE__ of reference_depth_flag.cc, for Subcommand::flag_sources.
extern const char kReferenceDepthFlagSource[];

// One line for the report when the rig has a thick port ("thick port:
// exact for points 2 m in front of the cameras, ..."); empty otherwise.
std::string ThickPortNote(const StereoRig& rig);

// The pixel error of a camera behind a dome made central at
// --reference-depth (RefractiveCamera::CreateWithDome) at other depths:
// the largest over the image at each of `depths` (meters), from
// EvaluateDomePortError's central camera.
struct DomeDepthErrors {
  std::vector<double> depths;
  std::vector<double> max_px;
};
StatusOr<DomeDepthErrors> DomeErrorsAtDepths(const Camera& camera,
                                             const DomePort& dome, double n);

// One line for the report of a dome rig: "dome (camchain port blocks):
// exact for points 2.00 m in front of the cameras (--reference-depth);
// the parallax of its rays: 0.8 px at 0.5 m, 0.1 px at 10 m"; per camera
// the largest of the two.
std::string DomeNote(const StereoRig& rig, const std::array<DomePort, 2>& domes,
                     double n);

// The JSON's "dome_parallax_px": per camera (left, right) the errors at
// the depths as [{"depth_m", "max_px"}, ...], null when they cannot be
// evaluated.
nlohmann::json DomeParallaxJson(const StereoRig& rig,
                                const std::array<DomePort, 2>& domes, double n);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_REFERENCE_DEPTH_FLAG_H_
