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
// called after each fold with (done, total), from one thread at a time. Fails
// when fewer than 2 folds succeed (e.g. 3 views split 3 ways leave too few per
// camera).
StatusOr<CrossValidation> CrossValidateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibration& full,
    const StereoCalibrationOptions& calibration_options,
    const CrossValidationOptions& options = {},
    const std::function<void(int, int)>& progress = nullptr);

// The noise sigma of one component of an estimate whose views share
// errors (a dome's decentering, dome_calibration.h), from its covariance
// sigma s_c and its grouped jackknife sigma s_jk over g replicates:
//
//   sigma = sqrt((s_c^2 + s_jk^2) / 2)                      g >= 5
//         = max(s_c, s_jk)                                  2 <= g < 5
//         = s_c                       g < 2, or s_jk not finite
//
// The two fail in opposite ways. s_c is exact for independent corner
// noise and has no sampling noise of its own, but it does not count the
// errors a detector shares within a view (corners crowded on a steep or
// far board err alike). s_jk counts them, but from g replicates its
// variance varies by sqrt(2 / (g - 1)) (47 % at g = 10), and a z score
// over it is heavy-tailed (Student's t on g - 1 degrees of freedom). The
// mean of the two variances halves that noise and keeps half of what
// s_jk adds. Measured (z = error / sigma, its sd over the trials; honest
// is near 1), with the views weighed by their noise:
//   - independent Gaussian corners (DomeCalibration.MonteCarlo*, 50
//     trials): s_c alone z sd 0.83-1.10, s_jk alone up to 1.42 (small
//     sigmas from few replicates make large z), the mean 0.84-1.17;
//   - rendered dives, the detector's errors (benchmarks/dome_monte_carlo,
//     200 dives each of one camera and a pair): s_c alone 1.10-1.21, s_jk
//     alone 1.07-1.43, the mean 0.99-1.12. Before the views were weighed
//     s_c alone was 1.71 on a pair's x (50 dives), and the larger of the
//     two by a 95 % test, the rule then, over-covered (0.67-0.90).
// From fewer than kMinJackknifeReplicates replicates s_jk is too
// heavy-tailed (infinite variance at g = 3) to be averaged, and the larger
// of the two is taken.
inline constexpr int kMinJackknifeReplicates = 5;
double JackknifeNoiseSigma(double covariance_sigma, double jackknife_sigma,
                           int replicates);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CROSS_VALIDATION_H_
