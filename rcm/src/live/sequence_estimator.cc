#include "rcm/live/sequence_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <utility>

#include "rcm/estimation/estimate_warnings.h"

namespace rcm {
namespace {

double SequenceMilliseconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now() - start)
      .count();
}

void AddTimings(const FrontEndTimings& pair, FrontEndTimings* sum) {
  sum->preprocess_ms += pair.preprocess_ms;
  sum->detect_ms += pair.detect_ms;
  sum->match_ms += pair.match_ms;
  sum->refine_ms += pair.refine_ms;
  sum->total_ms += pair.total_ms;
}

}  // namespace

const std::vector<StereoCorrespondence>& SpreadSubset(
    const std::vector<StereoCorrespondence>& all, int cap,
    std::vector<StereoCorrespondence>* subset) {
  const size_t size = all.size();
  if (cap <= 0 || size <= static_cast<size_t>(cap)) return all;
  const size_t count = static_cast<size_t>(cap);
  subset->clear();
  subset->reserve(count);
  for (size_t k = 0; k < count; ++k) subset->push_back(all[k * size / count]);
  return *subset;
}

EstimationOptions SequenceEstimatorOptions::DefaultEstimation() {
  EstimationOptions options;
  options.refinement.systematic_px = kFrontEndSystematicPx;
  return options;
}

RefinementOptions SequenceEstimatorOptions::WindowRefinement() const {
  RefinementOptions window_refinement = estimation.refinement;
  window_refinement.refine_rotation = false;  // the window self-calibrates
  return window_refinement;
}

StereoFrontEndOptions SequenceEstimatorOptions::FrontEnd() const {
  StereoFrontEndOptions options = front_end;
  if (!keep_frames && options.max_refined_matches == 0) {
    options.max_refined_matches = window_matches;
  }
  return options;
}

Status SequenceEstimatorOptions::Check() const {
  RCM_RETURN_IF_ERROR(front_end.Check().WithContext("front end"));
  RCM_RETURN_IF_ERROR(estimation.Check().WithContext("estimator"));
  if (window_matches < 0) {
    return Status::Error("window matches must be >= 0, not " +
                         std::to_string(window_matches));
  }
  if (!(follow_rotation_px > 0.0)) {
    return Status::Error("the follow threshold must be > 0 pixels");
  }
  if (max_matching_passes < 1) {
    return Status::Error("matching passes must be >= 1, not " +
                         std::to_string(max_matching_passes));
  }
  RCM_RETURN_IF_ERROR(tracker.Check());
  if (estimation.estimator == EstimatorKind::kBundle && !keep_frames) {
    return Status::Error(
        "the bundle estimator needs the pairs kept (keep_frames): it is not "
        "a live window");
  }
  return Status::Ok();
}

StatusOr<std::unique_ptr<SequenceEstimator>> SequenceEstimator::Create(
    const StereoRig& rig, const SequenceEstimatorOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<StereoDetector> detector =
      StereoDetector::Create(options.FrontEnd());
  if (!detector.ok()) return detector.status();
  StatusOr<StereoFrontEnd> front_end =
      StereoFrontEnd::Create(rig, options.FrontEnd());
  if (!front_end.ok()) return front_end.status();
  StatusOr<SlidingWindowRefractiveIndexEstimator> window =
      SlidingWindowRefractiveIndexEstimator::Create(
          rig, options.WindowRefinement(), options.estimation.window);
  if (!window.ok()) return window.status();
  std::unique_ptr<SequenceEstimator> sequence(
      new SequenceEstimator(rig, options, std::move(*detector),
                            std::move(*front_end), std::move(*window)));
  RCM_RETURN_IF_ERROR(sequence->ResetTracker());
  return sequence;
}

SequenceEstimator::SequenceEstimator(
    const StereoRig& rig, const SequenceEstimatorOptions& options,
    StereoDetector detector, StereoFrontEnd front_end,
    SlidingWindowRefractiveIndexEstimator window)
    : rig_(rig),
      options_(options),
      detector_(std::move(detector)),
      front_end_(std::move(front_end)),
      window_(std::move(window)) {}

double SequenceEstimator::RotationPixels(const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b) const {
  const double focal = std::max({rig_.left().fx(), rig_.left().fy(),
                                 rig_.right().fx(), rig_.right().fy()});
  return (a - b).norm() * focal;
}

Status SequenceEstimator::ResetTracker() {
  tracker_.reset();
  if (options_.estimation.estimator != EstimatorKind::kBundle) {
    return Status::Ok();
  }
  StatusOr<StereoTracker> tracker =
      StereoTracker::Create(rig_, options_.tracker);
  if (!tracker.ok()) return tracker.status();
  tracker_ = std::move(*tracker);
  return Status::Ok();
}

