// The air calibration of one camera or of a stereo pair by bundle
// adjustment over planar-target views: the one solver behind
// CalibrateStereo (stereo_calibration.h, whose header states the
// unknowns, residuals, robust rounds, initialization and covariance) and
// CalibrateMono (mono_calibration.h). Internal to the library.
//
// With one camera the problem is the pair's without cam1: the unknowns are
// cam0's lens p_0, one pose (R_v, t_v) per view and the warp w; the
// residuals e = pi(p_0, R_v X_j(w) + t_v) - u of cam0's corners only; the
// p of sigma^2 = SSR / (2 m - p) counts n_lens + 6 V (+ 2) unknowns.
#ifndef RCM_CALIB_SRC_AIR_CALIBRATION_H_
#define RCM_CALIB_SRC_AIR_CALIBRATION_H_

#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/util/status.h"

namespace rcm::calib::internal {

// Calibrates sizes.size() cameras (1 or 2; CHECKed): cam0 from the views'
// left observations, cam1 (two cameras) from their right ones. With one
// camera every view's right observation is ignored, the result's
// num_cameras is 1 and its cam1 a copy of cam0 (StereoCalibration).
// Errors as CalibrateStereo's.
StatusOr<StereoCalibration> CalibrateInAir(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const std::vector<ImageSize>& sizes,
    const StereoCalibrationOptions& options);

}  // namespace rcm::calib::internal

#endif  // RCM_CALIB_SRC_AIR_CALIBRATION_H_
