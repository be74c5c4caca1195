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

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_COVARIANCE_H_
