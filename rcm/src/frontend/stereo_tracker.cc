#include "rcm/frontend/stereo_tracker.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <string>
#include <utility>

#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// Fewer links than this are not checked for one rigid motion (the
// essential matrix's RANSAC needs a margin over its 5 points) and are
// dropped: the keyframe starts new landmarks.
constexpr int kMinRigidLinks = 8;

}  // namespace

Status StereoTrackerOptions::Check() const {
  if (!(max_motion_px > 0.0) || !std::isfinite(max_motion_px)) {
    return Status::Error("tracker max motion = " + FormatDouble(max_motion_px) +
                         " px must be positive and finite");
  }
  if (!(ratio > 0.0 && ratio <= 1.0)) {
    return Status::Error("tracker ratio = " + FormatDouble(ratio) +
                         " must be in (0, 1]");
  }
  if (!(epipolar_threshold_px > 0.0) || !std::isfinite(epipolar_threshold_px)) {
    return Status::Error(
        "tracker epipolar threshold = " + FormatDouble(epipolar_threshold_px) +
        " px must be positive and finite");
  }
  if (!(n >= RefractiveCamera::kMinIndex && n <= RefractiveCamera::kMaxIndex)) {
    return Status::Error("tracker n = " + FormatDouble(n) +
                         " is outside [1, 2]");
  }
  return subpixel.Check().WithContext("tracker subpixel");
}

StatusOr<StereoTracker> StereoTracker::Create(
    const StereoRig& rig, const StereoTrackerOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<RefractiveCamera> left =
      RefractiveCamera::Create(rig.left(), options.n);
  if (!left.ok()) return left.status();
  return StereoTracker(rig, options, std::move(*left));
}