Status SequenceEstimator::Restart(const Eigen::Vector3d& rotation) {
  StatusOr<SlidingWindowRefractiveIndexEstimator> window =
      SlidingWindowRefractiveIndexEstimator::Create(
          rig_, options_.WindowRefinement(), options_.estimation.window);
  if (!window.ok()) return window.status();
  StatusOr<StereoRig> turned = rig_.WithCam1Moved(rotation);
  if (!turned.ok()) return turned.status();
  StatusOr<StereoFrontEnd> front_end =
      StereoFrontEnd::Create(*turned, options_.FrontEnd());
  if (!front_end.ok()) return front_end.status();
  window_ = std::move(*window);
  front_end_ = std::move(*front_end);
  guide_.reset();
  followed_ = rotation;
  first_ = rotation;
  any_pair_ = false;
  frames_.clear();
  own_rows_.clear();
  medium_first_.reset();
  return ResetTracker();
}

StatusOr<SequencePair> SequenceEstimator::AddPair(
    const cv::Mat& left, const cv::Mat& right, int64_t frame,
    std::optional<double> timestamp) {
  const auto start = std::chrono::steady_clock::now();
  StatusOr<DetectedStereoPair> detected =
      Detect(left, right, front_end_.options().num_threads);
  if (!detected.ok()) return detected.status();
  const double detect_ms = SequenceMilliseconds(start);
  StatusOr<SequencePair> pair = AddDetectedPair(*detected, frame, timestamp);
  // The front end's whole time: stages 1-2 here, 3-5 in AddDetectedPair.
  if (pair.ok()) pair->timings.total_ms += detect_ms;
  return pair;
}

StatusOr<DetectedStereoPair> SequenceEstimator::Detect(const cv::Mat& left,
                                                       const cv::Mat& right,
                                                       int num_threads) {
  return detector_.Detect(left, right, num_threads);
}

StatusOr<SequencePair> SequenceEstimator::AddDetectedPair(
    const DetectedStereoPair& detected, int64_t frame,
    std::optional<double> timestamp) {
  // 1. Matches within the guide's band.
  StatusOr<StereoMatches> matched =
      front_end_.Match(detected, frame, timestamp, guide_);
  if (!matched.ok()) return matched.status();
  if (!any_pair_) {
    first_ = followed_;
    any_pair_ = true;
  }
  SequencePair pair;
  pair.frame = frame;
  pair.timestamp = timestamp;
  pair.reacquired = matched->reacquired;
  pair.timings = matched->timings;
  if (tracker_) {
    StatusOr<int> continued = tracker_->AddKeyframe(detected, *matched);
    if (!continued.ok()) return continued.status();
    pair.continued_tracks = *continued;
  }

  // 2. The window: the pair's own estimate (the next guide), the window's
  // and a change of medium.
  const auto estimate_start = std::chrono::steady_clock::now();
  const std::vector<StereoCorrespondence>& subset =
      SpreadSubset(matched->matches, options_.window_matches, &subset_);
  pair.num_estimated = static_cast<int64_t>(subset.size());
  SlidingWindowRefractiveIndexEstimator::WindowUpdate update =
      window_.AddFrame(frame, subset);
  pair.estimate_ms = SequenceMilliseconds(estimate_start);
  if (update.frame_estimate.ok()) {
    guide_ =
        NextPairGuide(update.frame_estimate->n, update.frame_estimate->sigma_n);
  } else {
    guide_.reset();  // back to the prior search range
  }
  pair.own = std::move(update.frame_estimate);
  pair.window = std::move(update.window);
  pair.medium_switch = update.medium_switch;
  if (pair.medium_switch) medium_first_ = pair.medium_switch->first_frame;

  // 3. Follow a turned cam1.
  if (pair.window.ok() && pair.window->rotation &&
      RotationPixels(*pair.window->rotation, followed_) >
          options_.follow_rotation_px) {
    StatusOr<StereoRig> turned = rig_.WithCam1Moved(*pair.window->rotation);
    if (turned.ok()) {
      StatusOr<StereoFrontEnd> front_end =
          StereoFrontEnd::Create(*turned, options_.FrontEnd());
      if (front_end.ok()) {
        front_end_ = std::move(*front_end);
        followed_ = *pair.window->rotation;
        pair.followed = true;
      }
    }
  }

  // 4. Kept for the final estimate.
  if (options_.keep_frames) {
    FrameEstimateRow row{frame, timestamp};
    if (pair.own.ok()) {
      row.n = pair.own->n;
      row.sigma_n = pair.own->sigma_n;
    }
    own_rows_.push_back(row);
    frames_.push_back({frame, timestamp, matched->matches});
  }
  pair.matches = std::move(matched->matches);
  return pair;
}

