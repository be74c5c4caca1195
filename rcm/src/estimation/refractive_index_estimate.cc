#include "rcm/estimation/refractive_index_estimate.h"

namespace rcm {
namespace {

void SetEstimateRigFields(const StereoRig& rig,
                          RefractiveIndexEstimate* estimate) {
  estimate->port = rig.HasThickPort() ? "thick" : "thin";
  if (rig.calibration_uncertainty()) {
    estimate->rotation_prior_covariance =
        rig.calibration_uncertainty()->RotationPriorCovariance();
  }
}

}  // namespace

RefractiveIndexEstimate EstimateFromRefinement(
    const StereoRig& rig, const RefinementSummary& summary,
    const std::optional<AirGapEstimate>& air_gap) {
  RefractiveIndexEstimate estimate;
  estimate.estimator = "refine";
  SetEstimateRigFields(rig, &estimate);
  estimate.n = summary.n;
  estimate.sigma_n = summary.sigma_n;
  estimate.sigma_n_noise = summary.sigma_n_noise;
  estimate.sigma_n_calibration = summary.sigma_n_calibration;
  estimate.sigma_n_systematic = summary.sigma_n_systematic;
  estimate.crlb = summary.crlb;
  estimate.sigma_px = summary.sigma_px;
  estimate.n_closed_form = summary.n_closed_form;
  estimate.inliers = static_cast<int64_t>(summary.inliers.size());
  estimate.invalid = summary.num_invalid;
  estimate.correspondences = summary.num_correspondences;
  estimate.calibration = summary.calibration;
  estimate.consistency = summary.consistency;
  estimate.rotation = summary.rotation;
  estimate.focal = summary.focal;
  estimate.air_gap = air_gap;
  estimate.n_seed = summary.n_seed;
  estimate.n_robust = summary.n_robust;
  estimate.cost = summary.cost;
  estimate.iterations = summary.num_iterations;
  return estimate;
}

RefractiveIndexEstimate EstimateFromPooled(const StereoRig& rig,
                                           const PooledLocusEstimate& pooled) {
  RefractiveIndexEstimate estimate;
  SetEstimateRigFields(rig, &estimate);
  estimate.n = pooled.n;
  estimate.sigma_n = pooled.sigma_n;
  estimate.sigma_n_noise = pooled.sigma_n_noise;
  estimate.sigma_n_calibration = pooled.sigma_n_calibration;
  estimate.sigma_n_systematic = pooled.sigma_n_systematic;
  estimate.crlb = pooled.crlb;
  estimate.sigma_px = pooled.sigma_px;
  estimate.inliers = pooled.inliers;
  estimate.calibration = pooled.calibration;
  estimate.consistency = pooled.consistency;
  // The self-calibrated rotation and focal scales, with their sigmas and
  // correlations from the propagation's covariance (always with the drift
  // prior: the pooled estimators self-calibrate from it).
  if (pooled.rotation && pooled.calibration) {
    const StatusOr<StereoRig> turned = rig.WithCam1Moved(*pooled.rotation);
    estimate.rotation = RotationCorrectionOf(
        *pooled.calibration, *pooled.rotation, /*with_prior=*/true,
        turned.ok() ? turned->right_from_left() : rig.right_from_left());
  }
  if (pooled.focal_scale && pooled.calibration &&
      pooled.calibration->focal_estimated) {
    const CalibrationPropagation& p = *pooled.calibration;
    FocalScaleCorrection focal;
    focal.scale = *pooled.focal_scale;
    focal.sigma = p.focal_scale_covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    focal.correlation_with_n = p.focal_scale_correlation_with_n;
    estimate.focal = focal;
  }
  return estimate;
}

}  // namespace rcm
