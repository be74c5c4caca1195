#include "rcm/estimation/online_estimator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::online_estimator_test {
namespace {

// The bar for online == batch on the same data. Both solve the
// same least-squares problem on the same inliers, this estimator to ~1e-15
// in n (locus_cost_function_test.cc), the batch with Ceres until the cost
// changes by less than 1e-14 relative, which leaves ~1e-9 in n: the
// observed differences (printed) are 2e-10 - 5e-9.
constexpr double kBatchTolerance = 1e-6;
// Exact data: residuals below 1e-12 px at the true n (see
// sampson_coplanarity_error_test.cc); the bar for noise-free data.
constexpr double kExactTolerance = 1e-9;
// sigma_px on exact data: C(n) is stored at nodes to the rounding of its
// values on the panel (eps x ~100 px^2 for 300 matches), so the
// interpolated C(n) at the minimum is ~1e-14 px^2 rather than 1e-24, and
// sqrt(C / (N - 1)) has a floor of ~1e-8 px (measured 4e-9 - 8e-9).
constexpr double kExactSigmaPx = 1e-7;

// The matches split by frame, in frame order, with each match's index in
// the whole sequence.
struct Frames {
  std::vector<std::vector<StereoCorrespondence>> matches;
  std::vector<std::vector<int64_t>> source;
};
Frames SplitByFrame(const std::vector<StereoCorrespondence>& sequence) {
  std::map<int64_t, int> slot;
  Frames frames;
  for (size_t i = 0; i < sequence.size(); ++i) {
    auto [it, inserted] = slot.emplace(sequence[i].frame,
                                       static_cast<int>(frames.matches.size()));
    if (inserted) {
      frames.matches.emplace_back();
      frames.source.emplace_back();
    }
    frames.matches[it->second].push_back(sequence[i]);
    frames.source[it->second].push_back(static_cast<int64_t>(i));
  }
  return frames;
}

// Feeds the frames; returns the estimator and (through `inliers`) the
// union of the frames' inliers as indices into the whole sequence.
OnlineRefractiveIndexEstimator RunOnline(
    const StereoRig& rig, const std::vector<StereoCorrespondence>& sequence,
    const RefinementOptions& options, std::vector<int64_t>* inliers,
    double* seconds_per_frame = nullptr) {
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, options).value();
  const Frames frames = SplitByFrame(sequence);
  const auto start = std::chrono::steady_clock::now();
  for (size_t f = 0; f < frames.matches.size(); ++f) {
    const OnlineRefractiveIndexEstimator::FrameUpdate update =
        estimator.AddFrame(frames.matches[f]);
    EXPECT_EQ(update.frame, static_cast<int64_t>(f));
    for (const int64_t i : update.inliers) {
      inliers->push_back(frames.source[f][i]);
    }
  }
  if (seconds_per_frame != nullptr) {
    *seconds_per_frame =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count() /
        static_cast<double>(frames.matches.size());
  }
  std::sort(inliers->begin(), inliers->end());
  return estimator;
}

// The frames' rows share one rotation: the first pooled one, kept while
// the pooled rotation stays within kMaxDistance of it, moved to it beyond.
TEST(LinearizationPoint, FollowsThePooledRotationOnlyBeyondItsDistance) {
  LinearizationPoint point;
  point.Follow(std::nullopt);
  EXPECT_FALSE(point.rotation.has_value());
  const Eigen::Vector3d first(1e-3, -2e-3, 5e-4);
  point.Follow(first);
  ASSERT_TRUE(point.rotation.has_value());
  EXPECT_EQ(*point.rotation, first);
  const Eigen::Vector3d near =
      first + Eigen::Vector3d(0.9 * LinearizationPoint::kMaxDistance, 0, 0);
  point.Follow(near);
  EXPECT_EQ(*point.rotation, first);
  point.Follow(std::nullopt);  // no pooled rotation: the point stays
  EXPECT_EQ(*point.rotation, first);
  const Eigen::Vector3d far =
      first + Eigen::Vector3d(0, 1.1 * LinearizationPoint::kMaxDistance, 0);
  point.Follow(far);
  EXPECT_EQ(*point.rotation, far);
}

