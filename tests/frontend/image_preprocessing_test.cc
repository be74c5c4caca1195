#include "rcm/frontend/image_preprocessing.h"

#include <gtest/gtest.h>

#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace rcm::image_preprocessing_test {
namespace {

// Random blobs of random gray levels in [low, high] on a background of
// their mean, slightly blurred.
cv::Mat Blobs(int width, int height, int low, int high, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(height, width, CV_8UC1, cv::Scalar((low + high) / 2));
  for (int i = 0; i < width * height / 100; ++i) {
    // Each draw in a statement of its own, last argument first (gcc's
    // order): argument evaluation order is unspecified.
    const int center_y = rng.uniform(0, height);
    const cv::Point center(rng.uniform(0, width), center_y);
    const int axis_y = rng.uniform(2, 9);
    const cv::Size axes(rng.uniform(2, 9), axis_y);
    const int gray = rng.uniform(low, high + 1);
    cv::ellipse(image, center, axes, rng.uniform(0.0, 180.0), 0.0, 360.0,
                cv::Scalar(gray), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

double StandardDeviation(const cv::Mat& image) {
  cv::Scalar mean;
  cv::Scalar deviation;
  cv::meanStdDev(image, mean, deviation);
  return deviation[0];
}

TEST(CheckStereoImages, AcceptsEightBitGrayBgrAndBgraPairs) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4}) {
    const cv::Mat image(48, 64, type, cv::Scalar::all(90));
    EXPECT_TRUE(CheckStereoImages(image, image).ok()) << cv::typeToString(type);
  }
  // The two need not share a type, only a size.
  EXPECT_TRUE(
      CheckStereoImages(cv::Mat(48, 64, CV_8UC1), cv::Mat(48, 64, CV_8UC3))
          .ok());
}

TEST(CheckStereoImages, RejectsEmptyImages) {
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(90));
  EXPECT_EQ(CheckStereoImages(cv::Mat(), image).message(),
            "left image is empty");
  EXPECT_EQ(CheckStereoImages(image, cv::Mat()).message(),
            "right image is empty");
  EXPECT_EQ(CheckStereoImages(cv::Mat(), cv::Mat()).message(),
            "left image is empty");
}

TEST(CheckStereoImages, RejectsOtherDepthsAndChannelCounts) {
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(90));
  EXPECT_EQ(CheckStereoImages(cv::Mat(48, 64, CV_16UC1), image).message(),
            "left image is CV_16UC1: expected 8-bit gray, BGR or BGRA "
            "(CV_8UC1, CV_8UC3, CV_8UC4)");
  EXPECT_EQ(CheckStereoImages(image, cv::Mat(48, 64, CV_8UC2)).message(),
            "right image is CV_8UC2: expected 8-bit gray, BGR or BGRA "
            "(CV_8UC1, CV_8UC3, CV_8UC4)");
  EXPECT_EQ(CheckStereoImages(image, cv::Mat(48, 64, CV_32FC1)).message(),
            "right image is CV_32FC1: expected 8-bit gray, BGR or BGRA "
            "(CV_8UC1, CV_8UC3, CV_8UC4)");
  EXPECT_FALSE(CheckStereoImages(cv::Mat(48, 64, CV_16UC3), image).ok());
}

TEST(CheckStereoImages, RejectsPairsOfTwoSizes) {
  EXPECT_EQ(
      CheckStereoImages(cv::Mat(540, 720, CV_8UC1), cv::Mat(480, 640, CV_8UC1))
          .message(),
      "left image is 720 x 540, right image 640 x 480: a stereo pair "
      "needs images of one size");
  // Transposed: same pixel count, other size.
  EXPECT_FALSE(
      CheckStereoImages(cv::Mat(540, 720, CV_8UC1), cv::Mat(720, 540, CV_8UC1))
          .ok());
}

TEST(PreprocessImage, GrayWithoutClaheIsTheImageItself) {
  const cv::Mat gray = Blobs(64, 48, 0, 255, 1);
  const cv::Mat out = PreprocessImage(gray, ClaheOptions());
  EXPECT_EQ(out.data, gray.data);  // no copy
  EXPECT_EQ(out.size(), gray.size());
  EXPECT_EQ(out.type(), CV_8UC1);
}

