// Options shared by the refractive-index estimators of record: the batch
// refinement (batch_refinement.h), the online estimator and its sliding
// window. All fit n to the Sampson coplanarity residual
// (sampson_coplanarity_error.h) in two stages:
//
//   1. robust: minimize sum rho(r_i(n)^2) over n in [1, 2], seeded by a
//      coarse scan of the whole interval (so the solver cannot start in
//      the basin of a wrong minimum);
//   2. least squares on the inliers |r_i| <= inlier_threshold_px at the
//      robust estimate, whose covariance gives sigma_n.
//
// Stage 2 makes the estimate efficient (plain least squares is the
// first-order maximum-likelihood estimate under Gaussian pixel noise) and
// its sigma honest; stage 1 keeps outliers out of it.
#ifndef RCM_ESTIMATION_REFINEMENT_OPTIONS_H_
#define RCM_ESTIMATION_REFINEMENT_OPTIONS_H_

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/solver.h>

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string_view>

#include "rcm/util/status.h"

namespace rcm {

// Ceres' conventions, s = r^2 and c = the scale:
//   kNone:   rho(s) = s
//   kHuber:  rho(s) = s for s <= c^2, 2 c sqrt(s) - c^2 beyond
//   kCauchy: rho(s) = c^2 log(1 + s / c^2)
enum class RobustLoss { kNone, kHuber, kCauchy };

// "none", "huber", "cauchy".
std::string_view RobustLossName(RobustLoss loss);
std::optional<RobustLoss> RobustLossFromName(std::string_view name);

// rho(s) above.
double RobustLossRho(RobustLoss loss, double scale, double squared_residual);

// The loss's square root as a residual, for a cost that holds many
// residuals in one Ceres block (sampson_coplanarity_cost_function.h):
//
//   psi(r) = sign(r) sqrt(rho(r^2)),   psi'(r) = rho'(r^2) r / psi(r),
//
// so that psi^2 = rho(r^2) and psi is smooth through r = 0 (psi'(0) = 1):
//   kNone:   psi = r, psi' = 1;
//   kHuber:  psi = r for |r| <= c, sign(r) sqrt(2 c |r| - c^2) beyond,
//            where psi' = c / |psi|;
//   kCauchy: psi = r sqrt(h), h = log(1 + x) / x, x = r^2 / c^2 (h = 1 at
//            x = 0), psi' = 1 / ((1 + x) sqrt(h)).
void RobustLossRoot(RobustLoss loss, double scale, double residual,
                    double* root, double* slope);

// A Gaussian prior on n: N(n, sigma^2) (medium_prior.h gives the water's).
struct IndexPrior {
  double n = 0.0;
  double sigma = 0.0;
};

struct RefinementOptions {
  // Loss of stage 1.
  RobustLoss loss = RobustLoss::kCauchy;
  // Its scale, in pixels of Sampson distance; > 0. About twice the pixel
  // noise of good features, where Cauchy keeps ~95 % of the efficiency of
  // least squares.
  double loss_scale_px = 1.0;
  // Inlier threshold of stage 2, in pixels; > 0, +inf keeps every match.
  // Four times a 0.5 px noise: it drops about 1 in 16000 true matches.
  double inlier_threshold_px = 2.0;
  // Points of the coarse scan of [1, 2] that seeds stage 1; >= 3. The
  // default spacing 0.02 is finer than the width of the robust cost's
  // basin (loss scale / slope of r in n, about 0.1 for 1 px at 10 px per
  // unit of n).
  int num_scan_points = 51;
  // Fewest inliers accepted; >= 2 (one more than the parameters, so that
  // the pixel noise can be estimated), at least 5 with the rotation.
  int min_inliers = 10;
  // The data must observe n: refuse when the Cramer-Rao bound at 1 px of
  // pixel noise exceeds this. At 0.1 the data could not tell water (1.33)
  // from air (1.0) at 3 sigma; matches on the image axes, or few and far
  // away, are refused with a message instead of giving a number. > 0.
  double max_crlb_per_px = 0.1;
  // Also estimate a small rotation correction of cam1_from_cam0 without a
  // prior (batch only; see batch_refinement.h for when it is
  // identifiable).
  bool refine_rotation = false;
  // Self-calibration of the drift (batch_refinement.h): when the rig's
  // calibration uncertainty (StereoRig::calibration_uncertainty) gives
  // cam1's rotation a covariance, estimate that rotation with n, with the
  // covariance as its prior. Where the data separate the rotation from n
  // they decide it; where they do not, the prior does, and sigma_n carries
  // it. false: the rotation is held at the calibration's and its
  // uncertainty only propagated into sigma_n. Ignored with refine_rotation.
  bool self_calibrate_rotation = true;
  // Self-calibration of lenses that changed: when the rig's calibration
  // uncertainty has a focal drift prior (CalibrationUncertainty::
  // focal_drift_sigma > 0, the default of an air calibration), estimate
  // each camera's focal scale (1 + e) with n, the prior N(0, s_f^2) on each
  // e (batch_refinement.h). false: the focal lengths are held at the
  // calibration's and the prior only propagated into sigma_n. Thin ports:
  // the batch refinement, and the online estimators (with
  // self_calibrate_rotation, on the frames' quadratic models); the thick
  // port's refinement propagates it.
  bool self_calibrate_focal = true;
  // A systematic error floor of the matches, pixels, >= 0
  // (calibration_propagation.h): the standard deviation of each
  // coefficient of a smooth field of low order added to every residual,
  // which no number of matches averages away; propagated into sigma_n
  // (sigma_n_systematic). 0 (the default): the residuals' errors are
  // independent, as simulated matches' are. rcm estimate gives matches of
  // its image front end 0.03 px.
  double systematic_px = 0.0;
  // Test the residuals for that field and, where they show one (p < 1 %),
  // widen sigma_n by the field the data estimate (calibration_propagation.h,
  // systematic_detected_px): matches off the rigid scene (a surface's
  // mirror image, a swimmer) bias n by more than their pixel noise says.
  // Off by default (simulated matches have no field, and a rendered front
  // end's own field is the floor's); rcm estimate turns it on
  // (--detect-systematic).
  bool detect_systematic = false;
  // A prior on n from the physics of the medium (medium_prior.h, rcm
  // estimate --medium), batch refinement of thin ports only: the term
  // (sigma_px (n - prior.n) / prior.sigma)^2 joins the least squares as
  // cam1's rotation prior does, and its share of sigma_n is reported
  // (CalibrationPropagation::variance_medium). Where the data cannot tell n
  // from cam1's rotation (a narrow field at one depth) it is what makes
  // the rotation observable. Unset (the default): n is the free unknown.
  std::optional<IndexPrior> n_prior;
  // Where the normal equations (and the uncertainty reported from them)
  // are taken with cam1's rotation self-calibrated: at this rotation
  // correction (angle-axis, radians) instead of the solution's, for a
  // caller that pools frames' rows at one point (FitFrame's linearization
  // rotation); the solution is the same. Unset (the default): at the
  // solution. Finite.
  std::optional<Eigen::Vector3d> rows_at_rotation;
  // Solver iterations per stage; >= 1.
  int max_num_iterations = 100;
  // Threads for evaluating residuals; >= 1.
  int num_threads = 2;

