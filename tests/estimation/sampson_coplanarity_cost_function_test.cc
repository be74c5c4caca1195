#include "rcm/estimation/sampson_coplanarity_cost_function.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "support/test_rigs.h"

namespace rcm::sampson_coplanarity_cost_function_test {
namespace {

// The two forms compute the same functions in a different order (the
// rotation applied to the matrix once instead of to two vectors per match,
// the derivatives by the chain rule written out instead of carried by
// Jet<double, 6>), so they agree to rounding, amplified where the Sampson
// gradient is small. Measured over these rigs, matches and points: at most
// 9.2e-14 (residuals) and 1.1e-13 (derivatives), relative to
// max(1, |value|) in pixels and pixels per unit. The bars leave a factor of
// ten and a hundred.
constexpr double kResidualTolerance = 1e-12;
constexpr double kJacobianTolerance = 1e-11;

struct Point {
  double n;
  double rotation[3];
  double focal[2];
};

// n at the bound, in water and high; the rotation zero, below the
// small-angle branch of the angle-axis formulas (theta^2 < epsilon), small
// and large; focal scales zero and drifted.
std::vector<Point> Points() {
  return {{1.0, {0.0, 0.0, 0.0}, {0.0, 0.0}},
          {1.333, {0.0, 0.0, 0.0}, {0.0, 0.0}},
          {1.333, {1e-9, -2e-9, 5e-10}, {0.0, 0.0}},
          {1.34, {1e-3, -2e-3, 1.5e-3}, {2e-3, -1e-3}},
          {1.6, {-0.02, 0.01, 0.03}, {-4e-3, 3e-3}}};
}

std::vector<StereoRig> Rigs() {
  return {test::AlphasenseRealisticRig(),
          test::IdealRig(test::EurocRadtanCamera(), test::EurocRadtanCamera()),
          test::IdealRig(test::WideEquidistantCamera(),
                         test::WideEquidistantCamera())};
}

// Prepared noisy matches of `rig` with the focal scales' derivatives.
std::vector<PreparedCorrespondence> Matches(const StereoRig& rig) {
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 30);
  AddPixelNoise(0.5, 4, &data);
  const FocalStepRigs steps = FocalStepRigs::Of(rig).value();
  std::vector<PreparedCorrespondence> prepared;
  for (const StereoCorrespondence& match : data) {
    PreparedCorrespondence p = PrepareCorrespondence(rig, match).value();
    EXPECT_TRUE(PrepareFocalDerivatives(steps, match, &p));
    prepared.push_back(p);
  }
  return prepared;
}

// Evaluates `cost` at `point` into the residual and the derivatives in n,
// the rotation and, when `cost` has the block, the focal scales (4 or 6).
bool Evaluate(const ceres::CostFunction& cost, const Point& point,
              double* residual, double* jacobian) {
  const double* blocks[3] = {&point.n, point.rotation, point.focal};
  double* jacobians[3] = {jacobian, jacobian + 1, jacobian + 4};
  return cost.Evaluate(blocks, residual, jacobians);
}

TEST(SampsonCoplanarityCostFunction, EqualsTheAutodiffForm) {
  for (const StereoRig& rig : Rigs()) {
    const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
    for (const PreparedCorrespondence& match : Matches(rig)) {
      for (const bool focal : {false, true}) {
        std::unique_ptr<ceres::CostFunction> analytic(
            SampsonCoplanarityCostFunction::Create(essential, match, focal));
        std::unique_ptr<ceres::CostFunction> autodiff(
            focal ? SampsonCoplanarityError::CreateWithRotationAndFocal(
                        essential, match)
                  : SampsonCoplanarityError::CreateWithRotation(essential,
                                                                match));
        ASSERT_EQ(analytic->parameter_block_sizes(),
                  autodiff->parameter_block_sizes());
        for (Point point : Points()) {
          if (!focal) point.focal[0] = point.focal[1] = 0.0;
          double r_analytic = NAN;
          double r_autodiff = NAN;
          double j_analytic[6] = {};
          double j_autodiff[6] = {};
          ASSERT_TRUE(Evaluate(*analytic, point, &r_analytic, j_analytic));
          ASSERT_TRUE(Evaluate(*autodiff, point, &r_autodiff, j_autodiff));
          EXPECT_NEAR(r_analytic, r_autodiff,
                      kResidualTolerance * std::max(1.0, std::abs(r_autodiff)))
              << "n " << point.n;
          for (int k = 0; k < (focal ? 6 : 4); ++k) {
            EXPECT_NEAR(
                j_analytic[k], j_autodiff[k],
                kJacobianTolerance * std::max(1.0, std::abs(j_autodiff[k])))
                << "derivative " << k << " at n " << point.n;
          }
        }
      }
    }
  }
}

// A block the problem holds constant gets no Jacobian; the others are the
// same as with every block's.
TEST(SampsonCoplanarityCostFunction, SkipsTheJacobiansOfConstantBlocks) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  const PreparedCorrespondence match = Matches(rig).front();
  std::unique_ptr<ceres::CostFunction> cost(
      SampsonCoplanarityCostFunction::Create(essential, match, true));
  const Point point = Points()[3];
  double residual = NAN;
  double all[6];
  ASSERT_TRUE(Evaluate(*cost, point, &residual, all));
  const double* blocks[3] = {&point.n, point.rotation, point.focal};
  double jacobian_n = NAN;
  double jacobian_focal[2] = {NAN, NAN};
  double* jacobians[3] = {&jacobian_n, nullptr, jacobian_focal};
  double again = NAN;
  ASSERT_TRUE(cost->Evaluate(blocks, &again, jacobians));
  EXPECT_EQ(again, residual);
  EXPECT_EQ(jacobian_n, all[0]);
  EXPECT_EQ(jacobian_focal[0], all[4]);
  EXPECT_EQ(jacobian_focal[1], all[5]);
  ASSERT_TRUE(cost->Evaluate(blocks, &again, nullptr));
  EXPECT_EQ(again, residual);
}

// Where the pixel gradient vanishes (here: an inverse lens Jacobian of
// zero) the residual is undefined, and both forms say so.
TEST(SampsonCoplanarityCostFunction, FailsWhereTheGradientVanishes) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  PreparedCorrespondence match = Matches(rig).front();
  std::fill_n(match.left_normalized_from_pixel, 4, 0.0);
  std::fill_n(match.right_normalized_from_pixel, 4, 0.0);
  std::unique_ptr<ceres::CostFunction> analytic(
      SampsonCoplanarityCostFunction::Create(essential, match, false));
  std::unique_ptr<ceres::CostFunction> autodiff(
      SampsonCoplanarityError::CreateWithRotation(essential, match));
  double residual = NAN;
  double jacobian[6];
  EXPECT_FALSE(Evaluate(*analytic, Points()[1], &residual, jacobian));
  EXPECT_FALSE(Evaluate(*autodiff, Points()[1], &residual, jacobian));
}

}  // namespace
}  // namespace rcm::sampson_coplanarity_cost_function_test
