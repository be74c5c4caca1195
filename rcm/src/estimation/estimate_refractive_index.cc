#include "rcm/estimation/estimate_refractive_index.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/estimate_warnings.h"
#include "rcm/estimation/online_estimator.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// Above this deviation from a rectified pair the closed form is biased.
constexpr double kClosedFormRectifiedToleranceDeg = 0.05;
constexpr double kEstimateDegreesPerRadian = 180.0 / M_PI;

std::string EstimateLossDescription(const RefinementOptions& options) {
  std::string loss(RobustLossName(options.loss));
  if (options.loss != RobustLoss::kNone) {
    loss += " " + FormatFixed(options.loss_scale_px, 2) + " px";
  }
  return loss;
}

std::vector<StereoCorrespondence> PooledMatchesOf(
    const std::vector<FrameMatches>& frames) {
  size_t size = 0;
  for (const FrameMatches& frame : frames) size += frame.matches.size();
  std::vector<StereoCorrespondence> all;
  all.reserve(size);
  for (const FrameMatches& frame : frames) {
    all.insert(all.end(), frame.matches.begin(), frame.matches.end());
  }
  return all;
}

StatusOr<RefractiveIndexEstimate> RunRefineEstimator(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress) {
  const std::vector<StereoCorrespondence> matches = PooledMatchesOf(frames);
  const RefinementOptions& refinement = options.refinement;
  StatusOr<RefinementSummary> summary = Status::Error("not run");
  std::optional<AirGapEstimate> air_gap;
  if (options.estimate_air_gap) {
    // The thick-port model with the gap free, from the rig's ports (a rig
    // without port blocks: thin ports, the gap estimated from 0).
    const StereoRig::Ports ports = rig.ports().value_or(StereoRig::Ports{});
    ThickPortRefinementOptions thick_options;
    thick_options.base = refinement;
    thick_options.estimate_air_gap = true;
    StatusOr<ThickPortRefinementSummary> thick = RefineRefractiveIndexThickPort(
        rig, ports.left, ports.right, matches, thick_options);
    if (!thick.ok()) return thick.status();
    air_gap = thick->air_gap;
    summary = std::move(thick->refinement);
  } else {
    summary = RefineRefractiveIndex(rig, matches, refinement);
  }
  if (!summary.ok()) return summary.status();
  RefractiveIndexEstimate estimate =
      EstimateFromRefinement(rig, *summary, air_gap);
  estimate.method =
      std::string(rig.HasThickPort()
                      ? "robust least squares on the thick-port loci "
                        "(generalized epipolar constraint of the rays in the "
                        "medium; the camchain's port blocks)"
                      : "robust least squares on the refractive epipolar "
                        "loci") +
      " (loss " + EstimateLossDescription(refinement) + ", inliers within " +
      FormatFixed(refinement.inlier_threshold_px, 2) + " px)";
  if (options.per_frame_estimates) {
    RefinementOptions frame_options = refinement;
    frame_options.num_threads = 1;
    for (size_t i = 0; i < frames.size(); ++i) {
      FrameEstimateRow row{frames[i].frame, frames[i].timestamp};
      const StatusOr<RefinementSummary> own =
          RefineRefractiveIndex(rig, frames[i].matches, frame_options);
      if (own.ok()) {
        row.n = own->n;
        row.sigma_n = own->sigma_n;
      }
      estimate.per_frame.push_back(row);
      if (progress) progress(i + 1, frames.size());
    }
  }
  return estimate;
}

StatusOr<RefractiveIndexEstimate> RunOnlineEstimator(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress) {
  StatusOr<OnlineRefractiveIndexEstimator> estimator =
      OnlineRefractiveIndexEstimator::Create(rig, options.refinement);
  if (!estimator.ok()) return estimator.status();
  std::vector<FrameEstimateRow> rows;
  int64_t invalid = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const OnlineRefractiveIndexEstimator::FrameUpdate update =
        estimator->AddFrame(frames[i].matches);
    invalid += update.correspondences - update.usable;
    FrameEstimateRow row{frames[i].frame, frames[i].timestamp};
    if (update.cumulative.ok()) {
      row.n = update.cumulative->n;
      row.sigma_n = update.cumulative->sigma_n;
    }
    rows.push_back(row);
    if (progress) progress(i + 1, frames.size());
  }
  const StatusOr<OnlineRefractiveIndexEstimator::Estimate> current =
      estimator->Current();
  if (!current.ok()) return current.status();
  RefractiveIndexEstimate estimate = EstimateFromPooled(rig, *current);
  estimate.method =
      "online robust least squares on the refractive epipolar loci (loss " +
      EstimateLossDescription(options.refinement) + ", inliers within " +
      FormatFixed(options.refinement.inlier_threshold_px, 2) +
      " px of each frame's fit)";
  estimate.invalid = invalid;
  estimate.skipped_frames = estimator->num_skipped_frames();
  estimate.per_frame = std::move(rows);
  return estimate;
}

