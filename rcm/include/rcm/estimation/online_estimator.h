// The estimator of record (batch_refinement.h) fed one frame at a time,
// in memory and time per frame that do not grow with the number of frames.
//
// Per frame f (n alone):
//
//   1. prepare the frame's matches (prepared_correspondence.h); with fewer
//      than options.min_inliers usable ones the frame is skipped;
//   2. stage 1 on the frame alone: n_rob,f = argmin sum_i rho(r_i(n)^2)
//      (MinimizeRobustLocusCost: scan of [1, 2], golden section);
//   3. inliers I_f at n_rob,f: |r_i| <= options.inlier_threshold_px and
//      the rays meet in front of both cameras (ClassifyLocusInliers);
//   4. their least-squares cost as a function of n, kept as C_f(n) and
//      G_f(n) = sum (dr_i/dn)^2 at fixed nodes (locus_cost_function.h);
//   5. the running sums C = sum_f C_f, G = sum_f G_f.
//
// Stage 2 of all frames so far is then the 1-D problem on the running sums:
//
//   n          = argmin_{n in [1, 2]} C(n)
//   sigma_px^2 = C(n) / (N - 1)          (N inliers, one parameter)
//   sigma_n    = sigma_px / sqrt(G(n))   (= crlb for n alone)
//
// the same formulas as the batch's stage 2 and covariance (sigma_n then
// grows by the frames' consistency test and the calibration's uncertainty,
// as the batch's does, but with cam1's rotation held at the calibration's:
// calibration_propagation.h). Each frame's own
// estimate (n_f, sigma_f) is the same computed on C_f, G_f alone (and the
// reported one, FrameEstimateOf, with the frame's own calibration share and
// self-calibrated rotation, as the batch of that frame); a frame
// with too few inliers or too little information for an estimate of its
// own still adds its inliers to the running sums, as the batch would.
//
// With self-calibration (SelfCalibrates), each frame is fitted by the batch
// refinement of that frame (cam1's rotation and, with a focal drift prior,
// the focal scales, each under its prior), its normal equations taken at
// its own estimate on its own scaled lenses, and the pooled estimate is
// the MAP of the frames' quadratic models (SelfCalibrateQuadratic over
// x = (n, w, e)); the frames' consistency test couples each frame's n to
// (w, e) (FrameEstimateSums).
//
// Equivalence with the batch (RefineRefractiveIndex on all frames' matches
// at once): the batch classifies inliers at its global robust estimate,
// this estimator at each frame's own. The two inlier sets coincide unless a
// match's |r_i| lies between the threshold evaluated at the two estimates
// (|dr_i/dn| |n_rob,f - n_rob| of it, ~0.05 px at 200 matches per frame):
// with Gaussian noise well inside the threshold and gross outliers, that
// is rare, and on equal inlier sets the two stage-2 problems are the same
// sum of squares, so n agrees with the batch to the batch solver's
// tolerance (tested to 1e-6, measured 2e-10 - 5e-9; this estimator finds
// the minimizer of its interpolant to ~1e-15). Frames skipped in step 1
// are in the batch but not here.
//
// Cost per frame: the robust fit (~90 residual evaluations per match) and
// LocusCostFunction::kNumNodes residual evaluations per inlier, plus two
// 1-D minimizations of interpolants that do not depend on the data size:
// measured 1.7 ms per frame of 200 matches (estimation_benchmark), about
// half of it in the cost function's evaluations. State: a fixed number of
// doubles.
#ifndef RCM_ESTIMATION_ONLINE_ESTIMATOR_H_
#define RCM_ESTIMATION_ONLINE_ESTIMATOR_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/locus_cost_function.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// The stage-2 estimate of a LocusCostFunction (formulas above), for n
// alone with the calibration exact.
struct LocusEstimate {
  double n = 0.0;
  double sigma_n = 0.0;   // standard deviation
  double crlb = 0.0;      // Cramer-Rao bound; equals sigma_n for n alone
  double sigma_px = 0.0;  // estimated pixel noise of the inliers
  int64_t inliers = 0;    // N
};

