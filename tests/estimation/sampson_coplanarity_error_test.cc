#include "rcm/estimation/sampson_coplanarity_error.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>

#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "support/test_rigs.h"

namespace rcm::sampson_coplanarity_error_test {
namespace {

// Exact correspondences come from the model's forward map with round trips
// below 1.3e-12 px (refractive_camera_test.cc); the residual is a pixel
// distance, so it is as small.
constexpr double kExactResidualPx = 1e-9;

std::vector<StereoRig> TestRigs() {
  return {test::AlphasenseIdealRig(), test::AlphasenseRealisticRig(),
          test::IdealRig(test::EurocRadtanCamera(), test::EurocRadtanCamera()),
          test::IdealRig(test::PinholeCamera(), test::PinholeCamera()),
          test::IdealRig(test::WideEquidistantCamera(),
                         test::WideEquidistantCamera())};
}

double Residual(const StereoRig& rig, const StereoCorrespondence& match,
                double n, const double* rotation = nullptr) {
  const PreparedCorrespondence prepared =
      PrepareCorrespondence(rig, match).value();
  double residual = NAN;
  EXPECT_TRUE(
      SampsonCoplanarityResidual<double>(EssentialMatrix(rig.right_from_left()),
                                         prepared, n, rotation, &residual));
  return residual;
}

TEST(SampsonCoplanarityError, ZeroOnExactMatchesOfEveryRig) {
  for (const StereoRig& rig : TestRigs()) {
    for (const double n : {1.0, 1.333, 1.6}) {
      for (const StereoCorrespondence& match :
           test::ExactMatches(rig, n, 300)) {
        ASSERT_LT(std::abs(Residual(rig, match, n)), kExactResidualPx);
      }
    }
  }
}

TEST(SampsonCoplanarityError, IsCoplanarityOverItsPixelGradient) {
  // The same quantity from the unnormalized residual of epipolar.h, with
  // the pixel gradient taken by Jets through the lens undistortion (the
  // route of FirstOrderSigmaN) instead of the analytic chain rule.
  constexpr double kRelativeTolerance = 1e-9;  // two routes, same algebra
  using Jet = ceres::Jet<double, 4>;
  const double rotation[3] = {0.002, -0.004, 0.003};
  for (const StereoRig& rig : TestRigs()) {
    std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 50);
    AddPixelNoise(1.0, 3, &data);
    Eigen::Matrix3d delta;
    ceres::AngleAxisToRotationMatrix(
        rotation, ceres::ColumnMajorAdapter3x3(delta.data()));
    const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
    for (const bool rotated : {false, true}) {
      const Eigen::Matrix3d used =
          rotated ? Eigen::Matrix3d(delta * essential) : essential;
      for (const StereoCorrespondence& match : data) {
        const Jet left_pixel[2] = {Jet(match.left_pixel.x(), 0),
                                   Jet(match.left_pixel.y(), 1)};
        const Jet right_pixel[2] = {Jet(match.right_pixel.x(), 2),
                                    Jet(match.right_pixel.y(), 3)};
        Jet left[2], right[2];
        ASSERT_TRUE(rig.left().NormalizedFromImage(left_pixel, left));
        ASSERT_TRUE(rig.right().NormalizedFromImage(right_pixel, right));
        const Jet e = CoplanarityResidual(used, Jet(1.333), left, right);
        const double expected = e.a / e.v.norm();
        const double actual =
            Residual(rig, match, 1.333, rotated ? rotation : nullptr);
        EXPECT_NEAR(actual, expected,
                    kRelativeTolerance * std::max(1.0, std::abs(expected)));
      }
    }
  }
}

TEST(SampsonCoplanarityError, IsSignedPixelDistanceToFirstOrder) {
  // Moving the four pixels by s px along the unit pixel gradient of e
  // moves the residual by s, up to O(s^2) curvature of the locus.
  constexpr double kStepPx = 0.01;
  constexpr double kTolerancePx = 1e-5;  // curvature term, ~ step^2 / 10
  using Jet = ceres::Jet<double, 4>;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  for (StereoCorrespondence match : test::ExactMatches(rig, 1.333, 100)) {
    const Jet left_pixel[2] = {Jet(match.left_pixel.x(), 0),
                               Jet(match.left_pixel.y(), 1)};
    const Jet right_pixel[2] = {Jet(match.right_pixel.x(), 2),
                                Jet(match.right_pixel.y(), 3)};
    Jet left[2], right[2];
    ASSERT_TRUE(rig.left().NormalizedFromImage(left_pixel, left));
    ASSERT_TRUE(rig.right().NormalizedFromImage(right_pixel, right));
    const Eigen::Vector4d direction =
        CoplanarityResidual(essential, Jet(1.333), left, right).v.normalized();
    match.left_pixel += kStepPx * direction.head<2>();
    match.right_pixel += kStepPx * direction.tail<2>();
    EXPECT_NEAR(Residual(rig, match, 1.333), kStepPx, kTolerancePx);
  }
}

TEST(SampsonCoplanarityError, HasThePixelNoiseAsStandardDeviation) {
  // Under Gaussian noise sigma on the four pixels, r ~ N(0, sigma^2) to
  // first order. The sample standard deviation of 20000 residuals has a
  // relative sampling error of 1/sqrt(2 * 20000) = 0.5 %; 2 % allows 4 of
  // those.
  constexpr double kSigmaPx = 0.5;
  constexpr int kCount = 20000;
  constexpr double kRelativeTolerance = 0.02;
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> data =
      test::ExactMatches(rig, 1.333, kCount, 11);
  AddPixelNoise(kSigmaPx, 12, &data);
  double sum = 0.0, sum_squares = 0.0;
  for (const StereoCorrespondence& match : data) {
    const double r = Residual(rig, match, 1.333);
    sum += r;
    sum_squares += r * r;
  }
  const double mean = sum / kCount;
  const double deviation = std::sqrt(sum_squares / kCount - mean * mean);
  EXPECT_NEAR(deviation, kSigmaPx, kRelativeTolerance * kSigmaPx);
  EXPECT_LT(std::abs(mean), 4.0 * kSigmaPx / std::sqrt(kCount));
}

TEST(SampsonCoplanarityError, DoesNotDependOnTheBaselineLength) {
  constexpr double kRelativeTolerance = 1e-12;  // the unit t of E
  const StereoRig rig = test::AlphasenseRealisticRig();
  Rigid3d longer = rig.right_from_left();
  longer.translation *= 7.0;
  const StereoRig scaled =
      StereoRig::Create(rig.left(), rig.right(), longer).value();
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 50);
  AddPixelNoise(0.5, 4, &data);
  for (const StereoCorrespondence& match : data) {
    const double r = Residual(rig, match, 1.4);
    EXPECT_NEAR(Residual(scaled, match, 1.4), r,
                kRelativeTolerance * std::max(1.0, std::abs(r)));
  }
}

