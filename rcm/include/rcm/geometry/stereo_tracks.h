// Landmarks tracked over the keyframes of a stereo sequence: which camera
// of which keyframe saw which landmark, at which raw pixel. What the
// tracker of the front end makes (rcm/frontend/stereo_tracker.h) and the
// sequence bundle adjustment takes
// (rcm/estimation/sequence_bundle_adjustment.h).
#ifndef RCM_GEOMETRY_STEREO_TRACKS_H_
#define RCM_GEOMETRY_STEREO_TRACKS_H_

#include <Eigen/Core>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

// One observation of a tracked landmark: keyframe `frame` (0-based index
// of the keyframes), camera 0 (left) or 1 (right), raw pixel.
struct StereoTrackObservation {
  int frame = 0;
  int camera = 0;
  int landmark = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

struct StereoTracks {
  int num_frames = 0;
  int num_landmarks = 0;
  std::vector<StereoTrackObservation> observations;

  // Indices in range, pixels finite, at least two keyframes and a
  // landmark: "observation 12 names landmark 40 of 30".
  Status Check() const;
};

// The tracks of keyframes [first, first + count), renumbered: keyframe f
// becomes f - first, and the landmarks seen there are numbered in the
// order of their first observation in the window. `landmark_ids`
// (optional) receives, per new landmark, its index in `tracks`: a bundle
// over a window of the dive (sequence_bundle_adjustment.h). Errors: a
// window outside the tracks or of fewer than 2 keyframes, or one in which
// no landmark is seen.
StatusOr<StereoTracks> TracksInWindow(const StereoTracks& tracks, int first,
                                      int count,
                                      std::vector<int>* landmark_ids = nullptr);

}  // namespace rcm

#endif  // RCM_GEOMETRY_STEREO_TRACKS_H_
