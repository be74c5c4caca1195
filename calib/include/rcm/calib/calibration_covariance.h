// What `rcm calibrate` writes beside the camchain so that the estimators
// know how well it is known (rcm/io/calibration_covariance_file.h): the
// covariance of each lens and of cam1_from_cam0 from the bundle adjustment,
// made honest by the leave-out spread, and the drift prior the rig may
// move by after it.
//
// The covariance assumes independent corner noise; a leave-views-out
// spread above it (cross_validation.h) says the corners' errors are
// correlated within views (board flatness, blur, lens-model error). Each
// block is therefore scaled by
//
//   s^2,  s = max(1, max_q sigma_jackknife,q / sigma_covariance,q)
//
// over the quantities that measure it: fx, fy, cx, cy of a camera for its
// lens block, the baseline for the extrinsics (correlations are kept).
// Without a cross-validation the covariance is written as computed.
#ifndef RCM_CALIB_CALIBRATION_COVARIANCE_H_
#define RCM_CALIB_CALIBRATION_COVARIANCE_H_

#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/cross_validation.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::calib {

// The sidecar of an air calibration: medium "air", the default drift
// prior (CalibrationUncertainty::kDefaultDriftDegrees, ...Millimeters),
// the lens and extrinsics covariances scaled as above (one camera,
// CalibrateMono's: cam0's lens block only).
CalibrationCovarianceFile AirCalibrationCovariance(
    const StereoCalibration& calibration,
    const std::optional<CrossValidation>& cross_validation);

// The factor s above of a camera (0, 1) or of the baseline (camera = 2);
// 1 without a cross-validation.
double LeaveOutScale(const std::optional<CrossValidation>& cross_validation,
                     int camera);

// The names of the blocks of UnderwaterCovariance that make the held
// geometry h below, in its order: cam1_from_cam0, then each camera's
// air_gap and port_tilt (those present).
std::vector<std::string> HeldGeometryBlocks(
    const UnderwaterCalibration& result);

// How much wider than the covariance the leave-views-out replicates spread
// the held geometry h (below), as one factor s^2 >= 1: with C the
// covariance of h given the lenses (the fit's marginal, conditioned on the
// lens blocks when the lenses were estimated; the replicates hold them) and
// J the replicates' jackknife covariance (UnderwaterLeaveOut::covariance),
//
//   s^2 = max(1, trace(C^+ J) / rank C),
//
// the mean squared whitened spread (C^+ in correlation form, directions
// below 1e-12 of the largest dropped). One factor keeps the covariance's
// shape: the fit trades an air gap against the translation and a port's
// tilt against cam1's rotation, and a target-free estimate holds all of them,
// so their errors largely cancel in what they do to n; per-component
// factors would break that cancellation (a factor 3 on the rotation, 1 on
// the tilt) and claim errors of n that the rig does not have. 1 without a
// leave-out.
double GeometryLeaveOutScale(const UnderwaterCalibration& result);

// The sidecar of an underwater calibration: medium water, no drift prior
// (the extrinsics and the lenses were measured in this dive), and the
// joint covariance of the held geometry h and the lenses: the lenses' from
// the joint fit (air views given) or from the air rig's
// calibration_uncertainty() when it has one; h = [w; dt; q], the
// extrinsics' change and, when the calibration estimated them, the ports'
// parameters (calibration_uncertainty.h), with G from the bundle
// adjustment, its covariance with the lenses X (UnderwaterCalibration::
// extrinsics_lens_covariance, port_lens_covariance) and the lenses' share
// of its own. h's covariance given the lenses, G_h|L (ConditionalCovariance),
// is widened to the leave-out spread (GeometryLeaveOutScale, s^2), the
// lenses' share and X kept as the fit has them:
//
//   G' = s^2 G_h|L + (G - G_h|L),   X' = X,
//
// positive semi-definite with the lenses' block (its Schur complement is
// s^2 G_h|L). Scaling X too would claim a response of h to a lens error
// that the rig does not have, which a target-free estimate then counts as
// an error of n. Without X, G' = s^2 G. The ports' rows go to the file's
// `ports` block. One camera: the air calibration's extrinsics and their
// uncertainty are kept. An air gap estimated under water trades against
// the translation along the axis, so that given the ports the translation
// is known far better than its marginal says; the estimators that hold
// both carry them jointly (calibration_propagation.h).
CalibrationCovarianceFile UnderwaterCalibrationCovariance(
    const UnderwaterCalibration& result, const StereoRig& air_rig);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_COVARIANCE_H_
