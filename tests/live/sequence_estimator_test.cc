#include "rcm/live/sequence_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "rcm/io/stereo_rig_file.h"
#include "rcm/live/live_pipeline.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/sequence_simulator.h"

namespace rcm::sequence_estimator_test {
namespace {

constexpr double kWater = 1.333;
constexpr double kDegree = M_PI / 180.0;

// A rendered sequence of `rig` (one ray per pixel, as the simulator's
// quick tests), cam1 turned by `drift` since the rig's calibration.
std::unique_ptr<SequenceSimulator> Sequence(
    const std::vector<MediaSegment>& media,
    const Eigen::Vector3d& drift = Eigen::Vector3d::Zero()) {
  SequenceOptions options;
  options.media = media;
  options.render.supersampling = 1;
  options.cam1_drift.rotation = drift;
  return SequenceSimulator::Create(AlphasenseFrontRectifiedRig(), options)
      .value();
}

// The rig as `rcm` reads a camchain without a sidecar (the default drift
// prior: cam1's rotation is self-calibrated).
StereoRig RigAsRead() {
  return WithDefaultCalibrationUncertainty(AlphasenseFrontRectifiedRig())
      .value();
}

// The ROS node's pipeline runs the engine: on the same pairs with the same
// options its window estimate is the engine's, pair by pair (the same code
// on the same doubles, one thread: bit for bit; 1e-12 allows the order of
// a sum).
TEST(SequenceEstimator, TheLivePipelineRunsIt) {
  constexpr double kSameRun = 1e-12;
  std::unique_ptr<SequenceSimulator> simulator = Sequence({{kWater, 4}});
  const LivePipelineOptions live_options;
  std::unique_ptr<LivePipeline> pipeline =
      LivePipeline::Create(RigAsRead(), live_options).value();
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(RigAsRead(), LiveSequenceOptions(live_options))
          .value();
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    const StatusOr<LiveFrame> live =
        pipeline->Process(frame.left, frame.right, frame.t);
    const StatusOr<SequencePair> pair =
        sequence->AddPair(frame.left, frame.right, i, frame.t);
    ASSERT_TRUE(live.ok()) << live.status().message();
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    ASSERT_EQ(live->estimate.ok(), pair->window.ok());
    if (!pair->window.ok()) continue;
    EXPECT_NEAR(live->estimate->n, pair->window->n, kSameRun) << "pair " << i;
    EXPECT_NEAR(live->estimate->sigma_n, pair->window->sigma_n, kSameRun);
    EXPECT_EQ(live->num_matches, static_cast<int64_t>(pair->matches.size()));
  }
  EXPECT_TRUE(sequence->frames().empty());  // the live options keep none
}

// A pair detected apart (as EstimateSequence detects the next pair while
// this one is added) then added is the pair added whole: the same matches
// to the bit, pair after pair, and the same estimates (1e-12 allows the
// order of the solver's sums on two threads).
TEST(SequenceEstimator, DetectedPairsAreThePairsAddedWhole) {
  constexpr double kSameRun = 1e-12;
  std::unique_ptr<SequenceSimulator> simulator = Sequence({{kWater, 3}});
  const SequenceEstimatorOptions options;
  std::unique_ptr<SequenceEstimator> whole =
      SequenceEstimator::Create(RigAsRead(), options).value();
  std::unique_ptr<SequenceEstimator> apart =
      SequenceEstimator::Create(RigAsRead(), options).value();
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    const StatusOr<SequencePair> a =
        whole->AddPair(frame.left, frame.right, i, frame.t);
    const StatusOr<DetectedStereoPair> detected =
        apart->Detect(frame.left, frame.right, 1);
    ASSERT_TRUE(detected.ok()) << detected.status().message();
    const StatusOr<SequencePair> b =
        apart->AddDetectedPair(*detected, i, frame.t);
    ASSERT_TRUE(a.ok()) << a.status().message();
    ASSERT_TRUE(b.ok()) << b.status().message();
    ASSERT_EQ(a->matches.size(), b->matches.size());
    for (size_t k = 0; k < a->matches.size(); ++k) {
      EXPECT_EQ(a->matches[k].left_pixel, b->matches[k].left_pixel);
      EXPECT_EQ(a->matches[k].right_pixel, b->matches[k].right_pixel);
    }
    ASSERT_EQ(a->own.ok(), b->own.ok());
    if (a->own.ok()) EXPECT_NEAR(a->own->n, b->own->n, kSameRun) << i;
    ASSERT_EQ(a->window.ok(), b->window.ok());
    if (a->window.ok()) EXPECT_NEAR(a->window->n, b->window->n, kSameRun);
  }
  const StatusOr<RefractiveIndexEstimate> a = whole->Estimate();
  const StatusOr<RefractiveIndexEstimate> b = apart->Estimate();
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_NEAR(a->n, b->n, kSameRun);
  EXPECT_NEAR(a->sigma_n, b->sigma_n, kSameRun);
}

