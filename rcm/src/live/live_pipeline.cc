#include "rcm/live/live_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

#include "rcm/estimation/estimate_warnings.h"
#include "rcm/frontend/image_preprocessing.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

double Milliseconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now() - start)
      .count();
}

// The gray standard deviation of an 8-bit image of 1, 3 or 4 channels
// (its first channel: a blank frame is blank in every channel), on every
// 4th pixel of every 4th row: a blank frame is told from a scene in
// ~0.05 ms instead of ~0.8 ms for 720x540.
double Contrast(const cv::Mat& image) {
  const int channels = image.channels();
  double sum = 0.0;
  double sum_sq = 0.0;
  int64_t count = 0;
  for (int y = 0; y < image.rows; y += 4) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = 0; x < image.cols; x += 4) {
      const double v = row[x * channels];
      sum += v;
      sum_sq += v * v;
      ++count;
    }
  }
  if (count == 0) return 0.0;
  const double mean = sum / count;
  return std::sqrt(std::max(0.0, sum_sq / count - mean * mean));
}

}  // namespace

SequenceEstimatorOptions LiveSequenceOptions(
    const LivePipelineOptions& options) {
  SequenceEstimatorOptions sequence;
  sequence.front_end = options.front_end;
  sequence.estimation.estimator = EstimatorKind::kWindow;
  sequence.estimation.refinement = options.refinement;
  sequence.estimation.window = options.window;
  sequence.window_matches = options.window_matches;
  sequence.keep_frames = false;
  return sequence;
}

RefinementOptions LivePipelineOptions::DefaultRefinement() {
  RefinementOptions options;
  options.systematic_px = kFrontEndSystematicPx;
  // The window on the caller's thread alone: the budget is CPU time, and a
  // second thread adds more CPU than it saves in wall time (live_benchmark:
  // window + remaps of ~1200 matches 17.4 ms of CPU on one thread, 18.4-21.6
  // ms on two); the other core has the front end's second thread and the
  // map worker.
  options.num_threads = 1;
  return options;
}

VirtualPinholeRigOptions LivePipelineOptions::DefaultCorrection() {
  VirtualPinholeRigOptions options;
  options.rectify = true;
  options.num_threads = 1;  // the worker's: the caller keeps the other core
  return options;
}

Status LivePipelineOptions::Check() const {
  RCM_RETURN_IF_ERROR(front_end.Check().WithContext("front end"));
  RCM_RETURN_IF_ERROR(refinement.Check().WithContext("estimator"));
  if (refinement.refine_rotation) {
    return Status::Error(
        "estimator: the live pipeline's window cannot refine the rotation "
        "(it self-calibrates it from the drift prior)");
  }
  RCM_RETURN_IF_ERROR(window.Check().WithContext("window"));
  RCM_RETURN_IF_ERROR(correction.Check().WithContext("correction"));
  if (!(initial_n >= 1.0 && initial_n <= 2.0)) {
    return Status::Error("initial n must be in [1, 2], not " +
                         FormatDouble(initial_n));
  }
  if (!(map_update_threshold > 0.0) || !std::isfinite(map_update_threshold)) {
    return Status::Error(
        "the map update threshold must be positive and finite, not " +
        FormatDouble(map_update_threshold));
  }
  if (!(map_update_sigmas >= 0.0) || !std::isfinite(map_update_sigmas)) {
    return Status::Error("the map update sigmas must be >= 0 and finite, not " +
                         FormatDouble(map_update_sigmas));
  }
  if (window_matches < 0) {
    return Status::Error("window matches must be >= 0, not " +
                         std::to_string(window_matches));
  }
  if (!(min_contrast >= 0.0) || !std::isfinite(min_contrast)) {
    return Status::Error("min contrast must be >= 0 and finite, not " +
                         FormatDouble(min_contrast));
  }
  return Status::Ok();
}

StatusOr<std::unique_ptr<LivePipeline>> LivePipeline::Create(
    const StereoRig& rig, const LivePipelineOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<std::unique_ptr<SequenceEstimator>> sequence =
      SequenceEstimator::Create(rig, LiveSequenceOptions(options));
  if (!sequence.ok()) return sequence.status();
  StatusOr<VirtualPinholeRig> maps =
      VirtualPinholeRig::Create(rig, options.initial_n, options.correction);
  if (!maps.ok()) {
    return maps.status().WithContext("the corrected pair at n = " +
                                     FormatDouble(options.initial_n));
  }
  return std::unique_ptr<LivePipeline>(new LivePipeline(
      rig, options, std::move(*sequence),
      std::make_shared<const VirtualPinholeRig>(std::move(*maps))));
}

