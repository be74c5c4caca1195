// Model-robust underwater calibration: n from the candidate models a dive
// can support, with a sigma_n that covers the ones the data cannot tell
// apart.
//
// On a real dive the error of n is set by what the model leaves out, not
// by the pixel noise: a hand-held board's bow, a housing's air gap, a port
// tilted on its seat each move n by hundredths while the covariance of any
// one fit says thousandths (docs/calibrate.md, "What limits n on a real
// dive").
// So each candidate model is fitted (CalibrateUnderwater), and
//
// Evidence, per candidate k (held-out error, UnderwaterLeaveOut): over
// the V views that every candidate's leave-out holds out and images, with
// s_k(v) the view's held-out SSR [px^2] (its pose fitted to its own
// corners with the parameters of the replicate that left it out held),
// b = argmin_k sum_v ln s_k(v) the best, and the paired log ratios
//   d_v = ln(s_k(v) / s_b(v)),   mean d, SE = sd(d_v) / sqrt(V),
//   evidence_k = mean d / SE   (0 for the best),
// the t statistic of k's excess held-out error over the best's. Views,
// not corners, are the unit: a model error is shared by the corners of a
// view, so corner counts would make every difference look significant
// (an RMS 10 % lower over 6000 residuals is a chi^2 difference above
// 1000, and says nothing when both are model error); and ratios,
// not differences, so that a near view with many pixels does not outvote
// the rest.
//
// Rule:
//   plausible_k  <=>  evidence_k <= evidence_sigmas (all are when fewer
//                     than kMinEvidenceViews views are common, e.g. with
//                     folds 0);
//   chosen       =    the best (evidence 0); without evidence, the
//                     simplest.
// n is the chosen candidate's, and
//   sigma_n_noise  = its covariance sigma, or its leave-out sigma when that
//                    is larger by more than the leave-out's own sampling
//                    error allows (one-sided 95 % chi-square test on g - 1
//                    degrees of freedom, g replicates): the leave-out
//                    counts errors shared within a view, but from 5-10
//                    replicates it is too noisy to take whenever larger;
//   sigma_n_lenses = its sigma_n_lenses (the air lens covariance; 0
//                    without one);
//   sigma_n_model^2 = sum_k w_k b_k^2 / sum_k w_k over the plausible
//                    candidates (the chosen with b = 0, w = 1), where
//                    w_k = exp(-evidence_k^2 / 2) (1 without evidence) and
//                    b_k^2 = max(0, (n_k - n)^2 - |s_k^2 - s^2|), s the
//                    candidates' sigma_n_noise: the spread of n over the
//                    models, each as much as the data cannot rule it out,
//                    less what the two fits' noises alone make of the
//                    difference of nested fits (Var(n_k - n) = |s_k^2 -
//                    s^2|, Hausman);
//   sigma_n = sqrt(sigma_n_noise^2 + sigma_n_lenses^2 + sigma_n_model^2).
// A dive whose sigma_n exceeds max_sigma_n cannot pin n: `advice` says so
// in one line, with what views would separate n from the model that
// spreads it (the candidate of the largest w_k b_k^2).
#ifndef RCM_CALIB_UNDERWATER_MODEL_SELECTION_H_
#define RCM_CALIB_UNDERWATER_MODEL_SELECTION_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/underwater_calibration.h"

namespace rcm::calib {

// Fewest views held out by every candidate for the evidence to count.
inline constexpr int kMinEvidenceViews = 4;

// One model of the dive: the board flat or bowed, the port thin or with an
// air gap or tilted (the three flags of UnderwaterCalibrationOptions).
struct UnderwaterCandidateModel {
  bool board_warp = false;
  bool air_gap = false;
  bool port_tilt = false;