// cam1 turned by 0.4 degrees since the calibration (4 drift-prior sigmas):
// the window self-calibrates the turn, the front end follows it, and the
// final estimate (solved once, over every kept pair) names the stale
// calibration. The turn is found within 0.05 degrees (its sigma on 6 pairs
// is ~0.01 degree). n is read within 5 of its sigmas, not 3: the prior,
// centred on the calibration, pulls the turn 4 of its sigmas back, and n,
// correlated with it, moves (measured on these pairs: +3.2e-3, 3.1 sigma;
// the same pairs without the turn -1.0e-3, 1.0 sigma). That is what the
// warning is for: calibrate in the water.
TEST(SequenceEstimator, FollowsATurnedCam1AndSaysTheCalibrationIsStale) {
  const Eigen::Vector3d drift(0.0, 0.4 * kDegree, 0.0);
  std::unique_ptr<SequenceSimulator> simulator = Sequence({{kWater, 6}}, drift);
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(RigAsRead(), SequenceEstimatorOptions())
          .value();
  int followed = 0;
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    const StatusOr<SequencePair> pair =
        sequence->AddPair(frame.left, frame.right, i, frame.t);
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    followed += pair->followed ? 1 : 0;
  }
  EXPECT_GE(followed, 1);
  EXPECT_LT((sequence->matching_rotation() - drift).norm(), 0.05 * kDegree);
  EXPECT_EQ(sequence->first_matching_rotation(), Eigen::Vector3d::Zero());
  const StatusOr<RefractiveIndexEstimate> estimate = sequence->Estimate();
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  EXPECT_EQ(estimate->frames, 6);
  EXPECT_LT(std::abs(estimate->n - kWater), 5.0 * estimate->sigma_n)
      << estimate->n << " +- " << estimate->sigma_n;
  ASSERT_TRUE(estimate->rotation.has_value());
  EXPECT_LT((estimate->rotation->angle_axis - drift).norm(), 0.05 * kDegree);
  bool stale = false;
  for (const std::string& warning : estimate->warnings) {
    stale |= warning.find("the calibration is stale") != std::string::npos;
  }
  EXPECT_TRUE(stale);
  ASSERT_EQ(estimate->per_frame.size(), 6u);  // each pair's own estimate
}

// Air, then water: the window declares the change, and the final estimate
// takes the frames of the water only.
TEST(SequenceEstimator, EstimatesOverTheCurrentMedium) {
  std::unique_ptr<SequenceSimulator> simulator =
      Sequence({{1.0, 3}, {kWater, 4}});
  SequenceEstimatorOptions options;
  options.estimation.window.window_frames = 3;
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(AlphasenseFrontRectifiedRig(), options).value();
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    ASSERT_TRUE(sequence->AddPair(frame.left, frame.right, i, frame.t).ok());
  }
  ASSERT_TRUE(sequence->medium_first_frame().has_value());
  EXPECT_EQ(*sequence->medium_first_frame(), 3);
  const StatusOr<RefractiveIndexEstimate> estimate = sequence->Estimate();
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  EXPECT_EQ(estimate->frames, 4);
  EXPECT_LT(std::abs(estimate->n - kWater), 3.0 * estimate->sigma_n);
}

// Without kept frames only the window takes a pair's matches: the front end
// refines only as many; with them, the final estimate takes every match.
TEST(SequenceEstimatorOptions, FrontEndRefinesWhatTheMatchesAreFor) {
  SequenceEstimatorOptions options;
  EXPECT_EQ(options.FrontEnd().max_refined_matches, 0);
  options.keep_frames = false;
  EXPECT_EQ(options.FrontEnd().max_refined_matches, options.window_matches);
  options.window_matches = 0;  // the window takes all
  EXPECT_EQ(options.FrontEnd().max_refined_matches, 0);
  options.front_end.max_refined_matches = 50;  // the caller's own cap
  EXPECT_EQ(options.FrontEnd().max_refined_matches, 50);
}

