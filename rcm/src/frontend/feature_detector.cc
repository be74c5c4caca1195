#include "rcm/frontend/feature_detector.h"

#include <algorithm>

namespace rcm {
namespace {

// ORB's border and descriptor patch, OpenCV's defaults: the rotated BRIEF
// pattern needs a 31 x 31 patch.
constexpr int kOrbPatchSize = 31;
constexpr int kOrbEdgeThreshold = 31;

}  // namespace

const char* FeatureTypeName(FeatureType type) {
  switch (type) {
    case FeatureType::kOrb:
      return "orb";
    case FeatureType::kSift:
      return "sift";
    case FeatureType::kAkaze:
      return "akaze";
  }
  return "unknown";
}

std::optional<FeatureType> FeatureTypeFromName(const std::string& name) {
  for (FeatureType type :
       {FeatureType::kOrb, FeatureType::kSift, FeatureType::kAkaze}) {
    if (name == FeatureTypeName(type)) return type;
  }
  return std::nullopt;
}

Status FeatureOptions::Check() const {
  if (max_features <= 0) {
    return Status::Error("max_features must be positive, got " +
                         std::to_string(max_features));
  }
  if (fast_threshold < 1 || fast_threshold > 255) {
    return Status::Error("FAST threshold must be in [1, 255], got " +
                         std::to_string(fast_threshold));
  }
  return Status::Ok();
}

StatusOr<FeatureDetector> FeatureDetector::Create(
    const FeatureOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  cv::Ptr<cv::Feature2D> impl;
  switch (options.type) {
    case FeatureType::kOrb:
      impl = cv::ORB::create(options.max_features, /*scaleFactor=*/1.2f,
                             /*nlevels=*/1, kOrbEdgeThreshold,
                             /*firstLevel=*/0, /*WTA_K=*/2,
                             cv::ORB::HARRIS_SCORE, kOrbPatchSize,
                             options.fast_threshold);
      break;
    case FeatureType::kSift:
      impl = cv::SIFT::create(options.max_features);
      break;
    case FeatureType::kAkaze:
      impl = cv::AKAZE::create();
      break;
  }
  return FeatureDetector(options, std::move(impl));
}

Features FeatureDetector::Detect(const cv::Mat& gray) {
  CHECK_EQ(gray.type(), CV_8UC1) << "detectors take 8-bit gray images";
  Features features;
  impl_->detectAndCompute(gray, cv::noArray(), features.keypoints,
                          features.descriptors);
  features.norm_type = impl_->defaultNorm();
  // AKAZE has no keypoint budget: keep the strongest max_features.
  if (static_cast<int>(features.keypoints.size()) > options_.max_features) {
    std::vector<int> order(features.keypoints.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::nth_element(order.begin(), order.begin() + options_.max_features,
                     order.end(), [&](int a, int b) {
                       return features.keypoints[a].response >
                              features.keypoints[b].response;
                     });
    order.resize(options_.max_features);
    std::sort(order.begin(), order.end());
    Features kept;
    kept.norm_type = features.norm_type;
    kept.descriptors.create(static_cast<int>(order.size()),
                            features.descriptors.cols,
                            features.descriptors.type());
    for (size_t i = 0; i < order.size(); ++i) {
      kept.keypoints.push_back(features.keypoints[order[i]]);
      features.descriptors.row(order[i]).copyTo(
          kept.descriptors.row(static_cast<int>(i)));
    }
    return kept;
  }
  return features;
}

}  // namespace rcm
