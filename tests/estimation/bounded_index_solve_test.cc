#include "rcm/estimation/bounded_index_solve.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "rcm/estimation/refinement_options.h"

namespace rcm::bounded_index_solve_test {
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

// Which block the caller holds constant.
enum class Held { kNone, kW, kN };

struct Solved {
  double n = 0.0;
  Eigen::Vector2d w = Eigen::Vector2d::Zero();
  ceres::Solver::Summary summary;
  bool n_constant_after = false;  // n's block still constant afterwards
};

// Solves `p` from (n, w) with n bounded to [1, 2], by SolveWithBoundedIndex
// with the refinement's solver options.
Solved SolveFrom(const LinearProblem& p, double n, const Eigen::Vector2d& w,
                 Held held = Held::kNone,
                 int pinned_iterations = kPinnedIterations) {
  Solved solved;
  solved.n = n;
  solved.w = w;
  ceres::Problem problem;
  for (int i = 0; i < 6; ++i) {
    problem.AddResidualBlock(
        LinearResidual::Create(p.a.row(i).transpose(), p.b[i]), nullptr,
        &solved.n, solved.w.data());
  }
  problem.SetParameterLowerBound(&solved.n, 0, 1.0);
  problem.SetParameterUpperBound(&solved.n, 0, 2.0);
  if (held == Held::kW) problem.SetParameterBlockConstant(solved.w.data());
  if (held == Held::kN) problem.SetParameterBlockConstant(&solved.n);
  RefinementOptions refinement;
  solved.summary =
      SolveWithBoundedIndex(RefinementSolverOptions(refinement), &problem,
                            &solved.n, 1.0, 2.0, pinned_iterations);
  solved.n_constant_after = problem.IsParameterBlockConstant(&solved.n);
  return solved;
}

// n exactly on `bound`, w the least squares of the rest there.
void ExpectConstrainedMinimum(const LinearProblem& p, double bound,
                              const Solved& solved) {
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
  const Eigen::Vector2d w_expected =
      p.a.rightCols<2>().colPivHouseholderQr().solve(p.b - bound * p.a.col(0));
  EXPECT_EQ(solved.n, bound);
  EXPECT_NEAR(solved.w[0], w_expected[0], kExactTolerance);
  EXPECT_NEAR(solved.w[1], w_expected[1], kExactTolerance);
}

TEST(BoundedIndexSolve, MinimumBelowTheLowerBoundEndsOnItExactly) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  ExpectConstrainedMinimum(p, 1.0, SolveFrom(p, 1.2, {0.0, 0.0}));
}

TEST(BoundedIndexSolve, MinimumAboveTheUpperBoundEndsOnItExactly) {
  const LinearProblem p = ProblemWithMinimumAt(2.05);
  ExpectConstrainedMinimum(p, 2.0, SolveFrom(p, 1.5, {0.0, 0.0}));
}

// Started on the bound and stopped there at once (pinned_iterations 1: the
// starting point), n is held while w moves; the check at the bound then
// finds the cost falling into [1, 2] and releases n to the interior
// minimum.
TEST(BoundedIndexSolve, InteriorMinimumFromTheBoundIsReleased) {
  const LinearProblem p = ProblemWithMinimumAt(1.02);
  const Eigen::Vector3d x_expected = p.a.colPivHouseholderQr().solve(p.b);
  ASSERT_GT(x_expected[0], 1.0);
  const Solved solved = SolveFrom(p, 1.0, {3.0, -4.0}, Held::kNone,
                                  /*pinned_iterations=*/1);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
  EXPECT_NEAR(solved.n, x_expected[0], kExactTolerance);
  EXPECT_NEAR(solved.w[0], x_expected[1], kExactTolerance);
  EXPECT_NEAR(solved.w[1], x_expected[2], kExactTolerance);
}

// n alone (the refinement without self-calibration): nothing to hold the
// rest at; the bound is the answer.
TEST(BoundedIndexSolve, IndexAloneStaysOnTheBound) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  const Solved solved = SolveFrom(p, 1.3, {0.3, -0.2}, Held::kW);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
  EXPECT_EQ(solved.n, 1.0);
}

// A held n (the caller's choice) is left alone.
TEST(BoundedIndexSolve, ConstantIndexIsNotTouched) {
  const LinearProblem p = ProblemWithMinimumAt(0.97);
  const Solved solved = SolveFrom(p, 1.0, {0.0, 0.0}, Held::kN);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
  EXPECT_EQ(solved.n, 1.0);
  EXPECT_TRUE(solved.n_constant_after);
}

}  // namespace
}  // namespace rcm::bounded_index_solve_test