TEST(PreprocessImage, ConvertsBgrAndBgraToGray) {
  // Three different channels, so that the conversion's weights matter.
  const cv::Mat blue = Blobs(64, 48, 0, 255, 2);
  const cv::Mat green = Blobs(64, 48, 0, 255, 3);
  const cv::Mat red = Blobs(64, 48, 0, 255, 4);
  cv::Mat bgr;
  cv::merge(std::vector<cv::Mat>{blue, green, red}, bgr);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  const cv::Mat from_bgr = PreprocessImage(bgr, ClaheOptions());
  ASSERT_EQ(from_bgr.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(from_bgr, expected, cv::NORM_INF), 0.0);
  // 0.299 R + 0.587 G + 0.114 B: one pixel by hand.
  const double by_hand = 0.299 * red.at<uchar>(10, 20) +
                         0.587 * green.at<uchar>(10, 20) +
                         0.114 * blue.at<uchar>(10, 20);
  EXPECT_NEAR(from_bgr.at<uchar>(10, 20), by_hand, 1.0);

  // The alpha channel is ignored.
  const cv::Mat alpha = Blobs(64, 48, 0, 255, 5);
  cv::Mat bgra;
  cv::merge(std::vector<cv::Mat>{blue, green, red, alpha}, bgra);
  const cv::Mat from_bgra = PreprocessImage(bgra, ClaheOptions());
  ASSERT_EQ(from_bgra.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(from_bgra, expected, cv::NORM_INF), 0.0);
}

TEST(PreprocessImage, ClaheStretchesALowContrastImage) {
  // Gray levels 110-140 only: CLAHE spreads each tile's histogram over
  // the range, clipped at 2x the mean bin count. Without it the image
  // passes unchanged.
  const cv::Mat dull = Blobs(320, 240, 110, 140, 6);
  ClaheOptions options;
  EXPECT_EQ(cv::norm(PreprocessImage(dull, options), dull, cv::NORM_INF), 0.0);
  options.enabled = true;
  const cv::Mat equalized = PreprocessImage(dull, options);
  ASSERT_EQ(equalized.type(), CV_8UC1);
  ASSERT_EQ(equalized.size(), dull.size());
  double dull_min, dull_max, min, max;
  cv::minMaxLoc(dull, &dull_min, &dull_max);
  cv::minMaxLoc(equalized, &min, &max);
  EXPECT_GT(max - min, 2.0 * (dull_max - dull_min));
  EXPECT_GT(StandardDeviation(equalized), 2.0 * StandardDeviation(dull));
  // A higher clip limit stretches further.
  options.clip_limit = 8.0;
  EXPECT_GT(StandardDeviation(PreprocessImage(dull, options)),
            StandardDeviation(equalized));
  // Color input: CLAHE of its gray conversion.
  cv::Mat bgr;
  cv::cvtColor(dull, bgr, cv::COLOR_GRAY2BGR);
  options.clip_limit = 2.0;
  EXPECT_EQ(cv::norm(PreprocessImage(bgr, options), equalized, cv::NORM_INF),
            0.0);
  // The input is left alone.
  EXPECT_EQ(cv::norm(dull, Blobs(320, 240, 110, 140, 6), cv::NORM_INF), 0.0);
}

TEST(ClaheOptions, Check) {
  EXPECT_TRUE(ClaheOptions().Check().ok());
  ClaheOptions options;
  options.clip_limit = 0.0;
  EXPECT_EQ(options.Check().message(),
            "CLAHE clip limit must be positive, got 0.000000");
  options.clip_limit = -1.0;
  EXPECT_FALSE(options.Check().ok());
  options.clip_limit = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(options.Check().ok());
  options = ClaheOptions();
  options.tiles = 0;
  EXPECT_EQ(options.Check().message(),
            "CLAHE needs at least 1 tile per side, got 0");
  options.tiles = 1;
  EXPECT_TRUE(options.Check().ok());
}

}  // namespace
}  // namespace rcm::image_preprocessing_test