TEST(OnlineEstimator, MatchesBatchOnCleanData) {
  // No robust stage and no threshold: both estimators fit plain least
  // squares to every match, so they must agree whatever the noise.
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> sequence =
      test::ExactSequence(rig, 1.333, 6, 200, 1);
  AddPixelNoise(0.5, 2, &sequence);
  RefinementOptions options;
  options.loss = RobustLoss::kNone;
  options.inlier_threshold_px = std::numeric_limits<double>::infinity();

  std::vector<int64_t> inliers;
  const OnlineRefractiveIndexEstimator online =
      RunOnline(rig, sequence, options, &inliers);
  const RefinementSummary batch =
      RefineRefractiveIndex(rig, sequence, options).value();
  const OnlineRefractiveIndexEstimator::Estimate estimate =
      online.Current().value();
  std::printf("clean: online - batch: n %.3g, sigma_n %.3g (relative)\n",
              estimate.n - batch.n, estimate.sigma_n / batch.sigma_n - 1.0);
  EXPECT_NEAR(estimate.n, batch.n, kBatchTolerance);
  EXPECT_NEAR(estimate.sigma_n, batch.sigma_n, kBatchTolerance * batch.sigma_n);
  EXPECT_NEAR(estimate.sigma_px, batch.sigma_px,
              kBatchTolerance * batch.sigma_px);
  EXPECT_EQ(estimate.crlb, estimate.sigma_n);
  EXPECT_EQ(estimate.inliers, 1200);
  EXPECT_EQ(estimate.correspondences, 1200);
  EXPECT_EQ(estimate.frames, 6);
}

TEST(OnlineEstimator, MatchesBatchWithOutliers) {
  // Default (robust) options, 0.5 px noise, 20 % gross outliers: the
  // per-frame inlier classification picks the batch's inliers, and then
  // the two stage-2 problems are identical.
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> sequence =
      test::ExactSequence(rig, 1.333, 5, 200, 3);
  AddPixelNoise(0.5, 4, &sequence);
  AddOutliers(rig, 0.2, 5, &sequence);
  const RefinementOptions options;

  std::vector<int64_t> inliers;
  double seconds_per_frame = 0.0;
  const OnlineRefractiveIndexEstimator online =
      RunOnline(rig, sequence, options, &inliers, &seconds_per_frame);
  const RefinementSummary batch =
      RefineRefractiveIndex(rig, sequence, options).value();
  const OnlineRefractiveIndexEstimator::Estimate estimate =
      online.Current().value();
  std::printf(
      "outliers: online - batch: n %.3g, sigma_n %.3g (relative); %zu "
      "inliers; %.2f ms per frame of 200\n",
      estimate.n - batch.n, estimate.sigma_n / batch.sigma_n - 1.0,
      inliers.size(), 1e3 * seconds_per_frame);
  EXPECT_EQ(inliers, batch.inliers);
  EXPECT_EQ(estimate.inliers, static_cast<int64_t>(batch.inliers.size()));
  EXPECT_NEAR(estimate.n, batch.n, kBatchTolerance);
  EXPECT_NEAR(estimate.sigma_n, batch.sigma_n, kBatchTolerance * batch.sigma_n);
}

TEST(OnlineEstimator, FrameEstimateIsTheBatchOfThatFrame) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> sequence =
      test::ExactSequence(rig, 1.333, 3, 200, 6);
  AddPixelNoise(0.5, 7, &sequence);
  AddOutliers(rig, 0.2, 8, &sequence);
  const Frames frames = SplitByFrame(sequence);
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, RefinementOptions()).value();
  for (const std::vector<StereoCorrespondence>& frame : frames.matches) {
    const OnlineRefractiveIndexEstimator::FrameUpdate update =
        estimator.AddFrame(frame);
    const RefinementSummary batch =
        RefineRefractiveIndex(rig, frame, RefinementOptions()).value();
    ASSERT_TRUE(update.frame_estimate.ok());
    EXPECT_EQ(update.inliers, batch.inliers);
    EXPECT_NEAR(update.frame_estimate->n, batch.n, kBatchTolerance);
    EXPECT_NEAR(update.frame_estimate->sigma_n, batch.sigma_n,
                kBatchTolerance * batch.sigma_n);
    EXPECT_EQ(update.usable, 200);
    EXPECT_FALSE(update.skipped);
  }
}

