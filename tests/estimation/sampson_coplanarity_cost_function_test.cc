#include "rcm/estimation/sampson_coplanarity_cost_function.h"

#include <ceres/cost_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
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

// The parameter blocks of `parameters` at `point`, and where their
// Jacobians go for `count` residuals (row-major count x size per block).
struct Blocks {
  std::vector<const double*> values;
  std::vector<std::vector<double>> jacobians;
  std::vector<double*> pointers;
};
Blocks BlocksOf(SampsonParameters parameters, const Point& point, int count) {
  Blocks blocks;
  blocks.values = {&point.n};
  std::vector<int> sizes = {1};
  if (parameters != SampsonParameters::kIndex) {
    blocks.values.push_back(point.rotation);
    sizes.push_back(3);
  }
  if (parameters == SampsonParameters::kIndexRotationFocal) {
    blocks.values.push_back(point.focal);
    sizes.push_back(2);
  }
  for (const int size : sizes) {
    blocks.jacobians.emplace_back(static_cast<size_t>(count * size), NAN);
  }
  for (std::vector<double>& jacobian : blocks.jacobians) {
    blocks.pointers.push_back(jacobian.data());
  }
  return blocks;
}

// A block of matches is its matches one by one, row for row, to the bit
// (the same arithmetic), for each set of parameter blocks; n alone is the
// n column with the rotation at zero.
TEST(SampsonCoplanarityCostFunction, BlockOfMatchesIsItsMatchesOneByOne) {
  for (const StereoRig& rig : Rigs()) {
    const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
    const std::vector<PreparedCorrespondence> matches = Matches(rig);
    const int count = static_cast<int>(matches.size());
    for (const SampsonParameters parameters :
         {SampsonParameters::kIndex, SampsonParameters::kIndexRotation,
          SampsonParameters::kIndexRotationFocal}) {
      const SampsonCoplanarityCostFunction block(essential, matches,
                                                 parameters);
      ASSERT_EQ(block.num_residuals(), count);
      for (Point point : Points()) {
        if (parameters == SampsonParameters::kIndex) {
          std::fill_n(point.rotation, 3, 0.0);
        }
        if (parameters != SampsonParameters::kIndexRotationFocal) {
          std::fill_n(point.focal, 2, 0.0);
        }
        Blocks blocks = BlocksOf(parameters, point, count);
        std::vector<double> residuals(count, NAN);
        ASSERT_TRUE(block.Evaluate(blocks.values.data(), residuals.data(),
                                   blocks.pointers.data()));
        for (int i = 0; i < count; ++i) {
          std::unique_ptr<ceres::CostFunction> one(
              SampsonCoplanarityCostFunction::Create(
                  essential, matches[i],
                  parameters == SampsonParameters::kIndexRotationFocal));
          double residual = NAN;
          double jacobian[6] = {};
          ASSERT_TRUE(Evaluate(*one, point, &residual, jacobian));
          EXPECT_EQ(residuals[i], residual);
          EXPECT_EQ(blocks.jacobians[0][i], jacobian[0]);
          if (parameters == SampsonParameters::kIndex) continue;
          for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(blocks.jacobians[1][3 * i + k], jacobian[1 + k]);
          }
          if (parameters != SampsonParameters::kIndexRotationFocal) continue;
          for (int k = 0; k < 2; ++k) {
            EXPECT_EQ(blocks.jacobians[2][2 * i + k], jacobian[4 + k]);
          }
        }
      }
    }
  }
}

