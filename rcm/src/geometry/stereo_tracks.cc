#include "rcm/geometry/stereo_tracks.h"

#include <algorithm>
#include <string>
#include <utility>

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

StatusOr<StereoTracks> TracksInWindow(const StereoTracks& tracks, int first,
                                      int count,
                                      std::vector<int>* landmark_ids) {
  if (first < 0 || count < 2 || first > tracks.num_frames - count) {
    return Status::Error(
        "a window of " + std::to_string(count) + " keyframes from keyframe " +
        std::to_string(first) + " is not within the tracks' " +
        std::to_string(tracks.num_frames) + " (a window needs 2)");
  }
  StereoTracks window;
  window.num_frames = count;
  std::vector<int> renumbered(std::max(tracks.num_landmarks, 0), -1);
  std::vector<int> ids;
  for (const StereoTrackObservation& o : tracks.observations) {
    if (o.frame < first || o.frame >= first + count || o.landmark < 0 ||
        o.landmark >= tracks.num_landmarks) {
      continue;
    }
    int& landmark = renumbered[o.landmark];
    if (landmark < 0) {
      landmark = static_cast<int>(ids.size());
      ids.push_back(o.landmark);
    }
    StereoTrackObservation moved = o;
    moved.frame = o.frame - first;
    moved.landmark = landmark;
    window.observations.push_back(moved);
  }
  window.num_landmarks = static_cast<int>(ids.size());
  if (window.num_landmarks == 0) {
    return Status::Error("no landmark is seen in keyframes " +
                         std::to_string(first) + "-" +
                         std::to_string(first + count - 1));
  }
  if (landmark_ids != nullptr) *landmark_ids = std::move(ids);
  return window;
}

}  // namespace rcm
