// Leave-views-out cross-validation of a stereo calibration: how much the
// result moves when some views are left out, against the standard
// deviations the covariance reports.
//
// The views are split into g = min(folds, V) groups by index (view i in
// group i mod g); calibration k uses every group but k. For each quantity
// x with estimates x_1..x_g the grouped jackknife standard error is
//
//   sigma_jk = sqrt((g - 1) / g * sum_k (x_k - mean(x))^2)
//
// (Efron & Tibshirani, An Introduction to the Bootstrap, ch. 11). It
// counts what the covariance cannot: errors correlated within a view
// (a board that is not flat, blur, lens-model error). When sigma_jk is
// much larger than the covariance's sigma, the residuals are not
// independent pixel noise and sigma_jk is the honest figure.
#ifndef RCM_CALIB_CROSS_VALIDATION_H_
#define RCM_CALIB_CROSS_VALIDATION_H_

#include <functional>
#include <string>
#include <vector>

#include "rcm/calib/stereo_calibration.h"

namespace rcm::calib {

struct CrossValidationOptions {
  // Number of groups (leave-one-view-out when >= the number of views).
  int folds = 10;

  // Fails unless folds >= 2.
  Status Check() const;
};

// One calibrated quantity across the folds.
struct ParameterSpread {
  std::string name;   // "cam0 fx", ..., "baseline", "board bowl"
  std::string unit;   // "px", "m"
  double full = 0.0;  // the all-views estimate
  double min = 0.0;   // over the folds
  double max = 0.0;
  double jackknife_sigma = 0.0;
  double reported_sigma = 0.0;  // from the all-views covariance
};

struct CrossValidation {
  int folds = 0;         // calibrations run
  int failed_folds = 0;  // of which failed (too few views left); skipped
  // cam0 fx, fy, cx, cy, cam1 fx, fy, cx, cy, baseline, and the board's
  // bowl (StereoCalibration::BoardBowl) when the full calibration
  // estimated the warp: a bow that differs from view to view (a hand-held
  // board) shows as a leave-out spread well above its covariance sigma.
  // One camera: cam0's four and the bowl.
  std::vector<ParameterSpread> parameters;
};

// Runs the folds with the options of the full calibration `full`
// (CalibrateStereo of the same inputs, or CalibrateMono's: then each fold
// is one too and cam1_size is not used), calibration_options.num_threads
// folds at a time, each solved on one thread. `progress`, when set, is
// called after each fold with (done, total), from one thread at a time. Fails when fewer than 2 folds
// succeed (e.g. 3 views split 3 ways leave too few per camera).
StatusOr<CrossValidation> CrossValidateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibration& full,
    const StereoCalibrationOptions& calibration_options,
    const CrossValidationOptions& options = {},
    const std::function<void(int, int)>& progress = nullptr);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CROSS_VALIDATION_H_