// Fails, with the reason, with fewer than options.min_inliers inliers or
// when the data do not observe n: 1 / sqrt(G(n)), the crlb at 1 px of
// noise, above options.max_crlb_per_px (e.g. every match on the image
// axes, where the loci do not depend on n).
StatusOr<LocusEstimate> EstimateFromLocusCost(const LocusCostFunction& cost,
                                              const RefinementOptions& options);

// What the online and the sliding-window estimates report of their pooled
// frames (CalibratedLocusEstimate, below).
struct PooledLocusEstimate {
  double n = 0.0;
  // The total standard deviation, as the batch's: pixel noise (after the
  // frames' consistency test), the calibration's uncertainty and the
  // matches' systematic error floor (calibration_propagation.h).
  double sigma_n = 0.0;
  double sigma_n_noise = 0.0;
  double sigma_n_calibration = 0.0;
  double sigma_n_systematic = 0.0;
  double crlb = 0.0;  // of n alone with the calibration known
  double sigma_px = 0.0;
  int64_t inliers = 0;  // pooled
  std::optional<FrameConsistency> consistency;
  std::optional<CalibrationPropagation> calibration;
  // The self-calibrated rotation of cam1 (angle-axis, radians, the
  // convention of StereoRig::WithCam1Moved), when it is estimated.
  std::optional<Eigen::Vector3d> rotation;
  // The self-calibrated focal scales (e_l, e_r), relative, when they are
  // estimated (SelfCalibrationLayout).
  std::optional<Eigen::Vector2d> focal_scale;
};

// A LocusEstimate with the uncertainty of the calibration and the frames'
// consistency (calibration_propagation.h), shared by the online and the
// sliding-window estimators.
//
// Without a calibration uncertainty: n alone, sigma_n = sigma_px /
// sqrt(G(n)), inflated by the consistency test. With one whose rotation
// covariance is nonzero and options.self_calibrate_rotation: cam1's
// rotation w is self-calibrated as in the batch (batch_refinement.h), from
// the frames' normal equations. The residuals are linear in w to first
// order about the calibration's rotation, r_i(n, w) ~ r_i(n, 0) + j_w,i w,
// so that the cost
//
//   C(n) + 2 g(n) . w + w^T H w + sigma^2 w^T P w,
//   g(n) ~ g0 + b n  (gradient_intercept and M_{w, n} of the frames' sums),
//
// is minimized over w in closed form, w(n) = -(H + sigma^2 P)^-1 g(n), and
// over n by LocusCostFunction::Minimize of C(n) - g(n)^T (H + sigma^2
// P)^-1 g(n), a quadratic added to C; sigma^2 is refined from the
// residual at the solution (two or three passes). The linear g(n) holds
// near the frames' own estimates, not over all of [1, 2] (far away its
// concave quadratic would win), so the minimum is searched within 0.15
// of the estimate with the rotation held, the interval moved along (up to
// three times) while the minimum sits on one of its inner ends. The neglected
// second order in w is ~f |w|^2 / 2 in pixels (0.002 px at 0.15 degree and f =
// 500 px). Inliers are the frames' own, classified with the rotation held, so a
// drift that moves matches beyond the inlier threshold (about inlier_threshold
// / f radians) loses them: the batch refinement classifies with the rotation
// estimated. Otherwise the rotation is held and its uncertainty propagated.
struct CalibratedLocusEstimate {
  double sigma_n_systematic = 0.0;  // options.systematic_px's share
  // n, sigma_px and crlb at the solution (n alone, or with the rotation);
  // locus.sigma_n = sigma_n.
  LocusEstimate locus;
  // The self-calibrated rotation of cam1 (angle-axis, radians, the
  // convention of StereoRig::WithCam1Moved), when it is estimated.
  std::optional<Eigen::Vector3d> rotation;
  // The self-calibrated focal scales (e_l, e_r), relative, when they are
  // estimated (SelfCalibrationLayout).
  std::optional<Eigen::Vector2d> focal_scale;
  double sigma_n = 0.0;
  double sigma_n_noise = 0.0;
  double sigma_n_calibration = 0.0;
  std::optional<FrameConsistency> consistency;
  std::optional<CalibrationPropagation> calibration;
};
// `normal_equations` and `frame_estimates` sum the frames of `cost`; a rig
// without a calibration uncertainty ignores the former. An n pinned at the
// upper bound is an error (CheckNotPinnedAtUpperBound), never a number.
bool SelfCalibrates(const StereoRig& rig, const RefinementOptions& options);
// The layout of the frames' normal equations (calibration_propagation.h):
// with self-calibration (SelfCalibrates) and options.self_calibrate_focal,
// the focal scales' columns when the rig has a focal drift prior, so that
// the online estimators estimate them with n and the rotation as the
// batch refinement does.
CalibrationParameterLayout SelfCalibrationLayout(
    const StereoRig& rig, const RefinementOptions& options);
