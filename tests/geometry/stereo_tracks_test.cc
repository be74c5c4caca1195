#include "rcm/geometry/stereo_tracks.h"

#include <gtest/gtest.h>

#include <vector>

namespace rcm {
namespace {

// Landmark l seen by both cameras in keyframes [l, l + 2) of 5: each
// landmark spans two keyframes.
StereoTracks Staircase() {
  StereoTracks tracks;
  tracks.num_frames = 5;
  tracks.num_landmarks = 4;
  for (int l = 0; l < 4; ++l) {
    for (int f = l; f < l + 2; ++f) {
      for (int c = 0; c < 2; ++c) {
        tracks.observations.push_back(
            {f, c, l, Eigen::Vector2d(10.0 * l + c, 100.0 + f)});
      }
    }
  }
  return tracks;
}

TEST(TracksInWindow, RenumbersKeyframesAndLandmarks) {
  std::vector<int> ids;
  const StereoTracks window = TracksInWindow(Staircase(), 2, 3, &ids).value();
  EXPECT_EQ(window.num_frames, 3);
  // Keyframes 2-4 see landmarks 1 (in 2), 2 (2, 3) and 3 (3, 4).
  EXPECT_EQ(ids, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(window.num_landmarks, 3);
  ASSERT_TRUE(window.Check().ok()) << window.Check().message();
  ASSERT_EQ(window.observations.size(), 2u + 4u + 4u);
  for (const StereoTrackObservation& o : window.observations) {
    const int original_frame = o.frame + 2;
    const int original_landmark = ids[o.landmark];
    // The pixel names where it came from (Staircase).
    EXPECT_EQ(o.pixel, Eigen::Vector2d(10.0 * original_landmark + o.camera,
                                       100.0 + original_frame));
  }
  // The whole dive is itself.
  const StereoTracks all = TracksInWindow(Staircase(), 0, 5).value();
  EXPECT_EQ(all.num_landmarks, 4);
  EXPECT_EQ(all.observations.size(), Staircase().observations.size());
}

TEST(TracksInWindow, BadWindowsRefusedInOneLine) {
  EXPECT_EQ(TracksInWindow(Staircase(), 4, 2).status().message(),
            "a window of 2 keyframes from keyframe 4 is not within the "
            "tracks' 5 (a window needs 2)");
  EXPECT_FALSE(TracksInWindow(Staircase(), 0, 1).ok());
  EXPECT_FALSE(TracksInWindow(Staircase(), -1, 2).ok());
  StereoTracks sparse = Staircase();
  sparse.num_frames = 8;  // keyframes 5-7 see nothing
  EXPECT_EQ(TracksInWindow(sparse, 5, 3).status().message(),
            "no landmark is seen in keyframes 5-7");
}

}  // namespace
}  // namespace rcm
