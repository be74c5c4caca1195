// What the calibration's uncertainty does to n: the linearized error
// propagation shared by the estimators of record (batch_refinement.h,
// online_estimator.h, sliding_window_estimator.h), so that sigma_n counts
// the rig's calibration (calibration_uncertainty.h) and not only pixel
// noise.
//
// At the solution the Sampson residuals (pixels) are linearized in
//
//   n,  w  (3, a turn of cam1 about its center, radians, cam1 frame),
//   dt (3, a change of cam1_from_cam0's translation, meters),
//   the lens parameters of each camera (Camera::params order), when the
//   calibration measured their covariance,
//   the ports' parameters q = [d, a, b] of each camera (air gap, tilt;
//   CalibrationUncertainty::port_covariance), when the calibration
//   estimated them and the rig has a thick port,
//
// (StereoRig::WithCam1Moved's convention), one row j_i = dr_i / d(n, w, dt,
// lenses) per inlier: the Sampson coplanarity residual of a thin port
// (sampson_coplanarity_error.h), or the generalized epipolar residual of a
// thick one (generalized_epipolar_error.h). dr/dn comes from ceres::Jet,
// the rest from central differences (steps 1e-6 rad, 1e-6 m and
// 1e-6 (1 + |p|); the residuals are smooth and the truncation error is
// ~1e-12 relative; an air gap within a step of 0, where the port has no
// thinner side, by the forward difference, whose error is ~1e-6 relative).
// The estimators keep
// the sums
//
//   M = sum_i j_i j_i^T,   g = sum_i r_i j_i,   C = sum_i r_i^2,
//
// which add over frames (LocusNormalEquations).
//
// With the focal scales estimated (batch_refinement.h,
// self_calibrate_focal), x gains (e_l, e_r) under the focal drift prior,
// P_ee = 1 / s_f^2, and the held lenses carry the calibration's measured
// covariance without it (CalibrationUncertainty::WithoutFocalDrift).
//
// Estimated x = [n] or [n, w], the rest p held at the calibration and
// perturbed by its covariance Sigma_p; with A = M_xx, B = M_xp, pixel noise
// sigma and, when w is estimated under its prior, P = Sigma_w|p^-1, the
// inverse of w's covariance given the held parameters
// (CalibrationUncertainty::RotationPriorCovariance; P = 0 when w is free,
// --refine-rotation):
//
//   H        = A / sigma^2 + diag(0, P)          posterior information
//   S        = H^-1 B / sigma^2                  d x_hat / d p
//   cov(x)   = H^-1 A / sigma^2 H^-1             pixel noise
//            + H^-1 diag(0, P Sigma_ww P) H^-1   the prior's share of w
//            + S Sigma_p S^T                     the calibration held fixed
//
// (Sigma_ww the marginal covariance of w. When w is uncorrelated with the
// held parameters Sigma_w|p = Sigma_ww, and for a w drawn from the prior
// the first two sum to H^-1, the Bayesian posterior covariance: MAP
// estimation, Kay, Fundamentals of Statistical Signal Processing I, ch.
// 10-11. An underwater calibration's rotation is fitted through the air
// lenses, so its marginal is degrees while given the lenses it is what the
// water views measured: the conditional prior keeps n separable from w,
// and the terms here and below count the lenses' error in full.) When the
// calibration's extrinsics are correlated with its lenses
// (CalibrationUncertainty::extrinsics_lens_covariance, an underwater
// calibration's), Sigma_p is the joint covariance of the held columns, and
// with w under its prior the error H^-1 (B dp / sigma^2 - diag(0, P) dw) of
// a rotation off its prior by dw adds the cross term
//
//            - H^-1 (B Sigma_pw diag(0, P) / sigma^2 + transpose) H^-1,
//
// Sigma_pw the held columns' covariance with w. sigma_n is the square root of
// the (n, n) entry; sigma_n_noise of the first term's, sigma_n_calibration of
// the other two. With w held (online estimators without self-calibration), w is
// part of p.
//
// Sensitivities with everything but n held: dn/dq = -M_nq / M_nn for each
// q of w and dt (what a stale calibration does to an n estimated alone).
// Observability of w from the data alone: the multiple correlation R of n
// with w, R^2 = 1 - 1 / (M_nn [M_{n,w}^-1]_nn), and the inflation of
// sigma_n when w is estimated without a prior, 1 / sqrt(1 - R^2).
//
// A systematic error floor (RefinementOptions::systematic_px): the pixel
// noise model takes the residuals' errors as independent, so that their
// effect on n falls as 1 / sqrt(N). Matchers have smooth systematic errors
// as well (a lamp's brightness gradient between the two views, sub-pixel
// interpolation, a lens model's residual error) that no number of matches
// averages away, and where n and cam1's rotation are nearly collinear
// (a narrow field at near-constant depth) a few hundredths of a pixel of
// them move n by several of its noise sigmas. They are modeled as a field
// added to every residual,
//
//   r_i += sum_k c_k phi_k(x_i, y_i),   c_k ~ N(0, systematic_px^2),
//   phi = (1, x, y, x^2, x y, y^2),
//
// (x, y) the left pixel scaled to [-1, 1] over the image, held at c = 0
// and propagated like the calibration (its columns are part of p above).
// Its share is reported as sigma_n_systematic.
//
// A field the residuals show (layout.detect_systematic,
// RefinementOptions::detect_systematic): matches off the rigid scene (a
// water surface's mirror image, a swimmer) have residuals far above the
// floor, part of which the fit absorbs into n. With x the estimated
// columns and c the field's, the gradient projected off what the fit
// absorbed,
//
//   u = g_c - M_cx M_xx^-1 g_x,   A = M_cc - M_cx M_xx^-1 M_xc,
//
// has Cov(u) = tau^2 A A + sigma^2 A for c ~ N(0, tau^2 I), so that
// without a field u^T A^+ u / sigma^2 is chi^2 with rank A degrees of
// freedom, and E[u^T A^+ u] = tau^2 trace A + sigma^2 rank A gives
//
//   tau^2 = (u^T A^+ u - sigma^2 rank A) / trace A.
//
// At p < 1 % (FrameConsistency::kInflationP: 1 % of clean data is widened
// needlessly) c takes the standard deviation max(systematic_px, tau): the
// random-effects model of the field (its absorbed part as large as the part
// the residuals show).
//
// Consistency of frames: with s_f = sum_{i in f} r_i dr_i/dn and
// G_f = sum_{i in f} (dr_i/dn)^2, frame f's own n is n_hat - s_f / G_f to
// first order, with variance sigma^2 / G_f, so
//
//   chi^2 = sum_f s_f^2 / (sigma^2 G_f),   F - 1 degrees of freedom
//
// tests whether the frames agree within their sigmas. Its upper tail
// probability is from the Wilson-Hilferty cube-root approximation (a few
// percent of the probability itself for 2 or more degrees of freedom, ample
// for a 1 % test). When p < 1 %, the frames disagree beyond pixel noise
// (correlated matches, a calibration error that acts differently at other
// depths) and the pixel-noise share of sigma_n is scaled by the Birge ratio
// sqrt(chi^2 / (F - 1)).
#ifndef RCM_ESTIMATION_CALIBRATION_PROPAGATION_H_
#define RCM_ESTIMATION_CALIBRATION_PROPAGATION_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rcm/camera/lens_models.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/geometry/calibration_uncertainty.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// Columns of j_i: n, w (3), dt (3), the lens parameters of each camera
// whose covariance the rig's calibration uncertainty has, the ports'
// parameters q (kNumPorts) when it has their covariance and the rig a
// thick port (a thin rig's residual is the thin port's, which has no port
// parameters: its port covariance is not propagated), then with a
// systematic error floor the kNumSystematic coefficients of the systematic
// residual field (the file comment), then with the focal scales estimated
// the two focal scales (e_l, e_r) of calibration_uncertainty.h's focal
// drift, each the combination g^T (d r / d lens) of its camera's lens
// columns, g = [fx, fy, 0, ...] of the calibration's lenses.
struct CalibrationParameterLayout {
  static constexpr int kN = 0;
  static constexpr int kRotation = 1;
  static constexpr int kTranslation = 4;
  static constexpr int kNumSystematic = 6;
  static constexpr int kNumFocal = 2;
  static constexpr int kNumPorts = CalibrationUncertainty::kNumPortParams;
  int num_left_lens = 0;
  int num_right_lens = 0;
  // kNumPorts or 0; with them, which of q carry variance (the others'
  // columns are left 0, not computed).
  int num_ports = 0;
  bool port_varies[CalibrationUncertainty::kNumPortParams] = {};
  // Standard deviation of each systematic coefficient, pixels; 0: none.
  double systematic_px = 0.0;
  // The systematic field's columns even without a floor, for its test on
  // the data (PropagateCalibration: a field the residuals show).
  bool detect_systematic = false;
  // The focal scales' columns (estimated under the focal drift prior).
  bool focal = false;
  // Each camera's calibrated focal lengths (fx, fy), for g.
  double left_focal[2] = {0.0, 0.0};
  double right_focal[2] = {0.0, 0.0};

