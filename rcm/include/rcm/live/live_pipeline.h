// LivePipeline: rcm as it runs on the robot, between the camera driver and
// the VIO, free of any middleware. The ROS1 node (ros/rcm_ros_node.cc) is a
// thin adapter over it; a ROS 2 node would be another.
//
// Per stereo pair, Process(left, right, stamp), on the caller's thread:
//   1. the pair is checked: 8-bit images (gray, BGR or BGRA) of the
//      calibration's size, and not blank (a black, saturated or covered
//      frame: the gray standard deviation of either image below
//      min_contrast). A refused pair is an error (one line), changes
//      nothing and produces nothing;
//   2. the sequence engine (sequence_estimator.h, the pair loop `rcm
//      estimate`, `rcm demo` and Python run too) matches it, guided by the
//      last pair's own estimate n_f +- max(6 sigma_f, 0.01) or over the
//      prior search range when there is none, and following cam1's
//      self-calibrated turn; its sliding window (sliding_window_estimator.h)
//      takes the matches: the window's n and total sigma_n, and whether
//      this pair confirmed a change of medium. No estimate (too few
//      matches, n not observable, n pinned at the upper bound of [1, 2],
//      which a stale calibration gives) is the estimate's error, never a
//      number;
//   4. both images are remapped to the corrected pinhole pair
//      (virtual_pinhole_rig.h) with the maps of n_maps.
//
// The maps. n_maps starts at options.initial_n, whose maps Create builds.
// When the window's n differs from n_maps by more than map_update_threshold
// and by more than map_update_sigmas of the window's noise sigma (and the
// pipeline is not on hold), maps for that n are built on a worker
// thread while the pairs keep being corrected with the current ones; the
// first pair processed after the build has finished uses the new maps
// (LiveFrame::maps_updated). One build at a time: if n has moved on when
// it finishes, the next pair starts another. A build costs 47-77 ms (over
// this machine's runs) for 720x540 on one core (benchmarks/live_benchmark.cc),
// about a pair's whole period at 20 Hz, hence the worker.
//
// Cost per 720x540 pair (live_benchmark, this project's 2-core machine,
// whose speed drifts by tens of percent from minute to minute; medians of
// three repetitions on 2026-12-06): a whole pair (checks, front end,
// window, remaps) takes 22-31 ms of CPU and 15-19 ms of wall time in air
// or water (BM_LivePipelinePair; 22.5-23.3 ms in a fast phase; 40-50 ms
// before the refinement's blocks of matches and the maps' noise test;
// 28-34 ms of CPU for the window's update and remaps when it took, and
// the front end refined, all ~1200 matches). Of it the window's update of
// its 200 matches takes 4.3-5.5 ms and, with both remaps, 8.7 ms of CPU
// for a rig read as `rcm` reads a camchain without a sidecar (the default
// drift and focal drift priors: each pair's refinement estimates cam1's
// rotation and both focal scales with n, and its normal equations, taken
// once at the window's rotation, carry the lenses' columns). At 20 Hz a
// pair has 50 ms; the caller drops whole the pairs that come while one is
// processed (latest_slot.h). The map threshold's default, 1e-3, moves the
// corrected images' focal length by 0.1 %, below what a metric depth of
// 1 % needs.
//
// Hold (SetHold): the maps stay at their n and no build starts; the
// estimation keeps running and is reported. Reset(n): a new window and no
// guide (as at start-up), and with n, maps for n (built on the worker).
//
// Threads: Process, Reset and SetHold are called from one thread (not
// thread-safe); the map builds run on their own worker. The corrected
// images of a LiveFrame are the pipeline's buffers, overwritten by the next
// Process (no allocation per pair): copy what must outlive it.
#ifndef RCM_LIVE_LIVE_PIPELINE_H_
#define RCM_LIVE_LIVE_PIPELINE_H_

#include <cstdint>
#include <future>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/live/sequence_estimator.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct LivePipelineOptions {
  StereoFrontEndOptions front_end;
  // The estimator's options; systematic_px defaults to the front end's
  // floor (kFrontEndSystematicPx), as `rcm estimate` on images.
  RefinementOptions refinement = DefaultRefinement();
  SlidingWindowOptions window;
  // The corrected pair: fit, rectify, output size (virtual_pinhole_rig.h).
  // num_threads is the worker's.
  VirtualPinholeRigOptions correction = DefaultCorrection();
  // n of the maps before any estimate; in [1, 2]. 1: the robot starts in
  // air.
  double initial_n = 1.0;
  // |n - n_maps| above which new maps are built; > 0 and finite.
  double map_update_threshold = 1e-3;
  // ... and above this many of the window's noise sigma (its
  // sigma_n_noise); >= 0 and finite, 0: the threshold alone. The maps
  // follow changes of n, not its noise: with the default priors the
  // window's n scatters by about its noise sigma (1-4e-3 over the first
  // pairs of a dive), and at the threshold alone the maps were rebuilt for
  // 5 of 16 pairs of a steady rendered dive (live_pipeline_test.cc; ~50 ms
  // of CPU each) and moved the corrected images' focal length by ~0.1 %
  // back and forth under the odometry.
  double map_update_sigmas = 3.0;
  // Matches of a pair the window takes at most, every k-th of the front
  // end's (which come in image order, so the subset keeps their spread);
  // >= 0, 0 takes all. The sequence engine's own default
  // (SequenceEstimatorOptions::window_matches, the one policy `rcm
  // estimate` and Python run too): 200. The window's update costs ~60 us of
  // CPU per match with the default priors (the frame's refinement with
  // cam1's rotation and the focal scales, the lenses' columns of its normal
  // equations, the locus cost function's 577 nodes; ~12 us without
  // priors), so 200 keep it at ~12 ms where the ~1200 matches of a 720x540
  // pair took ~72 ms. The front end refines only those
  // (SequenceEstimatorOptions::FrontEnd()).
  int window_matches = SequenceEstimatorOptions().window_matches;
  // A gray standard deviation below this (either image) refuses the pair
  // as blank; >= 0 (0 accepts every pair). 2 gray levels: a lit scene has
  // tens, a covered or black frame its sensor noise.
  double min_contrast = 2.0;

  static RefinementOptions DefaultRefinement();
  static VirtualPinholeRigOptions DefaultCorrection();
  Status Check() const;
};

