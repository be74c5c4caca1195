// What the two target bundle adjustments of rcm::calib share: the air
// stereo calibration (stereo_calibration.h) and the underwater refinement
// (underwater_calibration.h). Internal to the library.
//
//   - the checks of the views' observations and the choice of the usable
//     ones;
//   - the pose blocks [angle-axis, translation] and the left-perturbation
//     Jacobian of the covariance;
//   - the Ceres settings;
//   - the robust fit: Huber solves with outlier rounds, then least squares
//     on the inliers (FitWithOutlierRejection);
//   - the joint covariance of chosen parameter blocks;
//   - the per-corner residuals and their statistics.
#ifndef RCM_CALIB_SRC_BOARD_BUNDLE_ADJUSTMENT_H_
#define RCM_CALIB_SRC_BOARD_BUNDLE_ADJUSTMENT_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm::calib::internal {

// Median of the Rayleigh distribution of |e| for a 2-D residual with
// independent N(0, sigma^2) components, in units of sigma: sqrt(2 ln 2).
inline constexpr double kRayleighMedian = 1.1774100225154747;

// A rigid transform as a Ceres parameter block: [rotation vector (rad),
// translation (m)].
using Pose = std::array<double, 6>;
Pose PoseFromRigid(const Rigid3d& rigid);
Rigid3d RigidFromPose(const double* pose);

// d w / d a: how the left-perturbation rotation vector w (R = exp([w]x)
// R(a)) moves with the angle-axis parameters a.
Eigen::Matrix3d LeftPerturbationFromAngleAxis(const double* angle_axis);

// The observations of each view that take part, per camera (nullptr for
// none): those with at least `min_corners` corners, and only stereo views
// unless `use_single_camera_views`. Errors: an observation whose ids and
// pixels differ in number, an id that is not on the target (num_points
// corners), a pixel that is not finite.
using UsedObservations = std::vector<std::array<const TargetObservation*, 2>>;
StatusOr<UsedObservations> SelectObservations(
    const std::vector<StereoView>& views, int num_points, int min_corners,
    bool use_single_camera_views);

// One corner of a problem.
struct Corner {
  int view;
  int camera;
  int point_id;
  Eigen::Vector2d pixel;
  bool inlier = true;
};

// The solver settings of both bundle adjustments.
ceres::Solver::Options BoardSolverOptions(int max_num_iterations,
                                          int num_threads);

// The settings both bundle adjustments' options share, and their one
// check: "huber_px must be positive and finite", ... (the field's name
// first).
struct SharedFitSettings {
  double huber_px;
  double outlier_sigmas;
  double min_outlier_threshold_px;
  int max_outlier_rounds;
  int max_num_iterations;
  int min_corners_per_view;
  int num_threads;
};
Status CheckSharedFitSettings(const SharedFitSettings& settings);

struct OutlierRejectionOptions {
  double huber_px = 1.0;
  double outlier_sigmas = 5.0;
  double min_outlier_threshold_px = 2.0;
  int max_outlier_rounds = 3;
};

// The robust fit of every board bundle adjustment:
//   max_outlier_rounds times: solve with Huber's loss at huber_px over the
//     inliers, then mark as outliers the corners whose |e| exceeds
//     max(outlier_sigmas * median|e| / kRayleighMedian,
//         min_outlier_threshold_px) (the median over the corners that
//     project; one that does not, NaN, is an outlier), stopping early when
//     the set does not change;
//   then plain least squares over the inliers, in `final_problem`, whose
//     Jacobian the covariance is computed from.
// `add_residuals(huber_px, problem)` adds the residuals of the corners
// marked inlier in `corners` (huber_px 0: no loss function) and sets any
// bounds; `residual(corner)` evaluates one corner at the current
// parameters. Fails when a solve fails or no corner projects.
Status FitWithOutlierRejection(
    const OutlierRejectionOptions& options,
    const ceres::Solver::Options& solver_options,
    const std::function<void(double, ceres::Problem*)>& add_residuals,
    const std::function<Eigen::Vector2d(const Corner&)>& residual,
    std::vector<Corner>* corners, ceres::Problem* final_problem);