  // The layout of `rig`: lens columns for the lens covariances it has, the
  // systematic field's when systematic_px > 0, and the focal scales' when
  // `estimate_focal` and the rig's uncertainty has a focal drift prior
  // (CalibrationUncertainty::focal_drift_sigma > 0) and both lenses'
  // columns.
  static CalibrationParameterLayout Of(const StereoRig& rig,
                                       double systematic_px = 0.0,
                                       bool estimate_focal = false,
                                       bool detect_systematic = false);
  int LeftLens() const { return 7; }
  int RightLens() const { return 7 + num_left_lens; }
  int Ports() const { return 7 + num_left_lens + num_right_lens; }
  int Systematic() const { return Ports() + num_ports; }
  int NumSystematic() const {
    return systematic_px > 0.0 || detect_systematic ? kNumSystematic : 0;
  }
  int Focal() const { return Systematic() + NumSystematic(); }
  int NumFocal() const { return focal ? kNumFocal : 0; }
  int Size() const { return Focal() + NumFocal(); }
};

// The sums M, g, C above, of a set of residuals. Fixed-capacity storage
// (no heap), so that the online estimators' memory stays constant.
struct LocusNormalEquations {
  static constexpr int kMaxSize = 7 + 2 * kMaxLensParams +
                                  CalibrationParameterLayout::kNumPorts +
                                  CalibrationParameterLayout::kNumSystematic +
                                  CalibrationParameterLayout::kNumFocal;
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0,
                               kMaxSize, kMaxSize>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSize, 1>;

