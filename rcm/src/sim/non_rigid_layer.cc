#include "rcm/sim/non_rigid_layer.h"

#include <cmath>
#include <sstream>

#include "rcm/util/splitmix64.h"

namespace rcm {

Status NonRigidLayer::Check() const {
  std::ostringstream message;
  if (!(image_fraction >= 0.0 && image_fraction <= 1.0)) {
    message << "non-rigid layer: image fraction " << image_fraction
            << " is outside [0, 1]";
  } else if (!(std::abs(offset_px) <= kMaxOffsetPx)) {
    message << "non-rigid layer: offset of " << offset_px << " px is outside [-"
            << kMaxOffsetPx << ", " << kMaxOffsetPx << "] px";
  } else if (!(offset_sd_px >= 0.0 && offset_sd_px <= kMaxOffsetPx)) {
    message << "non-rigid layer: offset sd of " << offset_sd_px
            << " px is outside [0, " << kMaxOffsetPx << "] px";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

double NonRigidLayer::OffsetOfFrame(uint64_t seed, int frame) const {
  if (IsZero()) return 0.0;
  // Keyed by (seed, frame), apart from ExposureDelay's keys.
  const uint64_t key =
      IndexKey(seed, 0x3C6EF372FE94F82Bull, static_cast<uint64_t>(frame));
  return offset_px + offset_sd_px * GaussianFromHash(SplitMix64(key));
}

}  // namespace rcm