StatusOr<RefractiveIndexEstimate> RunWindowEstimator(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress) {
  StatusOr<SlidingWindowRefractiveIndexEstimator> estimator =
      SlidingWindowRefractiveIndexEstimator::Create(rig, options.refinement,
                                                    options.window);
  if (!estimator.ok()) return estimator.status();
  std::vector<FrameEstimateRow> rows;
  std::map<int64_t, size_t> row_of_frame;
  int64_t invalid = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const SlidingWindowRefractiveIndexEstimator::WindowUpdate update =
        estimator->AddFrame(frames[i].frame, frames[i].matches);
    invalid += update.correspondences - update.usable;
    FrameEstimateRow row{frames[i].frame, frames[i].timestamp};
    if (update.window.ok()) {
      row.n = update.window->n;
      row.sigma_n = update.window->sigma_n;
    }
    row_of_frame[frames[i].frame] = rows.size();
    rows.push_back(row);
    if (progress) progress(i + 1, frames.size());
  }
  for (const MediumSwitch& medium_switch : estimator->switches()) {
    const auto row = row_of_frame.find(medium_switch.first_frame);
    if (row != row_of_frame.end()) rows[row->second].medium_switch = true;
  }
  const StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate> current =
      estimator->Current();
  if (!current.ok()) return current.status();
  RefractiveIndexEstimate estimate = EstimateFromPooled(rig, *current);
  estimate.method = "sliding window of " +
                    std::to_string(options.window.window_frames) +
                    " frames, robust least squares on the refractive "
                    "epipolar loci, change of medium at z > " +
                    FormatFixed(options.window.change_threshold, 1);
  estimate.invalid = invalid;
  estimate.switches = estimator->switches();
  estimate.window =
      WindowSpan{current->frames, current->first_frame, current->last_frame};
  estimate.dropped_frames = estimator->num_dropped_frames();
  estimate.skipped_frames = estimator->num_skipped_frames();
  estimate.per_frame = std::move(rows);
  return estimate;
}

StatusOr<RefractiveIndexEstimate> RunClosedFormEstimator(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress) {
  PaperOnlineEstimator estimator(rig, options.closed_form);
  std::vector<FrameEstimateRow> rows;
  for (size_t i = 0; i < frames.size(); ++i) {
    for (const StereoCorrespondence& match : frames[i].matches) {
      estimator.Add(match);
    }
    const std::optional<PaperOnlineEstimator::Estimate> current =
        estimator.Current();
    FrameEstimateRow row{frames[i].frame, frames[i].timestamp};
    if (current) {
      row.n = current->n;
      row.sigma_n = current->standard_error;
    }
    rows.push_back(row);
    if (progress) progress(i + 1, frames.size());
  }
  const std::optional<PaperOnlineEstimator::Estimate> current =
      estimator.Current();
  if (!current) {
    return Status::Error(
        "no usable correspondence: " + std::to_string(estimator.num_masked()) +
        " removed by the observability mask, " +
        std::to_string(estimator.num_invalid()) +
        " invalid; matches near the image axes do not observe n (lower "
        "--mask-eta to keep more)");
  }
  RefractiveIndexEstimate estimate;
  estimate.port = "thin";
  estimate.method = "closed form (eq. 14), mask sqrt|u|sqrt|v| > " +
                    FormatFixed(options.closed_form.eta, 2) +
                    ", radially weighted mean (eq. 17)";
  estimate.n = current->n;
  estimate.sigma_n = current->standard_error;
  estimate.n_closed_form = current->n;
  estimate.inliers = estimator.num_used();
  estimate.invalid = estimator.num_invalid();
  estimate.masked = estimator.num_masked();
  estimate.mask_eta = options.closed_form.eta;
  estimate.per_frame = std::move(rows);
  const StereoRig::RectificationDeviation deviation =
      rig.DeviationFromRectified();
  const double deviation_deg =
      kEstimateDegreesPerRadian *
      std::max(deviation.rotation, deviation.baseline_off_axis);
  if (deviation_deg > kClosedFormRectifiedToleranceDeg) {
    estimate.warnings.push_back(
        "the rig is " + FormatFixed(deviation_deg, 2) +
        " deg from a rectified pair; the closed form assumes one and is "
        "biased on this rig");
  }
  return estimate;
}

}  // namespace

const char* EstimatorName(EstimatorKind kind) {
  switch (kind) {
    case EstimatorKind::kRefine:
      return "refine";
    case EstimatorKind::kOnline:
      return "online";
    case EstimatorKind::kWindow:
      return "window";
    case EstimatorKind::kClosedForm:
      return "closed-form";
    case EstimatorKind::kBundle:
      return "bundle";
  }
  return "unknown";
}