  Matrix information;  // M
  Vector gradient;     // g
  // The affine model of each residual about x = (n, w, e) = 0: with x_i =
  // (n_i, w_i, e_i) where row i was taken (e_i the focal scales, with the
  // layout's focal columns), a_i = r_i - j_i[n, w, e] . x_i, so that
  // r_i(x) ~ a_i + j_i[n, w, e] . x. Sums over rows taken at different points
  // (frames, each linearized at its own estimate) then give the quadratic
  // model sum_i r_i(x)^2 ~ A + 2 intercept[n, w] . x + x^T M[n, w] x of
  // all of them (online_estimator.h).
  Vector gradient_intercept;       // sum_i a_i j_i
  double intercept_squares = 0.0;  // A = sum_i a_i^2
  double squared_residuals = 0.0;  // C
  int64_t count = 0;

  explicit LocusNormalEquations(int size = 7)
      : information(Matrix::Zero(size, size)),
        gradient(Vector::Zero(size)),
        gradient_intercept(Vector::Zero(size)) {}
  int size() const { return static_cast<int>(gradient.size()); }
  void Add(const LocusNormalEquations& other);
  // One row j with residual r and intercept a: M += j j^T (its lower
  // triangle only: symmetrize the sum after the last row), g += r j,
  // intercept += a j, A += a^2, C += r^2.
  void AddRow(const Vector& row, double r, double a);
};

// The unknowns self-calibrated beside n: cam1's rotation w (radians) and
// the focal scales e = (e_l, e_r) (relative), zero where not estimated.
using SelfCalibrationVector = Eigen::Matrix<double, 5, 1>;
inline SelfCalibrationVector SelfCalibrationOf(
    const Eigen::Vector3d& rotation,
    const Eigen::Vector2d& focal_scale = Eigen::Vector2d::Zero()) {
  SelfCalibrationVector x;
  x << rotation, focal_scale;
  return x;
}

