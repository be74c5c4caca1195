#include "rcm/frontend/stereo_front_end.h"

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

StatusOr<StereoFrontEnd> StereoFrontEnd::Create(
    const StereoRig& rig, const StereoFrontEndOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<FeatureDetector> left = FeatureDetector::Create(options.features);
  RCM_RETURN_IF_ERROR(left.status());
  StatusOr<FeatureDetector> right = FeatureDetector::Create(options.features);
  RCM_RETURN_IF_ERROR(right.status());
  return StereoFrontEnd(rig, options, std::move(*left), std::move(*right));
}

StatusOr<StereoMatches> StereoFrontEnd::Match(
    const cv::Mat& left, const cv::Mat& right, int64_t frame,
    std::optional<double> timestamp,
    const std::optional<RefractiveIndexInterval>& guide) {
  const Clock::time_point start = Clock::now();
  RCM_RETURN_IF_ERROR(CheckStereoImages(left, right));
  if (left.cols != rig_.left().width() || left.rows != rig_.left().height() ||
      right.cols != rig_.right().width() ||
      right.rows != rig_.right().height()) {
    std::ostringstream message;
    message << "images are " << left.cols << " x " << left.rows
            << " but the calibration is for " << rig_.left().width() << " x "
            << rig_.left().height() << " (left) and " << rig_.right().width()
            << " x " << rig_.right().height() << " (right)";
    return Status::Error(message.str());
  }
  if (guide) RCM_RETURN_IF_ERROR(guide->Check().WithContext("guide"));

  // Stages 1-2, the two images at once.
  ImageFeatures sides[2];
  const cv::Mat* images[2] = {&left, &right};
  FeatureDetector* detectors[2] = {&left_detector_, &right_detector_};
  ParallelFor(2, options_.num_threads, 1, [&](int64_t first, int64_t last) {
    for (int64_t side = first; side < last; ++side) {
      sides[side] = DetectImage(*images[side], options_.clahe, detectors[side]);
    }
  });
  StereoMatches result;
  result.left_keypoints = static_cast<int>(sides[0].features.keypoints.size());
  result.right_keypoints = static_cast<int>(sides[1].features.keypoints.size());
  result.timings.preprocess_ms =
      std::max(sides[0].preprocess_ms, sides[1].preprocess_ms);
  result.timings.detect_ms = std::max(sides[0].detect_ms, sides[1].detect_ms);

  // Stage 3 in a band; the band's keys are cheap (one undistortion per
  // keypoint) next to detection.
  const Clock::time_point match_start = Clock::now();
  const auto match_in =
      [&](const RefractiveIndexInterval& interval) -> StatusOr<BandMatches> {
    StatusOr<LocusBand> band = LocusBand::Create(rig_, interval, options_.band);
    RCM_RETURN_IF_ERROR(band.status());
    std::vector<LocusKey> left_keys =
        band->LeftKeys(sides[0].features.keypoints);
    const std::vector<LocusKey> right_keys =
        band->RightKeys(sides[1].features.keypoints);
    std::vector<KeypointMatch> matches =
        MatchInLocusBand(sides[0].features, left_keys, sides[1].features,
                         right_keys, *band, options_.matching);
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
    left_points.push_back(sides[0].features.keypoints[match.left].pt);
    right_points.push_back(sides[1].features.keypoints[match.right].pt);
  }
  std::vector<unsigned char> kept;
  RefineRightPixels(sides[0].gray, sides[1].gray, left_points, &right_points,
                    &kept, options_.subpixel);
  result.matches.reserve(left_points.size());
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
  }
  result.timings.refine_ms = MillisecondsSince(refine_start);
  result.timings.total_ms = MillisecondsSince(start);
  return result;
}

}  // namespace rcm