// The dataset rig as calibrated, with the default drift priors (`rig`),
// and as it is (`truth`): cam1 turned by (0, 0.1, 0.05) deg since.
struct TurnedRig {
  StereoRig truth;
  StereoRig rig;
};
TurnedRig TurnedRigWithDriftPriors() {
  const StereoRig nominal = test::AlphasenseRealisticRig();
  return {nominal.WithCam1Moved(Eigen::Vector3d(0.0, 0.1, 0.05) * M_PI / 180.0)
              .value(),
          nominal
              .WithCalibrationUncertainty(
                  CalibrationUncertainty::DefaultDriftPrior())
              .value()};
}

// With a calibration uncertainty (the default drift prior, so cam1's
// rotation is self-calibrated) and the front end's systematic floor, a
// frame's own estimate counts what the batch's sigma counts on that frame:
// the rotation's share, the calibration's and the systematic field's, not
// the pixel noise at a held rotation alone (which made the demo's frames
// scatter 7.5 of their sigmas). The batch solves the rotation by Ceres, the
// frame by the quadratic model of the normal equations (online_estimator.h,
// its neglected second order ~f |w|^2 / 2): they agree to a small fraction
// of sigma, not to the solver's tolerance.
TEST(OnlineEstimator, FrameEstimateWithCalibrationIsTheBatchOfThatFrame) {
  constexpr double kFractionOfSigma = 0.05;
  const TurnedRig turned = TurnedRigWithDriftPriors();
  const StereoRig& truth = turned.truth;
  const StereoRig& rig = turned.rig;
  std::vector<StereoCorrespondence> sequence =
      test::ExactSequence(truth, 1.333, 3, 200, 16);
  AddPixelNoise(0.3, 17, &sequence);
  const Frames frames = SplitByFrame(sequence);
  RefinementOptions options;
  options.systematic_px = 0.03;
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, options).value();
  for (const std::vector<StereoCorrespondence>& frame : frames.matches) {
    const OnlineRefractiveIndexEstimator::FrameUpdate update =
        estimator.AddFrame(frame);
    const RefinementSummary batch =
        RefineRefractiveIndex(rig, frame, options).value();
    ASSERT_TRUE(update.frame_estimate.ok())
        << update.frame_estimate.status().message();
    const PooledLocusEstimate& own = *update.frame_estimate;
    std::printf(
        "frame: n %.6f +- %.6f (noise %.6f, calibration %.6f, "
        "systematic %.6f); batch %.6f +- %.6f\n",
        own.n, own.sigma_n, own.sigma_n_noise, own.sigma_n_calibration,
        own.sigma_n_systematic, batch.n, batch.sigma_n);
    EXPECT_NEAR(own.n, batch.n, kFractionOfSigma * batch.sigma_n);
    EXPECT_NEAR(own.sigma_n, batch.sigma_n, kFractionOfSigma * batch.sigma_n);
    EXPECT_GT(own.sigma_n_calibration, 0.0);
    EXPECT_GT(own.sigma_n_systematic, 0.0);
    ASSERT_TRUE(own.rotation.has_value());
  }
}

TEST(OnlineEstimator, ExactOnEveryRigAndIndex) {
  for (const StereoRig& rig :
       {test::AlphasenseIdealRig(), test::AlphasenseRealisticRig(),
        test::IdealRig(test::WideEquidistantCamera(),
                       test::WideEquidistantCamera())}) {
    for (const double n : {1.0, 1.2, 1.333, 1.6}) {
      std::vector<int64_t> inliers;
      const OnlineRefractiveIndexEstimator online =
          RunOnline(rig, test::ExactSequence(rig, n, 3, 100, 9),
                    RefinementOptions(), &inliers);
      const OnlineRefractiveIndexEstimator::Estimate estimate =
          online.Current().value();
      EXPECT_NEAR(estimate.n, n, kExactTolerance);
      EXPECT_EQ(estimate.inliers, 300);
      EXPECT_LT(estimate.sigma_px, kExactSigmaPx);
    }
  }
}

