// SequenceEstimator: the pair loop, once. From raw stereo pairs in time
// order to the matches of each pair and one estimate of n, with the one
// policy for guiding the matching, following a turned cam1, re-matching, the
// window and the warnings. `rcm estimate` on images and bags, `rcm demo`,
// the live pipeline (and with it the ROS node) and Python's
// rcm.SequenceEstimator all run it; none of them has a policy of its own.
//
// Per pair, AddPair(left, right, frame, t):
//   1. the front end (stereo_front_end.h) matches it within the refractive
//      epipolar band of the guide: the last pair's own estimate
//      n_f +- max(6 sigma_f, 0.01) (NextPairGuide), or the prior search
//      range when there is none (the first pair, a pair without an own
//      estimate, a re-acquired medium);
//   2. the sliding window (sliding_window_estimator.h) takes its matches
//      (every k-th of them above window_matches, spread over the image:
//      SpreadSubset): the pair's own estimate (the next guide), the
//      window's estimate and a change of medium;
//   3. follow: when the window's self-calibrated rotation of cam1 moves
//      pixels at the focal length by more than follow_rotation_px from the
//      rotation the front end matches with, the front end is rebuilt for
//      the rig turned by it (a rig that turned since its calibration would
//      otherwise lose, and bias, the matches the turn moves out of the
//      band);
//   4. with keep_frames, the matches are kept for Estimate(); without, the
//      front end refines only the matches the window takes (FrontEnd()).
//
// Estimate() solves the final estimate once (estimate_refractive_index.h),
// with options.estimation, over the kept frames since the window's last
// change of medium (the window estimator: all kept frames; it finds the
// changes itself). Its per-frame series is each pair's own estimate
// (refine) or the estimator's. Without keep_frames it is the window's.
//
// Re-matching (offline: EstimateSequence below): the pairs before the
// rotation was found were matched with the calibration's band. When the
// final estimate's self-calibrated rotation differs from the rotation the
// first pair was matched with by more than follow_rotation_px, the source
// is matched again from the start with the front end turned by it, at most
// max_matching_passes passes in all.
#ifndef RCM_LIVE_SEQUENCE_ESTIMATOR_H_
#define RCM_LIVE_SEQUENCE_ESTIMATOR_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/estimate_refractive_index.h"
#include "rcm/estimation/refractive_index_estimate.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/frontend/stereo_tracker.h"
#include "rcm/io/stereo_image_source.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct SequenceEstimatorOptions {
  StereoFrontEndOptions front_end;
  // The final estimate: its estimator and the refinement's options, which
  // the window uses too. systematic_px defaults to the front end's floor
  // (kFrontEndSystematicPx), as `rcm estimate` on images (which also turns
  // on detect_systematic).
  // estimation.window is the sequence's window too (its length and change
  // test), the one that guides the pairs and finds changes of medium.
  EstimationOptions estimation = DefaultEstimation();
  // Matches of a pair the window takes at most (SpreadSubset); >= 0, 0
  // takes all. The window's update costs ~60 us of CPU per match with the
  // default drift priors (live_pipeline.h), so 200 keeps a pair's guide and
  // change test at ~12 ms (frontend_benchmark's BM_EndToEnd_Engine: 200 and
  // 400 give final estimates 4e-6 apart, sigma_n 1.3e-3); the final
  // estimate takes every match.
  int window_matches = 200;
  // Pixels at the focal length by which cam1's self-calibrated rotation
  // must move before the front end follows it; > 0 (infinity: never).
  // Half the band's ~1 px half-width.
  double follow_rotation_px = 0.5;
  // EstimateSequence's passes over the source, the first included; >= 1.
  int max_matching_passes = 3;
  // Keep each pair's matches for Estimate() (a live pipeline that reports
  // the window only does not).
  bool keep_frames = true;
  // The bundle estimator (estimation.estimator kBundle): every pair is a
  // keyframe of its tracker; its n from the tracks, or, where the bundle
  // refuses (a rig that does not move, ...), the refine estimate with the
  // bundle's reason as its first warning.
  StereoTrackerOptions tracker;

  static EstimationOptions DefaultEstimation();
  // The window's refinement: estimation.refinement without refine_rotation
  // (the window self-calibrates cam1's rotation from its drift prior; a
  // freely refined rotation is the final estimate's only).
  RefinementOptions WindowRefinement() const;
  // The front end's options: front_end, and without keep_frames (nothing
  // but the window takes the matches) at most window_matches of a pair
  // refined (StereoFrontEndOptions::max_refined_matches, unless front_end
  // sets it), the same subset the window would take of them all, without
  // refining the rest.
  StereoFrontEndOptions FrontEnd() const;
  // Errors: the parts' Check(); window_matches < 0; follow_rotation_px not
  // > 0; max_matching_passes < 1; the bundle without keep_frames.
  Status Check() const;
};

// What one pair gave.
struct SequencePair {
  int64_t frame = 0;
  std::optional<double> timestamp;
  std::vector<StereoCorrespondence> matches;  // the front end's, raw pixels
  int64_t num_estimated = 0;                  // of them, the window's
  // The pair's own estimate and the window's after it, or why there is
  // none.
  StatusOr<PooledLocusEstimate> own = Status::Error("no estimate");
  StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate> window =
      Status::Error("no estimate");
  std::optional<MediumSwitch> medium_switch;  // this pair confirmed one
  bool reacquired = false;  // the front end left the guide's band
  bool followed = false;    // the front end now follows a new rotation
  // The bundle: of its matches, how many continue a landmark of the
  // previous pair (StereoTracker::AddKeyframe).
  std::optional<int> continued_tracks;
  FrontEndTimings timings;
  double estimate_ms = 0.0;  // the window's update
};

