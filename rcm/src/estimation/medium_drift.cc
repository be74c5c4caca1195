#include "rcm/estimation/medium_drift.h"

#include <algorithm>
#include <cmath>

#include "rcm/util/number_format.h"

namespace rcm {

StatusOr<MediumDrift> EstimateDriftAssumingMedium(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    const RefinementOptions& options, const MediumPrior& medium) {
  RefinementOptions with_medium = options;
  with_medium.refine_rotation = true;
  with_medium.min_inliers = std::max(with_medium.min_inliers, 5);
  with_medium.n_prior = IndexPrior{medium.n, medium.sigma};
  StatusOr<RefinementSummary> summary =
      RefineRefractiveIndex(rig, correspondences, with_medium);
  if (!summary.ok()) {
    return summary.status().WithContext("cam1's rotation assuming " +
                                        medium.name);
  }
  if (!summary->rotation || !summary->calibration) {
    return Status::Error("cam1's rotation assuming " + medium.name +
                         ": not estimated");
  }
  MediumDrift drift;
  const Eigen::Vector3d w = summary->rotation->angle_axis;
  const Eigen::Matrix3d covariance = summary->calibration->rotation_covariance;
  drift.angle = w.norm();
  drift.sigma_angle =
      drift.angle > 0.0
          ? std::sqrt(std::max(0.0, w.dot(covariance * w))) / drift.angle
          : std::sqrt(std::max(0.0, covariance.trace() / 3.0));
  drift.turned = drift.angle > kMediumDriftSigmas * drift.sigma_angle;
  const double degrees = 180.0 / M_PI;
  const Eigen::Vector3d axis = drift.angle > 0.0
                                   ? Eigen::Vector3d(w / drift.angle)
                                   : Eigen::Vector3d::Zero();
  drift.message = "assuming " + medium.name + ", cam1 has turned by " +
                  FormatFixed(drift.angle * degrees, 3) + " +- " +
                  FormatFixed(drift.sigma_angle * degrees, 3) +
                  " deg since the calibration, about (" +
                  FormatFixed(axis.x(), 2) + ", " + FormatFixed(axis.y(), 2) +
                  ", " + FormatFixed(axis.z(), 2) + ")";
  drift.assuming_medium = *std::move(summary);
  return drift;
}

}  // namespace rcm
