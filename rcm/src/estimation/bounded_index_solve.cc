#include "rcm/estimation/bounded_index_solve.h"

#include <ceres/iteration_callback.h>

#include <algorithm>
#include <vector>

namespace rcm {
namespace {

// Stops the solver once *n has been within kPinnedDistance of a bound for
// `pinned` iterations in a row (the parameters are updated every
// iteration).
class PinnedIndexCallback : public ceres::IterationCallback {
 public:
  PinnedIndexCallback(const double* n, double lower, double upper, int pinned)
      : n_(n), lower_(lower), upper_(upper), pinned_(pinned) {}

  ceres::CallbackReturnType operator()(
      const ceres::IterationSummary& /*summary*/) override {
    const bool near_bound = *n_ - lower_ <= kPinnedDistance ||
                            upper_ - *n_ <= kPinnedDistance;
    on_bound_ = near_bound ? on_bound_ + 1 : 0;
    if (on_bound_ >= pinned_) {
      stopped_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

  bool stopped() const { return stopped_; }

 private:
  const double* n_;
  double lower_;
  double upper_;
  int pinned_;
  int on_bound_ = 0;
  bool stopped_ = false;
};

}  // namespace

ceres::Solver::Summary SolveWithBoundedIndex(
    const ceres::Solver::Options& options, ceres::Problem* problem, double* n,
    double lower, double upper, int pinned_iterations) {
  PinnedIndexCallback callback(n, lower, upper, std::max(1, pinned_iterations));
  ceres::Solver::Options first = options;
  first.update_state_every_iteration = true;
  first.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  ceres::Solve(first, problem, &summary);
  if (!summary.IsSolutionUsable() || !callback.stopped() ||
      problem->IsParameterBlockConstant(n)) {
    return summary;
  }
  std::vector<ceres::IterationSummary> iterations = summary.iterations;

  // 2. n held on its bound, the other parameters solved.
  const bool at_lower = *n - lower <= upper - *n;
  *n = at_lower ? lower : upper;
  if (problem->NumParameterBlocks() > 1) {
    problem->SetParameterBlockConstant(n);
    ceres::Solver::Summary held;
    ceres::Solve(options, problem, &held);
    problem->SetParameterBlockVariable(n);
    iterations.insert(iterations.end(), held.iterations.begin(),
                      held.iterations.end());
    summary = held;
    if (!held.IsSolutionUsable()) {
      summary.iterations = iterations;
      return summary;
    }
  }

  // 3. The cost's derivative in n there (the other blocks held).
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = {n};
  double cost = 0.0;
  std::vector<double> gradient;
  const bool evaluated =
      problem->Evaluate(evaluate, &cost, nullptr, &gradient, nullptr);
  const bool inward = evaluated && gradient.size() == 1 &&
                      (at_lower ? gradient[0] < 0.0 : gradient[0] > 0.0);
  if (inward) {
    ceres::Solver::Summary released;
    ceres::Solve(options, problem, &released);
    iterations.insert(iterations.end(), released.iterations.begin(),
                      released.iterations.end());
    summary = released;
  }
  summary.iterations = iterations;
  return summary;
}

}  // namespace rcm
