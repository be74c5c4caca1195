#include "rcm/estimation/sliding_window_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

namespace rcm {
namespace {

// z between two independent estimates (header); a zero denominator (exact
// data) gives 0 for equal values and +inf otherwise.
double ChangeStatistic(double n_a, double sigma_a, double n_b, double sigma_b) {
  const double difference = std::abs(n_a - n_b);
  const double sigma = std::hypot(sigma_a, sigma_b);
  if (sigma > 0.0) return difference / sigma;
  return difference == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
}

}  // namespace

void SlidingWindowOptions::SetWindowFrames(int frames) {
  window_frames = frames;
  confirm_frames = std::min(confirm_frames, std::max(1, frames));
}

Status SlidingWindowOptions::Check() const {
  std::ostringstream error;
  if (window_frames < 1) {
    error << "the window needs at least 1 frame, got window_frames = "
          << window_frames;
  } else if (!(change_threshold > 0.0) || !std::isfinite(change_threshold)) {
    error << "change_threshold must be a positive number, got "
          << change_threshold;
  } else if (confirm_frames < 1 || confirm_frames > window_frames) {
    error << "confirm_frames must be between 1 and window_frames ("
          << window_frames << "), got " << confirm_frames;
  } else {
    return Status::Ok();
  }
  return Status::Error(error.str());
}

SlidingWindowRefractiveIndexEstimator::SlidingWindowRefractiveIndexEstimator(
    const StereoRig& rig, const RefinementOptions& options,
    const SlidingWindowOptions& window_options)
    : rig_(rig),
      options_(options),
      window_options_(window_options),
      window_(window_options.window_frames),
      window_normal_equations_(SelfCalibrationLayout(rig, options).Size()) {
  pending_.reserve(window_options.confirm_frames);
}

StatusOr<SlidingWindowRefractiveIndexEstimator>
SlidingWindowRefractiveIndexEstimator::Create(
    const StereoRig& rig, const RefinementOptions& options,
    const SlidingWindowOptions& window_options) {
  RCM_RETURN_IF_ERROR(options.Check());
  RCM_RETURN_IF_ERROR(window_options.Check());
  if (options.refine_rotation) {
    return Status::Error(
        "the sliding-window estimator estimates n alone: the rotation "
        "correction (refine_rotation) is available in the batch refinement "
        "only");
  }
  if (options.n_prior) {
    return Status::Error(
        "the sliding-window estimator estimates n from the data alone: the "
        "prior on n (the medium) is available in the batch refinement only");
  }
  return SlidingWindowRefractiveIndexEstimator(rig, options, window_options);
}

void SlidingWindowRefractiveIndexEstimator::ResumWindow() {
  window_cost_.Clear();
  window_normal_equations_ =
      LocusNormalEquations(window_normal_equations_.size());
  window_estimates_ = FrameEstimateSums();
  for (int k = 0; k < window_count_; ++k) {
    const FrameCost& frame = window_[(window_begin_ + k) % window_.size()];
    window_cost_.Add(frame.cost);
    if (rig_.calibration_uncertainty() || options_.systematic_px > 0.0) {
      window_normal_equations_.Add(frame.normal_equations);
    }
    window_estimates_.Add(frame.model.n, frame.model.information,
                          frame.model.coupling);
  }
}

void SlidingWindowRefractiveIndexEstimator::PushToWindow(
    const FrameCost& frame) {
  const int capacity = static_cast<int>(window_.size());
  if (window_count_ == capacity) {
    window_[window_begin_] = frame;
    window_begin_ = (window_begin_ + 1) % capacity;
  } else {
    window_[(window_begin_ + window_count_) % capacity] = frame;
    ++window_count_;
  }
  ResumWindow();
}

SlidingWindowRefractiveIndexEstimator::WindowUpdate
SlidingWindowRefractiveIndexEstimator::AddFrame(
    int64_t frame, const std::vector<StereoCorrespondence>& frame_matches) {
  WindowUpdate update;
  update.frame = frame;
  // The window's frames scatter by its consistency inflation beyond their
  // noise (cameras not triggered together on a moving rig, a scene that
  // moves): so does this frame, in its reported sigma and in the change
  // test. Its rows are taken at the window's LinearizationPoint (FitFrame).
  const StatusOr<Estimate> window = Current();
  const double inflation = window.ok() ? ScatterInflationOf(*window) : 1.0;
  if (window.ok()) linearization_.Follow(window->rotation);
  FrameFit fit =
      FitFrame(rig_, frame_matches, options_, linearization_.rotation);
  update.correspondences = fit.correspondences;
  update.usable = fit.usable;
  update.frame_estimate = FrameEstimateOf(rig_, fit, options_, inflation);
  if (!fit.estimate.ok()) {
    ++num_skipped_frames_;
    update.decision = Decision::kSkipped;
    update.window = window;
    return update;
  }
  FrameCost frame_cost;
  frame_cost.frame = frame;
  frame_cost.estimate = *fit.estimate;
  frame_cost.cost = fit.cost;
  frame_cost.normal_equations = fit.normal_equations;
  frame_cost.model = *fit.model;

  if (window.ok()) {
    // With a self-calibrated window, the frame's own n at the window's
    // rotation (FrameFit::Model).
    const double own_n =
        window->rotation
            ? frame_cost.model.At(SelfCalibrationOf(
                  *window->rotation,
                  window->focal_scale.value_or(Eigen::Vector2d::Zero())))
            : frame_cost.estimate.n;
    update.z = ChangeStatistic(own_n, inflation * frame_cost.estimate.sigma_n,
                               window->n, window->sigma_n_noise);
  }
  if (!update.z || *update.z <= window_options_.change_threshold) {
    num_dropped_frames_ += static_cast<int64_t>(pending_.size());
    pending_.clear();
    PushToWindow(frame_cost);
    update.decision = Decision::kAccepted;
    update.window = Current();
    return update;
  }

  // Inconsistent with the window: pending, with the frames before it when
  // it agrees with the last of them.
  if (!pending_.empty() &&
      ChangeStatistic(frame_cost.estimate.n,
                      inflation * frame_cost.estimate.sigma_n,
                      pending_.back().estimate.n,
                      inflation * pending_.back().estimate.sigma_n) >
          window_options_.change_threshold) {
    num_dropped_frames_ += static_cast<int64_t>(pending_.size());
    pending_.clear();
  }
  pending_.push_back(std::move(frame_cost));
  if (static_cast<int>(pending_.size()) < window_options_.confirm_frames) {
    update.decision = Decision::kPending;
    update.window = window;
    return update;
  }

  // A switch: the pending frames start the new window.
  MediumSwitch medium_switch;
  medium_switch.first_frame = pending_.front().frame;
  medium_switch.detected_at_frame = frame;
  medium_switch.n_before = window->n;
  const double n_last = pending_.back().estimate.n;
  window_begin_ = 0;
  window_count_ = 0;
  for (const FrameCost& pending : pending_) PushToWindow(pending);
  pending_.clear();
  update.window = Current();
  medium_switch.n_after = update.window.ok() ? update.window->n : n_last;
  switches_.push_back(medium_switch);
  update.decision = Decision::kSwitch;
  update.medium_switch = medium_switch;
  return update;
}

StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate>
SlidingWindowRefractiveIndexEstimator::Current() const {
  const StatusOr<CalibratedLocusEstimate> calibrated =
      EstimateWithCalibration(rig_, window_cost_, window_normal_equations_,
                              window_estimates_, options_);
  if (!calibrated.ok()) {
    return calibrated.status().WithContext(
        "window of " + std::to_string(window_count_) + " frames");
  }
  Estimate estimate;
  static_cast<PooledLocusEstimate&>(estimate) = PooledEstimateOf(*calibrated);
  estimate.frames = window_count_;
  estimate.first_frame = window_[window_begin_].frame;
  estimate.last_frame =
      window_[(window_begin_ + window_count_ - 1) % window_.size()].frame;
  return estimate;
}

size_t SlidingWindowRefractiveIndexEstimator::MemoryBytes() const {
  return sizeof(*this) + window_.capacity() * sizeof(FrameCost) +
         pending_.capacity() * sizeof(FrameCost) +
         switches_.capacity() * sizeof(MediumSwitch);
}

}  // namespace rcm