//
// `scatter_inflation` (>= 1) is a floor on the consistency test's
// inflation: the scatter of the frames around this one, when the estimate
// is one frame's and the estimator's frames disagree beyond their noise
// (FrameEstimateOf).
StatusOr<CalibratedLocusEstimate> EstimateWithCalibration(
    const StereoRig& rig, const LocusCostFunction& cost,
    const LocusNormalEquations& normal_equations,
    const FrameEstimateSums& frame_estimates, const RefinementOptions& options,
    double scatter_inflation = 1.0);
// Its fields as the estimators report them.
PooledLocusEstimate PooledEstimateOf(const CalibratedLocusEstimate& estimate);
// The consistency test's inflation of a pooled estimate: 1 when its frames
// agree (or it has fewer than two).
inline double ScatterInflationOf(const PooledLocusEstimate& estimate) {
  return estimate.consistency ? estimate.consistency->inflation : 1.0;
}

// Steps 1-4 for one frame.
struct FrameFit {
  int64_t correspondences = 0;   // the frame's size
  int64_t usable = 0;            // prepared (pixels undistorted)
  bool skipped = true;           // fewer than min_inliers usable
  double n_robust = 0.0;         // stage 1, when not skipped
  std::vector<int64_t> inliers;  // indices into the frame, increasing
  LocusCostFunction cost;        // C_f, G_f of the inliers
  // n_f, sigma_f from C_f, G_f alone; the error says why there is none.
  StatusOr<LocusEstimate> estimate = Status::Error("frame not fitted");
  // With a rig that has a calibration uncertainty: the inliers' normal
  // equations (calibration_propagation.h, SelfCalibrationLayout) at n_f
  // (n_robust without an own estimate), the frame's own self-calibrated
  // focal scales (the lenses scaled by them) and the linearization
  // rotation (FitFrame); empty (all zero) otherwise.
  LocusNormalEquations normal_equations;
  // The frame's own n as the consistency test sees it, n_f(x) = n - b .
  // x / information to first order in x = (w, e) (FrameEstimateSums,
  // calibration_propagation.h): from normal_equations' model when there is
  // one (linearized at the frame's own self-calibrated estimate), else the
  // own estimate with C_f's information and b = 0. Unset without an own
  // estimate.
  struct Model {
    double n = 0.0;
    double information = 0.0;
    // b = sum dr/dn dr/dx, x = (w, e) (SelfCalibrationVector).
    SelfCalibrationVector coupling = SelfCalibrationVector::Zero();
    double At(const SelfCalibrationVector& x) const {
      return information > 0.0 ? n - coupling.dot(x) / information : n;
    }
  };
  std::optional<Model> model;
};
//
// The rows of the normal equations are linearized at cam1's rotation
// `linearization_rotation` when given (the estimator's
// LinearizationPoint), else at the frame's own. The pooled quadratic model
// sums the frames' affine models, which hold near where each was taken:
// frames whose own rotations scatter (cameras not triggered together on a
// moving rig: exposure_delay.h) would otherwise be summed from points
// tenths of a degree apart along the ridge where n and the rotation trade,
// and the pooled n is biased (z mean +1.5 to +2.9 in the pool, +7 on a
// narrow board, measured). Taken at one point they agree; exact data stay
// exact (the point is then the truth). The frame's refinement takes its
// rows there too (RefinementOptions::rows_at_rotation), and they are
// reused as they are at the frame's own rotation without an estimator.
FrameFit FitFrame(const StereoRig& rig,
                  const std::vector<StereoCorrespondence>& frame_matches,
                  const RefinementOptions& options,
                  const std::optional<Eigen::Vector3d>& linearization_rotation =
                      std::nullopt);

