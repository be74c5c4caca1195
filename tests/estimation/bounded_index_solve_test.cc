#include "rcm/estimation/bounded_index_solve.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "rcm/estimation/refinement_options.h"

namespace rcm {
namespace {

// The solves below are linear least squares: their minima are exact to
// the solver's tolerances (RefinementSolverOptions), far below this.
constexpr double kExactTolerance = 1e-9;

// r = A (n, w) - b: n with a coupled parameter w (a 2-vector), as n with
// cam1's rotation in the refinement; the columns nearly parallel, as n's
// and the rotation's are on a narrow field.
struct LinearResidual {
  LinearResidual(const Eigen::Vector3d& a, double b) : a(a), b(b) {}
  template <typename T>
  bool operator()(const T* n, const T* w, T* residual) const {
    residual[0] = a[0] * n[0] + a[1] * w[0] + a[2] * w[1] - b;
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& a, double b) {
    return new ceres::AutoDiffCostFunction<LinearResidual, 1, 1, 2>(
        new LinearResidual(a, b));
  }
  Eigen::Vector3d a;
  double b;
};

struct LinearProblem {
  Eigen::Matrix<double, 6, 3> a;
  Eigen::Matrix<double, 6, 1> b;
};

// Rows whose unconstrained least-squares minimum has n = n_free.
LinearProblem ProblemWithMinimumAt(double n_free) {
  LinearProblem p;
  p.a << 1.0, 0.6, 0.1,  //
      1.0, 0.8, -0.3,    //
      1.0, 1.0, 0.25,    //
      1.0, 1.2, 0.0,     //
      1.0, 1.4, -0.2,    //
      1.0, 0.5, 0.4;
  const Eigen::Vector3d x(n_free, 0.3, -0.2);
  p.b = p.a * x;
  // Off-model residuals (orthogonal to the columns) keep the cost > 0.
  Eigen::Matrix<double, 6, 1> noise;
  noise << 0.01, -0.02, 0.015, 0.0, -0.01, 0.005;
  const Eigen::Matrix<double, 6, 1> off =
      noise - p.a * p.a.colPivHouseholderQr().solve(noise);
  p.b += off;
  return p;
}

void Build(const LinearProblem& p, double* n, double* w,
           ceres::Problem* problem) {
  for (int i = 0; i < 6; ++i) {
    problem->AddResidualBlock(
        LinearResidual::Create(p.a.row(i).transpose(), p.b[i]), nullptr, n, w);
  }
  problem->SetParameterLowerBound(n, 0, 1.0);
  problem->SetParameterUpperBound(n, 0, 2.0);
}

ceres::Solver::Options Options() {
  RefinementOptions refinement;
  return RefinementSolverOptions(refinement);
}

TEST(BoundedIndexSolve, MinimumBelowTheLowerBoundEndsOnItExactly) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  double n = 1.2;
  double w[2] = {0.0, 0.0};
  ceres::Problem problem;
  Build(p, &n, w, &problem);
  const ceres::Solver::Summary summary =
      SolveWithBoundedIndex(Options(), &problem, &n, 1.0, 2.0);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  // The constrained minimum: n = 1, w the least squares of the rest.
  const Eigen::Vector2d w_expected =
      p.a.rightCols<2>().colPivHouseholderQr().solve(p.b - p.a.col(0));
  EXPECT_EQ(n, 1.0);
  EXPECT_NEAR(w[0], w_expected[0], kExactTolerance);
  EXPECT_NEAR(w[1], w_expected[1], kExactTolerance);
}

TEST(BoundedIndexSolve, MinimumAboveTheUpperBoundEndsOnItExactly) {
  const LinearProblem p = ProblemWithMinimumAt(2.05);
  double n = 1.5;
  double w[2] = {0.0, 0.0};
  ceres::Problem problem;
  Build(p, &n, w, &problem);
  const ceres::Solver::Summary summary =
      SolveWithBoundedIndex(Options(), &problem, &n, 1.0, 2.0);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  const Eigen::Vector2d w_expected =
      p.a.rightCols<2>().colPivHouseholderQr().solve(p.b - 2.0 * p.a.col(0));
  EXPECT_EQ(n, 2.0);
  EXPECT_NEAR(w[0], w_expected[0], kExactTolerance);
  EXPECT_NEAR(w[1], w_expected[1], kExactTolerance);
}

// Started on the bound and stopped there at once (pinned_iterations 1: the
// starting point), n is held while w moves; the check at the bound then
// finds the cost falling into [1, 2] and releases n to the interior
// minimum.
TEST(BoundedIndexSolve, InteriorMinimumFromTheBoundIsReleased) {
  const LinearProblem p = ProblemWithMinimumAt(1.02);
  const Eigen::Vector3d x_expected = p.a.colPivHouseholderQr().solve(p.b);
  ASSERT_GT(x_expected[0], 1.0);
  double n = 1.0;
  double w[2] = {3.0, -4.0};
  ceres::Problem problem;
  Build(p, &n, w, &problem);
  const ceres::Solver::Summary summary = SolveWithBoundedIndex(
      Options(), &problem, &n, 1.0, 2.0, /*pinned_iterations=*/1);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  EXPECT_NEAR(n, x_expected[0], kExactTolerance);
  EXPECT_NEAR(w[0], x_expected[1], kExactTolerance);
  EXPECT_NEAR(w[1], x_expected[2], kExactTolerance);
}

// n alone (the refinement without self-calibration): nothing to hold the
// rest at; the bound is the answer.
TEST(BoundedIndexSolve, IndexAloneStaysOnTheBound) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  double n = 1.3;
  double w[2] = {0.3, -0.2};
  ceres::Problem problem;
  Build(p, &n, w, &problem);
  problem.SetParameterBlockConstant(w);
  const ceres::Solver::Summary summary =
      SolveWithBoundedIndex(Options(), &problem, &n, 1.0, 2.0);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  EXPECT_EQ(n, 1.0);
}

// A held n (the caller's choice) is left alone.
TEST(BoundedIndexSolve, ConstantIndexIsNotTouched) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  double n = 1.0;
  double w[2] = {0.0, 0.0};
  ceres::Problem problem;
  Build(p, &n, w, &problem);
  problem.SetParameterBlockConstant(&n);
  const ceres::Solver::Summary summary =
      SolveWithBoundedIndex(Options(), &problem, &n, 1.0, 2.0);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  EXPECT_EQ(n, 1.0);
  EXPECT_TRUE(problem.IsParameterBlockConstant(&n));
}

}  // namespace
}  // namespace rcm
