#include "rcm/frontend/sift_matcher.h"

#include <future>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

namespace rcm {
namespace {

Status CheckImage(const cv::Mat& image, const char* name) {
  if (image.empty()) {
    return Status::Error(std::string(name) + " image is empty");
  }
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 &&
       image.channels() != 4)) {
    return Status::Error(std::string(name) + " image is " +
                         cv::typeToString(image.type()) +
                         ": expected 8-bit gray, BGR or BGRA (CV_8UC1, "
                         "CV_8UC3, CV_8UC4)");
  }
  return Status::Ok();
}

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(
      image, gray,
      image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  return gray;
}

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // CV_32F, one row per keypoint
};

Features Detect(const cv::Mat& image, int max_features) {
  Features features;
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(max_features);
  sift->detectAndCompute(Gray(image), cv::noArray(), features.keypoints,
                         features.descriptors);
  return features;
}

// Runs a() and b(), at once when `parallel`; returns both results.
template <typename A, typename B>
auto RunBoth(bool parallel, A a, B b) {
  if (!parallel) {
    auto first = a();
    return std::make_pair(std::move(first), b());
  }
  auto first = std::async(std::launch::async, std::move(a));
  auto second = b();
  return std::make_pair(first.get(), std::move(second));
}

}  // namespace

Status SiftMatcherOptions::Check() const {
  std::ostringstream message;
  if (max_features <= 0) {
    message << "max_features = " << max_features << " must be positive";
  } else if (!(ratio > 0.0 && ratio <= 1.0)) {
    message << "ratio = " << ratio << " must be in (0, 1]";
  } else if (num_threads < 1) {
    message << "num_threads = " << num_threads << " must be at least 1";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<std::vector<StereoCorrespondence>> MatchStereoPair(
    const cv::Mat& left, const cv::Mat& right,
    const SiftMatcherOptions& options, int64_t frame,
    std::optional<double> timestamp) {
  RCM_RETURN_IF_ERROR(options.Check());
  RCM_RETURN_IF_ERROR(CheckImage(left, "left"));
  RCM_RETURN_IF_ERROR(CheckImage(right, "right"));
  if (left.size() != right.size()) {
    std::ostringstream message;
    message << "left image is " << left.cols << " x " << left.rows
            << ", right image " << right.cols << " x " << right.rows
            << ": a stereo pair needs images of one size";
    return Status::Error(message.str());
  }
  const bool parallel = options.num_threads >= 2;

  const auto [left_features, right_features] = RunBoth(
      parallel, [&] { return Detect(left, options.max_features); },
      [&] { return Detect(right, options.max_features); });
  std::vector<StereoCorrespondence> correspondences;
  // knnMatch with k = 2 needs two right keypoints for the ratio test.
  if (left_features.keypoints.empty() || right_features.keypoints.size() < 2) {
    return correspondences;
  }

  // Left to right with the two nearest; right to left with the nearest for
  // the mutual check.
  const cv::BFMatcher matcher(cv::NORM_L2);
  using Matches = std::vector<std::vector<cv::DMatch>>;
  const auto [forward, backward] = RunBoth(
      parallel && options.cross_check,
      [&] {
        Matches matches;
        matcher.knnMatch(left_features.descriptors, right_features.descriptors,
                         matches, 2);
        return matches;
      },
      [&] {
        Matches matches;
        if (options.cross_check) {
          matcher.knnMatch(right_features.descriptors,
                           left_features.descriptors, matches, 1);
        }
        return matches;
      });

  std::set<std::tuple<float, float, float, float>> seen;
  for (const std::vector<cv::DMatch>& candidates : forward) {
    if (candidates.size() < 2) continue;
    const cv::DMatch& best = candidates[0];
    const bool distinct =
        options.ratio >= 1.0 ||
        best.distance < options.ratio * candidates[1].distance;
    if (!distinct) continue;
    if (options.cross_check) {
      const std::vector<cv::DMatch>& back = backward[best.trainIdx];
      if (back.empty() || back[0].trainIdx != best.queryIdx) continue;
    }
    const cv::Point2f& l = left_features.keypoints[best.queryIdx].pt;
    const cv::Point2f& r = right_features.keypoints[best.trainIdx].pt;
    if (!seen.emplace(l.x, l.y, r.x, r.y).second) continue;
    StereoCorrespondence correspondence;
    correspondence.frame = frame;
    correspondence.timestamp = timestamp;
    correspondence.left_pixel = Eigen::Vector2d(l.x, l.y);
    correspondence.right_pixel = Eigen::Vector2d(r.x, r.y);
    correspondences.push_back(correspondence);
  }
  return correspondences;
}

}  // namespace rcm