LivePipeline::LivePipeline(const StereoRig& rig,
                           const LivePipelineOptions& options,
                           std::unique_ptr<SequenceEstimator> sequence,
                           std::shared_ptr<const VirtualPinholeRig> maps)
    : rig_(rig),
      options_(options),
      sequence_(std::move(sequence)),
      maps_(std::move(maps)) {}

LivePipeline::~LivePipeline() {
  if (pending_.valid()) pending_.wait();
}

void LivePipeline::StartBuild(double n) {
  pending_n_ = n;
  pending_ = std::async(std::launch::async,
                        [rig = rig_, n, options = options_.correction]() {
                          return VirtualPinholeRig::Create(rig, n, options);
                        });
}

bool LivePipeline::CollectBuild(bool wait) {
  if (!pending_.valid()) return false;
  if (!wait &&
      pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    return false;
  }
  StatusOr<VirtualPinholeRig> built = pending_.get();
  if (!built.ok()) {
    ++num_failed_builds_;
    return false;
  }
  maps_ = std::make_shared<const VirtualPinholeRig>(std::move(*built));
  return true;
}

void LivePipeline::SetHold(bool hold) {
  if (hold && pending_.valid()) {
    const StatusOr<VirtualPinholeRig> discarded = pending_.get();
    (void)discarded;
  }
  hold_ = hold;
}

bool LivePipeline::WaitForMaps() { return CollectBuild(/*wait=*/true); }

Status LivePipeline::Reset(std::optional<double> n) {
  if (n && !(*n >= 1.0 && *n <= 2.0)) {
    return Status::Error("reset: n must be in [1, 2], not " + FormatDouble(*n));
  }
  // A new window and no guide; the front end keeps following the
  // rotation it follows.
  RCM_RETURN_IF_ERROR(sequence_->Restart(sequence_->matching_rotation()));
  if (n && std::abs(*n - maps_->n()) > 0.0) {
    CollectBuild(/*wait=*/true);
    StartBuild(*n);
  }
  return Status::Ok();
}

StatusOr<LiveFrame> LivePipeline::Process(const cv::Mat& left,
                                          const cv::Mat& right, double stamp) {
  // 1. The pair.
  Status valid = CheckStereoImages(left, right);
  const Camera& camera = rig_.left();
  if (valid.ok() &&
      (left.cols != camera.width() || left.rows != camera.height())) {
    valid =
        Status::Error("the images are " + std::to_string(left.cols) + " x " +
                      std::to_string(left.rows) + ", the calibration's " +
                      std::to_string(camera.width()) + " x " +
                      std::to_string(camera.height()));
  }
  if (valid.ok() && options_.min_contrast > 0.0) {
    const double contrast = std::min(Contrast(left), Contrast(right));
    if (contrast < options_.min_contrast) {
      valid = Status::Error("a blank pair (gray standard deviation " +
                            FormatFixed(contrast, 2) + " < " +
                            FormatFixed(options_.min_contrast, 2) +
                            "): a black, saturated or covered frame");
    }
  }
  if (!valid.ok()) {
    ++num_refused_;
    return valid;
  }

  // 2-3. Matches and the window (the sequence engine).
  LiveFrame out;
  out.stamp = stamp;
  const auto match_start = std::chrono::steady_clock::now();
  StatusOr<SequencePair> pair =
      sequence_->AddPair(left, right, next_frame_, stamp);
  if (!pair.ok()) {
    ++num_refused_;
    return pair.status();
  }
  out.estimate_ms = pair->estimate_ms;
  out.match_ms = Milliseconds(match_start) - pair->estimate_ms;
  out.frame = next_frame_++;
  out.num_matches = static_cast<int64_t>(pair->matches.size());
  out.num_estimated = pair->num_estimated;
  out.estimate = std::move(pair->window);
  out.medium_switch = pair->medium_switch;
  if (out.estimate.ok()) {
    out.warnings = EstimateWarnings(EstimateFromPooled(rig_, *out.estimate));
  }
  out.held = hold_;

  // 4. The maps, then the corrected pair.
  out.maps_updated = CollectBuild(/*wait=*/false);
  if (!hold_ && out.estimate.ok() && !pending_.valid() &&
      std::abs(out.estimate->n - maps_->n()) >
          std::max(options_.map_update_threshold,
                   options_.map_update_sigmas * out.estimate->sigma_n_noise)) {
    StartBuild(out.estimate->n);
  }
  const auto remap_start = std::chrono::steady_clock::now();
  maps_->left().Correct(left, &left_corrected_);
  maps_->right().Correct(right, &right_corrected_);
  out.remap_ms = Milliseconds(remap_start);
  out.left_corrected = left_corrected_;
  out.right_corrected = right_corrected_;
  out.corrected = maps_;
  out.maps_n = maps_->n();
  return out;
}

}  // namespace rcm