// Sums over frames of their own estimates n_f (cam1's rotation and the
// focal scales held), for the consistency test of frames whose residuals
// are no longer at hand. With G_f = sum (dr/dn)^2 and b_f = sum dr/dn
// dr/dx of the frame's inliers (x = (w, e), SelfCalibrationVector), a
// frame's own estimate at the pooled x is n_f - b_f . x / G_f to first
// order, and
//
//   chi^2 = sum_f G_f (n_f - b_f . x / G_f - n)^2 / sigma^2
//
// expands into the sums kept here; the same test as the per-frame
// FrameConsistencyOf to first order.
struct FrameEstimateSums {
  using Matrix = Eigen::Matrix<double, 5, 5>;
  double s0 = 0.0;                                           // sum G_f
  double s1 = 0.0;                                           // sum G_f n_f
  double s2 = 0.0;                                           // sum G_f n_f^2
  SelfCalibrationVector b = SelfCalibrationVector::Zero();   // sum b_f
  SelfCalibrationVector bn = SelfCalibrationVector::Zero();  // sum b_f n_f
  Matrix bb = Matrix::Zero();  // sum b_f b_f^T / G_f
  int frames = 0;

  void Add(
      double n_f, double information,
      const SelfCalibrationVector& coupling = SelfCalibrationVector::Zero());
  // chi^2 sigma^2 above at (n, x).
  double WeightedSquares(double n, const SelfCalibrationVector& x) const;
};

// Adds the rows j_i of `matches[indices]` at (n, w) for `rig` in
// `layout` (CalibrationParameterLayout::Of(rig, ...)); `raw` are the
// correspondences they were prepared from, same indexing, for the lens and
// systematic columns. With the layout's focal columns, `rig` and `matches`
// are the calibration's lenses scaled by (1 + focal_scale) (the solution's)
// and the layout the calibration's. Residuals that are undefined at (n, w)
// or at a difference step are skipped. Per-frame sums (for the consistency
// test) go to `per_frame` when it is not null: one entry per distinct
// raw[i].frame, in order of first appearance. The rows are summed on up to
// `num_threads` threads, in an order that does not depend on their number.
void AccumulateLocusNormalEquations(
    const StereoRig& rig, const CalibrationParameterLayout& layout,
    const std::vector<StereoCorrespondence>& raw,
    const std::vector<PreparedCorrespondence>& matches,
    const std::vector<int64_t>& indices, double n,
    const Eigen::Vector3d& rotation, const Eigen::Vector2d& focal_scale,
    LocusNormalEquations* equations,
    std::vector<LocusNormalEquations>* per_frame = nullptr,
    int num_threads = 1);

// The self-calibration of cam1's rotation (and, with the layout's focal
// columns, of the focal scales) on the quadratic model of `equations`
// (their rows' affine models, gradient_intercept): the MAP estimate of
// x = (n, w[, e]) with the priors P_ww = rotation_covariance^-1 and
// P_ee = I / focal_sigma^2,
//
//   x = -(M[x] + diag(0, sigma^2 P))^-1 intercept[x],
//
// with sigma^2 = (A + 2 intercept . x + x^T M x) / (N - dim x) re-estimated
// from the model's residual (N = equations.count) until it settles (a
// few passes from `sigma_px`), and n held in [1, 2] (the rest then solved
// at the bound). Used by the online estimators (online_estimator.h); the
// batch refinement solves the nonlinear problem instead.
struct QuadraticSelfCalibration {
  double n = 1.0;
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  Eigen::Vector2d focal_scale = Eigen::Vector2d::Zero();
  double sigma_px = 0.0;
};
QuadraticSelfCalibration SelfCalibrateQuadratic(
    const LocusNormalEquations& equations,
    const CalibrationParameterLayout& layout,
    const Eigen::Matrix3d& rotation_covariance, double focal_sigma,
    double sigma_px);

// How cam1's rotation w is treated.
enum class RotationMode {
  kHeld,   // w = 0, its uncertainty propagated
  kPrior,  // estimated with the calibration's rotation covariance as prior
  kFree,   // estimated without a prior (--refine-rotation)
};

// "held", "self-calibrated" or "free": the mode's name in reports (rcm
// estimate's JSON, the Python result's calibration dict).
const char* RotationModeName(RotationMode mode);

// The frames' agreement (the file comment).
struct FrameConsistency {
  int frames = 0;  // with information on n
  double chi_squared = 0.0;
  int dof = 0;           // frames - 1
  double p_value = 1.0;  // upper tail probability of chi_squared
  // sqrt(chi^2 / dof) when p_value < kInflationP, else 1.
  double inflation = 1.0;
  static constexpr double kInflationP = 0.01;
};

