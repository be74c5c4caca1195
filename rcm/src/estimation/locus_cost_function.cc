#include "rcm/estimation/locus_cost_function.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>

#include "rcm/estimation/sampson_residual_batch.h"
#include "rcm/util/golden_section.h"
#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

using Values = std::array<double, LocusCostFunction::kNumNodes>;

// Below this many residual evaluations AddMatches stays on one thread.
constexpr int64_t kMinEvaluationsPerThread = 20000;

// The barycentric interpolant of `values` at n (header formula).
double Interpolate(const Values& values, double n) {
  CHECK(n >= 1.0 && n <= 2.0) << "n = " << n << " is outside [1, 2]";
  const auto& edges = LocusCostFunction::PanelEdges();
  const auto& nodes = LocusCostFunction::Nodes();
  // Interior edges <= n: the index of n's panel (n = 2 in the last one).
  const int panel =
      static_cast<int>(std::upper_bound(edges.begin() + 1, edges.end() - 1, n) -
                       (edges.begin() + 1));
  const int first = panel * LocusCostFunction::kDegree;
  double numerator = 0.0;
  double denominator = 0.0;
  for (int j = 0; j <= LocusCostFunction::kDegree; ++j) {
    const double difference = n - nodes[first + j];
    if (difference == 0.0) return values[first + j];
    double weight = (j % 2 == 0) ? 1.0 : -1.0;
    if (j == 0 || j == LocusCostFunction::kDegree) weight *= 0.5;
    weight /= difference;
    numerator += weight * values[first + j];
    denominator += weight;
  }
  return numerator / denominator;
}

}  // namespace

const std::array<double, LocusCostFunction::kNumPanels + 1>&
LocusCostFunction::PanelEdges() {
  static const std::array<double, kNumPanels + 1> edges = [] {
    std::array<double, kNumPanels + 1> e{};
    e[0] = 1.0;
    // 1 + 2^-(kNumPanels - 1), ..., 1 + 2^-1, 1 + 2^0: exact in binary.
    for (int p = 1; p <= kNumPanels; ++p) {
      e[p] = 1.0 + std::ldexp(1.0, p - kNumPanels);
    }
    return e;
  }();
  return edges;
}

const std::array<double, LocusCostFunction::kNumNodes>&
LocusCostFunction::Nodes() {
  static const std::array<double, kNumNodes> nodes = [] {
    const auto& edges = PanelEdges();
    std::array<double, kNumNodes> x{};
    for (int p = 0; p < kNumPanels; ++p) {
      const double center = 0.5 * (edges[p] + edges[p + 1]);
      const double half_width = 0.5 * (edges[p + 1] - edges[p]);
      for (int j = 0; j <= kDegree; ++j) {
        // -cos(j pi / N) = sin(pi (2j - N) / (2N)): increasing from -1 to
        // 1, symmetric about 0 in floating point.
        const double t = std::sin(M_PI * (2 * j - kDegree) / (2.0 * kDegree));
        x[p * kDegree + j] = center + half_width * t;
      }
      x[p * kDegree] = edges[p];
      x[(p + 1) * kDegree] = edges[p + 1];
    }
    return x;
  }();
  return nodes;
}

int64_t LocusCostFunction::AddMatches(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches, int num_threads,
    std::vector<int64_t>* rejected) {
  CHECK_GE(num_threads, 1);
  if (rejected != nullptr) rejected->clear();
  const auto& nodes = Nodes();
  const int64_t count = static_cast<int64_t>(matches.size());
  if (count == 0) return 0;

  // r and dr/dn of all matches at one node at a time, vectorized
  // (sampson_residual_batch.h); each node's sums in the matches' order.
  const SampsonResidualBatch batch(essential, matches);
  Values cost{}, cost_derivative{}, information{};
  std::unique_ptr<std::atomic<bool>[]> invalid(new std::atomic<bool>[count] {});
  std::atomic<bool> any_invalid(false);
  ParallelFor(kNumNodes, num_threads,
              std::max<int64_t>(1, kMinEvaluationsPerThread / count),
              [&](int64_t begin, int64_t end) {
                SampsonResidualBatch::Workspace workspace;
                Eigen::ArrayXd r, dr;
                for (int64_t k = begin; k < end; ++k) {
                  batch.Evaluate(nodes[k], &workspace, &r, &dr);
                  double c = 0.0, d = 0.0, g = 0.0;
                  for (int64_t i = 0; i < count; ++i) {
                    if (!std::isfinite(r[i]) || !std::isfinite(dr[i])) {
                      invalid[i].store(true, std::memory_order_relaxed);
                      any_invalid.store(true, std::memory_order_relaxed);
                      continue;
                    }
                    c += r[i] * r[i];
                    d += 2.0 * r[i] * dr[i];
                    g += dr[i] * dr[i];
                  }
                  cost[k] = c;
                  cost_derivative[k] = d;
                  information[k] = g;
                }
              });
  if (any_invalid.load()) {
    // Rare (a match at an epipole): sum again without the undefined ones,
    // so that every node sums the same matches.
    std::vector<PreparedCorrespondence> valid;
    for (int64_t i = 0; i < count; ++i) {
      if (!invalid[i].load()) {
        valid.push_back(matches[i]);
      } else if (rejected != nullptr) {
        rejected->push_back(i);
      }
    }
    if (valid.empty()) return 0;
    return AddMatches(essential, valid, num_threads);
  }
  for (int k = 0; k < kNumNodes; ++k) {
    cost_[k] += cost[k];
    cost_derivative_[k] += cost_derivative[k];
    information_[k] += information[k];
  }
  num_matches_ += count;
  return count;
}

