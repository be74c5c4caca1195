// RefractiveIndexEstimate: the one result type of every estimator of n, as
// `rcm estimate`, Python (rcm.Estimate) and the sequence engine report it.
// Its JSON (estimate_json.h) is the one serialization: a key means the same
// thing wherever it is printed, and its name is the field's.
//
// The uncertainty (paper Sec. V-C, docs/design.md Sec. 5):
//
//   sigma_n^2 = sigma_n_noise^2 + sigma_n_calibration^2 + sigma_n_systematic^2
//
// sigma_n_noise is the pixel noise's share (inflated by the frames'
// disagreement, `consistency`); sigma_n_calibration the camchain's
// uncertainty carried into n (`calibration`: d n / d theta_calib and the
// prior's covariance, per block); sigma_n_systematic the matches'
// systematic field (`systematic_px`, and the field the residuals show).
// The closed form (eq. 14, 17) reports its standard error as sigma_n and
// has no parts (NaN).
//
// Fields an estimator does not have stay NaN / empty (null in the JSON).
#ifndef RCM_ESTIMATION_REFRACTIVE_INDEX_ESTIMATE_H_
#define RCM_ESTIMATION_REFRACTIVE_INDEX_ESTIMATE_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm {

// One row of the per-frame series: the frame's own estimate (refine), the
// estimate so far (online, closed-form) or the window's (window).
struct FrameEstimateRow {
  int64_t frame = 0;
  std::optional<double> timestamp;  // seconds, when the input has times
  double n = std::numeric_limits<double>::quiet_NaN();
  double sigma_n = std::numeric_limits<double>::quiet_NaN();
  bool medium_switch = false;  // the first frame of a new medium (window)
};

// The window estimator's window at the end.
struct WindowSpan {
  int frames = 0;
  int64_t first_frame = 0;
  int64_t last_frame = 0;
};

// The bundle estimator's own (sequence_bundle_adjustment.h).
struct BundlePose {
  int64_t frame = 0;
  std::optional<double> timestamp;  // seconds
  Rigid3d world_from_cam0;          // in the first keyframe's frame, metres
};

struct BundleSummary {
  int64_t frames_used = 0;   // keyframes in the solve
  int64_t landmarks = 0;     // landmarks in the solve
  int64_t tracks = 0;        // of those, seen in two keyframes or more
  int64_t observations = 0;  // inlier observations (pixels)
  // How the rig moved, one line (BundleMotionSummary::Describe).
  std::string motion;
  // The multiple correlation of n with cam1's turn the data leave.
  double correlation_n_rotation = std::numeric_limits<double>::quiet_NaN();
  // One pose per keyframe: the trajectory (TUM files).
  std::vector<BundlePose> trajectory;
};

struct RefractiveIndexEstimate {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  // "refine", "online", "window", "closed-form" or "bundle"; "thin" or
  // "thick".
  std::string estimator;
  std::string port = "thin";
  // One line: the estimator as it ran (loss, thresholds, mask).
  std::string method;

  double n = kNaN;
  double sigma_n = kNaN;  // total, 1 sigma
  double sigma_n_noise = kNaN;
  double sigma_n_calibration = kNaN;
  double sigma_n_systematic = kNaN;
  // The matches' systematic floor the estimate assumed, pixels.
  double systematic_px = 0.0;
  double crlb = kNaN;      // Cramer-Rao bound, the calibration exact
  double sigma_px = kNaN;  // pixel noise estimated from the inliers
  std::optional<double> n_closed_form;

  int64_t inliers = 0;          // used by the final fit (window: in it)
  int64_t invalid = 0;          // pixels that could not be undistorted
  int64_t correspondences = 0;  // input matches
  int64_t frames = 0;           // input frames

  // The calibration's share, the frames' agreement, and what was
  // self-calibrated with n (cam1's rotation; the focal scales; the air
  // gaps of a thick port with estimate_air_gap).
  std::optional<CalibrationPropagation> calibration;
  // The covariance of cam1's rotation prior, radians^2 (the rig's
  // calibration uncertainty; unset without one).
  std::optional<Eigen::Matrix3d> rotation_prior_covariance;
  std::optional<FrameConsistency> consistency;
  std::optional<RotationCorrection> rotation;
  std::optional<FocalScaleCorrection> focal;
  std::optional<AirGapEstimate> air_gap;

  // refine: the seeds and the solve.
  std::optional<double> n_seed;
  std::optional<double> n_robust;
  std::optional<double> cost;
  std::optional<int> iterations;
  // online and window: frames without an own estimate; window: frames
  // held back and dropped, the final window and the changes of medium.
  std::optional<int64_t> skipped_frames;
  std::optional<int64_t> dropped_frames;
  std::optional<WindowSpan> window;
  std::vector<MediumSwitch> switches;
  // closed-form: matches the observability mask removed, and its eta.
  std::optional<int64_t> masked;
  std::optional<double> mask_eta;

  // bundle: the landmarks, the tracks and the trajectory.
  std::optional<BundleSummary> bundle;

  std::vector<FrameEstimateRow> per_frame;
  // What the uncertainty says of the calibration and the data, one line
  // each (estimate_warnings.h); empty when there is nothing to say.
  std::vector<std::string> warnings;
};

// The fields of a batch refinement (thin or thick port); `rig` gives the
// port and the rotation prior. `inliers` counts the refinement's inliers,
// `invalid` its num_invalid.
RefractiveIndexEstimate EstimateFromRefinement(
    const StereoRig& rig, const RefinementSummary& summary,
    const std::optional<AirGapEstimate>& air_gap = std::nullopt);

// The fields every pooled estimate (online, window) shares.
RefractiveIndexEstimate EstimateFromPooled(const StereoRig& rig,
                                           const PooledLocusEstimate& pooled);

}  // namespace rcm

#endif  // RCM_ESTIMATION_REFRACTIVE_INDEX_ESTIMATE_H_
