// Refinement of the refractive index n for a rig whose housings have an
// air gap and glass (flat_port_geometry.h): the estimator of record
// (batch_refinement.h) with the locus residual generalized to the
// non-central rays of a thick port (generalized_epipolar_error.h), and
// optionally the air gap estimated with n.
//
// Stages, as for the thin port:
//   seed:    the minimum of the robust cost over a scan of [1, 2]
//            (options.base.num_scan_points);
//   stage 1: min sum_i rho(r_i(n, g)^2) over all matches (Ceres, robust);
//   stage 2: min sum_{inliers} r_i(n, g)^2, |r_i| <= inlier threshold;
// with g the air-gap offset added to both ports' gaps when
// options.estimate_air_gap (else 0). When the rig's calibration carries a
// rotation covariance (a drift prior or a measured one) and
// base.self_calibrate_rotation, cam1's rotation correction w is estimated
// with n under that prior, as for the thin port (batch_refinement.h,
// r_i(n, g, w), generalized_epipolar_error.h), and sigma_n splits as
// there (calibration_propagation.h, RotationMode::kPrior); not together
// with the air gap (then w is held and its uncertainty propagated). A
// tilted port is the case that needs it: its tilt and cam1's rotation,
// both fitted under water, trade against each other, so that w held at
// the calibration's carries its whole marginal uncertainty into n, while
// the data pin the combination the loci see. Uncertainty from stage 2:
//   sigma_px^2 = sum r_i^2 / (N - p),   cov = sigma_px^2 (J^T J)^-1,
//   crlb = sigma_px / sqrt(sum_i (dr_i/dn)^2)   (port known).
// The air gap and n are strongly correlated (a larger gap shifts every ray
// sideways, which the loci partly read as a smaller n; docs/thin_port_bias.md's
// thin-port table): estimating the gap costs precision in n, reported as the
// correlation and as sigma_n against crlb.
#ifndef RCM_ESTIMATION_THICK_PORT_REFINEMENT_H_
#define RCM_ESTIMATION_THICK_PORT_REFINEMENT_H_

#include <optional>
#include <vector>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct ThickPortRefinementOptions {
  // Loss, thresholds, scan, iterations, threads and the rotation's
  // self-calibration, as for the thin port. refine_rotation (w without a
  // prior) is not supported with a thick port (Check fails).
  RefinementOptions base;
  // Estimate an offset of the air gap (the same for both cameras) with n.
  bool estimate_air_gap = false;

  Status Check() const;
};

struct AirGapEstimate {
  // The estimated gaps of the two ports, meters.
  double left_air_gap = 0.0;
  double right_air_gap = 0.0;
  // Standard deviation of the gap offset, meters, and its correlation
  // with n.
  double sigma = 0.0;
  double correlation_with_n = 0.0;
};

struct ThickPortRefinementSummary {
  // n, sigma_n, crlb, sigma_px, n_seed, n_robust, costs, inliers, counts
  // and the rotation correction (when self-calibrated) as for the thin
  // port (n_closed_form unset).
  RefinementSummary refinement;
  // With options.estimate_air_gap.
  std::optional<AirGapEstimate> air_gap;
};

// Errors: invalid options or ports; too few usable matches or inliers;
// data that do not observe n; a failed solve or singular covariance
// (with the air gap: n and the gap not separable on these data).
StatusOr<ThickPortRefinementSummary> RefineRefractiveIndexThickPort(
    const StereoRig& rig, const FlatPort& left_port, const FlatPort& right_port,
    const std::vector<StereoCorrespondence>& correspondences,
    const ThickPortRefinementOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_THICK_PORT_REFINEMENT_H_
