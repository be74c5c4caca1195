#include "rcm/stereo/observability.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::observability_test {
namespace {

std::vector<StereoCorrespondence> ObservableMatches(const StereoRig& rig,
                                                    double n, int count) {
  StereoSamplerOptions options;
  options.n = n;
  options.per_frame = 4 * count;
  options.max_depth = 3.0;
  std::vector<StereoCorrespondence> kept;
  for (const StereoCorrespondence& c :
       SampleStereoCorrespondences(rig, options).value()) {
    if (PassesObservabilityMask(rig.Normalize(c)->left, 0.3) &&
        static_cast<int>(kept.size()) < count) {
      kept.push_back(c);
    }
  }
  return kept;
}

TEST(Observability, TangentAngleIsSlopeOfLocusAtLeftPoint) {
  // phi(n) against central differences of yr(xr) (locus.h) at xr = xl.
  for (double n : {1.1, 1.333, 1.7}) {
    for (const Eigen::Vector2d& left :
         {Eigen::Vector2d(0.4, 0.3), Eigen::Vector2d(-0.9, 0.2),
          Eigen::Vector2d(0.1, -0.8)}) {
      const double xl = left.x(), yl = left.y();
      const double h = 1e-5;  // truncation ~1e-10, rounding ~1e-11
      const auto right_y = [&](double xr) {
        return yl * std::sqrt((n * n + (n * n - 1) * xr * xr) /
                              (n * n + (n * n - 1) * xl * xl));
      };
      const double slope = (right_y(xl + h) - right_y(xl - h)) / (2 * h);
      EXPECT_NEAR(std::tan(LocusTangentAngle(n, xl, yl)), slope, 1e-9);
    }
  }
}

TEST(Observability, TangentSeparationVanishesOnImageAxes) {
  EXPECT_EQ(LocusTangentSeparation(1.333, 0.05, 0.0, 0.6), 0.0);
  EXPECT_EQ(LocusTangentSeparation(1.333, 0.05, 0.6, 0.0), 0.0);
  const double off_axis = LocusTangentSeparation(1.333, 0.05, 0.6, 0.6);
  EXPECT_GT(off_axis, 0.01);
  // Moving toward an axis shrinks it.
  EXPECT_LT(LocusTangentSeparation(1.333, 0.05, 0.6, 0.1), off_axis);
  EXPECT_LT(LocusTangentSeparation(1.333, 0.05, 0.1, 0.6), off_axis);
}

TEST(Observability, TangentSeparationIsZeroInAirLimit) {
  // phi(1) = 0: in air every locus is the horizontal epipolar line.
  EXPECT_EQ(LocusTangentAngle(1.0, 0.6, 0.4), 0.0);
}

TEST(Observability, FirstOrderSigmaMatchesClosedFormGradient) {
  // Two derivations of the same number: the implicit-function sigma of the
  // coplanarity, and the Jet gradient of eq. 14 through the undistortion.
  const StereoRig rig = test::AlphasenseIdealRig();
  const double n = 1.333, sigma_px = 0.5;
  using Jet = ceres::Jet<double, 4>;
  for (const StereoCorrespondence& c : ObservableMatches(rig, n, 50)) {
    const Jet left_pixel[2] = {Jet(c.left_pixel.x(), 0),
                               Jet(c.left_pixel.y(), 1)};
    const Jet right_pixel[2] = {Jet(c.right_pixel.x(), 2),
                                Jet(c.right_pixel.y(), 3)};
    Jet left[2], right[2];
    ASSERT_TRUE(rig.left().NormalizedFromImage(left_pixel, left));
    ASSERT_TRUE(rig.right().NormalizedFromImage(right_pixel, right));
    using std::sqrt;
    const Jet n_closed_form =
        sqrt(ClosedFormNSquared(left[0], left[1], right[0], right[1]));
    EXPECT_NEAR(n_closed_form.a, n, 1e-9);
    const double expected = sigma_px * n_closed_form.v.norm();
    const std::optional<double> sigma = FirstOrderSigmaN(rig, c, n, sigma_px);
    ASSERT_TRUE(sigma.has_value());
    // Both are exact derivatives at the same point: agreement to the
    // conditioning of eq. 14 times rounding.
    EXPECT_NEAR(*sigma, expected, 1e-6 * expected);
  }
}

TEST(Observability, FirstOrderSigmaIsHonest) {
  // Monte Carlo: at 0.02 px the closed form is linear in the noise to
  // < 1 %, so the spread of n over trials must match the first-order sigma.
  // With 4000 trials the sample standard deviation has a relative standard
  // error of 1 / sqrt(2 * 3999) = 1.1 %; 5 % is 4.5 of those.
  const StereoRig rig = test::AlphasenseIdealRig();
  const double n = 1.333, sigma_px = 0.02;
  const int kTrials = 4000;
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (const StereoCorrespondence& c : ObservableMatches(rig, n, 6)) {
    const double predicted = FirstOrderSigmaN(rig, c, n, sigma_px).value();
    double sum = 0.0, sum_squares = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
      StereoCorrespondence noisy = c;
      // Each y before its x, in statements of their own (argument order is
      // unspecified).
      const double left_y = noise(rng);
      noisy.left_pixel += Eigen::Vector2d(noise(rng), left_y);
      const double right_y = noise(rng);
      noisy.right_pixel += Eigen::Vector2d(noise(rng), right_y);
      const double estimate = ClosedFormN(rig.Normalize(noisy).value()).value();
      sum += estimate;
      sum_squares += estimate * estimate;
    }
    const double mean = sum / kTrials;
    const double spread =
        std::sqrt((sum_squares - kTrials * mean * mean) / (kTrials - 1));
    EXPECT_NEAR(spread / predicted, 1.0, 0.05)
        << "predicted " << predicted << ", observed " << spread;
  }
}

