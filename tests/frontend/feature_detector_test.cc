#include "rcm/frontend/feature_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace rcm::feature_detector_test {
namespace {

// Random blobs of random gray levels on gray, slightly blurred: corners
// and blobs for every detector.
cv::Mat Blobs(int width, int height, int count, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < count; ++i) {
    // Each draw in a statement of its own, last argument first (gcc's
    // order): argument evaluation order is unspecified.
    const int center_y = rng.uniform(0, height);
    const cv::Point center(rng.uniform(0, width), center_y);
    const int axis_y = rng.uniform(2, 9);
    const cv::Size axes(rng.uniform(2, 9), axis_y);
    const int gray = rng.uniform(0, 256);
    cv::ellipse(image, center, axes, rng.uniform(0.0, 180.0), 0.0, 360.0,
                cv::Scalar(gray), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

Features Detect(FeatureType type, const cv::Mat& gray,
                int max_features = 2000) {
  FeatureOptions options;
  options.type = type;
  options.max_features = max_features;
  return FeatureDetector::Create(options).value().Detect(gray);
}

TEST(FeatureType, NamesRoundTrip) {
  for (FeatureType type :
       {FeatureType::kOrb, FeatureType::kSift, FeatureType::kAkaze}) {
    EXPECT_EQ(FeatureTypeFromName(FeatureTypeName(type)), type);
  }
  EXPECT_STREQ(FeatureTypeName(FeatureType::kOrb), "orb");
  EXPECT_STREQ(FeatureTypeName(FeatureType::kSift), "sift");
  EXPECT_STREQ(FeatureTypeName(FeatureType::kAkaze), "akaze");
}

TEST(FeatureType, UnknownNamesAreRejected) {
  EXPECT_EQ(FeatureTypeFromName("surf"), std::nullopt);
  EXPECT_EQ(FeatureTypeFromName(""), std::nullopt);
  EXPECT_EQ(FeatureTypeFromName("ORB"), std::nullopt);  // lower case only
  EXPECT_EQ(FeatureTypeFromName("orb "), std::nullopt);
}

TEST(FeatureDetector, EachTypeDescribesTheKeypointsItFinds) {
  // Descriptor layouts: ORB 32 bytes, SIFT 128 floats, AKAZE 61 bytes
  // (486 bits of its full-size MLDB descriptor).
  struct Expected {
    FeatureType type;
    int descriptor_type;
    int descriptor_cols;
    int norm_type;
  };
  const cv::Mat image = Blobs(640, 480, 1500, 1);
  for (const Expected& expected :
       {Expected{FeatureType::kOrb, CV_8U, 32, cv::NORM_HAMMING},
        Expected{FeatureType::kSift, CV_32F, 128, cv::NORM_L2},
        Expected{FeatureType::kAkaze, CV_8U, 61, cv::NORM_HAMMING}}) {
    const char* name = FeatureTypeName(expected.type);
    const Features features = Detect(expected.type, image);
    EXPECT_GT(features.keypoints.size(), 300u) << name;
    EXPECT_LE(features.keypoints.size(), 2000u) << name;
    ASSERT_EQ(features.descriptors.rows,
              static_cast<int>(features.keypoints.size()))
        << name;
    EXPECT_EQ(features.descriptors.type(), expected.descriptor_type) << name;
    EXPECT_EQ(features.descriptors.cols, expected.descriptor_cols) << name;
    EXPECT_EQ(features.norm_type, expected.norm_type) << name;
    for (const cv::KeyPoint& keypoint : features.keypoints) {
      EXPECT_GE(keypoint.pt.x, 0.0f) << name;
      EXPECT_GE(keypoint.pt.y, 0.0f) << name;
      EXPECT_LE(keypoint.pt.x, image.cols - 1.0f) << name;
      EXPECT_LE(keypoint.pt.y, image.rows - 1.0f) << name;
    }
  }
}

TEST(FeatureDetector, SameImageSameFeatures) {
  const cv::Mat image = Blobs(320, 240, 400, 2);
  for (FeatureType type :
       {FeatureType::kOrb, FeatureType::kSift, FeatureType::kAkaze}) {
    const Features a = Detect(type, image);
    const Features b = Detect(type, image);
    ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
    ASSERT_FALSE(a.keypoints.empty());
    for (size_t i = 0; i < a.keypoints.size(); ++i) {
      EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt);
    }
    EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_INF), 0.0);
  }
}

TEST(FeatureDetector, BlankImageHasNoFeatures) {
  const cv::Mat blank(240, 320, CV_8UC1, cv::Scalar(90));
  for (FeatureType type :
       {FeatureType::kOrb, FeatureType::kSift, FeatureType::kAkaze}) {
    const Features features = Detect(type, blank);
    EXPECT_TRUE(features.keypoints.empty()) << FeatureTypeName(type);
    EXPECT_EQ(features.descriptors.rows, 0) << FeatureTypeName(type);
  }
}

