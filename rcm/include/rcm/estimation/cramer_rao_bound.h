// The Cramer-Rao bound of n from a set of correspondences (docs/design.md,
// "The estimator of record"), as a standard deviation:
//
//   crlb = sigma_px / sqrt(sum_i (dr_i/dn)^2),
//
// r_i the Sampson coplanarity residual in pixels
// (sampson_coplanarity_error.h), whose first-order variance under pixel
// noise sigma_px on the four coordinates is sigma_px^2; the extrinsics are
// taken as known. Evaluated at the true n on exact correspondences it is
// the bound that an unbiased estimator's RMSE cannot beat (to first order).
#ifndef RCM_ESTIMATION_CRAMER_RAO_BOUND_H_
#define RCM_ESTIMATION_CRAMER_RAO_BOUND_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm {

// sum_i (dr_i/dn)^2 at n, the Fisher information of n times sigma_px^2.
// Matches whose residual is undefined contribute nothing.
double LocusInformation(const Eigen::Matrix3d& essential,
                        const std::vector<PreparedCorrespondence>& matches,
                        double n);

// crlb above; nullopt when no correspondence can be undistorted or the
// information is zero (n unobservable from these correspondences).
std::optional<double> CramerRaoBoundN(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences, double n,
    double sigma_px);

}  // namespace rcm

#endif  // RCM_ESTIMATION_CRAMER_RAO_BOUND_H_