TEST(SampsonCoplanarityError, ZeroRotationEqualsNoRotation) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 50);
  AddPixelNoise(0.5, 5, &data);
  const double zero[3] = {0.0, 0.0, 0.0};
  for (const StereoCorrespondence& match : data) {
    EXPECT_EQ(Residual(rig, match, 1.3, zero), Residual(rig, match, 1.3));
  }
}

TEST(SampsonCoplanarityError, CeresJacobianMatchesCentralDifferences) {
  // Central differences with step h have error ~ h^2 r''' / 6 ~ 1e-10 for
  // h = 1e-5 and derivatives of order 10 px per unit; roundoff adds
  // ~1e-16 / h ~ 1e-11.
  constexpr double kStep = 1e-5;
  constexpr double kTolerance = 1e-7;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 40);
  AddPixelNoise(0.5, 6, &data);
  for (const StereoCorrespondence& match : data) {
    const PreparedCorrespondence prepared =
        PrepareCorrespondence(rig, match).value();
    std::unique_ptr<ceres::CostFunction> cost(
        SampsonCoplanarityError::CreateWithRotation(essential, prepared));
    double parameters[4] = {1.35, 0.001, -0.002, 0.0015};
    const double* blocks[2] = {&parameters[0], &parameters[1]};
    double residual;
    double jacobian_n[1], jacobian_rotation[3];
    double* jacobians[2] = {jacobian_n, jacobian_rotation};
    ASSERT_TRUE(cost->Evaluate(blocks, &residual, jacobians));
    const double analytic[4] = {jacobian_n[0], jacobian_rotation[0],
                                jacobian_rotation[1], jacobian_rotation[2]};
    for (int k = 0; k < 4; ++k) {
      double plus[4], minus[4];
      std::copy(parameters, parameters + 4, plus);
      std::copy(parameters, parameters + 4, minus);
      plus[k] += kStep;
      minus[k] -= kStep;
      double r_plus, r_minus;
      const double* blocks_plus[2] = {&plus[0], &plus[1]};
      const double* blocks_minus[2] = {&minus[0], &minus[1]};
      ASSERT_TRUE(cost->Evaluate(blocks_plus, &r_plus, nullptr));
      ASSERT_TRUE(cost->Evaluate(blocks_minus, &r_minus, nullptr));
      const double numeric = (r_plus - r_minus) / (2.0 * kStep);
      EXPECT_NEAR(analytic[k], numeric,
                  kTolerance * std::max(1.0, std::abs(numeric)))
          << "parameter " << k;
    }
  }
}

}  // namespace
}  // namespace rcm::sampson_coplanarity_error_test

