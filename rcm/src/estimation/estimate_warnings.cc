#include "rcm/estimation/estimate_warnings.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "rcm/util/number_format.h"

namespace rcm {
namespace {

constexpr double kWarningDegreesPerRadian = 180.0 / M_PI;

}  // namespace

std::vector<std::string> EstimateWarnings(
    const RefractiveIndexEstimate& estimate) {
  std::vector<std::string> warnings;
  const std::optional<CalibrationPropagation>& calibration =
      estimate.calibration;
  if (estimate.rotation && calibration && estimate.rotation_prior_covariance) {
    const RotationCorrection& rotation = *estimate.rotation;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(
        *estimate.rotation_prior_covariance);
    if (rotation.with_prior && ldlt.info() == Eigen::Success) {
      const double sigmas =
          std::sqrt(rotation.angle_axis.dot(ldlt.solve(rotation.angle_axis)));
      if (sigmas > kStaleRotationSigmas) {
        warnings.push_back(
            "the calibration is stale: cam1 has turned by " +
            FormatFixed(rotation.angle_axis.norm() * kWarningDegreesPerRadian,
                        3) +
            " deg since it was made (" + FormatFixed(sigmas, 1) +
            " drift-prior sigmas); n is self-calibrated with the rotation, "
            "but for the best n calibrate in the water (rcm calibrate "
            "--underwater) and estimate with that camchain");
      }
    }
    if (!rotation.with_prior &&
        rotation.multiple_correlation_with_n > kHardlySeparableCorrelation) {
      warnings.push_back(
          "n and cam1's rotation are hardly separable in these data "
          "(correlation R = " +
          FormatFixed(rotation.multiple_correlation_with_n, 3) +
          "): sigma_n says so, " +
          FormatFixed(calibration->rotation_sigma_inflation, 1) +
          "x its value with the rotation known; calibrate in the water (rcm "
          "calibrate --underwater) for a better n");
    }
  }
  // The lenses' possible change since the calibration (the focal drift
  // prior of an air calibration) is most of a sigma_n too wide to use.
  // (A share above the whole sigma_n^2 is one that the held parameters
  // fitted with the lenses cancel, not most of it.)
  const double sigma_n = estimate.sigma_n;
  if (calibration && sigma_n > kWideSigmaN &&
      calibration->variance_lenses > 0.5 * sigma_n * sigma_n &&
      calibration->variance_lenses <= sigma_n * sigma_n) {
    warnings.push_back(
        "sigma_n " + FormatFixed(sigma_n, 3) + " is mostly the lenses' (" +
        FormatFixed(std::sqrt(calibration->variance_lenses), 3) +
        "): these data cannot tell a change of the focal lengths since the "
        "calibration (" +
        calibration->source +
        ") from n; calibrate in the water (rcm calibrate --underwater, with "
        "the air views: --air-left/--air-right) for a better n");
  }
  if (calibration && calibration->systematic_detected_px > 0.0) {
    const CalibrationPropagation& p = *calibration;
    warnings.push_back(
        "the residuals show a smooth field beyond the pixel noise (chi2 " +
        FormatFixed(p.systematic_chi_squared, 1) + " for " +
        std::to_string(p.systematic_dof) + " dof, " +
        FormatFixed(p.systematic_detected_px, 3) +
        " px per coefficient): matches off the rigid scene (a water "
        "surface's mirror image, a swimmer, particles) or a lens model's "
        "error; sigma_n counts it (matches' systematic error " +
        FormatFixed(p.sigma_n_systematic, 4) +
        "); matches of the rigid scene only (--matches) give a better n");
  }
  if (estimate.consistency && estimate.consistency->inflation > 1.0) {
    const FrameConsistency& c = *estimate.consistency;
    warnings.push_back(
        "the frames disagree beyond their sigmas (chi2 " +
        FormatFixed(c.chi_squared, 1) + " for " + std::to_string(c.dof) +
        " dof): sigma_n's pixel-noise share is inflated x" +
        FormatFixed(c.inflation, 2) +
        " (matches correlated over frames, or a calibration error that "
        "acts differently at other depths)");
  }
  return warnings;
}

}  // namespace rcm