  Status Check() const;
};

// The Ceres solver settings of both refinements (batch_refinement.h,
// thick_port_refinement.h): dense QR, options' iterations and threads,
// silent, and tight tolerances: one parameter (or a few) and cheap
// iterations, and the noise-free case must reach 1e-9 in n.
ceres::Solver::Options RefinementSolverOptions(
    const RefinementOptions& options);

// Ok unless n is pinned at the upper bound of [1, 2], which no medium
// reaches: within max(1e-6, sigma_n) of 2, so that the data cannot tell
// it from the bound. Then the one-line failure that names the likely
// causes (the rig moved since its calibration, a wrong rig file) and the
// remedies (rcm calibrate --underwater, --refine-rotation); an n more
// than 0.05 below 2 whose sigma reaches the bound gets one that says the
// data cannot pin n (its sigma is the calibration's). The lower bound
// stays a valid answer (air).
Status CheckNotPinnedAtUpperBound(double n, double sigma_n = 0.0);

// A new Ceres loss of `loss` with scale `scale_px` (owned by the problem
// it is given to); nullptr for kNone (least squares).
ceres::LossFunction* NewLossFunction(RobustLoss loss, double scale_px);

// The prior of cam1's rotation correction w (self_calibrate_rotation) as
// a Ceres residual in pixels: with the prior's covariance Sigma = L L^T
// (Cholesky, positive definite) and the pixel noise sigma_px,
//   |sigma_px L^-1 w|^2 = sigma_px^2 w^T Sigma^-1 w,
// the prior's negative log-likelihood in the units of the locus
// residuals' sum of squares. Owned by the problem it is given to.
ceres::CostFunction* NewRotationPrior(const Eigen::Matrix3d& covariance,
                                      double sigma_px);

// Stage 2 of both refinements with priors in pixels of residual
// (NewRotationPrior, the prior on n): a prior's weight needs the data's
// pixel noise, so `solve(prior_sigma_px)` (a Status; it solves with the
// priors weighted by prior_sigma_px) runs first at the data's sigma at the
// start, `data_sigma_px()`, then again at the solution's, until the two
// agree within 2 % (at most 3 solves; two or three in practice). Without
// a prior, one solve (prior_sigma_px 0). `*sigma_px` is the data's sigma
// at the last solution.
template <typename Solve, typename DataSigma>
Status SolveUntilThePriorWeightSettles(bool with_prior, const Solve& solve,
                                       const DataSigma& data_sigma_px,
                                       double* sigma_px) {
  constexpr int kMaxSolves = 3;
  constexpr double kTolerance = 0.02;  // relative
  double prior_sigma_px = with_prior ? data_sigma_px() : 0.0;
  for (int solves = 1;; ++solves) {
    RCM_RETURN_IF_ERROR(solve(prior_sigma_px));
    *sigma_px = data_sigma_px();
    if (!with_prior || solves >= kMaxSolves ||
        std::abs(*sigma_px - prior_sigma_px) <= kTolerance * *sigma_px) {
      return Status::Ok();
    }
    prior_sigma_px = *sigma_px;
  }
}

}  // namespace rcm

#endif  // RCM_ESTIMATION_REFINEMENT_OPTIONS_H_