// Where an estimator takes its frames' rows (FitFrame): the pooled
// self-calibrated rotation when it first has one, and again only when the
// pooled rotation has moved more than kMaxDistance from it, so that the
// frames it sums share one point. The affine model's neglected second
// order is ~f |dw|^2 / 2 in pixels: 0.002 px at kMaxDistance and f = 500
// px (a rig that turns slowly over a long run moves the point along).
struct LinearizationPoint {
  static constexpr double kMaxDistance = 0.15 * M_PI / 180.0;  // radians
  std::optional<Eigen::Vector3d> rotation;

  void Follow(const std::optional<Eigen::Vector3d>& pooled) {
    if (pooled && (!rotation || (*pooled - *rotation).norm() > kMaxDistance)) {
      rotation = pooled;
    }
  }
};

// The frame's own estimate as the estimators report it: EstimateWithCalibration
// of the frame alone, so that its sigma_n counts what the pooled one counts
// (pixel noise with cam1's rotation marginalized when it is self-calibrated,
// the calibration's uncertainty, the systematic floor), i.e. what the batch
// refinement reports on that frame's matches alone. `fit.estimate` (n_f,
// sigma_f: pixel noise at the frame's own rotation) stays the estimators'
// internal measure of frame-to-frame agreement. The error says why there is
// no estimate.
//
// `scatter_inflation` is the estimator's frames' consistency inflation
// (FrameConsistency::inflation of its pooled estimate, 1 when they agree):
// frames that disagree beyond their pixel noise (cameras not triggered
// together on a moving rig, a scene that moves) scatter each frame's n by
// that factor more than its noise share says, so the frame's noise share
// is inflated by it as the pooled one is.
StatusOr<PooledLocusEstimate> FrameEstimateOf(const StereoRig& rig,
                                              const FrameFit& fit,
                                              const RefinementOptions& options,
                                              double scatter_inflation = 1.0);

class OnlineRefractiveIndexEstimator {
 public:
  // Fails on invalid options or options.refine_rotation (the rotation
  // correction is batch-only).
  static StatusOr<OnlineRefractiveIndexEstimator> Create(
      const StereoRig& rig, const RefinementOptions& options);

  // The estimate of all frames so far: the pooled estimate, with the
  // counts of the whole run.
  struct Estimate : PooledLocusEstimate {
    int64_t correspondences = 0;  // every correspondence of every frame
    int64_t frames = 0;           // frames added, skipped ones included
  };

  struct FrameUpdate {
    int64_t frame = 0;  // 0-based count of AddFrame calls
    int64_t correspondences = 0;
    int64_t usable = 0;
    bool skipped = false;
    // Indices into the frame of the inliers added to the running sums.
    std::vector<int64_t> inliers;
    // The frame's own estimate (FrameEstimateOf), and the cumulative one
    // after the frame; each with the reason when there is none.
    StatusOr<PooledLocusEstimate> frame_estimate = Status::Error("no estimate");
    StatusOr<Estimate> cumulative = Status::Error("no estimate");
  };
  FrameUpdate AddFrame(const std::vector<StereoCorrespondence>& frame_matches);

  // The cumulative estimate; an error (never a number) until
  // options.min_inliers inliers are in or while the data do not observe n.
  StatusOr<Estimate> Current() const;

  int64_t num_frames() const { return num_frames_; }
  int64_t num_skipped_frames() const { return num_skipped_frames_; }
  const LocusCostFunction& cost() const { return cost_; }

  // Bytes held, heap included: constant (tested over 1000 frames).
  size_t MemoryBytes() const { return sizeof(*this); }

 private:
  OnlineRefractiveIndexEstimator(const StereoRig& rig,
                                 const RefinementOptions& options);

  StereoRig rig_;
  RefinementOptions options_;
  LocusCostFunction cost_;
  // The frames' normal equations and own estimates, summed.
  LocusNormalEquations normal_equations_;
  FrameEstimateSums frame_estimates_;
  LinearizationPoint linearization_;
  int64_t num_frames_ = 0;
  int64_t num_skipped_frames_ = 0;
  int64_t num_correspondences_ = 0;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_ONLINE_ESTIMATOR_H_
