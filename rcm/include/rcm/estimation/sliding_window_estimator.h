// The sliding-window variant of the online estimator (paper Sec. V-D): n
// from the last w_s frames only, with a statistical test that detects a
// change of medium (air <-> water), drops the window and restarts, and
// reports each switch with its frame.
//
// Per frame f, the frame's own fit exactly as in the online estimator
// (online_estimator.h, FitFrame): own robust fit, inliers, own least-squares
// cost C_f, G_f and own estimate (n_f, sigma_f). Frames without an own
// estimate (too few usable matches or inliers, or n unobservable from the
// frame) are skipped: they can be tested against nothing.
//
// Window: the cost functions of the last window_frames accepted frames in a
// ring buffer; C_w = sum C_f, G_w = sum G_f over it, and the window
// estimate (n_w, sigma_w) is the online estimator's on these sums.
//
// Change test, for a frame with an own estimate against the current
// window estimate (the frame is not in the window, so the two estimates
// are independent):
//
//   z = |n_f - n_w| / sqrt(sigma_f^2 + sigma_w^2)
//
// z <= change_threshold: the frame is accepted (added to the window, the
// oldest frame leaves a full window), and any pending frames are dropped
// (counted in num_dropped_frames()).
// z >  change_threshold: the frame is pending and not added. It joins the
// pending frames when it is consistent with the last of them (the same z
// between the two frames' own estimates <= change_threshold), else it
// replaces them (they are dropped). When confirm_frames frames are pending
// a switch is declared: the window is emptied, the pending frames become
// the new window, and MediumSwitch records the first pending frame (the
// first frame in the new medium), the frame that confirmed it, and n
// before and after. With no window estimate (at the start, after too few
// frames) frames are accepted without a test.
//
// False alarms: under no change z is |N(0, 1)| to first order, and
// P(z > 5) = 5.7e-7 per frame; a switch needs confirm_frames consecutive
// such frames, so with the defaults (5, 2) at most (5.7e-7)^2 = 3.3e-13
// per frame: once in ~5000 years at 20 Hz (6.3e8 frames a year). A lone
// inconsistent frame (a bad frame) is dropped and counted, never
// declared.
//
// Detection: a step of dn is declared at the confirm_frames-th frame after
// it when dn > change_threshold sqrt(sigma_f^2 + sigma_w^2). Measured on
// the Alphasense rig with 200 matches per frame and 0.5 px noise
// (sliding_window_estimator_test.cc): sigma_f ~ 0.009 in water and
// sigma_w ~ 0.002 for a full window, so air -> water (dn = 0.333) gives
// z ~ 35 and is declared one frame after the change (confirm_frames = 2);
// steps below ~0.05 are not declared as switches but tracked by the window
// as a gradual change, with a lag of about half a window.
//
// The window estimate's sigma_n is the total, as the online estimator's:
// pixel noise inflated when the window's frames disagree (the consistency
// test of calibration_propagation.h) and the calibration's uncertainty with
// cam1's rotation held. The change test uses the frames' own sigma and the
// window's pixel-noise share (a calibration error is common to both and
// cancels from their difference); when the window's frames disagree beyond
// their noise (its consistency inflation r > 1: cameras not triggered
// together on a moving rig, a scene that moves), a frame's own sigma is
// r sigma_f, in the change test and in the frame's reported estimate
// (FrameEstimateOf), so that a frame that scatters as the window's own
// frames do is not taken for a change of medium.
//
// Memory: window_frames + confirm_frames cost functions (each
// LocusCostFunction::kNumNodes x 3 doubles), allocated at Create, plus one
// MediumSwitch per switch. Time per frame: the frame's fit (online
// estimator) and a re-sum of the window's cost functions (window_frames x
// 3 x kNumNodes additions, exact where subtracting the oldest frame would
// accumulate rounding over a long run).
#ifndef RCM_ESTIMATION_SLIDING_WINDOW_ESTIMATOR_H_
#define RCM_ESTIMATION_SLIDING_WINDOW_ESTIMATOR_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/estimation/locus_cost_function.h"
#include "rcm/estimation/online_estimator.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct SlidingWindowOptions {
  // w_s, frames in the window; >= 1. 20 = 1 s at the dataset's 20 Hz.
  int window_frames = 20;
  // z above which a frame is inconsistent with the window; > 0 (finite).
  double change_threshold = 5.0;
  // Consecutive, mutually consistent inconsistent frames that declare a
  // switch; >= 1, at most window_frames.
  int confirm_frames = 2;

  // Sets window_frames to `frames` and lowers confirm_frames to it when it
  // was larger (a window of one frame confirms a change at its first
  // frame); frames < 1 is left to Check(). The one place that rule lives:
  // `rcm estimate --window`, Python's window_frames= and the node use it.
  void SetWindowFrames(int frames);
  Status Check() const;
};

