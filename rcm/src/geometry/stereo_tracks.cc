#include "rcm/geometry/stereo_tracks.h"

#include <string>

namespace rcm {

Status StereoTracks::Check() const {
  if (num_frames < 2) {
    return Status::Error("tracks need at least 2 keyframes, not " +
                         std::to_string(num_frames));
  }
  if (num_landmarks < 1) {
    return Status::Error("tracks need a landmark, not " +
                         std::to_string(num_landmarks));
  }
  for (size_t i = 0; i < observations.size(); ++i) {
    const StereoTrackObservation& o = observations[i];
    const std::string name = "observation " + std::to_string(i);
    if (o.frame < 0 || o.frame >= num_frames) {
      return Status::Error(name + " names keyframe " + std::to_string(o.frame) +
                           " of " + std::to_string(num_frames));
    }
    if (o.camera != 0 && o.camera != 1) {
      return Status::Error(name + " names camera " + std::to_string(o.camera) +
                           " (0 left, 1 right)");
    }
    if (o.landmark < 0 || o.landmark >= num_landmarks) {
      return Status::Error(name + " names landmark " +
                           std::to_string(o.landmark) + " of " +
                           std::to_string(num_landmarks));
    }
    if (!o.pixel.allFinite()) {
      return Status::Error(name + " has a non-finite pixel");
    }
  }
  return Status::Ok();
}

}  // namespace rcm
