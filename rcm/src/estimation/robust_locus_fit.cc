#include "rcm/estimation/robust_locus_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/util/golden_section.h"
#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

// Below this many residual evaluations a scan stays on one thread.
constexpr int64_t kMinEvaluationsPerThread = 20000;
// Golden-section search stops when its bracket is narrower than this.
constexpr double kBracketTolerance = 1e-9;

}  // namespace

std::vector<double> LocusResiduals(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches, double n) {
  std::vector<double> residuals(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    double residual;
    residuals[i] = SampsonCoplanarityResidual<double>(essential, matches[i], n,
                                                      nullptr, &residual)
                       ? residual
                       : std::numeric_limits<double>::quiet_NaN();
  }
  return residuals;
}

double RobustLocusCost(const Eigen::Matrix3d& essential,
                       const std::vector<PreparedCorrespondence>& matches,
                       double n, const RefinementOptions& options) {
  const auto sum = [&](int64_t begin, int64_t end) {
    double cost = 0.0;
    for (int64_t i = begin; i < end; ++i) {
      double residual;
      if (SampsonCoplanarityResidual<double>(essential, matches[i], n, nullptr,
                                             &residual) &&
          std::isfinite(residual)) {
        cost += RobustLossRho(options.loss, options.loss_scale_px,
                              residual * residual);
      }
    }
    return cost;
  };
  const int64_t count = static_cast<int64_t>(matches.size());
  if (options.num_threads == 1 || count < 2 * kMinEvaluationsPerThread) {
    return sum(0, count);
  }
  std::vector<double> partial(options.num_threads, 0.0);
  ParallelFor(options.num_threads, options.num_threads, 1,
              [&](int64_t begin, int64_t end) {
                for (int64_t t = begin; t < end; ++t) {
                  partial[t] = sum(count * t / options.num_threads,
                                   count * (t + 1) / options.num_threads);
                }
              });
  double cost = 0.0;
  for (const double value : partial) cost += value;
  return cost;
}

double ScanRobustLocusCost(const Eigen::Matrix3d& essential,
                           const std::vector<PreparedCorrespondence>& matches,
                           const RefinementOptions& options,
                           std::optional<double> candidate) {
  std::vector<double> grid(options.num_scan_points);
  for (int k = 0; k < options.num_scan_points; ++k) {
    grid[k] = 1.0 + static_cast<double>(k) / (options.num_scan_points - 1);
  }
  if (candidate && *candidate >= 1.0 && *candidate <= 2.0) {
    grid.push_back(*candidate);
  }
  std::vector<double> costs(grid.size());
  const int64_t evaluations_per_point =
      std::max<int64_t>(1, static_cast<int64_t>(matches.size()));
  ParallelFor(
      static_cast<int64_t>(grid.size()), options.num_threads,
      std::max<int64_t>(1, kMinEvaluationsPerThread / evaluations_per_point),
      [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k) {
          costs[k] = RobustLocusCost(essential, matches, grid[k], options);
        }
      });
  const size_t best = static_cast<size_t>(
      std::min_element(costs.begin(), costs.end()) - costs.begin());
  return grid[best];
}

double MinimizeRobustLocusCost(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches,
    const RefinementOptions& options, std::optional<double> candidate,
    double* scan_seed) {
  const double seed =
      ScanRobustLocusCost(essential, matches, options, candidate);
  if (scan_seed != nullptr) *scan_seed = seed;
  const double step = 1.0 / (options.num_scan_points - 1);
  const double low = std::max(1.0, seed - step);
  const double high = std::min(2.0, seed + step);
  const auto cost = [&](double n) {
    return RobustLocusCost(essential, matches, n, options);
  };
  const double middle =
      GoldenSectionMinimize(cost, low, high, kBracketTolerance);
  // The seed itself may be better when the minimum sits on a bound.
  return cost(middle) <= cost(seed) ? middle : seed;
}

bool TriangulatesInFront(const Rigid3d& right_from_left,
                         const PreparedCorrespondence& match, double n) {
  Eigen::Vector3d left, right;
  FlatPortRefraction::BearingInWater(n, match.left_normalized[0],
                                     match.left_normalized[1], left.data());
  FlatPortRefraction::BearingInWater(n, match.right_normalized[0],
                                     match.right_normalized[1], right.data());
  // Rays a(s) = s left and b(u) = center + u right_in_left, both in the
  // left frame; closest approach from the 2x2 normal equations.
  const Eigen::Matrix3d& rotation = right_from_left.rotation;
  const Eigen::Vector3d center =
      -rotation.transpose() * right_from_left.translation;
  const Eigen::Vector3d right_in_left = rotation.transpose() * right;
  const double aa = left.dot(left);
  const double ab = left.dot(right_in_left);
  const double bb = right_in_left.dot(right_in_left);
  const double ac = left.dot(center);
  const double bc = right_in_left.dot(center);
  const double determinant = aa * bb - ab * ab;
  if (!(determinant > 0.0)) return false;  // parallel rays: at infinity
  const double s = (ac * bb - ab * bc) / determinant;
  const double u = (ab * ac - aa * bc) / determinant;
  return s > 0.0 && u > 0.0;
}

std::vector<int64_t> ClassifyLocusInliers(
    const Rigid3d& right_from_left,
    const std::vector<PreparedCorrespondence>& matches, double n,
    const RefinementOptions& options) {
  const Eigen::Matrix3d essential = EssentialMatrix(right_from_left);
  std::vector<int64_t> inliers;
  inliers.reserve(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    double residual;
    if (SampsonCoplanarityResidual<double>(essential, matches[i], n, nullptr,
                                           &residual) &&
        std::abs(residual) <= options.inlier_threshold_px &&
        TriangulatesInFront(right_from_left, matches[i], n)) {
      inliers.push_back(static_cast<int64_t>(i));
    }
  }
  return inliers;
}

}  // namespace rcm