TEST(FeatureDetector, MaxFeaturesIsRespected) {
  const cv::Mat image = Blobs(640, 480, 1500, 3);
  for (FeatureType type :
       {FeatureType::kOrb, FeatureType::kSift, FeatureType::kAkaze}) {
    const Features features = Detect(type, image, 100);
    EXPECT_LE(features.keypoints.size(), 100u) << FeatureTypeName(type);
    // There is texture for more.
    EXPECT_GE(features.keypoints.size(), 90u) << FeatureTypeName(type);
    EXPECT_EQ(features.descriptors.rows,
              static_cast<int>(features.keypoints.size()));
  }
}

TEST(FeatureDetector, AkazeKeepsItsStrongestKeypointsInOrder) {
  // AKAZE has no keypoint budget of its own: the detector trims to the
  // max_features strongest, in the order AKAZE found them, each with its
  // own descriptor row.
  const cv::Mat image = Blobs(640, 480, 1500, 4);
  const Features all = Detect(FeatureType::kAkaze, image, 1000000);
  ASSERT_GT(all.keypoints.size(), 200u);
  const int budget = static_cast<int>(all.keypoints.size()) / 2;
  const Features kept = Detect(FeatureType::kAkaze, image, budget);
  ASSERT_EQ(static_cast<int>(kept.keypoints.size()), budget);
  ASSERT_EQ(kept.descriptors.rows, budget);
  EXPECT_EQ(kept.descriptors.type(), all.descriptors.type());
  EXPECT_EQ(kept.norm_type, cv::NORM_HAMMING);

  // Each kept keypoint is one of all, later in all than the one before.
  std::vector<bool> is_kept(all.keypoints.size(), false);
  size_t next = 0;
  for (int i = 0; i < budget; ++i) {
    const cv::KeyPoint& keypoint = kept.keypoints[i];
    while (next < all.keypoints.size() &&
           !(all.keypoints[next].pt == keypoint.pt &&
             all.keypoints[next].response == keypoint.response &&
             all.keypoints[next].octave == keypoint.octave)) {
      ++next;
    }
    ASSERT_LT(next, all.keypoints.size()) << "kept keypoint " << i;
    is_kept[next] = true;
    EXPECT_EQ(
        cv::norm(kept.descriptors.row(i),
                 all.descriptors.row(static_cast<int>(next)), cv::NORM_HAMMING),
        0.0)
        << "kept keypoint " << i;
    ++next;
  }
  // None dropped is stronger than any kept.
  float weakest_kept = std::numeric_limits<float>::infinity();
  float strongest_dropped = 0.0f;
  for (size_t j = 0; j < all.keypoints.size(); ++j) {
    if (is_kept[j]) {
      weakest_kept = std::min(weakest_kept, all.keypoints[j].response);
    } else {
      strongest_dropped =
          std::max(strongest_dropped, all.keypoints[j].response);
    }
  }
  EXPECT_GE(weakest_kept, strongest_dropped);
}

TEST(FeatureDetector, OptionsCheck) {
  EXPECT_TRUE(FeatureOptions().Check().ok());
  FeatureOptions options;
  options.max_features = 0;
  EXPECT_EQ(options.Check().message(), "max_features must be positive, got 0");
  EXPECT_EQ(FeatureDetector::Create(options).status().message(),
            "max_features must be positive, got 0");
  options = FeatureOptions();
  options.fast_threshold = 0;
  EXPECT_EQ(options.Check().message(),
            "FAST threshold must be in [1, 255], got 0");
  options.fast_threshold = 256;
  EXPECT_EQ(options.Check().message(),
            "FAST threshold must be in [1, 255], got 256");
  options.fast_threshold = 255;
  EXPECT_TRUE(options.Check().ok());
  options.fast_threshold = 1;
  EXPECT_TRUE(options.Check().ok());
}

TEST(FeatureDetector, LowerFastThresholdFindsWeakerCorners) {
  // ORB on a low-contrast image (gray levels 118-138): FAST at 20 gray
  // levels sees few corners, at 5 many more.
  cv::Mat dull;
  Blobs(640, 480, 1500, 5).convertTo(dull, CV_8U, 20.0 / 255.0, 118.0);
  FeatureOptions options;
  const size_t strict =
      FeatureDetector::Create(options).value().Detect(dull).keypoints.size();
  options.fast_threshold = 5;
  const size_t loose =
      FeatureDetector::Create(options).value().Detect(dull).keypoints.size();
  EXPECT_GT(loose, 2 * strict + 100);
  EXPECT_EQ(FeatureDetector::Create(options).value().options().fast_threshold,
            5);
}

}  // namespace
}  // namespace rcm::feature_detector_test