TEST(OnlineEstimator, FrameWithTooFewMatchesIsSkipped) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, RefinementOptions()).value();
  const OnlineRefractiveIndexEstimator::FrameUpdate small =
      estimator.AddFrame(test::ExactMatches(rig, 1.333, 5));
  EXPECT_TRUE(small.skipped);
  EXPECT_EQ(small.usable, 5);
  ASSERT_FALSE(small.frame_estimate.ok());
  EXPECT_NE(small.frame_estimate.status().message().find("frame skipped"),
            std::string::npos)
      << small.frame_estimate.status().message();
  ASSERT_FALSE(small.cumulative.ok());
  EXPECT_NE(small.cumulative.status().message().find("too few inliers"),
            std::string::npos)
      << small.cumulative.status().message();
  EXPECT_EQ(estimator.num_skipped_frames(), 1);

  // A full frame afterwards is estimated from its own matches alone.
  const OnlineRefractiveIndexEstimator::FrameUpdate full =
      estimator.AddFrame(test::ExactMatches(rig, 1.333, 100, 2));
  EXPECT_FALSE(full.skipped);
  ASSERT_TRUE(full.cumulative.ok()) << full.cumulative.status().message();
  EXPECT_EQ(full.cumulative->inliers, 100);
  EXPECT_EQ(full.cumulative->correspondences, 105);
  EXPECT_EQ(full.cumulative->frames, 2);
  EXPECT_NEAR(full.cumulative->n, 1.333, kExactTolerance);
}

TEST(OnlineEstimator, MatchesOnTheImageAxesGiveNoEstimate) {
  // On the axes the loci (nearly) do not depend on n: at 1 px of noise
  // these matches would know n to worse than max_crlb_per_px, so the
  // estimator must refuse rather than report the minimizer of a flat cost.
  const StereoRig rig = test::AlphasenseIdealRig();
  std::vector<StereoCorrespondence> axes = test::ExactMatchesOnAxis(true, 200);
  const std::vector<StereoCorrespondence> column =
      test::ExactMatchesOnAxis(false, 200);
  axes.insert(axes.end(), column.begin(), column.end());
  ASSERT_GT(axes.size(), 300u);
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, RefinementOptions()).value();
  const OnlineRefractiveIndexEstimator::FrameUpdate update =
      estimator.AddFrame(axes);
  EXPECT_FALSE(update.skipped);
  ASSERT_FALSE(update.frame_estimate.ok());
  EXPECT_NE(update.frame_estimate.status().message().find("do not observe n"),
            std::string::npos)
      << update.frame_estimate.status().message();
  ASSERT_FALSE(estimator.Current().ok()) << estimator.Current()->n;
  EXPECT_NE(estimator.Current().status().message().find("do not observe n"),
            std::string::npos);

  // The refusal is about the information, not a stuck state: a frame that
  // observes n makes the estimate available.
  estimator.AddFrame(test::ExactMatches(rig, 1.333, 100, 3));
  ASSERT_TRUE(estimator.Current().ok())
      << estimator.Current().status().message();
  EXPECT_NEAR(estimator.Current()->n, 1.333, kExactTolerance);
}

TEST(OnlineEstimator, MemoryStaysConstantOverThousandFrames) {
  // 1000 frames of 20 matches: the state does not grow, and it still holds
  // everything the batch needs (plain least squares, so the inlier sets are
  // trivially the same).
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> sequence =
      test::ExactSequence(rig, 1.333, 1000, 20, 10);
  AddPixelNoise(0.5, 11, &sequence);
  RefinementOptions options;
  options.loss = RobustLoss::kNone;
  options.inlier_threshold_px = std::numeric_limits<double>::infinity();
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, options).value();
  const Frames frames = SplitByFrame(sequence);
  ASSERT_EQ(frames.matches.size(), 1000u);
  estimator.AddFrame(frames.matches[0]);
  const size_t memory = estimator.MemoryBytes();
  for (size_t f = 1; f < frames.matches.size(); ++f) {
    estimator.AddFrame(frames.matches[f]);
    ASSERT_EQ(estimator.MemoryBytes(), memory) << "frame " << f;
  }
  const RefinementSummary batch =
      RefineRefractiveIndex(rig, sequence, options).value();
  ASSERT_TRUE(estimator.Current().ok());
  EXPECT_NEAR(estimator.Current()->n, batch.n, kBatchTolerance);
  EXPECT_EQ(estimator.Current()->inliers, 20000);
  EXPECT_EQ(estimator.num_frames(), 1000);
  std::printf("1000 frames: online - batch: n %.3g; state %zu bytes\n",
              estimator.Current()->n - batch.n, memory);
}