// The covariance (J^T J)^-1 of parameter blocks of a solved problem
// (unscaled by the pixel noise), rows in the order of `blocks`, each block
// of its ambient size: the joint matrix, or only its diagonal blocks (the
// rest zero) unless `cross_blocks`. SPARSE_QR, then DENSE_SVD when that
// fails (rank deficiency). False when both fail or the result is not
// finite.
struct CovarianceBlockRef {
  const double* block;
  int size;
};
bool JointCovariance(const std::vector<CovarianceBlockRef>& blocks,
                     bool cross_blocks, int num_threads,
                     ceres::Problem* problem, Eigen::MatrixXd* covariance);

// Every corner's residual at the solution, and their statistics. A corner
// that does not project (residual NaN, always an outlier) is counted, not
// summed.
struct ResidualStatistics {
  std::vector<CornerResidual> corners;
  double rms_px = 0.0;         // all corners that project
  double inlier_rms_px = 0.0;  // inliers
  double inlier_ssr = 0.0;     // sum |e|^2 over the inliers
  int num_inliers = 0;
  int num_outliers = 0;
  int num_unprojected = 0;  // of the outliers
};
ResidualStatistics SummarizeResiduals(
    const std::vector<Corner>& corners,
    const std::function<Eigen::Vector2d(const Corner&)>& residual);

// Moves `statistics` into the fields of the same names of a result
// (StereoCalibration, UnderwaterCalibration).
template <typename Result>
void StoreResidualStatistics(ResidualStatistics statistics, Result* result) {
  result->corners = std::move(statistics.corners);
  result->rms_px = statistics.rms_px;
  result->inlier_rms_px = statistics.inlier_rms_px;
  result->num_inliers = statistics.num_inliers;
  result->num_outliers = statistics.num_outliers;
}

// The options of the conventional fit beside an underwater calibration
// (the air model's lens free, no port): the robust-fit settings of
// `options` (an UnderwaterCalibrationOptions or DomeCalibrationOptions),
// no covariance.
template <typename Options>
StereoCalibrationOptions ConventionalFitOptions(LensModelId model,
                                                const Options& options,
                                                bool estimate_board_warp) {
  StereoCalibrationOptions fit;
  fit.model = model;
  fit.huber_px = options.huber_px;
  fit.outlier_sigmas = options.outlier_sigmas;
  fit.min_outlier_threshold_px = options.min_outlier_threshold_px;
  fit.max_outlier_rounds = options.max_outlier_rounds;
  fit.max_num_iterations = options.max_num_iterations;
  fit.min_corners_per_view = options.min_corners_per_view;
  fit.compute_covariance = false;
  fit.estimate_board_warp = estimate_board_warp;
  fit.num_threads = options.num_threads;
  return fit;
}

// The noise sigma of an estimate with a covariance sigma and a
// leave-views-out (grouped jackknife) sigma from `replicates` replicates:
// the leave-out sigma when it exceeds the covariance's by more than its
// own sampling error allows (a one-sided 95 % chi-square test with
// replicates - 1 degrees of freedom; Wilson-Hilferty's quantile), else the
// covariance's. The leave-out counts errors shared within a view (a
// detector's, on a steep or crowded board), which the covariance does
// not; from 5-10 replicates it is too noisy to take whenever larger.
double LeaveOutOrCovarianceSigma(double covariance_sigma,
                                 double leave_out_sigma, int replicates);

// The grouped jackknife of g >= 2 replicates x_1..x_g of an estimate,
// each with the same components:
//   (g - 1) / g sum_k (x_k - mean)(x_k - mean)^T,
// and its per-component standard deviations (the diagonal's roots).
Eigen::MatrixXd JackknifeCovariance(
    const std::vector<Eigen::VectorXd>& samples);
Eigen::VectorXd JackknifeSigma(const std::vector<Eigen::VectorXd>& samples);

// The target poses of the views `used`, nullopt for the others.
std::vector<std::optional<Rigid3d>> UsedViewPoses(
    const std::vector<Pose>& poses, const std::vector<bool>& used);

}  // namespace rcm::calib::internal

#endif  // RCM_CALIB_SRC_BOARD_BUNDLE_ADJUSTMENT_H_