// Through a loss, half the block's sum of squares is the robust cost
// sum rho(r_i^2) / 2 Ceres gives the same matches one block each with the
// loss, and each row of the Jacobian is the central difference of its
// residual.
TEST(SampsonCoplanarityCostFunction, RobustBlockCostIsCeresLossCost) {
  // The cost: the same sum by other formulas, rounding of ~30 terms.
  constexpr double kCostTolerance = 1e-12;
  // Central differences with h = 1e-7 (n, rad, scale): truncation h^2 times
  // third derivatives of O(10^3) px per unit^3 at this baseline, ~1e-11,
  // and rounding 1e-16 * 10^3 px / h, ~1e-6 of derivatives of O(10^3).
  constexpr double kStep = 1e-7;
  constexpr double kDifferenceTolerance = 1e-6;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<PreparedCorrespondence> matches = Matches(rig);
  // Outliers: the right pixels of every third match moved several pixels.
  for (size_t i = 0; i < matches.size(); i += 3) {
    matches[i].right_normalized[1] += 0.01 * static_cast<double>(i % 7 + 1);
  }
  const int count = static_cast<int>(matches.size());
  const Point point = Points()[3];
  for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    const SampsonCoplanarityCostFunction block(
        essential, matches, SampsonParameters::kIndexRotationFocal, loss, 0.7);
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(options);
    Point at = point;
    std::vector<std::unique_ptr<ceres::CostFunction>> ones;
    for (const PreparedCorrespondence& match : matches) {
      ones.emplace_back(
          SampsonCoplanarityCostFunction::Create(essential, match, true));
      problem.AddResidualBlock(ones.back().get(), NewLossFunction(loss, 0.7),
                               &at.n, at.rotation, at.focal);
    }
    double ceres_cost = NAN;
    ASSERT_TRUE(problem.Evaluate(ceres::Problem::EvaluateOptions(), &ceres_cost,
                                 nullptr, nullptr, nullptr));

    Blocks blocks =
        BlocksOf(SampsonParameters::kIndexRotationFocal, point, count);
    std::vector<double> residuals(count, NAN);
    ASSERT_TRUE(block.Evaluate(blocks.values.data(), residuals.data(),
                               blocks.pointers.data()));
    double cost = 0.0;
    for (const double r : residuals) cost += 0.5 * r * r;
    EXPECT_NEAR(cost, ceres_cost, kCostTolerance * ceres_cost)
        << RobustLossName(loss);

    const int sizes[3] = {1, 3, 2};
    for (int b = 0; b < 3; ++b) {
      for (int k = 0; k < sizes[b]; ++k) {
        std::vector<double> plus(count);
        std::vector<double> minus(count);
        for (const double sign : {1.0, -1.0}) {
          Point moved = point;
          double* values[3] = {&moved.n, moved.rotation, moved.focal};
          values[b][k] += sign * kStep;
          const double* moved_blocks[3] = {&moved.n, moved.rotation,
                                           moved.focal};
          ASSERT_TRUE(block.Evaluate(
              moved_blocks, (sign > 0 ? plus : minus).data(), nullptr));
        }
        for (int i = 0; i < count; ++i) {
          const double expected = (plus[i] - minus[i]) / (2.0 * kStep);
          EXPECT_NEAR(blocks.jacobians[b][sizes[b] * i + k], expected,
                      kDifferenceTolerance * std::max(1.0, std::abs(expected)))
              << RobustLossName(loss) << " block " << b << " column " << k
              << " match " << i;
        }
      }
    }
  }
}

// Solved with Ceres, blocks of matches with the loss inside reach the
// minimum of the same matches one block each under Ceres' loss: the same
// robust cost, minimized from the same start (only the steps differ).
TEST(SampsonCoplanarityCostFunction, RobustBlocksSolveToCeresLossMinimum) {
  // Both solves stop where the cost changes by less than 1e-14 of itself
  // (function_tolerance); along the minimum's flat valley (n with the
  // rotation, R ~ 0.97) that leaves n and the rotation ~1e-9 apart
  // (measured 2.2e-9 with Cauchy's loss), a millionth of sigma_n here.
  constexpr double kTolerance = 1e-8;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<StereoCorrespondence> data = test::ExactMatches(rig, 1.333, 400);
  AddPixelNoise(0.5, 9, &data);
  for (size_t i = 0; i < data.size(); i += 10) {
    data[i].right_pixel.y() += 3.0 + static_cast<double>(i % 5);  // outliers
  }
  const std::vector<PreparedCorrespondence> matches =
      PrepareCorrespondences(rig, data).prepared;
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-12;
  options.max_num_iterations = 200;
  for (const RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    Point ones = {1.36, {0.0, 0.0, 0.0}, {0.0, 0.0}};
    Point blocks = ones;
    ceres::Problem one_by_one;
    for (const PreparedCorrespondence& match : matches) {
      one_by_one.AddResidualBlock(
          SampsonCoplanarityCostFunction::Create(essential, match, false),
          NewLossFunction(loss, 1.0), &ones.n, ones.rotation);
    }
    ceres::Problem in_blocks;
    for (size_t begin = 0; begin < matches.size();
         begin += kSampsonBlockMatches) {
      const size_t end =
          std::min(matches.size(), begin + size_t{kSampsonBlockMatches});
      in_blocks.AddResidualBlock(
          SampsonCoplanarityCostFunction::Create(
              essential, {matches.begin() + begin, matches.begin() + end},
              SampsonParameters::kIndexRotation, loss, 1.0),
          nullptr, &blocks.n, blocks.rotation);
    }
    ceres::Solver::Summary one_summary;
    ceres::Solver::Summary block_summary;
    ceres::Solve(options, &one_by_one, &one_summary);
    ceres::Solve(options, &in_blocks, &block_summary);
    ASSERT_TRUE(one_summary.IsSolutionUsable());
    ASSERT_TRUE(block_summary.IsSolutionUsable());
    EXPECT_NEAR(blocks.n, ones.n, kTolerance) << RobustLossName(loss);
    EXPECT_GT(one_summary.num_successful_steps, 0);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(blocks.rotation[k], ones.rotation[k], kTolerance)
          << RobustLossName(loss);
    }
    EXPECT_NEAR(block_summary.final_cost, one_summary.final_cost,
                1e-12 * one_summary.final_cost);
  }
}

}  // namespace
}  // namespace rcm::sampson_coplanarity_cost_function_test
