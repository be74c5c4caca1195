// An estimate of n against the medium the rig dived in (medium_prior.h),
// and what the medium says of the rig: cam1's rotation since the
// calibration, estimated with n under the medium's prior.
//
// A rig that turned by w since its calibration moves the refractive
// epipolar loci as a change of n does; with a narrow field at one depth
// the two are nearly collinear (calibration_propagation.h, R ~ 0.99), so
// neither n alone nor the drift prior can tell them apart, and n comes out
// biased with a small sigma. The medium's physics adds what the images
// lack: with n ~ N(medium.n, medium.sigma^2) in the least squares and w
// free (no drift prior), the data give w, within its sigma, at every field
// of view:
//
//   min_{n, w} sum_i r_i(n, w)^2 + sigma_px^2 (n - medium.n)^2 / medium.sigma^2
//
// The estimate of n stays the data's own; this is the check beside it.
#ifndef RCM_ESTIMATION_MEDIUM_DRIFT_H_
#define RCM_ESTIMATION_MEDIUM_DRIFT_H_

#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/medium_prior.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// Beyond this many of its sigmas a rotation since the calibration says the
// camchain is stale (3: a 0.3 % tail).
inline constexpr double kMediumDriftSigmas = 3.0;

struct MediumDrift {
  // The refinement with the medium's prior on n and cam1's rotation free.
  RefinementSummary assuming_medium;
  // |w| and its standard deviation (sqrt(w^T C_w w) / |w|), radians.
  double angle = 0.0;
  double sigma_angle = 0.0;
  // angle > kMediumDriftSigmas sigma_angle.
  bool turned = false;
  // "assuming sea water (...), cam1 has turned by 0.52 +- 0.04 deg since
  // the calibration, about (x, y, z)".
  std::string message;
};

// Fails as RefineRefractiveIndex does, and for a thick port (the prior is
// for thin ports). `options` are the estimate's own (refine_rotation and
// n_prior are set here).
StatusOr<MediumDrift> EstimateDriftAssumingMedium(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences,
    const RefinementOptions& options, const MediumPrior& medium);

}  // namespace rcm

#endif  // RCM_ESTIMATION_MEDIUM_DRIFT_H_
