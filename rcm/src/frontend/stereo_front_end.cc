#include "rcm/frontend/stereo_front_end.h"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <utility>

#include "rcm/util/parallel_for.h"

namespace rcm {

RefractiveIndexInterval NextPairGuide(double n, double sigma_n) {
  constexpr double kGuideSigmas = 6.0;
  constexpr double kGuideMinHalfWidth = 0.01;
  return RefractiveIndexInterval::Around(n, sigma_n, kGuideSigmas,
                                         kGuideMinHalfWidth);
}

namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start)
      .count();
}

// Stages 1-2 of one image.
struct ImageFeatures {
  cv::Mat gray;
  Features features;
  double preprocess_ms = 0.0;
  double detect_ms = 0.0;
};

ImageFeatures DetectImage(const cv::Mat& image, const ClaheOptions& clahe,
                          FeatureDetector* detector) {
  ImageFeatures out;
  const Clock::time_point start = Clock::now();
  out.gray = PreprocessImage(image, clahe);
  out.preprocess_ms = MillisecondsSince(start);
  const Clock::time_point detect = Clock::now();
  out.features = detector->Detect(out.gray);
  out.detect_ms = MillisecondsSince(detect);
  return out;
}

// Images of the size the rig is calibrated for.
Status CheckCalibratedSize(const StereoRig& rig, const cv::Mat& left,
                           const cv::Mat& right) {
  if (left.cols == rig.left().width() && left.rows == rig.left().height() &&
      right.cols == rig.right().width() && right.rows == rig.right().height()) {
    return Status::Ok();
  }
  std::ostringstream message;
  message << "images are " << left.cols << " x " << left.rows
          << " but the calibration is for " << rig.left().width() << " x "
          << rig.left().height() << " (left) and " << rig.right().width()
          << " x " << rig.right().height() << " (right)";
  return Status::Error(message.str());
}

// Stage 3 in the band of one interval, with what verification reuses.
struct BandMatches {
  LocusBand band;
  std::vector<LocusKey> left_keys;
  std::vector<KeypointMatch> matches;
};

}  // namespace

Status StereoFrontEndOptions::Check() const {
  RCM_RETURN_IF_ERROR(clahe.Check());
  RCM_RETURN_IF_ERROR(features.Check());
  RCM_RETURN_IF_ERROR(band.Check());
  RCM_RETURN_IF_ERROR(matching.Check());
  RCM_RETURN_IF_ERROR(subpixel.Check());
  RCM_RETURN_IF_ERROR(search_range.Check().WithContext("search range"));
  if (!(reacquire_fraction >= 0.0 && reacquire_fraction <= 1.0)) {
    return Status::Error("re-acquisition fraction must be in [0, 1]");
  }
  if (max_refined_matches < 0) {
    return Status::Error("max refined matches must be >= 0, got " +
                         std::to_string(max_refined_matches));
  }
  if (num_threads < 1) {
    return Status::Error("threads must be at least 1, got " +
                         std::to_string(num_threads));
  }
  return Status::Ok();
}

StatusOr<StereoDetector> StereoDetector::Create(
    const StereoFrontEndOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<FeatureDetector> left = FeatureDetector::Create(options.features);
  RCM_RETURN_IF_ERROR(left.status());
  StatusOr<FeatureDetector> right = FeatureDetector::Create(options.features);
  RCM_RETURN_IF_ERROR(right.status());
  return StereoDetector(options.clahe, std::move(*left), std::move(*right));
}

StatusOr<DetectedStereoPair> StereoDetector::Detect(const cv::Mat& left,
                                                    const cv::Mat& right,
                                                    int num_threads) {
  RCM_RETURN_IF_ERROR(CheckStereoImages(left, right));
  // Stages 1-2, the two images at once.
  ImageFeatures sides[2];
  const cv::Mat* images[2] = {&left, &right};
  FeatureDetector* detectors[2] = {&left_, &right_};
  ParallelFor(2, num_threads, 1, [&](int64_t first, int64_t last) {
    for (int64_t side = first; side < last; ++side) {
      sides[side] = DetectImage(*images[side], clahe_, detectors[side]);
    }
  });
  DetectedStereoPair detected;
  for (int side = 0; side < 2; ++side) {
    detected.gray[side] = std::move(sides[side].gray);
    detected.features[side] = std::move(sides[side].features);
  }
  detected.preprocess_ms =
      std::max(sides[0].preprocess_ms, sides[1].preprocess_ms);
  detected.detect_ms = std::max(sides[0].detect_ms, sides[1].detect_ms);
  return detected;
}

StatusOr<StereoFrontEnd> StereoFrontEnd::Create(
    const StereoRig& rig, const StereoFrontEndOptions& options) {
  StatusOr<StereoDetector> detector = StereoDetector::Create(options);
  RCM_RETURN_IF_ERROR(detector.status());
  return StereoFrontEnd(rig, options, std::move(*detector));
}