TEST(OnlineEstimator, CreateRejectsInvalidOptions) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  RefinementOptions rotation;
  rotation.refine_rotation = true;
  const auto with_rotation =
      OnlineRefractiveIndexEstimator::Create(rig, rotation);
  ASSERT_FALSE(with_rotation.ok());
  EXPECT_NE(with_rotation.status().message().find("refine_rotation"),
            std::string::npos);
  RefinementOptions invalid;
  invalid.min_inliers = 1;
  const auto with_invalid =
      OnlineRefractiveIndexEstimator::Create(rig, invalid);
  ASSERT_FALSE(with_invalid.ok());
  EXPECT_EQ(with_invalid.status().message(), invalid.Check().message());
}

// A frame's rows at the estimator's linearization rotation are its
// refinement's, taken there (RefinementOptions::rows_at_rotation): the
// same numbers, bit for bit, and not those at the frame's own rotation
// (the option takes effect); the refinement's solution does not move.
TEST(FitFrame, RowsAtTheLinearizationAreTheRefinementsTakenThere) {
  const TurnedRig turned = TurnedRigWithDriftPriors();
  const StereoRig& truth = turned.truth;
  const StereoRig& rig = turned.rig;
  std::vector<StereoCorrespondence> frame =
      test::ExactSequence(truth, 1.333, 1, 200, 21);
  AddPixelNoise(0.3, 22, &frame);
  RefinementOptions options;
  options.systematic_px = 0.03;
  const Eigen::Vector3d linearization =
      Eigen::Vector3d(0.01, 0.08, 0.06) * M_PI / 180.0;
  const FrameFit fit = FitFrame(rig, frame, options, linearization);
  ASSERT_TRUE(fit.estimate.ok()) << fit.estimate.status().message();

  RefinementOptions frame_options = options;
  frame_options.self_calibrate_focal =
      SelfCalibrationLayout(rig, options).focal;
  const RefinementSummary own =
      RefineRefractiveIndex(rig, frame, frame_options).value();
  frame_options.rows_at_rotation = linearization;
  const RefinementSummary there =
      RefineRefractiveIndex(rig, frame, frame_options).value();
  ASSERT_TRUE(own.rotation && there.rotation && own.normal_equations &&
              there.normal_equations && there.rows_rotation);
  EXPECT_EQ(there.n, own.n);
  EXPECT_EQ(there.rotation->angle_axis, own.rotation->angle_axis);
  EXPECT_EQ(*own.rows_rotation, own.rotation->angle_axis);
  EXPECT_EQ(*there.rows_rotation, linearization);
  ASSERT_EQ(fit.inliers.size(), there.inliers.size());

  const LocusNormalEquations& taken = *there.normal_equations;
  EXPECT_EQ(fit.normal_equations.information, taken.information);
  EXPECT_EQ(fit.normal_equations.gradient, taken.gradient);
  EXPECT_EQ(fit.normal_equations.gradient_intercept, taken.gradient_intercept);
  EXPECT_EQ(fit.normal_equations.count, taken.count);
  EXPECT_NE(own.normal_equations->gradient_intercept, taken.gradient_intercept);

  RefinementOptions invalid = options;
  invalid.rows_at_rotation = Eigen::Vector3d(0.0, NAN, 0.0);
  EXPECT_FALSE(invalid.Check().ok());
}

}  // namespace
}  // namespace rcm::online_estimator_test
