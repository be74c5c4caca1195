// Joint refinement of the refractive index n over captured stereo pairs:
// the estimator of record (docs/design.md, "The estimator of record").
//
// One Ceres problem over all correspondences of all frames, with one
// Sampson coplanarity residual each (sampson_coplanarity_error.h), n
// bounded to [1, 2], in the two stages of refinement_options.h:
//
//   seed:    the best of a coarse scan of the robust cost over [1, 2] and
//            the closed-form seed (median of eq. 14 over the paper's mask);
//   stage 1: min_n sum_i rho(r_i(n)^2)          (robust, all matches;
//            a 1-D golden-section search for n alone, Ceres with the
//            rotation correction)
//   stage 2: min_n sum_{i in inliers} r_i(n)^2  (|r_i| <= threshold)
//
// Uncertainty, from stage 2 with p parameters and N inliers:
//
//   sigma_px^2 = sum r_i^2 / (N - p)          (pixel noise, estimated)
//   cov        = sigma_px^2 (J^T J)^-1        (Ceres covariance)
//   crlb       = sigma_px / sqrt(sum_i (dr_i/dn)^2)
//
// crlb is the Cramer-Rao bound (as a standard deviation) of n with the
// extrinsics known (docs/design.md, "The estimator of record":
// 1 / sum (de_i/dn)^2 / sigma_px^2 is its square). With n alone sigma_n
// equals it; with the rotation correction, sigma_n >= crlb shows what
// estimating the rotation costs.
//
// Rotation correction (options.refine_rotation): a small rotation of cam1
// about its own center (sampson_coplanarity_error.h). The pixel-space
// signature of a rotation is nearly independent of depth, while that of n
// grows with the ray angle and varies with depth; the two separate when
// the matches spread over a wide field of view and a range of depths, and
// are nearly collinear in a narrow central field. Measured (tests): over
// the whole Alphasense image R = 0.79 (sigma_n 1.6x the bound with the
// rotation known); within 60 px of the center R > 0.98 (sigma_n > 5x),
// i.e. not identifiable.
#ifndef RCM_ESTIMATION_BATCH_REFINEMENT_H_
#define RCM_ESTIMATION_BATCH_REFINEMENT_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct RotationCorrection {
  // Angle-axis of cam1's rotation, radians, in the cam1 frame.
  Eigen::Vector3d angle_axis = Eigen::Vector3d::Zero();
  // Standard deviations of its three components, radians.
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  // Correlation of n with each component.
  Eigen::Vector3d correlation_with_n = Eigen::Vector3d::Zero();
  // Multiple correlation R of n with the whole rotation,
  // sqrt(1 - (crlb / sigma_n)^2): sigma_n = crlb / sqrt(1 - R^2). Near 1,
  // the data cannot tell a rotation from a change of n.
  double multiple_correlation_with_n = 0.0;
  // Estimated with the calibration's rotation covariance as prior
  // (self-calibration), not freely (refine_rotation).
  bool with_prior = false;
  // The corrected extrinsics.
  Rigid3d cam1_from_cam0;
};

// The report of a rotation correction `angle_axis` estimated with n: its
// sigmas and correlations from the propagation at the solution (the thin
// and the thick port's refinements), and the corrected extrinsics.
RotationCorrection RotationCorrectionOf(
    const CalibrationPropagation& propagation,
    const Eigen::Vector3d& angle_axis, bool with_prior,
    const Rigid3d& cam1_from_cam0);

// Each camera's focal scale e (focal lengths times 1 + e since the
// calibration), estimated with n under the focal drift prior
// (RefinementOptions::self_calibrate_focal).
struct FocalScaleCorrection {
  Eigen::Vector2d scale = Eigen::Vector2d::Zero();  // (left, right), relative
  Eigen::Vector2d sigma = Eigen::Vector2d::Zero();  // their standard deviations
  Eigen::Vector2d correlation_with_n = Eigen::Vector2d::Zero();
};

struct RefinementSummary {
  double n = 0.0;
  // Standard deviation of n, the total: pixel noise (sigma_n_noise, after
  // the frames' consistency test) and the rig's calibration uncertainty
  // (sigma_n_calibration), and the matches' systematic error floor
  // (sigma_n_systematic), the root of the sum of their squares; see
  // calibration_propagation.h. A rig made in code has no calibration
  // uncertainty: then sigma_n = sigma_n_noise.
  double sigma_n = 0.0;
  double sigma_n_noise = 0.0;
  double sigma_n_calibration = 0.0;
  // With options.systematic_px > 0: the systematic error floor's share
  // (calibration_propagation.h), part of sigma_n.
  double sigma_n_systematic = 0.0;
  double crlb = 0.0;      // Cramer-Rao bound of n (standard deviation)
  double sigma_px = 0.0;  // estimated pixel noise of the inliers
  // The seeds: the closed-form median (nullopt when no match passes the
  // mask or eq. 14 is undefined for all) and the start of stage 1.
  std::optional<double> n_closed_form;
  double n_seed = 0.0;
  double n_robust = 0.0;  // the stage-1 estimate
  // Costs in Ceres' convention, 1/2 sum of (robust) squared residuals.
  double robust_cost = 0.0;  // stage 1, all usable matches
  double cost = 0.0;         // stage 2, inliers
  // Indices into the input of the inliers of stage 2, increasing.
  std::vector<int64_t> inliers;
  int64_t num_correspondences = 0;  // input size
  int64_t num_invalid = 0;          // pixels that could not be undistorted
  int num_iterations = 0;           // solver iterations, both stages
  // With refine_rotation, or self-calibration with a rotation prior.
  std::optional<RotationCorrection> rotation;
  // With self_calibrate_focal and a focal drift prior (thin ports).
  std::optional<FocalScaleCorrection> focal;
  // The propagation of the calibration's uncertainty, when the rig has one
  // (sensitivities, shares, observability of the rotation).
  std::optional<CalibrationPropagation> calibration;
  // The frames' agreement, with two or more frames.
  std::optional<FrameConsistency> consistency;
  // The inliers' normal equations at the solution, over the layout of the
  // propagation (thin ports; calibration_propagation.h), for callers that
  // pool refinements (the online estimators' frames), and cam1's rotation
  // correction they were taken at: the solution's, or
  // RefinementOptions::rows_at_rotation when the rotation self-calibrated
  // (unset: the thick port's model).
  std::optional<LocusNormalEquations> normal_equations;
  std::optional<Eigen::Vector3d> rows_rotation;
};

// A rig with a thick port (StereoRig::HasThickPort, from a camchain's port
// blocks) is refined with the thick-port model instead
// (RefineRefractiveIndexThickPort with these options: cam1's rotation
// self-calibrated as for the thin port; the focal scales held); a rig
// without ports, or with thin ones, exactly as above.
// Fails with one line (and never returns a number) on invalid options,
// fewer than options.min_inliers usable matches or inliers, data that do
// not observe n (crlb at 1 px above options.max_crlb_per_px), or a
// rotation correction that the data cannot separate from n.
StatusOr<RefinementSummary> RefineRefractiveIndex(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    const RefinementOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_BATCH_REFINEMENT_H_