void LocusCostFunction::Add(const LocusCostFunction& other) {
  for (int k = 0; k < kNumNodes; ++k) {
    cost_[k] += other.cost_[k];
    cost_derivative_[k] += other.cost_derivative_[k];
    information_[k] += other.information_[k];
  }
  num_matches_ += other.num_matches_;
}

void LocusCostFunction::Subtract(const LocusCostFunction& other) {
  CHECK_LE(other.num_matches_, num_matches_)
      << "subtracting matches that were not added";
  for (int k = 0; k < kNumNodes; ++k) {
    cost_[k] -= other.cost_[k];
    cost_derivative_[k] -= other.cost_derivative_[k];
    information_[k] -= other.information_[k];
  }
  num_matches_ -= other.num_matches_;
}

void LocusCostFunction::Clear() { *this = LocusCostFunction(); }

double LocusCostFunction::Cost(double n) const { return Interpolate(cost_, n); }

double LocusCostFunction::CostDerivative(double n) const {
  return Interpolate(cost_derivative_, n);
}

double LocusCostFunction::Information(double n) const {
  return Interpolate(information_, n);
}

LocusCostFunction::Minimum LocusCostFunction::Minimize(double linear,
                                                       double quadratic,
                                                       double low_bound,
                                                       double high_bound) const {
  CHECK(low_bound >= 1.0 && high_bound <= 2.0 && low_bound < high_bound)
      << low_bound << " " << high_bound;
  // The function minimized, F = C + linear n + quadratic n^2, and F'.
  const auto cost = [&](double n) {
    return Cost(n) + (linear + quadratic * n) * n;
  };
  const auto derivative = [&](double n) {
    return CostDerivative(n) + linear + 2.0 * quadratic * n;
  };
  // The samples, increasing: each panel's kSamplesPerPanel points from its
  // left edge, then n = 2; of a sub-interval, those inside it and its ends.
  const auto& edges = PanelEdges();
  constexpr int kNumGridSamples = kNumPanels * kSamplesPerPanel + 1;
  const auto grid = [&](int s) {
    if (s == kNumGridSamples - 1) return 2.0;
    const int panel = s / kSamplesPerPanel;
    const int offset = s % kSamplesPerPanel;
    return edges[panel] + (edges[panel + 1] - edges[panel]) * offset /
                              static_cast<double>(kSamplesPerPanel);
  };
  std::array<double, kNumGridSamples + 2> samples;
  int num_samples = 0;
  if (low_bound > 1.0) samples[num_samples++] = low_bound;
  for (int s = 0; s < kNumGridSamples; ++s) {
    const double n = grid(s);
    if (n >= low_bound && n <= high_bound) samples[num_samples++] = n;
  }
  if (high_bound < 2.0) samples[num_samples++] = high_bound;
  const auto sample = [&](int s) { return samples[s]; };

  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int s = 0; s < num_samples; ++s) {
    const double c = cost(sample(s));
    if (c < best_cost) {
      best_cost = c;
      best = s;
    }
  }

  const auto result = [&](double n) {
    return Minimum{n, Cost(n), Information(n)};
  };
  const double at_best = sample(best);
  const double slope = derivative(at_best);
  if (slope == 0.0) return result(at_best);
  if (best == 0 && slope > 0.0) return result(low_bound);
  if (best == num_samples - 1 && slope < 0.0) return result(high_bound);
  // The root of F' between the best sample and the neighbour downhill.
  double low = slope > 0.0 ? sample(best - 1) : at_best;
  double high = slope > 0.0 ? at_best : sample(best + 1);
  if (derivative(low) < 0.0 && derivative(high) > 0.0) {
    while (true) {
      const double middle = 0.5 * (low + high);
      if (!(middle > low && middle < high)) break;
      (derivative(middle) > 0.0 ? high : low) = middle;
    }
    return result(derivative(high) < -derivative(low) ? high : low);
  }
  // F' changes sign more than once between two samples (F has a maximum
  // and a minimum there): golden-section search of F over both neighbours.
  low = sample(std::max(0, best - 1));
  high = sample(std::min(num_samples - 1, best + 1));
  const double middle =
      GoldenSectionMinimize(cost, low, high,
                            4.0 * std::numeric_limits<double>::epsilon());
  return result(cost(middle) <= best_cost ? middle : at_best);
}

}  // namespace rcm