// The bundle estimator runs in the engine: the pairs are its keyframes.
// Keyframes 7.5 cm apart (4 Hz), cam1 turned 0.5 deg since the
// calibration (with the default drift prior, which the bundle's turn
// absorbs and whose translation sigma_n carries; the focal drift prior's
// propagation is tested in sequence_bundle_adjustment_test.cc): n within
// 2e-3 and within 3 sigma, the turn within 0.05 deg, one pose per pair.
TEST(SequenceEstimator, BundleOverTheRenderedPairs) {
  const int frames = 6;
  const Eigen::Vector3d turn =
      0.5 * kDegree * Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  SequenceOptions simulation;
  simulation.media = {{kWater, frames}};
  simulation.trajectory.frame_rate = 4.0;
  simulation.cam1_drift.rotation = turn;
  simulation.render.supersampling = 1;
  simulation.seed = 11;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(AlphasenseFrontRectifiedRig(), simulation)
          .value();
  SequenceEstimatorOptions options;
  options.estimation.estimator = EstimatorKind::kBundle;
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(
          AlphasenseFrontRectifiedRig()
              .WithCalibrationUncertainty(
                  CalibrationUncertainty::DefaultDriftPrior())
              .value(),
          options)
          .value();
  for (int i = 0; i < frames; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    const StatusOr<SequencePair> pair =
        sequence->AddPair(frame.left, frame.right, i, frame.t);
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    ASSERT_TRUE(pair->continued_tracks.has_value());
    if (i > 0) {
      EXPECT_GT(*pair->continued_tracks,
                static_cast<int>(pair->matches.size()) / 3);
    }
  }
  const StatusOr<RefractiveIndexEstimate> estimate = sequence->Estimate();
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  ASSERT_EQ(estimate->estimator, "bundle");
  ASSERT_TRUE(estimate->bundle.has_value());
  EXPECT_EQ(estimate->bundle->trajectory.size(), static_cast<size_t>(frames));
  EXPECT_GT(estimate->bundle->tracks, 0);
  EXPECT_LT(std::abs(estimate->n - kWater), 2e-3);
  EXPECT_LT(std::abs(estimate->n - kWater), 3.0 * estimate->sigma_n);
  ASSERT_TRUE(estimate->rotation.has_value());
  EXPECT_LT((estimate->rotation->angle_axis - turn).norm() / kDegree, 0.05);
}

// Where the bundle refuses (a rig that does not move), the engine gives
// the refine estimate, the bundle's reason its first warning.
TEST(SequenceEstimator, BundleFallsBackToRefineForAStillRig) {
  SequenceOptions simulation;
  simulation.media = {{kWater, 3}};
  simulation.render.supersampling = 1;
  simulation.trajectory.speed = 0.0;
  simulation.trajectory.sway_amplitude = 0.0;
  simulation.trajectory.heave_amplitude = 0.0;
  simulation.trajectory.yaw_amplitude_deg = 0.0;
  simulation.trajectory.rock_amplitude_deg = 0.0;
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(AlphasenseFrontRectifiedRig(), simulation)
          .value();
  SequenceEstimatorOptions options;
  options.estimation.estimator = EstimatorKind::kBundle;
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(RigAsRead(), options).value();
  for (int i = 0; i < simulator->num_frames(); ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    ASSERT_TRUE(sequence->AddPair(frame.left, frame.right, i, frame.t).ok());
  }
  const StatusOr<RefractiveIndexEstimate> estimate = sequence->Estimate();
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  EXPECT_EQ(estimate->estimator, "refine");
  ASSERT_FALSE(estimate->warnings.empty());
  EXPECT_EQ(estimate->warnings[0].rfind(
                "the bundle estimator: the rig does not move: ", 0),
            0u)
      << estimate->warnings[0];
  EXPECT_FALSE(estimate->bundle.has_value());
}

TEST(SequenceEstimator, RefusesBadPairsAndOptions) {
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(AlphasenseFrontRectifiedRig(),
                                SequenceEstimatorOptions())
          .value();
  const cv::Mat small(10, 10, CV_8UC1, cv::Scalar(0));
  EXPECT_FALSE(sequence->AddPair(small, small, 0).ok());
  EXPECT_FALSE(sequence->Estimate().ok());  // nothing kept

  SequenceEstimatorOptions options;
  options.window_matches = -1;
  EXPECT_FALSE(options.Check().ok());
  options = SequenceEstimatorOptions();
  options.follow_rotation_px = 0.0;
  EXPECT_FALSE(options.Check().ok());
  options = SequenceEstimatorOptions();
  options.max_matching_passes = 0;
  EXPECT_FALSE(options.Check().ok());
  // A freely refined rotation is the final estimate's; the window keeps
  // its self-calibration.
  options = SequenceEstimatorOptions();
  options.estimation.refinement.refine_rotation = true;
  EXPECT_TRUE(options.Check().ok());
  EXPECT_FALSE(options.WindowRefinement().refine_rotation);
  options.estimation.estimator = EstimatorKind::kWindow;
  EXPECT_FALSE(options.Check().ok());  // refine_rotation: refine only
  EXPECT_TRUE(SequenceEstimatorOptions().Check().ok());
  // The bundle keeps the pairs.
  options = SequenceEstimatorOptions();
  options.estimation.estimator = EstimatorKind::kBundle;
  EXPECT_TRUE(options.Check().ok());
  options.keep_frames = false;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm::sequence_estimator_test