StatusOr<int> StereoTracker::AddKeyframe(const DetectedStereoPair& detected,
                                         const StereoMatches& matches) {
  const Features& left_features = detected.features[0];
  const cv::Mat& left_gray = detected.gray[0];
  const cv::Mat& right_gray = detected.gray[1];
  if (!previous_left_.empty() && left_gray.size() != previous_left_.size()) {
    return Status::Error("the keyframe's images are " +
                         std::to_string(left_gray.cols) + " x " +
                         std::to_string(left_gray.rows) + ", the previous " +
                         std::to_string(previous_left_.cols) + " x " +
                         std::to_string(previous_left_.rows));
  }
  const size_t count = matches.matches.size();
  if (matches.left_keypoints_of_matches.size() != count) {
    return Status::Error(
        "the matches do not carry their left keypoints (" +
        std::to_string(matches.left_keypoints_of_matches.size()) + " for " +
        std::to_string(count) + " matches)");
  }
  const int num_keypoints = static_cast<int>(left_features.keypoints.size());
  for (int k : matches.left_keypoints_of_matches) {
    if (k < 0 || k >= num_keypoints || k >= left_features.descriptors.rows) {
      return Status::Error("a match names left keypoint " + std::to_string(k) +
                           " of " + std::to_string(num_keypoints));
    }
  }
  const int frame = tracks_.num_frames;
  cv::Mat descriptors(static_cast<int>(count), left_features.descriptors.cols,
                      left_features.descriptors.type());
  for (size_t i = 0; i < count; ++i) {
    left_features.descriptors.row(matches.left_keypoints_of_matches[i])
        .copyTo(descriptors.row(static_cast<int>(i)));
  }

  // 1-3. Candidates, ratio, uniqueness.
  std::vector<int> link(count, -1);
  const bool comparable = !previous_descriptors_.empty() && count > 0 &&
                          previous_descriptors_.cols == descriptors.cols &&
                          previous_descriptors_.type() == descriptors.type() &&
                          previous_norm_ == left_features.norm_type;
  if (comparable) {
    const int previous = previous_descriptors_.rows;
    cv::Mat mask(static_cast<int>(count), previous, CV_8U);
    const double radius_squared =
        options_.max_motion_px * options_.max_motion_px;
    for (size_t i = 0; i < count; ++i) {
      uint8_t* row = mask.ptr<uint8_t>(static_cast<int>(i));
      const Eigen::Vector2d& pixel = matches.matches[i].left_pixel;
      for (int j = 0; j < previous; ++j) {
        row[j] = (pixel - previous_pixels_[j]).squaredNorm() <= radius_squared
                     ? 1
                     : 0;
      }
    }
    cv::BFMatcher matcher(left_features.norm_type);
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(descriptors, previous_descriptors_, knn, 2, mask);
    std::vector<int> claimed(previous, -1);
    std::vector<float> claimed_distance(previous, 0.0f);
    for (const std::vector<cv::DMatch>& candidates : knn) {
      if (candidates.empty()) continue;
      const cv::DMatch& best = candidates[0];
      if (candidates.size() > 1 &&
          !(best.distance < options_.ratio * candidates[1].distance)) {
        continue;
      }
      const int j = best.trainIdx;
      if (claimed[j] >= 0) {
        if (best.distance >= claimed_distance[j]) continue;
        link[claimed[j]] = -1;
      }
      claimed[j] = best.queryIdx;
      claimed_distance[j] = best.distance;
      link[best.queryIdx] = j;
    }
  }

  // 4. The linked pixels refined: left against the previous keyframe's
  // patch, then right against the refined left.
  std::vector<Eigen::Vector2d> left_pixels(count);
  std::vector<Eigen::Vector2d> right_pixels(count);
  for (size_t i = 0; i < count; ++i) {
    left_pixels[i] = matches.matches[i].left_pixel;
    right_pixels[i] = matches.matches[i].right_pixel;
  }
  {
    std::vector<size_t> refined;
    std::vector<cv::Point2f> template_points;
    std::vector<cv::Point2f> left_points;
    for (size_t i = 0; i < count; ++i) {
      if (link[i] < 0) continue;
      refined.push_back(i);
      const Eigen::Vector2d& from = previous_pixels_[link[i]];
      template_points.emplace_back(static_cast<float>(from.x()),
                                   static_cast<float>(from.y()));
      left_points.emplace_back(static_cast<float>(left_pixels[i].x()),
                               static_cast<float>(left_pixels[i].y()));
    }
    if (!refined.empty()) {
      std::vector<unsigned char> kept;
      RefineRightPixels(previous_left_, left_gray, template_points,
                        &left_points, &kept, options_.subpixel);
      std::vector<cv::Point2f> right_points;
      for (size_t k = 0; k < refined.size(); ++k) {
        const Eigen::Vector2d& right = right_pixels[refined[k]];
        right_points.emplace_back(static_cast<float>(right.x()),
                                  static_cast<float>(right.y()));
      }
      std::vector<unsigned char> right_kept;
      RefineRightPixels(left_gray, right_gray, left_points, &right_points,
                        &right_kept, options_.subpixel);
      for (size_t k = 0; k < refined.size(); ++k) {
        const size_t i = refined[k];
        if (!kept[k] || !right_kept[k]) {
          link[i] = -1;  // a new landmark at the front end's pixels
          continue;
        }
        left_pixels[i] = Eigen::Vector2d(left_points[k].x, left_points[k].y);
        right_pixels[i] = Eigen::Vector2d(right_points[k].x, right_points[k].y);
      }
    }
  }

  // 5. One rigid motion.
  std::vector<size_t> linked;
  std::vector<cv::Point2d> previous_points;
  std::vector<cv::Point2d> current_points;
  for (size_t i = 0; i < count; ++i) {
    if (link[i] < 0) continue;
    const std::optional<Eigen::Vector3d> a =
        left_.BearingInWaterFromImage(previous_pixels_[link[i]]);
    const std::optional<Eigen::Vector3d> b =
        left_.BearingInWaterFromImage(left_pixels[i]);
    if (!a || !b || !(a->z() > 0.0) || !(b->z() > 0.0)) {
      link[i] = -1;
      continue;
    }
    linked.push_back(i);
    previous_points.emplace_back(a->x() / a->z(), a->y() / a->z());
    current_points.emplace_back(b->x() / b->z(), b->y() / b->z());
  }
  if (static_cast<int>(linked.size()) < kMinRigidLinks) {
    for (size_t i : linked) link[i] = -1;
  } else {
    std::vector<unsigned char> inliers;
    const cv::Mat essential = cv::findEssentialMat(
        previous_points, current_points, 1.0, cv::Point2d(0.0, 0.0), cv::RANSAC,
        0.999, options_.epipolar_threshold_px / rig_.left().fx(), inliers);
    for (size_t k = 0; k < linked.size(); ++k) {
      if (essential.empty() || k >= inliers.size() || !inliers[k]) {
        link[linked[k]] = -1;
      }
    }
  }

  // The keyframe's observations.
  std::vector<int> landmarks(count);
  int continued = 0;
  for (size_t i = 0; i < count; ++i) {
    if (link[i] >= 0) {
      landmarks[i] = previous_landmarks_[link[i]];
      ++continued;
    } else {
      landmarks[i] = tracks_.num_landmarks++;
    }
    // An unlinked match keeps the front end's pixels (link -1 above).
    const bool moved = link[i] >= 0;
    const Eigen::Vector2d& left =
        moved ? left_pixels[i] : matches.matches[i].left_pixel;
    const Eigen::Vector2d& right =
        moved ? right_pixels[i] : matches.matches[i].right_pixel;
    left_pixels[i] = left;
    tracks_.observations.push_back({frame, 0, landmarks[i], left});
    tracks_.observations.push_back({frame, 1, landmarks[i], right});
  }
  tracks_.num_frames = frame + 1;
  previous_left_ = left_gray;
  previous_descriptors_ = descriptors;
  previous_norm_ = left_features.norm_type;
  previous_pixels_ = std::move(left_pixels);
  previous_landmarks_ = std::move(landmarks);
  return continued;
}

}  // namespace rcm
