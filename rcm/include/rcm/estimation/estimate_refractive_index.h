// EstimateRefractiveIndex: n from the matches of a sequence of stereo
// frames with the estimator of one's choice, as one RefractiveIndexEstimate
// (refractive_index_estimate.h). It is the place where the estimators meet:
// `rcm estimate`, Python's rcm.estimate_refractive_index and the sequence
// engine call it; none of them holds a policy of its own.
//
//   refine       robust least squares over all frames (batch_refinement.h;
//                a thick port's camchain: thick_port_refinement.h, with
//                estimate_air_gap the gaps free). The estimator of record.
//   online       the same estimate updated frame by frame in constant
//                memory (online_estimator.h).
//   window       over the last window.window_frames frames, restarting on
//                a change of medium (sliding_window_estimator.h).
//   closed-form  the paper's baseline: eq. 14 per match, the mask
//                sqrt|u| sqrt|v| > eta, the radially weighted mean eq. 17
//                (paper_online_estimator.h); biased under pixel noise and
//                off a rectified rig (a warning says so).
//   bundle       n, cam1's turn and the trajectory from landmarks tracked
//                over keyframes (sequence_bundle_adjustment.h): from
//                images only (EstimateRefractiveIndexFromTracks; the
//                sequence engine tracks them), not from matches.
//
// The per-frame series (RefractiveIndexEstimate::per_frame): online and
// closed-form the estimate so far, window the window's, refine each frame's
// own estimate (one refinement per frame: only with per_frame_estimates).
// The warnings of estimate_warnings.h are filled in.
#ifndef RCM_ESTIMATION_ESTIMATE_REFRACTIVE_INDEX_H_
#define RCM_ESTIMATION_ESTIMATE_REFRACTIVE_INDEX_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/refractive_index_estimate.h"
#include "rcm/estimation/sequence_bundle_adjustment.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/geometry/stereo_tracks.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

enum class EstimatorKind { kRefine, kOnline, kWindow, kClosedForm, kBundle };

// "refine", "online", "window", "closed-form", "bundle".
const char* EstimatorName(EstimatorKind kind);
std::optional<EstimatorKind> EstimatorFromName(std::string_view name);

// The matches of one stereo frame.
struct FrameMatches {
  int64_t frame = 0;
  std::optional<double> timestamp;  // seconds
  std::vector<StereoCorrespondence> matches;
};

// Consecutive matches with equal `frame` as one frame each, in input order.
std::vector<FrameMatches> SplitFrames(
    const std::vector<StereoCorrespondence>& matches);

struct EstimationOptions {
  EstimatorKind estimator = EstimatorKind::kRefine;
  // The refinement's options (every estimator but closed-form).
  RefinementOptions refinement;
  // window: its length and change test.
  SlidingWindowOptions window;
  // closed-form: the observability mask.
  PaperOnlineEstimatorOptions closed_form;
  // bundle: the sequence bundle adjustment's, and the keyframes it adjusts:
  // the last bundle_window of them (TracksInWindow), 0 every keyframe.
  SequenceBundleOptions bundle;
  int bundle_window = 0;
  // refine: estimate the ports' air gaps with n (a thin port's rig: from
  // zero). Not with refinement.refine_rotation.
  bool estimate_air_gap = false;
  // refine: each frame's own estimate into per_frame (one refinement per
  // frame, on one thread).
  bool per_frame_estimates = false;

  // Errors: the parts' Check(); refine_rotation or estimate_air_gap with
  // another estimator than refine; estimate_air_gap with refine_rotation.
  Status Check() const;
};

// Called after each frame (online, window, closed-form, refine's per-frame
// estimates): frames done, frames in all.
using EstimationProgress = std::function<void(size_t done, size_t total)>;

// Errors: options.Check(); a thick port's rig with another estimator than
// refine; the bundle (it needs tracks: below); the estimator's own (too
// few matches or inliers, n not observable, n pinned at the bound 2, no
// match through the mask).
StatusOr<RefractiveIndexEstimate> EstimateRefractiveIndex(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress = {});

// The bundle estimator over landmarks tracked across keyframes
// (StereoTracker), `keyframes[k]` the frame and time of keyframe k: n, the
// total sigma_n with its noise and calibration parts, cam1's turn
// (`rotation`, estimated freely: with_prior false) and `bundle` (the
// trajectory in the first keyframe's frame). Errors: options.Check(),
// options.estimator not kBundle, a keyframe count that differs from the
// tracks', the bundle's own (motion that does not help, said in one line;
// broken tracks; n not observable or pinned at 2).
struct KeyframeStamp {
  int64_t frame = 0;
  std::optional<double> timestamp;
};
StatusOr<RefractiveIndexEstimate> EstimateRefractiveIndexFromTracks(
    const StereoRig& rig, const StereoTracks& tracks,
    const std::vector<KeyframeStamp>& keyframes,
    const EstimationOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_ESTIMATE_REFRACTIVE_INDEX_H_