// A declared change of medium.
struct MediumSwitch {
  int64_t first_frame = 0;        // the first frame in the new medium
  int64_t detected_at_frame = 0;  // the frame that confirmed it
  double n_before = 0.0;          // window estimate before the switch
  double n_after = 0.0;           // estimate of the confirming frames
};

class SlidingWindowRefractiveIndexEstimator {
 public:
  // Fails on invalid options or options.refine_rotation.
  static StatusOr<SlidingWindowRefractiveIndexEstimator> Create(
      const StereoRig& rig, const RefinementOptions& options,
      const SlidingWindowOptions& window_options);

  // The window's pooled estimate, with which frames it holds.
  struct Estimate : PooledLocusEstimate {
    int frames = 0;           // frames in the window
    int64_t first_frame = 0;  // oldest frame in the window
    int64_t last_frame = 0;   // newest frame in the window
  };

  enum class Decision {
    kSkipped,   // no own estimate; the frame is not used
    kAccepted,  // added to the window
    kPending,   // inconsistent with the window; held back
    kSwitch,    // confirmed a switch; the new window starts
  };

  struct WindowUpdate {
    int64_t frame = 0;
    int64_t correspondences = 0;  // the frame's size
    int64_t usable = 0;           // pixels that could be undistorted
    Decision decision = Decision::kSkipped;
    // The frame's own estimate, with the reason when there is none.
    StatusOr<PooledLocusEstimate> frame_estimate = Status::Error("no estimate");
    // z against the window estimate before this frame, when both exist.
    std::optional<double> z;
    // The window estimate after this frame, with the reason when there is
    // none.
    StatusOr<Estimate> window = Status::Error("no estimate");
    // Set when this frame confirmed a switch.
    std::optional<MediumSwitch> medium_switch;
  };
  // `frame` identifies the frame in the reports (e.g. its index in the
  // sequence).
  WindowUpdate AddFrame(int64_t frame,
                        const std::vector<StereoCorrespondence>& frame_matches);

  // The window estimate; an error (never a number) while the window has
  // too few inliers or does not observe n.
  StatusOr<Estimate> Current() const;

  const std::vector<MediumSwitch>& switches() const { return switches_; }
  // Inconsistent frames dropped without a switch.
  int64_t num_dropped_frames() const { return num_dropped_frames_; }
  int64_t num_skipped_frames() const { return num_skipped_frames_; }

  // Bytes held, heap included: constant apart from one MediumSwitch per
  // switch.
  size_t MemoryBytes() const;

 private:
  SlidingWindowRefractiveIndexEstimator(
      const StereoRig& rig, const RefinementOptions& options,
      const SlidingWindowOptions& window_options);

  struct FrameCost {
    int64_t frame = 0;
    LocusEstimate estimate;  // the frame's own
    LocusCostFunction cost;
    LocusNormalEquations normal_equations;  // FrameFit's
    FrameFit::Model model;                  // FrameFit's
  };

  // Appends to the ring buffer (dropping the oldest when full) and
  // re-sums the window.
  void PushToWindow(const FrameCost& frame);
  void ResumWindow();

  StereoRig rig_;
  RefinementOptions options_;
  SlidingWindowOptions window_options_;

  // Ring buffer: window_.size() == window_frames, oldest at window_begin_.
  std::vector<FrameCost> window_;
  int window_begin_ = 0;
  int window_count_ = 0;
  LocusCostFunction window_cost_;
  LocusNormalEquations window_normal_equations_;
  FrameEstimateSums window_estimates_;
  LinearizationPoint linearization_;
  // Pending frames, oldest first; capacity confirm_frames.
  std::vector<FrameCost> pending_;

  std::vector<MediumSwitch> switches_;
  int64_t num_dropped_frames_ = 0;
  int64_t num_skipped_frames_ = 0;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_SLIDING_WINDOW_ESTIMATOR_H_