  // "flat board, thin ports", "bowed board, air gaps", "flat board, tilted
  // ports", "bowed board, air gaps and tilted ports".
  std::string Name() const;
  // Its unknowns beyond n, the extrinsics and the poses, per camera for
  // the ports: warp 2, gap 1 per port, tilt 2 per port.
  int ExtraParameters() const;
  bool operator==(const UnderwaterCandidateModel& other) const;
};

// The candidates: the board flat and, unless `flat_board`, bowed; the
// ports thin when `thin_port`, else as `air_gap` / `port_tilt` say when
// either is set, else all four (thin, with an air gap, tilted, both).
// Simplest first. (thin_port with air_gap or port_tilt is the caller's to
// refuse: thin_port wins here.)
std::vector<UnderwaterCandidateModel> UnderwaterCandidates(
    bool flat_board, bool air_gap, bool port_tilt, bool thin_port = false);

struct UnderwaterModelSelectionOptions {
  // The fit of each candidate; its estimate_board_warp, estimate_air_gap
  // and estimate_port_tilt are the candidate's. With folds 0 there is no
  // held-out error: every candidate that fits is plausible.
  UnderwaterCalibrationOptions fit;
  // The candidates (default: all eight of UnderwaterCandidates(false,
  // false, false)); none twice.
  std::vector<UnderwaterCandidateModel> candidates =
      UnderwaterCandidates(false, false, false);
  // A candidate is plausible while its held-out error exceeds the best's by
  // at most this many standard errors (header).
  double evidence_sigmas = 2.0;
  // A dive that cannot pin n to this says so (advice): half the distance
  // between fresh water (1.333) and sea water (1.340), so that a dive that
  // passes tells the two apart.
  double max_sigma_n = 0.0035;

  Status Check() const;
};

struct UnderwaterCandidate {
  UnderwaterCandidateModel model;
  // The fit, or why it failed.
  std::optional<UnderwaterCalibration> fit;
  std::string error;
  // The failure was n on a bound of [1, 2] (IsIndexOnBoundError).
  bool on_bound = false;
  // The noise sigma of its n (header).
  double sigma_n_noise = 0.0;
  // Evidence (header): held-out RMS [px] over the common views, and the
  // excess over the best in standard errors; NaN when not computed.
  double held_out_rms_px = 0.0;
  double evidence = 0.0;
  bool plausible = false;
};

struct UnderwaterModelSelection {
  std::vector<UnderwaterCandidate> candidates;
  int chosen = -1;  // index into candidates
  // Header.
  double n = 0.0;
  double sigma_n = 0.0;
  double sigma_n_noise = 0.0;
  double sigma_n_lenses = 0.0;
  double sigma_n_model = 0.0;
  // The views the evidence is over (0: not computed, one candidate).
  int num_evidence_views = 0;
  // sigma_n <= max_sigma_n.
  bool pinned = true;
  // When not pinned: one line, what limits n and what views would help.
  std::string advice;

  const UnderwaterCalibration& Chosen() const {
    return *candidates[chosen].fit;
  }
};

// Fits every candidate and chooses (header). The candidates are fitted
// side by side on options.fit.num_threads threads, without lens refits;
// the chosen one is then fitted again, all threads on the lens refits of
// its sigma_n_lenses (the others' are not used). `progress`, when set, is
// called with (done, total) in hundredths of a candidate as the fits
// advance (the lens refits count as one more candidate), one call at a
// time but from any of those threads. Fails with the simplest
// candidate's error when no candidate can be fitted, or on bad options.
// With `air` (the joint calibration of air and water, CalibrateUnderwater)
// every candidate is the joint fit, whose covariance carries the lenses:
// no lens refits run.
StatusOr<UnderwaterModelSelection> SelectUnderwaterModel(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoRig& air_rig, const UnderwaterModelSelectionOptions& options,
    const std::function<void(int, int)>& progress = nullptr,
    const AirTargetViews* air = nullptr);

}  // namespace rcm::calib

#endif  // RCM_CALIB_UNDERWATER_MODEL_SELECTION_H_
