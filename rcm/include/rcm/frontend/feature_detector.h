// Keypoints and descriptors of one image, for stereo matching.
//
// Three detectors, selectable:
//   kOrb   (default) FAST corners ranked by the Harris score, with rotated
//          BRIEF binary descriptors (Rublee et al. 2011). One pyramid
//          level: the two images of a stereo pair see the scene at one
//          scale, and keypoints of coarser levels sit up to a pixel off
//          the corner they describe, which the subpixel stage (window
//          centered on the keypoint) turns into a bias of n (measured:
//          +1.0e-3 with 8 levels, +0.2e-3 with one, 10 pairs, n = 1.333).
//          About 3 ms per 720 x 540 image.
//   kSift  the paper's detector (Lowe 2004): scale-space extrema, 128-float
//          descriptors; the most distinctive, about 80 ms per image.
//   kAkaze nonlinear scale space, binary descriptors (Alcantarilla 2013);
//          between the two, about 40 ms per image.
#ifndef RCM_FRONTEND_FEATURE_DETECTOR_H_
#define RCM_FRONTEND_FEATURE_DETECTOR_H_

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

enum class FeatureType { kOrb, kSift, kAkaze };

// "orb", "sift", "akaze".
const char* FeatureTypeName(FeatureType type);
std::optional<FeatureType> FeatureTypeFromName(const std::string& name);

struct FeatureOptions {
  FeatureType type = FeatureType::kOrb;
  // Keypoints kept per image, the strongest first; > 0. 2000 gives about
  // 1300 verified matches per 720 x 540 pair of the simulated pool.
  int max_features = 2000;
  // kOrb: FAST intensity threshold, in gray levels; in [1, 255]. Lower
  // finds corners in weaker texture (and in noise).
  int fast_threshold = 20;

  Status Check() const;
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // one row per keypoint: CV_8U (binary) or CV_32F
  // How descriptors compare: cv::NORM_HAMMING or cv::NORM_L2.
  int norm_type = cv::NORM_HAMMING;
};

// One detector; holds OpenCV state, so give each thread its own.
class FeatureDetector {
 public:
  // Errors: options.Check().
  static StatusOr<FeatureDetector> Create(const FeatureOptions& options);

  // Features of an 8-bit gray image (image_preprocessing.h). Keypoints
  // whose descriptor window leaves the image are dropped by OpenCV.
  Features Detect(const cv::Mat& gray);

  const FeatureOptions& options() const { return options_; }

 private:
  FeatureDetector(const FeatureOptions& options, cv::Ptr<cv::Feature2D> impl)
      : options_(options), impl_(std::move(impl)) {}

  FeatureOptions options_;
  cv::Ptr<cv::Feature2D> impl_;
};

}  // namespace rcm

#endif  // RCM_FRONTEND_FEATURE_DETECTOR_H_