// What one pair gave.
struct LiveFrame {
  int64_t frame = 0;        // 0, 1, ... in the order of Process calls accepted
  double stamp = 0.0;       // the caller's, unchanged
  int64_t num_matches = 0;  // the front end's
  int64_t num_estimated = 0;  // of them, the window's (window_matches)
  // The window estimate after this pair, or why there is none.
  StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate> estimate =
      Status::Error("no estimate");
  // This pair confirmed a change of medium (the window restarted).
  std::optional<MediumSwitch> medium_switch;
  // What the window's estimate says of the calibration and the data, one
  // line each (estimate_warnings.h: a stale calibration, n and cam1's
  // rotation hardly separable, ...), as `rcm estimate` prints them.
  std::vector<std::string> warnings;
  bool held = false;
  // The corrected pair and its rig: the maps' n, and whether the maps
  // changed at this pair.
  double maps_n = 1.0;
  bool maps_updated = false;
  cv::Mat left_corrected;
  cv::Mat right_corrected;
  std::shared_ptr<const VirtualPinholeRig> corrected;
  // Milliseconds of this pair's stages.
  double match_ms = 0.0;
  double estimate_ms = 0.0;
  double remap_ms = 0.0;
};

class LivePipeline {
 public:
  // Builds the front end, the estimator and the maps of initial_n. Errors:
  // options.Check(), and the rig's (no maps for it).
  static StatusOr<std::unique_ptr<LivePipeline>> Create(
      const StereoRig& rig, const LivePipelineOptions& options);
  ~LivePipeline();
  LivePipeline(const LivePipeline&) = delete;
  LivePipeline& operator=(const LivePipeline&) = delete;

  // One stereo pair (raw images, as the cameras give them). Errors: the
  // pair is refused (1. above), or the front end failed; the pipeline is
  // then unchanged.
  StatusOr<LiveFrame> Process(const cv::Mat& left, const cv::Mat& right,
                              double stamp);

  // A new window and no guide; with n (in [1, 2]), maps for n are built.
  Status Reset(std::optional<double> n = std::nullopt);
  // On hold, a build in flight is waited for and discarded.
  void SetHold(bool hold);
  bool hold() const { return hold_; }

  const StereoRig& rig() const { return rig_; }
  const LivePipelineOptions& options() const { return options_; }
  // The maps in use, and whether a build is in flight.
  const VirtualPinholeRig& corrected() const { return *maps_; }
  bool building() const { return pending_.valid(); }
  // Waits for a build in flight and puts its maps in use (tests,
  // shutdown); false when none was in flight.
  bool WaitForMaps();
  // Pairs refused at step 1, and map builds that failed.
  int64_t num_refused() const { return num_refused_; }
  int64_t num_failed_builds() const { return num_failed_builds_; }

 private:
  LivePipeline(const StereoRig& rig, const LivePipelineOptions& options,
               std::unique_ptr<SequenceEstimator> sequence,
               std::shared_ptr<const VirtualPinholeRig> maps);
  // Puts a finished build in use; true when the maps changed.
  bool CollectBuild(bool wait);
  void StartBuild(double n);

  StereoRig rig_;
  LivePipelineOptions options_;
  std::unique_ptr<SequenceEstimator> sequence_;
  std::shared_ptr<const VirtualPinholeRig> maps_;
  std::future<StatusOr<VirtualPinholeRig>> pending_;
  double pending_n_ = 0.0;
  bool hold_ = false;
  int64_t next_frame_ = 0;
  int64_t num_refused_ = 0;
  int64_t num_failed_builds_ = 0;
  cv::Mat left_corrected_;
  cv::Mat right_corrected_;
};

// The sequence engine's options of a live pipeline's: its front end,
// refinement and window, the window estimate as the estimate, no frames
// kept.
SequenceEstimatorOptions LiveSequenceOptions(
    const LivePipelineOptions& options);

}  // namespace rcm

#endif  // RCM_LIVE_LIVE_PIPELINE_H_