TEST(Observability, FirstOrderSigmaUndefinedOnHorizontalAxis) {
  // yl = yr = 0: e = yr m_l - yl m_r vanishes for every n.
  const StereoRig rig =
      test::IdealRig(test::PinholeCamera(), test::PinholeCamera());
  StereoCorrespondence c;
  c.left_pixel = Eigen::Vector2d(500.0, rig.left().cy());
  c.right_pixel = Eigen::Vector2d(480.0, rig.right().cy());
  EXPECT_FALSE(FirstOrderSigmaN(rig, c, 1.333, 0.5).has_value());
}

// Found by fuzz_closed_form: a negative pixel sigma gave a negative sigma_n.
TEST(Observability, FirstOrderSigmaUndefinedForInvalidPixelSigma) {
  const StereoRig rig =
      test::IdealRig(test::PinholeCamera(), test::PinholeCamera());
  StereoCorrespondence c;
  c.left_pixel = Eigen::Vector2d(500.0, 400.0);
  c.right_pixel = Eigen::Vector2d(480.0, 401.0);
  ASSERT_TRUE(FirstOrderSigmaN(rig, c, 1.333, 0.5).has_value());
  EXPECT_FALSE(FirstOrderSigmaN(rig, c, 1.333, -0.5).has_value());
  EXPECT_FALSE(FirstOrderSigmaN(rig, c, 1.333, NAN).has_value());
  EXPECT_FALSE(FirstOrderSigmaN(rig, c, 1.333, INFINITY).has_value());
}

TEST(Observability, FirstOrderSigmaGrowsTowardTheAxes) {
  // The same depth and disparity, closer to the horizontal axis: worse.
  const StereoRig rig =
      test::IdealRig(test::PinholeCamera(), test::PinholeCamera());
  const double n = 1.333;
  const RefractiveCamera camera =
      RefractiveCamera::Create(rig.left(), n).value();
  const auto sigma_at = [&](const Eigen::Vector3d& point) {
    StereoCorrespondence c;
    c.left_pixel = camera.ImageFromPointInWater(point).value();
    c.right_pixel =
        camera.ImageFromPointInWater(rig.right_from_left() * point).value();
    return FirstOrderSigmaN(rig, c, n, 0.5).value();
  };
  EXPECT_GT(sigma_at({0.5, 0.05, 1.5}), 3.0 * sigma_at({0.5, 0.4, 1.5}));
}

}  // namespace
}  // namespace rcm::observability_test