std::optional<EstimatorKind> EstimatorFromName(std::string_view name) {
  for (const EstimatorKind kind :
       {EstimatorKind::kRefine, EstimatorKind::kOnline, EstimatorKind::kWindow,
        EstimatorKind::kClosedForm, EstimatorKind::kBundle}) {
    if (name == EstimatorName(kind)) return kind;
  }
  return std::nullopt;
}

std::vector<FrameMatches> SplitFrames(
    const std::vector<StereoCorrespondence>& matches) {
  std::vector<FrameMatches> frames;
  for (const StereoCorrespondence& match : matches) {
    if (frames.empty() || frames.back().frame != match.frame) {
      frames.push_back({match.frame, match.timestamp, {}});
    }
    frames.back().matches.push_back(match);
  }
  return frames;
}

Status EstimationOptions::Check() const {
  RCM_RETURN_IF_ERROR(refinement.Check());
  RCM_RETURN_IF_ERROR(window.Check());
  RCM_RETURN_IF_ERROR(closed_form.Check());
  RCM_RETURN_IF_ERROR(bundle.Check().WithContext("bundle"));
  if (bundle_window < 0 || bundle_window == 1) {
    return Status::Error("bundle window = " + std::to_string(bundle_window) +
                         " keyframes must be 0 (every keyframe) or >= 2");
  }
  if (!bundle.refine_n) {
    return Status::Error(
        "the bundle's refine_n is false: an estimate of n estimates n (hold n "
        "with SequenceBundleAdjustment itself, for odometry)");
  }
  if (refinement.refine_rotation && estimator != EstimatorKind::kRefine) {
    return Status::Error(
        "refine_rotation works with the refine estimator only");
  }
  if (estimate_air_gap &&
      (estimator != EstimatorKind::kRefine || refinement.refine_rotation)) {
    return Status::Error(
        "estimate_air_gap works with the refine estimator only, without "
        "refine_rotation");
  }
  return Status::Ok();
}

StatusOr<RefractiveIndexEstimate> EstimateRefractiveIndex(
    const StereoRig& rig, const std::vector<FrameMatches>& frames,
    const EstimationOptions& options, const EstimationProgress& progress) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (options.estimator == EstimatorKind::kBundle) {
    return Status::Error(
        "the bundle estimator needs landmarks tracked over keyframes: images "
        "(--left and --right, or a bag), not matches");
  }
  if (rig.HasThickPort() && options.estimator != EstimatorKind::kRefine) {
    return Status::Error(
        std::string("the rig gives a thick port (an air gap or glass), which "
                    "only the refine estimator models; the ") +
        EstimatorName(options.estimator) +
        " estimator assumes the paper's thin port");
  }
  StatusOr<RefractiveIndexEstimate> estimate = Status::Error("not run");
  switch (options.estimator) {
    case EstimatorKind::kRefine:
      estimate = RunRefineEstimator(rig, frames, options, progress);
      break;
    case EstimatorKind::kOnline:
      estimate = RunOnlineEstimator(rig, frames, options, progress);
      break;
    case EstimatorKind::kWindow:
      estimate = RunWindowEstimator(rig, frames, options, progress);
      break;
    case EstimatorKind::kClosedForm:
      estimate = RunClosedFormEstimator(rig, frames, options, progress);
      break;
    case EstimatorKind::kBundle:
      break;  // refused above
  }
  if (!estimate.ok()) return estimate;
  estimate->estimator = EstimatorName(options.estimator);
  estimate->systematic_px = options.refinement.systematic_px;
  estimate->frames = static_cast<int64_t>(frames.size());
  int64_t correspondences = 0;
  for (const FrameMatches& frame : frames) {
    correspondences += static_cast<int64_t>(frame.matches.size());
  }
  estimate->correspondences = correspondences;
  for (std::string& warning : EstimateWarnings(*estimate)) {
    estimate->warnings.push_back(std::move(warning));
  }
  return estimate;
}

