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

#include "rcm/calib/cross_validation.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/geometry/stereo_rig.h"
#include "rcm/io/calibration_covariance_file.h"

namespace rcm::calib {

// The sidecar of an air calibration: medium "air", the default drift
// prior (CalibrationUncertainty::kDefaultDriftDegrees, ...Millimeters),
// the lens and extrinsics covariances scaled as above.
CalibrationCovarianceFile AirCalibrationCovariance(
    const StereoCalibration& calibration,
    const std::optional<CrossValidation>& cross_validation);

// The factor s above of a camera (0, 1) or of the baseline (camera = 2);
// 1 without a cross-validation.
double LeaveOutScale(const std::optional<CrossValidation>& cross_validation,
                     int camera);

// Per component of [w; dt], the leave-out spread over the covariance's
// sigma, at least 1: the scales S of the extrinsics' rows in an underwater
// calibration's sidecar (one scale for all six, as the air sidecar has it,
// would carry the ratio of the best-known component, often the rotation
// about the optical axis, to the others).
Eigen::Matrix<double, 6, 1> ExtrinsicsLeaveOutScales(
    const ExtrinsicChange& change);

// The sidecar of an underwater calibration: medium water, no drift prior
// (the extrinsics and the lenses were measured in this dive), and the
// joint covariance of the extrinsics [w; dt] and the lenses: the lenses'
// from the joint fit (air views given) or from the air rig's
// calibration_uncertainty() when it has one; the extrinsics' E from the
// bundle adjustment with their covariance with the lenses X
// (UnderwaterCalibration::extrinsics_lens_covariance) and the lenses'
// share of their own. The extrinsics' covariance given the lenses, E_e|L
// (ConditionalCovariance), is scaled by the leave-out spread per component
// (ExtrinsicsLeaveOutScales, S), the lenses' share and X kept as the fit
// has them:
//
//   E' = S E_e|L S + (E - E_e|L),   X' = X,
//
// positive semi-definite with the lenses' block (its Schur complement is
// S E_e|L S). Scaling X too would claim a response of the extrinsics to a
// lens error that the rig does not have, which a target-free estimate then
// counts as an error of n. Without X, E' = S E S. One camera: the air
// calibration's extrinsics and their uncertainty are kept.
CalibrationCovarianceFile UnderwaterCalibrationCovariance(
    const UnderwaterCalibration& result, const StereoRig& air_rig);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_COVARIANCE_H_
