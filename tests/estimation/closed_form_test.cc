#include "rcm/estimation/closed_form.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/observability.h"
#include "support/test_rigs.h"

namespace rcm::closed_form_test {
namespace {

// Exact data: the undistortion leaves 1e-14 in normalized coordinates and
// eq. 14 amplifies it by its conditioning, largest for distant points near
// the axes (measured worst case 4.5e-10 over 2000 matches at depths up to
// 6 m, 2e-13 inside the paper's mask). The bar is 1e-9.
constexpr double kExactTolerance = 1e-9;

TEST(ClosedForm, ExactOnIdealRig) {
  const StereoRig rig = test::AlphasenseIdealRig();
  for (double n : {1.0, 1.333, 1.5, 2.0}) {
    for (const StereoCorrespondence& c : test::ExactMatches(rig, n, 2000)) {
      const std::optional<double> estimate =
          ClosedFormN(rig.Normalize(c).value());
      ASSERT_TRUE(estimate.has_value());
      EXPECT_NEAR(*estimate, n, kExactTolerance)
          << "left " << c.left_pixel.transpose() << " right "
          << c.right_pixel.transpose();
    }
  }
}

TEST(ClosedForm, ExactOnIdealRigWithOtherLenses) {
  for (const Camera& camera : {test::PinholeCamera(), test::EurocRadtanCamera(),
                               test::WideEquidistantCamera()}) {
    const StereoRig rig = test::IdealRig(camera, camera, 0.2);
    for (const StereoCorrespondence& c : test::ExactMatches(rig, 1.333, 500)) {
      EXPECT_NEAR(ClosedFormN(rig.Normalize(c).value()).value(), 1.333,
                  kExactTolerance);
    }
  }
}

TEST(ClosedForm, MatchesEquationFourteenAsWritten) {
  // The evaluated form a / (a + (yl - yr)(yl + yr)) against the paper's.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const double xl = uniform(rng), yl = uniform(rng);
    const double xr = uniform(rng), yr = uniform(rng);
    const double rl2 = xl * xl + yl * yl, rr2 = xr * xr + yr * yr;
    const double paper = (yl * yl * rr2 - rl2 * yr * yr) /
                         (yl * yl * rr2 + yl * yl - rl2 * yr * yr - yr * yr);
    const double ours = ClosedFormNSquared(xl, yl, xr, yr);
    EXPECT_NEAR(ours, paper, 1e-10 * (1.0 + std::abs(paper)));
  }
}

TEST(ClosedForm, UndefinedOnHorizontalAxis) {
  NormalizedCorrespondence match;
  match.left = Eigen::Vector2d(0.5, 0.0);
  match.right = Eigen::Vector2d(0.45, 0.0);
  EXPECT_FALSE(ClosedFormN(match).has_value());  // 0 / 0
}

TEST(ClosedForm, UndefinedForPointAtInfinity) {
  // Identical normalized coordinates: every n fits, eq. 14 is 0 / 0.
  NormalizedCorrespondence match;
  match.left = match.right = Eigen::Vector2d(0.4, 0.3);
  EXPECT_FALSE(ClosedFormN(match).has_value());
}

TEST(ClosedForm, UndefinedWhenSquareIsNegative) {
  // a = 0.02128 > 0 but yr^2 - yl^2 = 0.0325 > a: no real n fits.
  NormalizedCorrespondence match;
  match.left = Eigen::Vector2d(0.1, 0.3);
  match.right = Eigen::Vector2d(0.5, 0.35);
  ASSERT_LT(ClosedFormNSquared(0.1, 0.3, 0.5, 0.35), 0.0);
  EXPECT_FALSE(ClosedFormN(match).has_value());
}

TEST(ClosedForm, JetDerivativeMatchesCentralDifferences) {
  using Jet = ceres::Jet<double, 4>;
  const double x[4] = {0.42, -0.31, 0.37, -0.305};
  const Jet n2 = ClosedFormNSquared(Jet(x[0], 0), Jet(x[1], 1), Jet(x[2], 2),
                                    Jet(x[3], 3));
  const double h = 1e-7;  // truncation ~1e-11 here, rounding ~1e-9
  for (int k = 0; k < 4; ++k) {
    double plus[4] = {x[0], x[1], x[2], x[3]},
           minus[4] = {x[0], x[1], x[2], x[3]};
    plus[k] += h;
    minus[k] -= h;
    const double difference =
        (ClosedFormNSquared(plus[0], plus[1], plus[2], plus[3]) -
         ClosedFormNSquared(minus[0], minus[1], minus[2], minus[3])) /
        (2 * h);
    EXPECT_NEAR(n2.v[k], difference, 1e-6 * (1.0 + std::abs(difference)));
  }
}

TEST(ClosedForm, NoisyMatchesSpreadAsFirstOrderSigma) {
  // 0.02 px noise on 400 observable matches: z_i = (n_i - n) / sigma_i with
  // sigma_i the first-order sigma (observability.h). The closed form is
  // linear to ~1 % at this noise, so z is standard normal: its RMS over 400
  // values is 1 +- 0.035 (1 / sqrt(2 * 400)); 15 % is 4 of those. |z| < 5
  // everywhere (chance of a 5-sigma value among 400: 2e-4).
  const StereoRig rig = test::AlphasenseIdealRig();
  const double n = 1.333, sigma_px = 0.02;
  std::vector<StereoCorrespondence> matches;
  for (const StereoCorrespondence& c : test::ExactMatches(rig, n, 1000)) {
    if (PassesObservabilityMask(rig.Normalize(c)->left, 0.3))
      matches.push_back(c);
  }
  matches.resize(400);
  std::vector<StereoCorrespondence> noisy = matches;
  AddPixelNoise(sigma_px, 17, &noisy);
  double sum_z2 = 0.0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const double sigma = FirstOrderSigmaN(rig, matches[i], n, sigma_px).value();
    const double z =
        (ClosedFormN(rig.Normalize(noisy[i]).value()).value() - n) / sigma;
    EXPECT_LT(std::abs(z), 5.0);
    sum_z2 += z * z;
  }
  EXPECT_NEAR(std::sqrt(sum_z2 / matches.size()), 1.0, 0.15);
}

}  // namespace
}  // namespace rcm::closed_form_test