class SequenceEstimator {
 public:
  // Errors: options.Check(); the front end's or the window's.
  static StatusOr<std::unique_ptr<SequenceEstimator>> Create(
      const StereoRig& rig, const SequenceEstimatorOptions& options);

  // One stereo pair, raw images. Errors: the front end's (the images'
  // size or type); the estimator is then unchanged.
  StatusOr<SequencePair> AddPair(const cv::Mat& left, const cv::Mat& right,
                                 int64_t frame,
                                 std::optional<double> timestamp = {});

  // AddPair in two steps, for a caller that detects the next pair while
  // this one is added (EstimateSequence does): Detect runs the front end's
  // stages 1-2 with the sequence's own detectors, on `num_threads`
  // threads; it may run on another thread while AddDetectedPair runs, one
  // Detect at a time. AddDetectedPair(Detect(l, r, k), ...) is
  // AddPair(l, r, ...), to the bit. Errors: as AddPair's.
  StatusOr<DetectedStereoPair> Detect(const cv::Mat& left, const cv::Mat& right,
                                      int num_threads);
  StatusOr<SequencePair> AddDetectedPair(const DetectedStereoPair& detected,
                                         int64_t frame,
                                         std::optional<double> timestamp = {});

  // The final estimate (above), with its warnings. Errors: the
  // estimator's (too few matches, n not observable, ...).
  StatusOr<RefractiveIndexEstimate> Estimate() const;

  // A new window, no guide, no kept frames; the front end matches with
  // cam1 turned by `rotation` (angle-axis, radians, StereoRig::
  // WithCam1Moved) from now on.
  Status Restart(const Eigen::Vector3d& rotation = Eigen::Vector3d::Zero());

  // The rotation the front end matches with, and the one the first pair
  // since the last Restart was matched with.
  const Eigen::Vector3d& matching_rotation() const { return followed_; }
  const Eigen::Vector3d& first_matching_rotation() const { return first_; }
  // The kept frames (all since the last Restart) and the first frame of
  // the current medium.
  const std::vector<FrameMatches>& frames() const { return frames_; }
  std::optional<int64_t> medium_first_frame() const { return medium_first_; }
  const std::vector<MediumSwitch>& switches() const {
    return window_.switches();
  }
  const StereoRig& rig() const { return rig_; }
  const SequenceEstimatorOptions& options() const { return options_; }
  // Pixels a rotation moves at the focal length (the follow test's).
  double RotationPixels(const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) const;

 private:
  SequenceEstimator(const StereoRig& rig,
                    const SequenceEstimatorOptions& options,
                    StereoDetector detector, StereoFrontEnd front_end,
                    SlidingWindowRefractiveIndexEstimator window);
  // A new tracker for the bundle estimator (none for the others).
  Status ResetTracker();

  StereoRig rig_;
  SequenceEstimatorOptions options_;
  // Stages 1-2, never rebuilt (they do not depend on the rig): Detect may
  // use them while AddDetectedPair rebuilds front_end_ to follow cam1.
  StereoDetector detector_;
  StereoFrontEnd front_end_;
  SlidingWindowRefractiveIndexEstimator window_;
  std::optional<RefractiveIndexInterval> guide_;
  Eigen::Vector3d followed_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d first_ = Eigen::Vector3d::Zero();
  bool any_pair_ = false;
  std::vector<FrameMatches> frames_;
  std::vector<FrameEstimateRow> own_rows_;  // each kept pair's own
  std::optional<int64_t> medium_first_;
  std::vector<StereoCorrespondence> subset_;  // SpreadSubset's buffer
  // The bundle's tracker (its keyframes are the kept frames_).
  std::optional<StereoTracker> tracker_;
};

// The matches the window takes of `all` (SequenceEstimatorOptions::
// window_matches, `cap`): all of them when cap is 0 or not below their
// number, else every (size / cap)-th, which keeps the front end's spread
// over the image; the subset is written into `subset` (its capacity
// reused).
const std::vector<StereoCorrespondence>& SpreadSubset(
    const std::vector<StereoCorrespondence>& all, int cap,
    std::vector<StereoCorrespondence>* subset);

// An offline run over a source: every pair once per pass (the next pair
// decoded on a second thread while the current one is matched), the passes
// of re-matching (above), and the final estimate.
struct SequenceRun {
  StatusOr<RefractiveIndexEstimate> estimate = Status::Error("not run");
  std::vector<FrameMatches> frames;  // of the last pass
  int passes = 0;
  Eigen::Vector3d matching_rotation = Eigen::Vector3d::Zero();  // last pass
  int reacquired = 0;        // pairs, last pass
  FrontEndTimings timings;   // sums over the last pass's pairs
  double read_ms = 0.0;      // decoding, summed
  double estimate_ms = 0.0;  // the window's updates, summed
  double seconds = 0.0;      // wall clock of the last pass
};

// Called after each pair (pass 1, 2, ...; pairs done, pairs in all), with
// the pair's images and what it gave.
using SequenceProgress =
    std::function<void(int pass, size_t done, size_t total,
                       const StereoImagePair& images, const SequencePair&)>;

// The pairs of `source` through one SequenceEstimator, in order, and its
// final estimate; the next pair is read and detected (Detect, one thread)
// on another thread while this one is added. Errors: a pair that cannot be
// read or matched (with its file names); options' and the rig's as Create.
// An estimate that fails is SequenceRun::estimate's error.
StatusOr<SequenceRun> EstimateSequence(const StereoRig& rig,
                                       StereoImageSource* source,
                                       const SequenceEstimatorOptions& options,
                                       const SequenceProgress& progress = {});

}  // namespace rcm

#endif  // RCM_LIVE_SEQUENCE_ESTIMATOR_H_
