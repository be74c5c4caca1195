#include "reference_depth_flag.h"

#include "rcm/util/number_format.h"

DEFINE_double(reference_depth, 2.0,
              "with a thick port (camchain port blocks): depth in meters at "
              "which the central water-side camera is exact; nearer and "
              "farther points carry the port's parallax");

namespace rcm::cli {

extern const char kReferenceDepthFlagSource[] = __FILE__;

std::string ThickPortNote(const StereoRig& rig) {
  if (!rig.HasThickPort()) return "";
  return "thick port (camchain port blocks): exact for points " +
         FormatFixed(FLAGS_reference_depth, 2) +
         " m in front of the cameras (--reference-depth); nearer and farther "
         "points carry the port's parallax";
}

}  // namespace rcm::cli