// From the per-frame sums of AccumulateLocusNormalEquations at the
// solution; nullopt for fewer than two frames with information on n.
std::optional<FrameConsistency> FrameConsistencyOf(
    const std::vector<LocusNormalEquations>& per_frame, double sigma_px);
// From the frames' own estimates at the pooled n and x = (w, e) (zero
// where held); nullopt for fewer than two frames.
std::optional<FrameConsistency> FrameConsistencyOf(
    const FrameEstimateSums& sums, double n, double sigma_px,
    const SelfCalibrationVector& x = SelfCalibrationVector::Zero());
// P(chi^2_dof > chi_squared), Wilson-Hilferty; dof >= 1.
double ChiSquaredUpperTail(double chi_squared, int dof);

struct CalibrationPropagation {
  RotationMode mode = RotationMode::kHeld;
  std::string source;  // CalibrationUncertainty::source
  // sigma_n = sqrt(noise^2 + calibration^2); noise after the consistency
  // test's inflation.
  double sigma_n = 0.0;
  double sigma_n_noise = 0.0;
  double sigma_n_calibration = 0.0;
  // Of sigma_n_calibration^2: the estimated rotation's prior share and the
  // held parameters' (w when held, dt, lenses, ports). The lenses' share counts
  // their correlation with the extrinsics, when the calibration measured
  // one, and is then negative where the extrinsics fitted through the
  // lenses cancel more than the lenses add.
  double variance_rotation = 0.0;
  double variance_translation = 0.0;
  double variance_lenses = 0.0;
  // The held ports' share, with their correlation with the extrinsics and
  // the lenses (an air gap fitted with the translation: negative where the
  // two cancel more than the ports add).
  double variance_ports = 0.0;
  // With a prior on n (RefinementOptions::n_prior): its share, part of
  // sigma_n_calibration^2 (the medium's uncertainty).
  double variance_medium = 0.0;
  // The systematic residual field's share, sigma_n_systematic^2: part of
  // sigma_n, reported apart from the calibration's.
  double variance_systematic = 0.0;
  double sigma_n_systematic = 0.0;
  // The systematic field the residuals show (layout.detect_systematic): its
  // test statistic u^T A^+ u / sigma^2 with its degrees of freedom and upper
  // tail probability, and the coefficients' standard deviation estimated
  // from it (0 unless p < FrameConsistency::kInflationP and it is above
  // 1e-6 px, rounding), which replaces systematic_px when larger.
  double systematic_chi_squared = 0.0;
  int systematic_dof = 0;
  double systematic_p_value = 1.0;
  double systematic_detected_px = 0.0;
  // dn/dw and dn/dt with everything but n held (per radian, per meter).
  Eigen::Vector3d dn_drotation = Eigen::Vector3d::Zero();
  Eigen::Vector3d dn_dtranslation = Eigen::Vector3d::Zero();
  // Observability of w from the data alone (the file comment).
  double rotation_multiple_correlation = 0.0;
  double rotation_sigma_inflation = 1.0;
  // With w estimated: its covariance (radians^2; every term above) and the
  // correlation of each component with n.
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rotation_correlation_with_n = Eigen::Vector3d::Zero();
  // With the focal scales estimated (the layout's focal columns): their
  // covariance (relative^2) and correlations with n. Their prior's share
  // is part of variance_lenses.
  bool focal_estimated = false;
  Eigen::Matrix2d focal_scale_covariance = Eigen::Matrix2d::Zero();
  Eigen::Vector2d focal_scale_correlation_with_n = Eigen::Vector2d::Zero();
};

// The propagation above from the sums at the solution. `noise_inflation`
// (>= 1) scales the pixel-noise share. `n_prior_sigma` > 0: n has the
// prior N(., n_prior_sigma^2) (RefinementOptions::n_prior), in P as w's
// prior is: P_nn = 1 / n_prior_sigma^2, its share variance_medium. Fails
// when the information on the estimated parameters is singular (w free and
// not separable from n).
StatusOr<CalibrationPropagation> PropagateCalibration(
    const LocusNormalEquations& equations,
    const CalibrationParameterLayout& layout,
    const CalibrationUncertainty& uncertainty, RotationMode mode,
    double sigma_px, double noise_inflation = 1.0, double n_prior_sigma = 0.0);

}  // namespace rcm

#endif  // RCM_ESTIMATION_CALIBRATION_PROPAGATION_H_
