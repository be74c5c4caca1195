// SolveWithBoundedIndex: ceres::Solve for a refinement whose refractive
// index n is bounded to [lower, upper] (Problem::SetParameterLowerBound and
// UpperBound, [1, 2] in the estimators), finishing on a bound by an active
// set instead of the solver's projected steps.
//
// Ceres projects each trust-region step onto the bounds. When the minimum
// lies on a bound (n = 1 in air, about half the time, as the noise falls
// on either side of it) the projected step of the parameters coupled to n
// (cam1's rotation, the focal scales, an air gap) is a poor model of the
// cost: most steps are rejected, and the solver spends its whole iteration
// budget before it stops. Live, that was 100 iterations and ~110 ms of a
// 720x540 air pair (live_benchmark's air-water-air sequence), half of the
// 250 ms a 4 Hz camera allows. Here:
//
//   1. Solve, with a callback that stops the solver once n has stayed
//      within kPinnedDistance of a bound for kPinnedIterations iterations
//      in a row (the projected steps move it by less than that on and off
//      the bound);
//   2. when it stopped so, n is put on that bound and held, and the other
//      parameters are solved (unconstrained: a few steps);
//   3. the Karush-Kuhn-Tucker check: at the bound, the cost C must not
//      decrease into [lower, upper] (dC/dn >= 0 at the lower bound, <= 0
//      at the upper). When it does, n is released and the problem solved
//      again from there with its bounds and no callback.
//
// The result is the constrained minimum, as a projected solve would reach
// with unlimited iterations; exact data further than kPinnedDistance
// from the bounds never meet step 2.
// The summary returned is the last solve's, its `iterations` those of all
// the solves (so the callers' iteration counts stay the total).
#ifndef RCM_ESTIMATION_BOUNDED_INDEX_SOLVE_H_
#define RCM_ESTIMATION_BOUNDED_INDEX_SOLVE_H_

#include <ceres/problem.h>
#include <ceres/solver.h>

namespace rcm {

// Iterations near a bound in a row after which step 1 stops, and how near:
// a millionth, below any sigma_n a dive gives (>= 1e-5). A minimum that
// near but inside is found all the same: step 3 releases n.
inline constexpr int kPinnedIterations = 4;
inline constexpr double kPinnedDistance = 1e-6;

// `n` is the problem's parameter block of size 1, bounded to
// [lower, upper] by the caller; `options` are the caller's (step 1 adds
// its callback and updates the parameters every iteration).
// `pinned_iterations` (>= 1) is step 1's count (tests shorten it; the
// first call of the callback is the starting point, iteration 0).
ceres::Solver::Summary SolveWithBoundedIndex(
    const ceres::Solver::Options& options, ceres::Problem* problem, double* n,
    double lower, double upper, int pinned_iterations = kPinnedIterations);

}  // namespace rcm

#endif  // RCM_ESTIMATION_BOUNDED_INDEX_SOLVE_H_
