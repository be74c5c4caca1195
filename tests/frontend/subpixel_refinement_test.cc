#include "rcm/frontend/subpixel_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace rcm::subpixel_refinement_test {
namespace {

// Random blobs of random gray levels on gray, slightly blurred: texture
// everywhere, none alike. Drawn `scale`
// times larger (blob sizes, positions and blur scaled with it).
cv::Mat Blobs(int width, int height, int count, uint64_t seed, int scale = 1) {
  cv::RNG rng(seed);
  cv::Mat image(scale * height, scale * width, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < count; ++i) {
    // Each draw in a statement of its own, last argument first (gcc's
    // order): argument evaluation order is unspecified.
    const int center_y = scale * rng.uniform(0, height);
    const cv::Point center(scale * rng.uniform(0, width), center_y);
    const int axis_y = scale * rng.uniform(2, 9);
    const cv::Size axes(scale * rng.uniform(2, 9), axis_y);
    const int gray = rng.uniform(0, 256);
    cv::ellipse(image, center, axes, rng.uniform(0.0, 180.0), 0.0, 360.0,
                cv::Scalar(gray), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0 * scale);
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

// A blob image and its copy moved by a subpixel (dx, dy). Both are drawn
// and moved 4 times larger, then shrunk by pixel area: moving the small
// image itself would smooth it by the bilinear interpolation (by
// a (1 - a) / 2 px^2 for a fractional shift a), which moves the alignment
// of each patch by up to a few tenths of a pixel (measured median 0.057 px
// at (0.37, -0.62)); 4 times larger that smoothing is 16 times weaker.
struct MovedPair {
  cv::Mat left;
  cv::Mat right;
};

MovedPair MovedBlobs(int width, int height, int count, uint64_t seed, double dx,
                     double dy) {
  constexpr int kScale = 4;
  const cv::Mat large = Blobs(width, height, count, seed, kScale);
  const cv::Size size(width, height);
  MovedPair pair;
  cv::resize(large, pair.left, size, 0.0, 0.0, cv::INTER_AREA);
  cv::resize(Shifted(large, kScale * dx, kScale * dy), pair.right, size, 0.0,
             0.0, cv::INTER_AREA);
  return pair;
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

// Left pixels on a grid `margin` px inside the image.
std::vector<cv::Point2f> Grid(const cv::Mat& image, int step, int margin) {
  std::vector<cv::Point2f> points;
  for (int v = margin; v < image.rows - margin; v += step) {
    for (int u = margin; u < image.cols - margin; u += step) {
      points.emplace_back(static_cast<float>(u), static_cast<float>(v));
    }
  }
  return points;
}

// Each left pixel moved by the shift and then by `offset`: a detector's
// guess `offset` from the true right pixel.
std::vector<cv::Point2f> Starts(const std::vector<cv::Point2f>& left,
                                const cv::Point2f& shift,
                                const cv::Point2f& offset) {
  std::vector<cv::Point2f> right;
  for (const cv::Point2f& point : left) right.push_back(point + shift + offset);
  return right;
}

constexpr double kDx = 0.37;
constexpr double kDy = -0.62;

TEST(SubpixelRefinement, TranslationRecoversASubpixelShiftFromOnePixelOff) {
  // The right image is the left one moved by (0.37, -0.62) px; every start
  // is 1 px from the true right pixel, in one of four directions.
  // Tolerance: what is left is the rounding of both images to 8 bits, which
  // differs between them at a subpixel shift: measured median error
  // 0.035 px (0.0004 px at an integer shift, where the two are exact
  // copies). 0.05 px is the header's figure for the refined matches of the
  // simulated pool.
  constexpr double kTolerance = 0.05;
  const MovedPair images = MovedBlobs(320, 240, 600, 31, kDx, kDy);
  const cv::Point2f shift(static_cast<float>(kDx), static_cast<float>(kDy));
  const std::vector<cv::Point2f> left_points = Grid(images.left, 12, 16);
  ASSERT_GT(left_points.size(), 300u);
  int kept_count = 0;
  std::vector<double> errors;
  for (const cv::Point2f& offset : {cv::Point2f(1, 0), cv::Point2f(-1, 0),
                                    cv::Point2f(0, 1), cv::Point2f(0, -1)}) {
    std::vector<cv::Point2f> right_points = Starts(left_points, shift, offset);
    std::vector<unsigned char> kept;
    SubpixelOptions translation;
    translation.affine = false;
    RefineRightPixels(images.left, images.right, left_points, &right_points,
                      &kept, translation);
    ASSERT_EQ(kept.size(), left_points.size());
    ASSERT_EQ(right_points.size(), left_points.size());
    for (size_t i = 0; i < left_points.size(); ++i) {
      if (!kept[i]) continue;
      ++kept_count;
      errors.push_back(cv::norm(right_points[i] - left_points[i] - shift));
    }
  }
  // Grid points in flat gray between blobs (about 10 %) are dropped by
  // min_texture.
  EXPECT_GT(kept_count, 0.85 * 4 * left_points.size());
  EXPECT_LT(Median(errors), kTolerance);
  // Nearly all of them well under the 1 px of the starts.
  const auto within = std::count_if(errors.begin(), errors.end(),
                                    [](double e) { return e < 0.2; });
  EXPECT_GT(within, 0.95 * errors.size());
}

// ORB corners of the blob image, as the front end refines them.
std::vector<cv::Point2f> Corners(const cv::Mat& image) {
  std::vector<cv::KeyPoint> keypoints;
  cv::ORB::create(500, 1.2f, 1)->detect(image, keypoints);
  std::vector<cv::Point2f> points;
  for (const cv::KeyPoint& keypoint : keypoints) points.push_back(keypoint.pt);
  return points;
}

TEST(SubpixelRefinement, AffineRecoversASubpixelShiftAtCorners) {
  // The default (affine) fit at the keypoints the front end gives it.
  // Tolerance: measured median 0.057 px (two more degrees of freedom per
  // axis than the translation's 0.025 px, see the header); 0.1 px leaves
  // room for other seeds, and stays 10 times below the 1 px of the starts.
  constexpr double kTolerance = 0.1;
  const MovedPair images = MovedBlobs(320, 240, 600, 31, kDx, kDy);
  const cv::Point2f shift(static_cast<float>(kDx), static_cast<float>(kDy));
  const std::vector<cv::Point2f> left_points = Corners(images.left);
  ASSERT_GT(left_points.size(), 300u);
  std::vector<double> errors;
  for (const cv::Point2f& offset : {cv::Point2f(1, 0), cv::Point2f(0, -1)}) {
    std::vector<cv::Point2f> right_points = Starts(left_points, shift, offset);
    std::vector<unsigned char> kept;
    RefineRightPixels(images.left, images.right, left_points, &right_points,
                      &kept, SubpixelOptions());
    for (size_t i = 0; i < left_points.size(); ++i) {
      if (kept[i]) {
        errors.push_back(cv::norm(right_points[i] - left_points[i] - shift));
      }
    }
  }
  EXPECT_GT(errors.size(), 0.95 * 2 * left_points.size());
  EXPECT_LT(Median(errors), kTolerance);
}

TEST(SubpixelRefinement, AffineFollowsASlantedSurface) {
  // The right view stretched by 10 % in x about the image center, as a
  // surface slanted in depth is: the displacement varies across each
  // window. The affine fit returns the displacement of the window's center;
  // the translation alone that of its gradient-weighted centroid, which at
  // a corner is off center (the bias the header measures on the pool).
  constexpr double kStretch = 1.1;
  const cv::Mat left = Blobs(320, 240, 600, 38);
  const cv::Mat transform =
      (cv::Mat_<double>(2, 3) << kStretch, 0, 160 * (1 - kStretch), 0, 1, 0);
  cv::Mat right;
  cv::warpAffine(left, right, transform, left.size(), cv::INTER_LINEAR,
                 cv::BORDER_REPLICATE);
  const std::vector<cv::Point2f> left_points = Corners(left);
  const auto median_error = [&](bool affine) {
    std::vector<cv::Point2f> right_points;
    std::vector<cv::Point2f> truth;
    for (const cv::Point2f& point : left_points) {
      const cv::Point2f moved(
          static_cast<float>(kStretch * point.x + 160 * (1 - kStretch)),
          point.y);
      truth.push_back(moved);
      right_points.push_back(moved + cv::Point2f(0.6f, -0.4f));
    }
    std::vector<unsigned char> kept;
    SubpixelOptions options;
    options.affine = affine;
    RefineRightPixels(left, right, left_points, &right_points, &kept,
                      options);
    std::vector<double> errors;
    for (size_t i = 0; i < left_points.size(); ++i) {
      if (kept[i]) errors.push_back(cv::norm(right_points[i] - truth[i]));
    }
    EXPECT_GT(errors.size(), 0.8 * left_points.size());
    return Median(errors);
  };
  const double affine = median_error(true);
  const double translation = median_error(false);
  EXPECT_LT(affine, 0.1);
  EXPECT_LT(affine, 0.7 * translation)
      << "affine " << affine << " px, translation " << translation << " px";
}

TEST(SubpixelRefinement, IntegerShiftIsRecoveredExactly) {
  // Moved by whole pixels, the right image is an exact copy: the
  // alignment is limited by its stopping step (0.01 px) alone.
  constexpr double kTolerance = 0.01;
  const cv::Mat left = Blobs(320, 240, 600, 36);
  const cv::Mat right = Shifted(left, 3.0, -2.0);
  const std::vector<cv::Point2f> left_points = Grid(left, 12, 16);
  std::vector<cv::Point2f> right_points =
      Starts(left_points, cv::Point2f(3, -2), cv::Point2f(0.7f, 0.7f));
  std::vector<unsigned char> kept;
  RefineRightPixels(left, right, left_points, &right_points, &kept,
                    SubpixelOptions());
  std::vector<double> errors;
  for (size_t i = 0; i < left_points.size(); ++i) {
    if (!kept[i]) continue;
    errors.push_back(
        cv::norm(right_points[i] - left_points[i] - cv::Point2f(3, -2)));
  }
  // Grid points in flat gray between blobs are dropped by min_texture.
  ASSERT_GT(errors.size(), 0.85 * left_points.size());
  EXPECT_LT(Median(errors), kTolerance);
}

TEST(SubpixelRefinement, DisabledLeavesThePixelsAndKeepsAll) {
  const MovedPair images = MovedBlobs(160, 120, 150, 32, kDx, kDy);
  const std::vector<cv::Point2f> left_points = Grid(images.left, 20, 16);
  const std::vector<cv::Point2f> starts =
      Starts(left_points, cv::Point2f(0, 0), cv::Point2f(1, 1));
  std::vector<cv::Point2f> right_points = starts;
  std::vector<unsigned char> kept = {0, 0, 0};
  SubpixelOptions options;
  options.enabled = false;
  RefineRightPixels(images.left, images.right, left_points, &right_points,
                    &kept, options);
  EXPECT_EQ(right_points, starts);
  EXPECT_EQ(kept, std::vector<unsigned char>(left_points.size(), 1));
}

TEST(SubpixelRefinement, NoPointsNoWork) {
  const cv::Mat image = Blobs(64, 48, 20, 33);
  std::vector<cv::Point2f> right;
  std::vector<unsigned char> kept = {1};
  RefineRightPixels(image, image, {}, &right, &kept, SubpixelOptions());
  EXPECT_TRUE(right.empty());
  EXPECT_TRUE(kept.empty());
}

TEST(SubpixelRefinement, MatchesMovedFartherThanMaxShiftAreDropped) {
  // Starting 1 px off, the alignment moves each right pixel about 1 px:
  // kept with the default 2 px limit (above), dropped with 0.5 px, and a
  // dropped pixel is left where it started.
  const MovedPair images = MovedBlobs(320, 240, 600, 34, kDx, kDy);
  const cv::Mat& left = images.left;
  const cv::Mat& right = images.right;
  const cv::Point2f shift(static_cast<float>(kDx), static_cast<float>(kDy));
  const std::vector<cv::Point2f> left_points = Grid(left, 12, 16);
  const std::vector<cv::Point2f> starts =
      Starts(left_points, shift, cv::Point2f(1, 0));
  SubpixelOptions options;
  options.max_shift_px = 0.5;
  std::vector<cv::Point2f> right_points = starts;
  std::vector<unsigned char> kept;
  RefineRightPixels(left, right, left_points, &right_points, &kept, options);
  int dropped = 0;
  for (size_t i = 0; i < left_points.size(); ++i) {
    if (kept[i]) continue;
    ++dropped;
    EXPECT_EQ(right_points[i], starts[i]);
  }
  EXPECT_GT(dropped, 0.95 * left_points.size());

  // A start 6 px off, beyond the 2 px limit from the true patch: a match
  // is either dropped or, when the alignment stalls on another patch
  // within 2 px of its start, kept 4 px or more from the truth; never
  // moved onto the true patch and kept.
  right_points = Starts(left_points, shift, cv::Point2f(6, 0));
  RefineRightPixels(left, right, left_points, &right_points, &kept,
                    SubpixelOptions());
  int far_kept = 0;
  for (size_t i = 0; i < left_points.size(); ++i) {
    if (!kept[i]) continue;
    ++far_kept;
    EXPECT_GE(cv::norm(right_points[i] - left_points[i] - shift), 4.0);
  }
  // Measured: none kept.
  EXPECT_LT(far_kept, 0.05 * left_points.size());
}

TEST(SubpixelRefinement, FlatRegionsAreDropped) {
  // Left half textured, right half flat gray: in the flat half the
  // alignment has no gradient to follow (OpenCV reports it lost).
  MovedPair images = MovedBlobs(320, 240, 600, 35, kDx, kDy);
  const cv::Mat& left = images.left;
  const cv::Mat& right = images.right;
  left(cv::Rect(160, 0, 160, 240)).setTo(cv::Scalar(128));
  right(cv::Rect(160, 0, 160, 240)).setTo(cv::Scalar(128));
  const cv::Point2f shift(static_cast<float>(kDx), static_cast<float>(kDy));
  const std::vector<cv::Point2f> left_points = Grid(left, 12, 16);
  std::vector<cv::Point2f> right_points =
      Starts(left_points, shift, cv::Point2f(0, 1));
  const std::vector<cv::Point2f> starts = right_points;
  std::vector<unsigned char> kept;
  RefineRightPixels(left, right, left_points, &right_points, &kept,
                    SubpixelOptions());
  int flat = 0;
  int textured = 0;
  int textured_kept = 0;
  for (size_t i = 0; i < left_points.size(); ++i) {
    // Windows (11 px) clear of the texture's edge at u = 160.
    if (left_points[i].x > 175) {
      ++flat;
      EXPECT_FALSE(kept[i]) << left_points[i];
      EXPECT_EQ(right_points[i], starts[i]);
    } else if (left_points[i].x < 145) {
      ++textured;
      if (kept[i]) ++textured_kept;
    }
  }
  EXPECT_GT(flat, 100);
  // Some grid points of the textured half fall in flat gray between blobs.
  EXPECT_GT(textured_kept, 0.8 * textured);
}

TEST(SubpixelRefinement, OptionsCheck) {
  EXPECT_TRUE(SubpixelOptions().Check().ok());
  SubpixelOptions options;
  for (int window : {3, 4, 6, 12}) {
    options.window = window;
    EXPECT_EQ(options.Check().message(),
              "subpixel window must be odd and at least 5, got " +
                  std::to_string(window));
  }
  options.window = 5;
  EXPECT_TRUE(options.Check().ok());
  options = SubpixelOptions();
  options.max_iterations = 0;
  EXPECT_EQ(options.Check().message(),
            "subpixel refinement needs at least 1 iteration");
  options = SubpixelOptions();
  for (double bad : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN()}) {
    options.min_step_px = bad;
    EXPECT_EQ(options.Check().message(),
              "subpixel step, shift and warp limits must be positive");
    options.min_step_px = 0.01;
    options.max_shift_px = bad;
    EXPECT_EQ(options.Check().message(),
              "subpixel step, shift and warp limits must be positive");
    options.max_shift_px = 2.0;
  }
}

}  // namespace
}  // namespace rcm::subpixel_refinement_test