StatusOr<StereoMatches> StereoFrontEnd::Match(
    const cv::Mat& left, const cv::Mat& right, int64_t frame,
    std::optional<double> timestamp,
    const std::optional<RefractiveIndexInterval>& guide) {
  const Clock::time_point start = Clock::now();
  RCM_RETURN_IF_ERROR(CheckStereoImages(left, right));
  RCM_RETURN_IF_ERROR(CheckCalibratedSize(rig_, left, right));
  StatusOr<DetectedStereoPair> detected =
      detector_.Detect(left, right, options_.num_threads);
  RCM_RETURN_IF_ERROR(detected.status());
  StatusOr<StereoMatches> matched = Match(*detected, frame, timestamp, guide);
  if (matched.ok()) matched->timings.total_ms = MillisecondsSince(start);
  return matched;
}

StatusOr<StereoMatches> StereoFrontEnd::Match(
    const DetectedStereoPair& detected, int64_t frame,
    std::optional<double> timestamp,
    const std::optional<RefractiveIndexInterval>& guide) {
  const Clock::time_point start = Clock::now();
  const cv::Mat& left = detected.gray[0];
  const cv::Mat& right = detected.gray[1];
  RCM_RETURN_IF_ERROR(CheckCalibratedSize(rig_, left, right));
  if (guide) RCM_RETURN_IF_ERROR(guide->Check().WithContext("guide"));
  const Features* features = detected.features;
  StereoMatches result;
  result.left_keypoints = static_cast<int>(features[0].keypoints.size());
  result.right_keypoints = static_cast<int>(features[1].keypoints.size());
  result.timings.preprocess_ms = detected.preprocess_ms;
  result.timings.detect_ms = detected.detect_ms;

  // Stage 3 in a band; the band's keys are cheap (one undistortion per
  // keypoint) next to detection.
  const Clock::time_point match_start = Clock::now();
  const auto match_in =
      [&](const RefractiveIndexInterval& interval) -> StatusOr<BandMatches> {
    StatusOr<LocusBand> band = LocusBand::Create(rig_, interval, options_.band);
    RCM_RETURN_IF_ERROR(band.status());
    std::vector<LocusKey> left_keys = band->LeftKeys(features[0].keypoints);
    const std::vector<LocusKey> right_keys =
        band->RightKeys(features[1].keypoints);
    std::vector<KeypointMatch> matches =
        MatchInLocusBand(features[0], left_keys, features[1], right_keys, *band,
                         options_.matching);
    return BandMatches{std::move(*band), std::move(left_keys),
                       std::move(matches)};
  };
  StatusOr<BandMatches> matched =
      match_in(guide ? *guide : options_.search_range);
  RCM_RETURN_IF_ERROR(matched.status());
  if (!guide) {
    prior_band_matches_ = static_cast<int>(matched->matches.size());
  } else if (prior_band_matches_ > 0 &&
             matched->matches.size() <
                 options_.reacquire_fraction * prior_band_matches_) {
    StatusOr<BandMatches> prior = match_in(options_.search_range);
    RCM_RETURN_IF_ERROR(prior.status());
    if (prior->matches.size() > matched->matches.size()) {
      prior_band_matches_ = static_cast<int>(prior->matches.size());
      matched = std::move(prior);
      result.reacquired = true;
    }
  }
  const LocusBand& band = matched->band;
  result.band = band.interval();
  result.descriptor_matches = static_cast<int>(matched->matches.size());
  result.timings.match_ms = MillisecondsSince(match_start);

  // Stages 4-5.
  const Clock::time_point refine_start = Clock::now();
  // The matches refined: all, or every k-th (SpreadSubset's rule).
  std::vector<KeypointMatch>& descriptor_matches = matched->matches;
  const size_t size = descriptor_matches.size();
  const size_t cap = static_cast<size_t>(options_.max_refined_matches);
  if (cap > 0 && size > cap) {
    for (size_t k = 0; k < cap; ++k) {
      descriptor_matches[k] = descriptor_matches[k * size / cap];
    }
    descriptor_matches.resize(cap);
  }
  std::vector<cv::Point2f> left_points;
  std::vector<cv::Point2f> right_points;
  left_points.reserve(descriptor_matches.size());
  right_points.reserve(descriptor_matches.size());
  for (const KeypointMatch& match : descriptor_matches) {
    left_points.push_back(features[0].keypoints[match.left].pt);
    right_points.push_back(features[1].keypoints[match.right].pt);
  }
  std::vector<unsigned char> kept;
  RefineRightPixels(left, right, left_points, &right_points, &kept,
                    options_.subpixel);
  result.matches.reserve(left_points.size());
  result.left_keypoints_of_matches.reserve(left_points.size());
  for (size_t i = 0; i < left_points.size(); ++i) {
    if (!kept[i]) continue;
    StereoCorrespondence correspondence;
    correspondence.frame = frame;
    correspondence.timestamp = timestamp;
    correspondence.left_pixel =
        Eigen::Vector2d(left_points[i].x, left_points[i].y);
    correspondence.right_pixel =
        Eigen::Vector2d(right_points[i].x, right_points[i].y);
    // The left pixel is the keypoint's: its key is the one matched with.
    const LocusKey& left_key = matched->left_keys[descriptor_matches[i].left];
    if (!band.Contains(left_key, band.RightKey(correspondence.right_pixel))) {
      continue;
    }
    result.matches.push_back(correspondence);
    result.left_keypoints_of_matches.push_back(descriptor_matches[i].left);
  }
  result.timings.refine_ms = MillisecondsSince(refine_start);
  result.timings.total_ms = MillisecondsSince(start);
  return result;
}

}  // namespace rcm