StatusOr<RefractiveIndexEstimate> EstimateRefractiveIndexFromTracks(
    const StereoRig& rig, const StereoTracks& tracks,
    const std::vector<KeyframeStamp>& keyframes,
    const EstimationOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (options.estimator != EstimatorKind::kBundle) {
    return Status::Error(std::string("tracks are the bundle estimator's, not "
                                     "the ") +
                         EstimatorName(options.estimator) + " estimator's");
  }
  if (static_cast<int>(keyframes.size()) != tracks.num_frames) {
    return Status::Error("the tracks have " +
                         std::to_string(tracks.num_frames) + " keyframes, " +
                         std::to_string(keyframes.size()) + " are stamped");
  }
  // A window of the last keyframes (the options), or every one.
  const StereoTracks* adjusted = &tracks;
  std::vector<KeyframeStamp> window_keyframes;
  StatusOr<StereoTracks> window = Status::Error("not windowed");
  if (options.bundle_window > 0 && options.bundle_window < tracks.num_frames) {
    const int first = tracks.num_frames - options.bundle_window;
    window = TracksInWindow(tracks, first, options.bundle_window);
    if (!window.ok()) return window.status();
    adjusted = &*window;
    window_keyframes.assign(keyframes.begin() + first, keyframes.end());
  }
  const std::vector<KeyframeStamp>& stamps =
      adjusted == &tracks ? keyframes : window_keyframes;
  SequenceBundleOptions bundle_options = options.bundle;
  bundle_options.num_threads = options.refinement.num_threads;
  // The tracks come from the front end: its systematic floor, the one
  // policy of every estimator (the refinement's, --systematic-px).
  bundle_options.systematic_px = options.refinement.systematic_px;
  StatusOr<SequenceBundleAdjustment> bundle =
      SequenceBundleAdjustment::Create(rig, bundle_options);
  if (!bundle.ok()) return bundle.status();
  StatusOr<SequenceBundleResult> result = bundle->Solve(*adjusted);
  if (!result.ok()) return result.status();

  RefractiveIndexEstimate estimate;
  estimate.estimator = EstimatorName(EstimatorKind::kBundle);
  estimate.port = rig.HasThickPort() ? "thick" : "thin";
  estimate.method =
      "bundle adjustment of landmarks tracked over keyframes (loss " +
      std::string(RobustLossName(bundle_options.loss)) + " " +
      FormatFixed(bundle_options.loss_scale_px, 2) + " px, inliers within " +
      FormatFixed(bundle_options.inlier_threshold_px, 2) + " px)";
  estimate.n = result->n;
  estimate.sigma_n = result->sigma_n;
  estimate.sigma_n_noise = result->sigma_n_noise;
  estimate.sigma_n_calibration = result->sigma_n_calibration;
  estimate.sigma_n_systematic = result->sigma_n_systematic;
  estimate.systematic_px = bundle_options.systematic_px;
  estimate.sigma_px = result->pixel_sigma;
  if (result->focal_scales_estimated) {
    FocalScaleCorrection focal;
    focal.scale = result->state.focal_scales;
    for (int c = 0; c < 2; ++c) {
      focal.sigma[c] = std::sqrt(result->focal_scale_covariance(c, c));
      focal.correlation_with_n[c] = result->correlation_n_focal_scales[c];
    }
    estimate.focal = focal;
  }
  estimate.inliers = result->num_inliers;
  estimate.correspondences = result->num_observations;
  estimate.frames = adjusted->num_frames;
  estimate.iterations = result->iterations;
  if (bundle_options.refine_rotation) {
    RotationCorrection rotation;
    rotation.angle_axis = result->state.cam1_rotation;
    rotation.sigma = result->rotation_covariance.diagonal().cwiseSqrt();
    for (int i = 0; i < 3; ++i) {
      rotation.correlation_with_n[i] =
          result->correlation_n_rotation_components[i];
    }
    rotation.multiple_correlation_with_n = result->correlation_n_rotation;
    rotation.with_prior = false;
    StatusOr<StereoRig> turned = rig.WithCam1Moved(result->state.cam1_rotation);
    if (turned.ok()) rotation.cam1_from_cam0 = turned->right_from_left();
    estimate.rotation = rotation;
  }
  BundleSummary summary;
  summary.frames_used = result->num_frames;
  summary.landmarks = result->num_landmarks;
  summary.observations = result->num_inliers;
  summary.motion = result->motion.Describe();
  summary.correlation_n_rotation = result->correlation_n_rotation;
  {
    std::vector<int> first(adjusted->num_landmarks, -1);
    std::vector<bool> tracked(adjusted->num_landmarks, false);
    for (const StereoTrackObservation& o : adjusted->observations) {
      if (!result->state.landmarks[o.landmark].allFinite()) continue;
      if (first[o.landmark] < 0) {
        first[o.landmark] = o.frame;
      } else if (first[o.landmark] != o.frame) {
        tracked[o.landmark] = true;
      }
    }
    summary.tracks = std::count(tracked.begin(), tracked.end(), true);
  }
  for (int k = 0; k < adjusted->num_frames; ++k) {
    summary.trajectory.push_back(
        {stamps[k].frame, stamps[k].timestamp, result->WorldFromCam0(k)});
  }
  estimate.bundle = std::move(summary);
  for (std::string& warning : EstimateWarnings(estimate)) {
    estimate.warnings.push_back(std::move(warning));
  }
  return estimate;
}

}  // namespace rcm
