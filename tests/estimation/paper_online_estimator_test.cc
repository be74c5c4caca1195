#include "rcm/estimation/paper_online_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rcm/estimation/closed_form.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/observability.h"
#include "support/test_rigs.h"

namespace rcm::paper_online_estimator_test {
namespace {

// See closed_form_test.cc: exact data give every n_i to < 1e-9, and the
// weighted mean of such values is as close.
constexpr double kExactTolerance = 1e-9;

PaperOnlineEstimator::Estimate EstimateAll(
    const StereoRig& rig, const std::vector<StereoCorrespondence>& data) {
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  for (const StereoCorrespondence& c : data) estimator.Add(c);
  return estimator.Current().value();
}

TEST(PaperOnlineEstimator, ExactOnIdealRig) {
  const StereoRig rig = test::AlphasenseIdealRig();
  for (double n : {1.0, 1.333, 1.5}) {
    const PaperOnlineEstimator::Estimate estimate =
        EstimateAll(rig, test::ExactMatches(rig, n, 1000));
    EXPECT_NEAR(estimate.n, n, kExactTolerance);
    EXPECT_LT(estimate.standard_error, kExactTolerance);
    EXPECT_GT(estimate.used, 500);
  }
}

TEST(PaperOnlineEstimator, IsRadiallyWeightedMeanOfMaskedClosedForms) {
  // Eq. 17 recomputed from scratch on noisy data.
  const StereoRig rig = test::AlphasenseIdealRig();
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 500);
  AddPixelNoise(0.3, 5, &data);
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  double sum_rn = 0.0, sum_r = 0.0;
  int used = 0, masked = 0, invalid = 0;
  for (const StereoCorrespondence& c : data) {
    const PaperOnlineEstimator::Contribution contribution = estimator.Add(c);
    const NormalizedCorrespondence m = rig.Normalize(c).value();
    const double u = m.left.x(), v = m.left.y();
    if (!(std::sqrt(std::abs(u)) * std::sqrt(std::abs(v)) > 0.3)) {
      EXPECT_EQ(contribution.outcome, PaperOnlineEstimator::Outcome::kMasked);
      ++masked;
      continue;
    }
    const std::optional<double> n = ClosedFormN(m);
    if (!n) {
      EXPECT_EQ(contribution.outcome, PaperOnlineEstimator::Outcome::kInvalid);
      ++invalid;
      continue;
    }
    ASSERT_EQ(contribution.outcome, PaperOnlineEstimator::Outcome::kUsed);
    EXPECT_EQ(contribution.n, *n);
    EXPECT_DOUBLE_EQ(contribution.weight, std::hypot(u, v));
    sum_rn += std::hypot(u, v) * *n;
    sum_r += std::hypot(u, v);
    ++used;
  }
  EXPECT_NEAR(estimator.Current()->n, sum_rn / sum_r, 1e-13);
  EXPECT_EQ(estimator.num_used(), used);
  EXPECT_EQ(estimator.num_masked(), masked);
  EXPECT_EQ(estimator.num_invalid(), invalid);
  EXPECT_EQ(estimator.num_added(), 500);
  EXPECT_GT(masked, 0);
  EXPECT_GT(invalid, 0);  // 0.3 px already makes some n^2 negative.
}

TEST(PaperOnlineEstimator, NoisyEstimateWithinFirstOrderTolerance) {
  // 0.02 px on 2000 matches. The first-order sigma of the weighted mean is
  // sqrt(sum w_i^2 sigma_i^2) / sum w_i with sigma_i from observability.h;
  // the second-order bias at this noise is ~0.15 of it (measured), so 4
  // sigma bounds the error.
  const StereoRig rig = test::AlphasenseIdealRig();
  const double n = 1.333, sigma_px = 0.02;
  const std::vector<StereoCorrespondence> exact =
      test::ExactMatches(rig, n, 2000);
  std::vector<StereoCorrespondence> noisy = exact;
  AddPixelNoise(sigma_px, 11, &noisy);
  double sum_w = 0.0, sum_w2_sigma2 = 0.0;
  for (const StereoCorrespondence& c : exact) {
    const NormalizedCorrespondence m = rig.Normalize(c).value();
    if (!PassesObservabilityMask(m.left, 0.3)) continue;
    const double w = m.left.norm();
    const double sigma = FirstOrderSigmaN(rig, c, n, sigma_px).value();
    sum_w += w;
    sum_w2_sigma2 += w * w * sigma * sigma;
  }
  const double predicted = std::sqrt(sum_w2_sigma2) / sum_w;
  const PaperOnlineEstimator::Estimate estimate = EstimateAll(rig, noisy);
  EXPECT_NEAR(estimate.n, n, 4.0 * predicted);
}

TEST(PaperOnlineEstimator, StandardErrorIsHonestInMeanSquare) {
  // Fixed geometry, 400 noise draws. The spread of the estimate over draws
  // must match the RMS of the reported standard error (its square is an
  // unbiased variance estimate). 400 trials give the spread a relative
  // standard error of ~4 % for these heavy-tailed values; 15 % is > 3.5 of
  // those. At 0.02 px the tails are light and the mean reported value is
  // honest too.
  const StereoRig rig = test::AlphasenseIdealRig();
  const std::vector<StereoCorrespondence> exact =
      test::ExactMatches(rig, 1.333, 2000, 5);
  for (double sigma_px : {0.02, 0.1}) {
    const int kTrials = 400;
    double sum = 0.0, sum_squares = 0.0, sum_se = 0.0, sum_se2 = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
      std::vector<StereoCorrespondence> noisy = exact;
      AddPixelNoise(sigma_px, 1000 + trial, &noisy);
      const PaperOnlineEstimator::Estimate estimate = EstimateAll(rig, noisy);
      sum += estimate.n;
      sum_squares += estimate.n * estimate.n;
      sum_se += estimate.standard_error;
      sum_se2 += estimate.standard_error * estimate.standard_error;
    }
    const double mean = sum / kTrials;
    const double spread =
        std::sqrt((sum_squares - kTrials * mean * mean) / (kTrials - 1));
    EXPECT_NEAR(spread / std::sqrt(sum_se2 / kTrials), 1.0, 0.15) << sigma_px;
    if (sigma_px == 0.02) {
      EXPECT_NEAR(spread / (sum_se / kTrials), 1.0, 0.15);
    }
  }
}

TEST(PaperOnlineEstimator, BiasedUpwardUnderHalfPixelNoise) {
  // The measurement of docs/design.md, "The estimator of record": at 0.5 px
  // the paper's pipeline reads ~1.42 for a true 1.333 (here 1.41). This
  // pins the baseline: if it ever reads right, it is no longer the paper's
  // estimator.
  const StereoRig rig = test::AlphasenseIdealRig();
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 2000);
  AddPixelNoise(0.5, 2, &data);
  const PaperOnlineEstimator::Estimate estimate = EstimateAll(rig, data);
  EXPECT_GT(estimate.n, 1.333 + 0.04);
  EXPECT_GT(estimate.n - 1.333, 3.0 * estimate.standard_error);
}

TEST(PaperOnlineEstimator, BiasedOnUnrectifiedRig) {
  // Exact data of a rig 0.5 degrees from rectified: eq. 14 does not hold.
  const StereoRig rig = test::AlphasenseRealisticRig();
  const PaperOnlineEstimator::Estimate estimate =
      EstimateAll(rig, test::ExactMatches(rig, 1.333, 2000));
  EXPECT_GT(std::abs(estimate.n - 1.333), 0.01);
}

TEST(PaperOnlineEstimator, MaskRemovesFeaturesNearAxes) {
  const StereoRig rig = test::AlphasenseIdealRig();
  EXPECT_TRUE(PassesObservabilityMask({0.4, 0.4}, 0.3));
  EXPECT_FALSE(PassesObservabilityMask({0.8, 0.1}, 0.3));  // sqrt(0.08) < 0.3
  EXPECT_FALSE(PassesObservabilityMask({0.0, 1.0}, 0.0));
  EXPECT_TRUE(PassesObservabilityMask({1e-3, 1e-3}, 0.0));
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  StereoCorrespondence on_axis;
  on_axis.left_pixel = Eigen::Vector2d(500.0, rig.left().cy());
  on_axis.right_pixel = Eigen::Vector2d(480.0, rig.right().cy());
  EXPECT_EQ(estimator.Add(on_axis).outcome,
            PaperOnlineEstimator::Outcome::kMasked);
  EXPECT_FALSE(estimator.Current().has_value());
}

TEST(PaperOnlineEstimator, NonFinitePixelIsInvalid) {
  const StereoRig rig = test::AlphasenseIdealRig();
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  StereoCorrespondence c;
  c.left_pixel =
      Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 10.0);
  EXPECT_EQ(estimator.Add(c).outcome, PaperOnlineEstimator::Outcome::kInvalid);
  EXPECT_EQ(estimator.num_invalid(), 1);
}

TEST(PaperOnlineEstimator, SingleValueHasNoStandardError) {
  const StereoRig rig = test::AlphasenseIdealRig();
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  for (const StereoCorrespondence& c : test::ExactMatches(rig, 1.333, 50)) {
    if (estimator.Add(c).outcome == PaperOnlineEstimator::Outcome::kUsed) break;
  }
  ASSERT_EQ(estimator.num_used(), 1);
  EXPECT_TRUE(std::isnan(estimator.Current()->standard_error));
}

TEST(PaperOnlineEstimator, ResetEmptiesTheBuffer) {
  const StereoRig rig = test::AlphasenseIdealRig();
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  for (const StereoCorrespondence& c : test::ExactMatches(rig, 1.0, 300))
    estimator.Add(c);
  ASSERT_TRUE(estimator.Current().has_value());
  estimator.Reset();
  EXPECT_FALSE(estimator.Current().has_value());
  EXPECT_EQ(estimator.num_added(), 0);
  // A new medium after the reset: the old values are gone.
  for (const StereoCorrespondence& c : test::ExactMatches(rig, 1.5, 300))
    estimator.Add(c);
  EXPECT_NEAR(estimator.Current()->n, 1.5, kExactTolerance);
}

TEST(PaperOnlineEstimatorOptions, CheckRejectsInvalidEta) {
  PaperOnlineEstimatorOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.eta = -0.1;
  EXPECT_EQ(options.Check().message(),
            "mask threshold eta = -0.1 must be a finite number >= 0");
  options.eta = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm::paper_online_estimator_test