namespace rcm::sampson_coplanarity_error_test {
namespace {

// PrepareCorrespondenceSide is PrepareCorrespondence's half for one
// camera, bit for bit, and leaves the other half as it was.
TEST(PreparedCorrespondence, OneSideIsTheSameHalfAndLeavesTheOther) {
  for (const StereoRig& rig : TestRigs()) {
    for (const StereoCorrespondence& match :
         test::ExactMatches(rig, 1.333, 50)) {
      const PreparedCorrespondence both =
          PrepareCorrespondence(rig, match).value();
      PreparedCorrespondence left = both;
      std::fill_n(left.left_normalized, 2, -7.0);
      std::fill_n(left.left_normalized_from_pixel, 4, -7.0);
      std::fill_n(left.left_focal_direction, 2, -7.0);
      std::fill_n(left.left_normalized_from_pixel_focal, 4, -7.0);
      ASSERT_TRUE(
          PrepareCorrespondenceSide(rig.left(), match.left_pixel, 0, &left));
      PreparedCorrespondence right = both;
      std::fill_n(right.right_normalized, 2, -7.0);
      std::fill_n(right.right_normalized_from_pixel, 4, -7.0);
      ASSERT_TRUE(
          PrepareCorrespondenceSide(rig.right(), match.right_pixel, 1, &right));
      for (const PreparedCorrespondence* side : {&left, &right}) {
        for (int k = 0; k < 2; ++k) {
          EXPECT_EQ(side->left_normalized[k], both.left_normalized[k]);
          EXPECT_EQ(side->right_normalized[k], both.right_normalized[k]);
          EXPECT_EQ(side->left_focal_direction[k],
                    both.left_focal_direction[k]);
          EXPECT_EQ(side->right_focal_direction[k],
                    both.right_focal_direction[k]);
        }
        for (int k = 0; k < 4; ++k) {
          EXPECT_EQ(side->left_normalized_from_pixel[k],
                    both.left_normalized_from_pixel[k]);
          EXPECT_EQ(side->right_normalized_from_pixel[k],
                    both.right_normalized_from_pixel[k]);
          EXPECT_EQ(side->left_normalized_from_pixel_focal[k],
                    both.left_normalized_from_pixel_focal[k]);
          EXPECT_EQ(side->right_normalized_from_pixel_focal[k],
                    both.right_normalized_from_pixel_focal[k]);
        }
      }
    }
  }
}

TEST(PreparedCorrespondence, OneSideRejectsAPixelThatDoesNotPrepare) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  PreparedCorrespondence prepared;
  EXPECT_FALSE(PrepareCorrespondenceSide(rig.left(), Eigen::Vector2d(NAN, 10.0),
                                         0, &prepared));
  EXPECT_FALSE(PrepareCorrespondenceSide(
      rig.right(), Eigen::Vector2d(1e9, -1e9), 1, &prepared));
}

// Near a prepared side, for each lens parameter of every test rig's
// cameras moved by +-h (h = 1e-6 (1 + |p|), the propagation's step): the
// central difference of what one Newton step prepares equals that of the
// undistortion from scratch. The Newton step's own error, ~(h x')^2 ~
// 1e-12, is the same for +h and -h to O(h^3); the difference of the two
// over 2h leaves ~1e-12 of the derivatives (rounding ~1e-16 / h ~ 1e-10 of
// the values dominates).
TEST(PreparedCorrespondence, NearSideGivesTheCentralDifferencesOfTheFull) {
  constexpr double kStepScale = 1e-6;
  constexpr double kTolerance = 1e-8;  // relative to max(1, |derivative|)
  for (const StereoRig& rig : TestRigs()) {
    for (const StereoCorrespondence& match :
         test::ExactMatches(rig, 1.333, 20)) {
      const PreparedCorrespondence at =
          PrepareCorrespondence(rig, match).value();
      for (int side = 0; side < 2; ++side) {
        const Camera& camera = side == 0 ? rig.left() : rig.right();
        const Eigen::Vector2d& pixel =
            side == 0 ? match.left_pixel : match.right_pixel;
        for (int j = 0; j < camera.num_params(); ++j) {
          const double h = kStepScale * (1.0 + std::abs(camera.params()[j]));
          PreparedCorrespondence full[2] = {at, at};
          PreparedCorrespondence near[2] = {at, at};
          for (int s = 0; s < 2; ++s) {
            std::vector<double> params(camera.params(),
                                       camera.params() + camera.num_params());
            params[j] += s == 0 ? h : -h;
            const Camera moved = camera.WithParams(params.data()).value();
            ASSERT_TRUE(
                PrepareCorrespondenceSide(moved, pixel, side, &full[s]));
            ASSERT_TRUE(
                PrepareCorrespondenceSideNear(moved, pixel, side, &near[s]));
          }
          const auto values = [side](const PreparedCorrespondence& p) {
            std::vector<double> v;
            const double* normalized =
                side == 0 ? p.left_normalized : p.right_normalized;
            const double* jacobian = side == 0 ? p.left_normalized_from_pixel
                                               : p.right_normalized_from_pixel;
            const double* focal =
                side == 0 ? p.left_focal_direction : p.right_focal_direction;
            v.insert(v.end(), normalized, normalized + 2);
            v.insert(v.end(), jacobian, jacobian + 4);
            v.insert(v.end(), focal, focal + 2);
            return v;
          };
          const std::vector<double> full_plus = values(full[0]);
          const std::vector<double> full_minus = values(full[1]);
          const std::vector<double> near_plus = values(near[0]);
          const std::vector<double> near_minus = values(near[1]);
          for (size_t k = 0; k < full_plus.size(); ++k) {
            const double expected = (full_plus[k] - full_minus[k]) / (2 * h);
            EXPECT_NEAR((near_plus[k] - near_minus[k]) / (2 * h), expected,
                        kTolerance * std::max(1.0, std::abs(expected)))
                << "side " << side << " parameter " << j << " value " << k;
          }
        }
      }
    }
  }
}

// The matches prepared on two threads are those prepared on one, bit for
// bit, in input order, with the same matches left out (a pixel far outside
// the image does not prepare) and enough matches for several chunks.
TEST(PreparedCorrespondence, PreparedOnThreadsAsOnOne) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  std::vector<StereoCorrespondence> matches =
      test::ExactMatches(rig, 1.333, 1500);
  for (size_t i = 7; i < matches.size(); i += 97) {
    matches[i].right_pixel = Eigen::Vector2d(1e7, -1e7);
  }
  const PreparedCorrespondences one = PrepareCorrespondences(rig, matches, 1);
  const PreparedCorrespondences two = PrepareCorrespondences(rig, matches, 2);
  ASSERT_LT(one.prepared.size(), matches.size());
  ASSERT_GT(one.prepared.size(), 1000u);
  EXPECT_EQ(two.source_index, one.source_index);
  ASSERT_EQ(two.prepared.size(), one.prepared.size());
  for (size_t i = 0; i < one.prepared.size(); ++i) {
    EXPECT_EQ(std::memcmp(&two.prepared[i], &one.prepared[i],
                          sizeof(PreparedCorrespondence)),
              0)
        << "match " << i;
  }
}

// The focal derivatives with the stepped rigs made once are those made per
// match.
TEST(PreparedCorrespondence, FocalStepRigsMadeOnceGiveTheSameDerivatives) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const FocalStepRigs steps = FocalStepRigs::Of(rig).value();
  for (const StereoCorrespondence& match : test::ExactMatches(rig, 1.333, 20)) {
    PreparedCorrespondence once = PrepareCorrespondence(rig, match).value();
    PreparedCorrespondence each = once;
    ASSERT_TRUE(PrepareFocalDerivatives(steps, match, &once));
    ASSERT_TRUE(PrepareFocalDerivatives(rig, match, &each));
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(once.left_normalized_from_pixel_focal[k],
                each.left_normalized_from_pixel_focal[k]);
      EXPECT_EQ(once.right_normalized_from_pixel_focal[k],
                each.right_normalized_from_pixel_focal[k]);
    }
  }
}

}  // namespace
}  // namespace rcm::sampson_coplanarity_error_test
