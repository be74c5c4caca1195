// The least-squares cost of the Sampson coplanarity residuals
// (sampson_coplanarity_error.h) as a function of n alone, in memory that
// does not grow with the number of correspondences: what the online and
// sliding-window estimators keep instead of the correspondences.
//
// For matches i with residual r_i(n) (pixels), the three functions
//
//   C(n)  = sum_i r_i(n)^2                (twice Ceres' cost)
//   C'(n) = sum_i 2 r_i(n) dr_i/dn(n)     (its derivative)
//   G(n)  = sum_i (dr_i/dn(n))^2          (LocusInformation, the Fisher
//                                          information of n times sigma_px^2)
//
// are stored as their values at fixed nodes of [1, 2]. r_i and dr_i/dn come
// from SampsonResidualBatch (sampson_residual_batch.h: all matches at a node
// at once, equal to SampsonCoplanarityResidual<ceres::Jet<double, 1>> to
// rounding). Values at fixed nodes are linear in the data, so
// two sets of matches (frames, windows) combine by Add and Subtract, and
// the memory is kNumNodes x 3 doubles however many matches are summed.
//
// Nodes: [1, 2] is cut into kNumPanels panels with edges
//
//   1,  1 + 2^-17,  1 + 2^-16,  ...,  1 + 2^-1,  2
//
// (graded geometrically toward n = 1), and each panel carries the kDegree + 1
// Chebyshev points of the second kind (endpoints included, shared between
// neighbouring panels). Between nodes the functions are the panel's
// polynomial interpolant, evaluated with the barycentric formula
//
//   p(n) = sum_j w_j f_j / (n - n_j)  /  sum_j w_j / (n - n_j),
//   w_j = (-1)^j, halved at j = 0 and j = kDegree
//
// (Trefethen, Approximation Theory and Approximation Practice, ch. 5).
//
// Why the grading: the radial factor m = sqrt(n^2 + (n^2 - 1) r^2) has a
// branch point at n = sin(theta_air) < 1, theta_air the ray's angle in air
// (sin^2 theta = r^2 / (1 + r^2)); at 82.7 degrees (the dataset camera's
// corners) it lies 8e-3 below n = 1, at 89.5 degrees (the widest test
// fisheye) 3.8e-5 below. A Chebyshev interpolant of degree N on a panel
// converges like rho^-N, rho the parameter of the largest Bernstein ellipse
// of the panel free of singularities (ATAP Thm. 8.2). A panel
// [1 + a, 1 + 2a] is as wide as its distance from n = 1, which puts every
// singularity below n = 1 at a scaled distance of at least 3 half-widths
// from the panel's center: rho >= 3 + sqrt(8) = 5.83 whatever the field of
// view. The first panel [1, 1 + 2^-17] (7.6e-6 wide) gives rho = 22 at
// 89.5 degrees.
//
// Why degree 32 (where 16 would do for the branch point alone, 5.83^-16 =
// 6e-13): the Sampson gradient |de/dp|^2 has complex zeros, poles of r^2,
// near the real axis when a ray grazes the port (88-89 degrees in air): its
// pixels hardly move the water-side ray, the gradient nearly vanishes at
// some n and r swings by ~15 px within 0.1 of it. Measured on the
// 89.5-degree fisheye: a zero at 1.095 +- 0.049i for one match, which
// leaves degree 16 at 1e-8 (relative) and degree 24 at 6e-10 on such
// matches; degree 32 brings them to 2e-13. Cost: kNumNodes residual
// evaluations per match (8 us in all, ~14 ns each, vectorized), once, when
// the match is added.
//
// Measured (locus_cost_function_test.cc): the interpolants match the
// directly summed C, C' and G to a relative 1e-12 or better on the
// Alphasense rig and the 89.5-degree fisheye, at random n and at n within
// 1e-12 of 1.
#ifndef RCM_ESTIMATION_LOCUS_COST_FUNCTION_H_
#define RCM_ESTIMATION_LOCUS_COST_FUNCTION_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"

namespace rcm {

class LocusCostFunction {
 public:
  static constexpr int kNumPanels = 18;
  static constexpr int kDegree = 32;
  static constexpr int kNumNodes = kNumPanels * kDegree + 1;

  // The panel edges, increasing from 1 to 2.
  static const std::array<double, kNumPanels + 1>& PanelEdges();
  // All nodes, increasing from 1 to 2; panel p owns nodes
  // p * kDegree ... (p + 1) * kDegree.
  static const std::array<double, kNumNodes>& Nodes();

  // An empty sum: C = C' = G = 0.
  LocusCostFunction() = default;

  // Adds every match whose residual is defined and finite at every node
  // (SampsonCoplanarityResidual fails only where its gradient vanishes, at
  // an epipole); returns how many were added, and the indices of the
  // others in `rejected` (increasing) when it is not null. Work: kNumNodes
  // residual evaluations per match, split over num_threads (>= 1) by node,
  // so the result does not depend on the number of threads.
  int64_t AddMatches(const Eigen::Matrix3d& essential,
                     const std::vector<PreparedCorrespondence>& matches,
                     int num_threads = 1,
                     std::vector<int64_t>* rejected = nullptr);

  // The sum (difference) of the two sets of matches. Exact up to the
  // rounding of one addition per node; Subtract must only remove what was
  // added (num_matches() would go negative: CHECK-fails).
  void Add(const LocusCostFunction& other);
  void Subtract(const LocusCostFunction& other);
  void Clear();

  int64_t num_matches() const { return num_matches_; }

  // The interpolants at n in [1, 2] (CHECK-fails outside).
  double Cost(double n) const;            // C(n)
  double CostDerivative(double n) const;  // C'(n)
  double Information(double n) const;     // G(n)

  // The global minimizer of C over [1, 2]: C sampled at kSamplesPerPanel
  // equally spaced points per panel locates the best sample, then the root
  // of the interpolant of C' next to it is bisected to the last bit of n
  // (|error| ~ 1e-16 in n on top of the interpolation error). A minimum on
  // a bound (C' of one sign there) returns the bound.
  struct Minimum {
    double n = 1.0;
    double cost = 0.0;         // C(n)
    double information = 0.0;  // G(n)
  };
  static constexpr int kSamplesPerPanel = 32;
  // With `linear` and `quadratic`, the same for C(n) + linear n +
  // quadratic n^2 (a rotation profiled out, online_estimator.h), and over
  // [low, high] within [1, 2] (the samples inside it and its ends; a
  // minimum on an end returns it); Minimum's cost is still C(n).
  Minimum Minimize(double linear = 0.0, double quadratic = 0.0,
                   double low = 1.0, double high = 2.0) const;

 private:
  // Values at Nodes().
  std::array<double, kNumNodes> cost_{};
  std::array<double, kNumNodes> cost_derivative_{};
  std::array<double, kNumNodes> information_{};
  int64_t num_matches_ = 0;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_LOCUS_COST_FUNCTION_H_