StatusOr<RefractiveIndexEstimate> SequenceEstimator::Estimate() const {
  if (!options_.keep_frames) {
    const StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate> current =
        window_.Current();
    if (!current.ok()) return current.status();
    RefractiveIndexEstimate estimate = EstimateFromPooled(rig_, *current);
    estimate.estimator = EstimatorName(EstimatorKind::kWindow);
    estimate.method = "the sequence's sliding window";
    estimate.window =
        WindowSpan{current->frames, current->first_frame, current->last_frame};
    estimate.switches = window_.switches();
    estimate.frames = current->frames;
    estimate.warnings = EstimateWarnings(estimate);
    return estimate;
  }
  // The frames of the current medium (the window estimator: all).
  const bool all =
      options_.estimation.estimator == EstimatorKind::kWindow || !medium_first_;
  std::vector<FrameMatches> since;
  std::vector<FrameEstimateRow> rows;
  for (size_t i = 0; i < frames_.size(); ++i) {
    if (all || frames_[i].frame >= *medium_first_) {
      since.push_back(frames_[i]);
      rows.push_back(own_rows_[i]);
    }
  }
  EstimationOptions options = options_.estimation;
  options.per_frame_estimates = false;  // the pairs' own estimates
  std::optional<std::string> bundle_refused;
  if (options.estimator == EstimatorKind::kBundle) {
    // Every kept pair is a keyframe (the bundle keeps them all).
    std::vector<KeyframeStamp> keyframes;
    for (const FrameMatches& kept : frames_) {
      keyframes.push_back({kept.frame, kept.timestamp});
    }
    StatusOr<RefractiveIndexEstimate> bundle =
        EstimateRefractiveIndexFromTracks(rig_, tracker_->tracks(), keyframes,
                                          options);
    if (bundle.ok()) {
      bundle->per_frame = own_rows_;
      return bundle;
    }
    // The epipolar estimate, with the bundle's reason (header).
    bundle_refused = bundle.status().message();
    options.estimator = EstimatorKind::kRefine;
  }
  StatusOr<RefractiveIndexEstimate> estimate =
      EstimateRefractiveIndex(rig_, since, options);
  if (!estimate.ok()) return estimate;
  if (bundle_refused) {
    estimate->warnings.insert(estimate->warnings.begin(),
                              "the bundle estimator: " + *bundle_refused +
                                  "; this is the refine estimate");
  }
  if (options.estimator == EstimatorKind::kRefine) {
    estimate->per_frame = std::move(rows);
  }
  return estimate;
}

StatusOr<SequenceRun> EstimateSequence(const StereoRig& rig,
                                       StereoImageSource* source,
                                       const SequenceEstimatorOptions& options,
                                       const SequenceProgress& progress) {
  StatusOr<std::unique_ptr<SequenceEstimator>> created =
      SequenceEstimator::Create(rig, options);
  if (!created.ok()) return created.status();
  SequenceEstimator& sequence = **created;
  SequenceRun run;
  const size_t pairs = source->NumPairs();
  Eigen::Vector3d start_rotation = Eigen::Vector3d::Zero();
  for (int pass = 1;; ++pass) {
    if (pass > 1) RCM_RETURN_IF_ERROR(sequence.Restart(start_rotation));
    run = SequenceRun();
    run.passes = pass;
    const auto start = std::chrono::steady_clock::now();
    // The next pair is decoded and detected (the front end's stages 1-2,
    // which do not depend on the guide) on another thread while this one is
    // matched and estimated: one read at a time, the source read in order,
    // never by two threads at once; one thread for the detection, the
    // matching has the others.
    struct Read {
      StatusOr<StereoImagePair> images = Status::Error("not read");
      StatusOr<DetectedStereoPair> detected = Status::Error("not detected");
      double ms = 0.0;
    };
    const auto read = [source, &sequence](size_t i) {
      const auto read_start = std::chrono::steady_clock::now();
      Read result{source->ReadPair(i), Status::Error("not detected"), 0.0};
      result.ms = SequenceMilliseconds(read_start);
      if (result.images.ok()) {
        result.detected =
            sequence.Detect(result.images->left, result.images->right, 1);
      }
      return result;
    };
    std::future<Read> next;
    if (pairs > 0) next = std::async(std::launch::async, read, size_t{0});
    for (size_t i = 0; i < pairs; ++i) {
      Read current = next.get();
      if (!current.images.ok()) return current.images.status();
      if (i + 1 < pairs) next = std::async(std::launch::async, read, i + 1);
      run.read_ms += current.ms;
      const StereoImagePair& images = *current.images;
      StatusOr<SequencePair> pair =
          current.detected.ok()
              ? sequence.AddDetectedPair(*current.detected, images.frame,
                                         images.timestamp)
              : StatusOr<SequencePair>(current.detected.status());
      if (!pair.ok()) {
        return pair.status().WithContext(images.left_name + " and " +
                                         images.right_name);
      }
      AddTimings(pair->timings, &run.timings);
      run.estimate_ms += pair->estimate_ms;
      run.reacquired += pair->reacquired ? 1 : 0;
      if (progress) progress(pass, i + 1, pairs, images, *pair);
    }
    run.seconds = SequenceMilliseconds(start) / 1000.0;
    run.estimate = sequence.Estimate();
    run.frames = sequence.frames();
    run.matching_rotation = sequence.first_matching_rotation();
    // Match again from the start when the rotation found moves pixels
    // beyond the band's tolerance from the one the first pair had.
    if (pass >= options.max_matching_passes || !run.estimate.ok() ||
        !run.estimate->rotation || !run.estimate->rotation->with_prior) {
      break;
    }
    const Eigen::Vector3d& found = run.estimate->rotation->angle_axis;
    if (sequence.RotationPixels(found, sequence.first_matching_rotation()) <=
        options.follow_rotation_px) {
      break;
    }
    start_rotation = found;
  }
  return run;
}

}  // namespace rcm
