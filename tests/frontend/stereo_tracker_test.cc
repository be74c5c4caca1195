#include "rcm/frontend/stereo_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <vector>

#include "rcm/estimation/sequence_bundle_adjustment.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/sequence_simulator.h"

namespace rcm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// cam1's turn since the calibration: 0.5 degrees about a skew axis.
Eigen::Vector3d Turn() {
  return 0.5 * kPi / 180.0 * Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
}

// A rendered dive of the paper's rig (720x540, equidistant) through water
// of 1.333, cam1 turned since the calibration, keyframes 7.5 cm apart (the
// simulator's 0.3 m/s at 4 Hz); the tracker fed as `rcm` feeds it.
struct TrackedDive {
  std::vector<SequenceFrame> frames;
  StereoTracks tracks;
  std::vector<int> matches;
  std::vector<int> continued;
};

TrackedDive TrackDive(const StereoRig& calibration, int frames) {
  SequenceOptions options;
  options.media = {MediaSegment{1.333, frames}};
  options.trajectory.frame_rate = 4.0;
  options.cam1_drift.rotation = Turn();
  options.seed = 11;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(calibration, options).value();
  const StereoFrontEndOptions front_end_options;
  StereoDetector detector = StereoDetector::Create(front_end_options).value();
  StereoFrontEnd front_end =
      StereoFrontEnd::Create(calibration, front_end_options).value();
  StereoTracker tracker =
      StereoTracker::Create(calibration, StereoTrackerOptions()).value();
  TrackedDive dive;
  for (int i = 0; i < frames; ++i) {
    dive.frames.push_back(simulator->Frame(i).value());
    const SequenceFrame& frame = dive.frames.back();
    const DetectedStereoPair detected =
        detector.Detect(frame.left, frame.right, 2).value();
    const StereoMatches matches = front_end.Match(detected, i, frame.t).value();
    dive.matches.push_back(static_cast<int>(matches.matches.size()));
    dive.continued.push_back(tracker.AddKeyframe(detected, matches).value());
  }
  dive.tracks = tracker.tracks();
  return dive;
}

// The rendered dive, shortened to 6 keyframes (the issue asks
// 40; a test's budget is seconds): n within 2e-3 of the truth and within 3
// of its sigma, the turn within 0.05 degrees, the trajectory within 1 % of
// its length. Measured: n off by 2.8e-5 (sigma 2.8e-4), the turn by
// 0.0025 degrees, the trajectory by 0.3 mm over 0.39 m, the pixel noise
// 0.065 px (0.37 px with the links at the detector's keypoints, and n then
// 4 sigma off: the pyramid offset of stereo_tracker.h).
TEST(StereoTracker, RenderedDiveGivesTheBundleNTurnAndTrajectory) {
  const StereoRig calibration = AlphasenseFrontRectifiedRig();
  const int frames = 6;
  const TrackedDive dive = TrackDive(calibration, frames);
  ASSERT_EQ(dive.tracks.num_frames, frames);
  for (int i = 1; i < frames; ++i) {
    // Most matches continue a landmark (~55 % measured): the tracks hold.
    EXPECT_GT(dive.continued[i], dive.matches[i] / 3) << "keyframe " << i;
  }
  const StatusOr<SequenceBundleResult> result =
      SequenceBundleAdjustment::Create(calibration, SequenceBundleOptions())
          .value()
          .Solve(dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_LT(std::abs(result->n - 1.333), 2e-3);
  EXPECT_LT(std::abs(result->n - 1.333), 3.0 * result->sigma_n)
      << "n " << result->n << " +- " << result->sigma_n;
  EXPECT_LT((result->state.cam1_rotation - Turn()).norm() * 180.0 / kPi, 0.05);
  EXPECT_LT(result->pixel_sigma, 0.15);
  double path = 0.0;
  double squared_error = 0.0;
  const Rigid3d first_from_world = dive.frames[0].world_from_cam0.Inverse();
  for (int f = 0; f < frames; ++f) {
    const Rigid3d truth = first_from_world * dive.frames[f].world_from_cam0;
    squared_error += (truth.translation - result->WorldFromCam0(f).translation)
                         .squaredNorm();
    if (f > 0) {
      path += (dive.frames[f].world_from_cam0.translation -
               dive.frames[f - 1].world_from_cam0.translation)
                  .norm();
    }
  }
  EXPECT_LT(std::sqrt(squared_error / frames), 0.01 * path);
}

TEST(StereoTracker, BadKeyframesRefusedInOneLine) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  StereoTracker tracker =
      StereoTracker::Create(rig, StereoTrackerOptions()).value();
  DetectedStereoPair detected;
  detected.gray[0] =
      cv::Mat(rig.left().height(), rig.left().width(), CV_8U, cv::Scalar(0));
  detected.gray[1] = detected.gray[0].clone();
  detected.features[0].keypoints.resize(2);
  detected.features[0].descriptors = cv::Mat::zeros(2, 32, CV_8U);
  StereoMatches matches;
  matches.matches.resize(1);
  StatusOr<int> added = tracker.AddKeyframe(detected, matches);
  ASSERT_FALSE(added.ok());
  EXPECT_EQ(added.status().message(),
            "the matches do not carry their left keypoints (0 for 1 "
            "matches)");
  matches.left_keypoints_of_matches = {5};
  added = tracker.AddKeyframe(detected, matches);
  ASSERT_FALSE(added.ok());
  EXPECT_EQ(added.status().message(), "a match names left keypoint 5 of 2");
  matches.left_keypoints_of_matches = {1};
  ASSERT_TRUE(tracker.AddKeyframe(detected, matches).ok());
  EXPECT_EQ(tracker.num_keyframes(), 1);
  DetectedStereoPair smaller = detected;
  smaller.gray[0] = cv::Mat(100, 100, CV_8U, cv::Scalar(0));
  EXPECT_FALSE(tracker.AddKeyframe(smaller, matches).ok());
  EXPECT_EQ(tracker.num_keyframes(), 1);
}

TEST(StereoTrackerOptions, CheckNamesTheField) {
  StereoTrackerOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.ratio = 1.5;
  EXPECT_EQ(options.Check().message(), "tracker ratio = 1.5 must be in (0, 1]");
  options = StereoTrackerOptions();
  options.max_motion_px = 0.0;
  EXPECT_FALSE(options.Check().ok());
  options = StereoTrackerOptions();
  options.n = 2.5;
  EXPECT_FALSE(options.Check().ok());
  options = StereoTrackerOptions();
  options.subpixel.window = 4;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm
