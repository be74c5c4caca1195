#include "rcm/estimation/robust_locus_fit.h"

#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "support/test_rigs.h"

namespace rcm::robust_locus_fit_test {
namespace {

std::vector<PreparedCorrespondence> Prepare(
    const StereoRig& rig, const std::vector<StereoCorrespondence>& data) {
  return PrepareCorrespondences(rig, data).prepared;
}

TEST(RobustLoss, MatchesCeresLossFunctions) {
  constexpr double kTolerance = 1e-12;  // same formulas, different code
  const ceres::HuberLoss huber(1.5);
  const ceres::CauchyLoss cauchy(1.5);
  for (const double s : {0.0, 0.3, 2.25, 4.0, 100.0}) {
    double rho[3];
    huber.Evaluate(s, rho);
    EXPECT_NEAR(RobustLossRho(RobustLoss::kHuber, 1.5, s), rho[0], kTolerance);
    cauchy.Evaluate(s, rho);
    EXPECT_NEAR(RobustLossRho(RobustLoss::kCauchy, 1.5, s), rho[0], kTolerance);
    EXPECT_EQ(RobustLossRho(RobustLoss::kNone, 1.5, s), s);
  }
}

// psi(r)^2 = rho(r^2) and psi' psi = rho'(r^2) r (the derivative of
// rho(r^2) / 2) against Ceres' own loss functions, psi' against a central
// difference of psi, and psi through zero with slope one, about and beyond
// the Huber knee (|r| = 1.5) and far out.
TEST(RobustLoss, RootSquaresToTheLossWithItsDerivative) {
  // Same formulas as Ceres' in another order: rounding, ~1e-15 relative.
  constexpr double kTolerance = 1e-13;
  // Central difference with h = 1e-6 max(1, |r|) of a function whose third
  // derivative is O(1 / max(1, |r|)^2) here: h^2 ~ 1e-12, plus rounding
  // 1e-16 |psi| / h <= 1e-10.
  constexpr double kStep = 1e-6;
  constexpr double kDifferenceTolerance = 1e-8;
  const ceres::HuberLoss huber(1.5);
  const ceres::CauchyLoss cauchy(1.5);
  for (const RobustLoss loss :
       {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    for (const double r :
         {0.0, 1e-9, -1e-6, 0.3, -1.4, 1.5, 1.6, -4.0, 30.0, -1e4}) {
      double root = NAN;
      double slope = NAN;
      RobustLossRoot(loss, 1.5, r, &root, &slope);
      double rho[3] = {r * r, 1.0, 0.0};
      if (loss == RobustLoss::kHuber) huber.Evaluate(r * r, rho);
      if (loss == RobustLoss::kCauchy) cauchy.Evaluate(r * r, rho);
      const double scale = std::max(1.0, rho[0]);
      EXPECT_NEAR(root * root, rho[0], kTolerance * scale) << "r " << r;
      EXPECT_NEAR(slope * root, rho[1] * r, kTolerance * scale) << "r " << r;
      EXPECT_TRUE(root == 0.0 || std::signbit(root) == std::signbit(r));
      double plus = NAN;
      double minus = NAN;
      double unused = NAN;
      const double h = kStep * std::max(1.0, std::abs(r));
      RobustLossRoot(loss, 1.5, r + h, &plus, &unused);
      RobustLossRoot(loss, 1.5, r - h, &minus, &unused);
      if (loss != RobustLoss::kHuber || std::abs(std::abs(r) - 1.5) > h) {
        EXPECT_NEAR(slope, (plus - minus) / (2.0 * h), kDifferenceTolerance)
            << RobustLossName(loss) << " r " << r;
      }
    }
    double root = NAN;
    double slope = NAN;
    RobustLossRoot(loss, 1.5, 0.0, &root, &slope);
    EXPECT_EQ(root, 0.0);
    EXPECT_EQ(slope, 1.0);
  }
}

TEST(RobustLoss, NamesRoundTrip) {
  for (const RobustLoss loss :
       {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    EXPECT_EQ(RobustLossFromName(RobustLossName(loss)), loss);
  }
  EXPECT_FALSE(RobustLossFromName("tukey").has_value());
}

TEST(RefinementOptions, DefaultsAreValid) {
  EXPECT_TRUE(RefinementOptions().Check().ok());
}

TEST(RefinementOptions, RejectsInvalidValues) {
  const auto expect_rejected = [](RefinementOptions options,
                                  const char* fragment) {
    const Status status = options.Check();
    ASSERT_FALSE(status.ok()) << fragment;
    EXPECT_NE(status.message().find(fragment), std::string::npos)
        << status.message();
  };
  RefinementOptions options;
  options.loss_scale_px = 0.0;
  expect_rejected(options, "loss scale");
  options = RefinementOptions();
  options.loss_scale_px = NAN;
  expect_rejected(options, "loss scale");
  options = RefinementOptions();
  options.inlier_threshold_px = -1.0;
  expect_rejected(options, "inlier threshold");
  options = RefinementOptions();
  options.num_scan_points = 2;
  expect_rejected(options, "scan");
  options = RefinementOptions();
  options.min_inliers = 1;
  expect_rejected(options, "inliers");
  options = RefinementOptions();
  options.refine_rotation = true;
  options.min_inliers = 4;
  expect_rejected(options, "rotation");
  options = RefinementOptions();
  options.max_crlb_per_px = 0.0;  // must be positive
  expect_rejected(options, "max_crlb_per_px");
  options = RefinementOptions();
  options.max_num_iterations = 0;
  expect_rejected(options, "max_num_iterations");
  options = RefinementOptions();
  options.num_threads = 0;
  expect_rejected(options, "num_threads");
}

TEST(RobustLocusFit, MinimizesExactDataToTheTruth) {
  // The golden-section bracket closes below 1e-9.
  constexpr double kTolerance = 1e-9;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  for (const double n : {1.0, 1.12, 1.333, 1.71}) {
    const std::vector<PreparedCorrespondence> matches =
        Prepare(rig, test::ExactMatches(rig, n, 200));
    EXPECT_NEAR(
        MinimizeRobustLocusCost(essential, matches, RefinementOptions()), n,
        kTolerance);
  }
}

TEST(RobustLocusFit, FindsTheGlobalMinimumDespiteOutliers) {
  // Half of the matches are gross outliers. The search from the scan's
  // seed must end at the global minimum of the robust cost, found here by
  // brute force on a 1e-4 grid (so within 1e-4 of it), and that minimum
  // near the truth (the 200 inliers know n to ~0.01 at 0.5 px).
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 400);
  AddPixelNoise(0.5, 7, &data);
  AddOutliers(rig, 0.5, 8, &data);
  const std::vector<PreparedCorrespondence> matches = Prepare(rig, data);
  const RefinementOptions options;
  double best_n = 1.0;
  double best_cost = INFINITY;
  for (int k = 0; k <= 10000; ++k) {
    const double n = 1.0 + k * 1e-4;
    const double cost = RobustLocusCost(essential, matches, n, options);
    if (cost < best_cost) {
      best_cost = cost;
      best_n = n;
    }
  }
  EXPECT_NEAR(MinimizeRobustLocusCost(essential, matches, options), best_n,
              1e-4);
  // A wrong candidate does not win over the grid.
  EXPECT_NEAR(MinimizeRobustLocusCost(essential, matches, options, 1.9), best_n,
              1e-4);
  EXPECT_NEAR(best_n, 1.333, 0.06);
}

TEST(RobustLocusFit, CostIsTheSumOfLossesOfTheResiduals) {
  constexpr double kRelativeTolerance = 1e-12;
  const StereoRig rig = test::AlphasenseIdealRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 100);
  AddPixelNoise(0.5, 9, &data);
  const std::vector<PreparedCorrespondence> matches = Prepare(rig, data);
  RefinementOptions options;
  double expected = 0.0;
  for (const double r : LocusResiduals(essential, matches, 1.3)) {
    expected += RobustLossRho(options.loss, options.loss_scale_px, r * r);
  }
  EXPECT_NEAR(RobustLocusCost(essential, matches, 1.3, options), expected,
              kRelativeTolerance * expected);
}

TEST(RobustLocusFit, CheiralityRejectsRaysThatMeetBehindTheCameras) {
  const StereoRig rig = test::AlphasenseIdealRig();
  for (const StereoCorrespondence& match :
       test::ExactMatches(rig, 1.333, 200)) {
    const PreparedCorrespondence good =
        PrepareCorrespondence(rig, match).value();
    EXPECT_TRUE(TriangulatesInFront(rig.right_from_left(), good, 1.333));
    // Swapping the pixels reverses the disparity: the rays now meet
    // behind the cameras.
    StereoCorrespondence swapped = match;
    std::swap(swapped.left_pixel, swapped.right_pixel);
    const PreparedCorrespondence bad =
        PrepareCorrespondence(rig, swapped).value();
    EXPECT_FALSE(TriangulatesInFront(rig.right_from_left(), bad, 1.333));
  }
}

TEST(RobustLocusFit, InliersAreCloseToTheLocusAndInFront) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 500);
  AddPixelNoise(0.3, 13, &data);
  const std::vector<int64_t> outliers = AddOutliers(rig, 0.3, 14, &data);
  const std::vector<PreparedCorrespondence> matches = Prepare(rig, data);
  ASSERT_EQ(matches.size(), data.size());
  const RefinementOptions options;
  const std::vector<int64_t> inliers =
      ClassifyLocusInliers(rig.right_from_left(), matches, 1.333, options);
  const std::vector<double> residuals =
      LocusResiduals(EssentialMatrix(rig.right_from_left()), matches, 1.333);
  size_t expected = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const bool inlier =
        std::abs(residuals[i]) <= options.inlier_threshold_px &&
        TriangulatesInFront(rig.right_from_left(), matches[i], 1.333);
    expected += inlier;
    EXPECT_EQ(std::binary_search(inliers.begin(), inliers.end(),
                                 static_cast<int64_t>(i)),
              inlier);
    // Every true match (0.3 px noise, threshold at 6.7 sigma) is kept.
    if (!std::binary_search(outliers.begin(), outliers.end(),
                            static_cast<int64_t>(i))) {
      EXPECT_TRUE(inlier) << i;
    }
  }
  EXPECT_EQ(inliers.size(), expected);
}

}  // namespace
}  // namespace rcm::robust_locus_fit_test
