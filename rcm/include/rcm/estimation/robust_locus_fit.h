// Stage 1 of the estimators of record (refinement_options.h) for n alone:
// the robust cost of the Sampson residuals as a function of n, its coarse
// scan over [1, 2], and a derivative-free 1-D minimization for small
// problems (one frame) where building a Ceres problem would dominate.
#ifndef RCM_ESTIMATION_ROBUST_LOCUS_FIT_H_
#define RCM_ESTIMATION_ROBUST_LOCUS_FIT_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/rigid3d.h"

namespace rcm {

// r_i(n) of every match (sampson_coplanarity_error.h); NaN where undefined.
std::vector<double> LocusResiduals(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches, double n);

// sum_i rho(r_i(n)^2) with the options' loss and scale; undefined
// residuals are skipped. Large sets are summed on options.num_threads
// threads (the result depends on the thread count in the last bits).
double RobustLocusCost(const Eigen::Matrix3d& essential,
                       const std::vector<PreparedCorrespondence>& matches,
                       double n, const RefinementOptions& options);

// The n of the smallest robust cost among the scan grid
// n_k = 1 + k / (num_scan_points - 1) and the optional `candidate` (e.g.
// the closed-form seed), on options.num_threads threads.
double ScanRobustLocusCost(const Eigen::Matrix3d& essential,
                           const std::vector<PreparedCorrespondence>& matches,
                           const RefinementOptions& options,
                           std::optional<double> candidate = std::nullopt);

// The scan, then a golden-section search of the bracket around its best
// point (37 evaluations for the default grid), to
// a bracket narrower than 1e-9 in n.
// `scan_seed`, when not null, receives the scan's best point.
double MinimizeRobustLocusCost(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches,
    const RefinementOptions& options,
    std::optional<double> candidate = std::nullopt,
    double* scan_seed = nullptr);

// Cheirality: true when the two water-side rays of the match at n meet
// (at their closest approach) in front of both cameras, at a positive
// distance along each ray. A random pair of pixels fails it about half of
// the time, while its Sampson residual alone may be small; and the
// outliers that pass the residual test with large implied disparities are
// the ones with the most leverage on n.
bool TriangulatesInFront(const Rigid3d& right_from_left,
                         const PreparedCorrespondence& match, double n);

// The inliers of stage 2 at n: indices of the matches with
// |r_i(n)| <= options.inlier_threshold_px that triangulate in front of
// both cameras, increasing. `right_from_left` is the rig's (or the
// rotation-corrected) cam1_from_cam0.
std::vector<int64_t> ClassifyLocusInliers(
    const Rigid3d& right_from_left,
    const std::vector<PreparedCorrespondence>& matches, double n,
    const RefinementOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_ROBUST_LOCUS_FIT_H_
