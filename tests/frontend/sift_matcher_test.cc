#include "rcm/frontend/sift_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace rcm {
namespace {

// Random blobs of random gray levels on gray, slightly blurred: texture
// SIFT finds keypoints in everywhere, none alike.
cv::Mat Blobs(int width, int height, int count, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < count; ++i) {
    const cv::Point center(rng.uniform(0, width), rng.uniform(0, height));
    const cv::Size axes(rng.uniform(2, 9), rng.uniform(2, 9));
    cv::ellipse(image, center, axes, rng.uniform(0.0, 180.0), 0.0, 360.0,
                cv::Scalar(rng.uniform(0, 256)), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

// `image` moved by (dx, dy): the pixel at (u, v) goes to (u + dx, v + dy).
cv::Mat Shifted(const cv::Mat& image, double dx, double dy) {
  const cv::Mat transform = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat shifted;
  cv::warpAffine(image, shifted, transform, image.size(), cv::INTER_LINEAR,
                 cv::BORDER_REPLICATE);
  return shifted;
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

TEST(SiftMatcher, RecoversAKnownShift) {
  const double dx = 7.3;
  const double dy = -3.6;
  const cv::Mat left = Blobs(320, 240, 400, 1);
  const cv::Mat right = Shifted(left, dx, dy);
  const StatusOr<std::vector<StereoCorrespondence>> matches =
      MatchStereoPair(left, right, SiftMatcherOptions(), 17, 1.25);
  ASSERT_TRUE(matches.ok()) << matches.status().message();
  ASSERT_GE(matches->size(), 100u);
  std::vector<double> errors;
  for (const StereoCorrespondence& match : *matches) {
    EXPECT_EQ(match.frame, 17);
    EXPECT_EQ(match.timestamp, 1.25);
    errors.push_back(
        (match.right_pixel - match.left_pixel - Eigen::Vector2d(dx, dy))
            .norm());
  }
  EXPECT_LT(Median(errors), 0.3);
  const auto within_one_px = std::count_if(errors.begin(), errors.end(),
                                           [](double e) { return e < 1; });
  EXPECT_GT(within_one_px, 0.95 * errors.size());
}

TEST(SiftMatcher, SameResultOnOneThreadAndInColor) {
  const cv::Mat left = Blobs(200, 150, 150, 2);
  const cv::Mat right = Shifted(left, -4.0, 1.5);
  SiftMatcherOptions serial;
  serial.num_threads = 1;
  const std::vector<StereoCorrespondence> one =
      MatchStereoPair(left, right, serial).value();
  const std::vector<StereoCorrespondence> two =
      MatchStereoPair(left, right).value();
  cv::Mat left_color, right_color;
  cv::cvtColor(left, left_color, cv::COLOR_GRAY2BGR);
  cv::cvtColor(right, right_color, cv::COLOR_GRAY2BGR);
  const std::vector<StereoCorrespondence> color =
      MatchStereoPair(left_color, right_color).value();
  ASSERT_GT(one.size(), 20u);
  ASSERT_EQ(one.size(), two.size());
  ASSERT_EQ(one.size(), color.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].left_pixel, two[i].left_pixel);
    EXPECT_EQ(one[i].right_pixel, two[i].right_pixel);
    EXPECT_EQ(one[i].left_pixel, color[i].left_pixel);
    EXPECT_EQ(one[i].right_pixel, color[i].right_pixel);
  }
}

TEST(SiftMatcher, RatioTestRejectsRepeatedTexture) {
  // A 32 px tile of blobs repeated 9 x 7 times: every keypoint away from
  // the image border has identical twins in the other image.
  const cv::Mat tile = Blobs(32, 32, 6, 3);
  cv::Mat periodic;
  cv::repeat(tile, 7, 9, periodic);
  const cv::Mat right = Shifted(periodic, 5.0, 2.0);
  SiftMatcherOptions no_test;
  no_test.ratio = 1.0;
  no_test.cross_check = false;
  SiftMatcherOptions ratio_test = no_test;
  ratio_test.ratio = 0.8;
  const std::vector<StereoCorrespondence> all =
      MatchStereoPair(periodic, right, no_test).value();
  const std::vector<StereoCorrespondence> kept =
      MatchStereoPair(periodic, right, ratio_test).value();
  ASSERT_GT(all.size(), 100u);
  EXPECT_LT(kept.size(), 0.1 * all.size())
      << kept.size() << " of " << all.size() << " kept";
  // Without the test most nearest neighbours are a twin: the wrong tile.
  int wrong = 0;
  for (const StereoCorrespondence& match : all) {
    if ((match.right_pixel - match.left_pixel - Eigen::Vector2d(5.0, 2.0))
            .norm() > 2.0) {
      ++wrong;
    }
  }
  EXPECT_GT(wrong, 0.3 * all.size());
}

TEST(SiftMatcher, RejectsBadImages) {
  const cv::Mat image = Blobs(64, 48, 20, 4);
  EXPECT_EQ(MatchStereoPair(cv::Mat(), image).status().message(),
            "left image is empty");
  EXPECT_EQ(MatchStereoPair(image, cv::Mat()).status().message(),
            "right image is empty");
  EXPECT_EQ(MatchStereoPair(image, Blobs(60, 48, 20, 4)).status().message(),
            "left image is 64 x 48, right image 60 x 48: a stereo pair needs "
            "images of one size");
  cv::Mat deep;
  image.convertTo(deep, CV_16U);
  EXPECT_EQ(MatchStereoPair(deep, image).status().message(),
            "left image is CV_16UC1: expected 8-bit gray, BGR or BGRA "
            "(CV_8UC1, CV_8UC3, CV_8UC4)");
  EXPECT_FALSE(MatchStereoPair(image, cv::Mat(48, 64, CV_8UC2)).ok());
  // A blank pair has no keypoints: no matches, no error.
  const cv::Mat blank(48, 64, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(MatchStereoPair(blank, blank).value().empty());
}

TEST(SiftMatcher, OptionsCheck) {
  EXPECT_TRUE(SiftMatcherOptions().Check().ok());
  SiftMatcherOptions options;
  options.max_features = 0;
  EXPECT_EQ(options.Check().message(), "max_features = 0 must be positive");
  options = SiftMatcherOptions();
  options.ratio = 1.5;
  EXPECT_EQ(options.Check().message(), "ratio = 1.5 must be in (0, 1]");
  options.ratio = 0.0;
  EXPECT_FALSE(options.Check().ok());
  options = SiftMatcherOptions();
  options.num_threads = 0;
  EXPECT_EQ(options.Check().message(), "num_threads = 0 must be at least 1");
  const cv::Mat image = Blobs(64, 48, 20, 4);
  EXPECT_EQ(MatchStereoPair(image, image, options).status().message(),
            "num_threads = 0 must be at least 1");
}

}  // namespace
}  // namespace rcm
