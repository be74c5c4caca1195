#include "rcm/calib/target_image.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <opencv2/aruco/charuco.hpp>
#include <vector>

#include "rcm/calib/calibration_target.h"

namespace rcm::calib::target_image_test {
namespace {

// A target point maps to a pixel edge crossing: both texture coordinates
// are half-integers up to rounding of the affine map.
constexpr double kToleranceTexturePx = 1e-6;

Eigen::Vector2d TextureOf(const TargetImage& image,
                          const Eigen::Vector3d& point) {
  const Eigen::Matrix2d linear = image.target_from_texture.leftCols<2>();
  return linear.inverse() *
         (point.head<2>() - image.target_from_texture.col(2));
}

// The four texture pixels around the edge crossing at `texture`:
// [0] up-left, [1] up-right, [2] down-left, [3] down-right (texture rows).
std::vector<int> PixelsAround(const TargetImage& image,
                              const Eigen::Vector2d& texture) {
  EXPECT_NEAR(texture.x() - std::floor(texture.x()), 0.5, kToleranceTexturePx);
  EXPECT_NEAR(texture.y() - std::floor(texture.y()), 0.5, kToleranceTexturePx);
  const int col = static_cast<int>(std::floor(texture.x()));
  const int row = static_cast<int>(std::floor(texture.y()));
  return {image.image.at<uint8_t>(row, col),
          image.image.at<uint8_t>(row, col + 1),
          image.image.at<uint8_t>(row + 1, col),
          image.image.at<uint8_t>(row + 1, col + 1)};
}

// The outermost `width` pixels of the texture are white.
void ExpectWhiteBorder(const cv::Mat& image, int width) {
  const cv::Rect inner(width, width, image.cols - 2 * width,
                       image.rows - 2 * width);
  cv::Mat outer = image.clone();
  outer(inner).setTo(255);
  EXPECT_EQ(cv::countNonZero(outer != 255), 0);
}

TEST(TargetImage, CheckerboardCornersAreExact) {
  const CalibrationTarget target =
      ParseCalibrationTarget(
          "target_type: checkerboard\ntargetCols: 6\ntargetRows: 4\n"
          "rowSpacingMeters: 0.03\ncolSpacingMeters: 0.025\n",
          "t.yaml")
          .value();
  const TargetImage image = DrawTargetImage(target, 1000.0);
  ASSERT_EQ(image.image.type(), CV_8UC1);
  // 25 and 30 pixels per square, 7 x 5 squares and a one-square margin.
  EXPECT_EQ(image.image.cols, 9 * 25);
  EXPECT_EQ(image.image.rows, 7 * 30);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const std::vector<int> around =
          PixelsAround(image, TextureOf(image, points[r * target.cols + c]));
      // Square (c, r) up-left of inner corner (r, c), black when c + r is
      // even (the top-left square is black).
      const int up_left = (c + r) % 2 == 0 ? 0 : 255;
      EXPECT_EQ(around[0], up_left) << r << ", " << c;
      EXPECT_EQ(around[3], up_left);
      EXPECT_EQ(around[1], 255 - up_left);
      EXPECT_EQ(around[2], 255 - up_left);
    }
  }
  ExpectWhiteBorder(image.image, 25);
}

TEST(TargetImage, AprilGridTagCornersAreExact) {
  const CalibrationTarget target = MakeAprilGridTarget(3, 2, 0.05, 0.3).value();
  const TargetImage image = DrawTargetImage(target, 1000.0);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  for (int id = 0; id < target.cols * target.rows; ++id) {
    // Corner k of the tag: lower-left, lower-right, upper-right,
    // upper-left with y up, i.e. texture rows flipped. The pixel inside the
    // tag (its black border) and the diagonal one (Kalibr's corner square)
    // are black, the other two white.
    // Which of PixelsAround is inside the tag, per corner: lower-left ->
    // up-right, lower-right -> up-left, upper-right -> down-left,
    // upper-left -> down-right.
    constexpr int kInside[4] = {1, 0, 2, 3};
    for (int k = 0; k < 4; ++k) {
      const std::vector<int> around =
          PixelsAround(image, TextureOf(image, points[4 * id + k]));
      const int in = kInside[k];
      EXPECT_EQ(around[in], 0) << id << ", " << k;
      EXPECT_EQ(around[3 - in], 0) << id << ", " << k;
      EXPECT_EQ(around[in ^ 1], 255) << id << ", " << k;
      EXPECT_EQ(around[(3 - in) ^ 1], 255) << id << ", " << k;
    }
  }
  // The quiet zone: one tag (50 px) beyond the corner squares (15 px).
  ExpectWhiteBorder(image.image, 50);
}

TEST(TargetImage, AprilGridTagZeroIsKalibrsPrint) {
  // kalibr_create_target_pdf: tag36h11 id 0 (code 0xd5d628584), bits
  // row-major from the upper-left seen with y up, most significant first,
  // a set bit white; a 2-bit black border.
  const CalibrationTarget target = MakeAprilGridTarget(2, 2, 0.1, 0.25).value();
  const TargetImage image = DrawTargetImage(target, 1000.0);  // 10 px bits
  constexpr uint64_t kTag0 = 0xd5d628584ull;
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 10; ++c) {
      // Centre of bit (r, c) of tag 0, r counted down from the top.
      const Eigen::Vector3d centre((c + 0.5) * 0.01, (9.5 - r) * 0.01, 0.0);
      const Eigen::Vector2d texture = TextureOf(image, centre);
      const int value =
          image.image.at<uint8_t>(static_cast<int>(std::lround(texture.y())),
                                  static_cast<int>(std::lround(texture.x())));
      const bool border = r < 2 || c < 2 || r >= 8 || c >= 8;
      const bool white =
          !border && ((kTag0 >> (35 - (6 * (r - 2) + (c - 2)))) & 1u) != 0;
      EXPECT_EQ(value, white ? 255 : 0) << r << ", " << c;
    }
  }
}

TEST(TargetImage, AprilGridInexactSpacingStaysWithinHalfAPixel) {
  // 0.2718 * 10 bits * b px is never whole for b = 1..16: tags rounded.
  const CalibrationTarget target =
      MakeAprilGridTarget(4, 3, 0.04, 0.2718).value();
  const TargetImage image = DrawTargetImage(target, 1000.0);
  for (const Eigen::Vector3d& point : TargetPoints(target)) {
    const Eigen::Vector2d texture = TextureOf(image, point);
    const Eigen::Vector2d rounded =
        (texture.array() - 0.5).round() + 0.5;  // nearest pixel edge
    EXPECT_LE((texture - rounded).cwiseAbs().maxCoeff(), 0.5 + 1e-9);
  }
}

TEST(TargetImage, CharucoCornersAreExact) {
  const CalibrationTarget target =
      MakeCharucoTarget(5, 4, 0.04, 0.03, "DICT_4X4_50").value();
  const TargetImage image = DrawTargetImage(target, 1000.0);
  EXPECT_EQ(image.image.cols, 7 * 40);
  EXPECT_EQ(image.image.rows, 6 * 40);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  for (int r = 0; r < target.rows - 1; ++r) {
    for (int c = 0; c < target.cols - 1; ++c) {
      const std::vector<int> around = PixelsAround(
          image, TextureOf(image, points[r * (target.cols - 1) + c]));
      // Up-left of corner (r, c) is square (c, r) (y down): black when
      // c + r is even. A white square's corner pixel is white (the
      // marker is inset).
      const int up_left = (c + r) % 2 == 0 ? 0 : 255;
      EXPECT_EQ(around[0], up_left) << r << ", " << c;
      EXPECT_EQ(around[3], up_left);
      EXPECT_EQ(around[1], 255 - up_left);
      EXPECT_EQ(around[2], 255 - up_left);
    }
  }
  ExpectWhiteBorder(image.image, 40);
}

TEST(TargetImage, CharucoMatchesOpenCvsDrawing) {
  for (const int squares_y : {4, 5}) {
    const CalibrationTarget target =
        MakeCharucoTarget(5, squares_y, 0.06, 0.042, "DICT_4X4_50").value();
    const TargetImage image = DrawTargetImage(target, 1000.0);  // 60 px
    const cv::Ptr<cv::aruco::CharucoBoard> board =
        cv::aruco::CharucoBoard::create(
            5, squares_y, 0.06f, 0.042f,
            cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50));
    cv::Mat drawn;
    board->draw(cv::Size(5 * 60, squares_y * 60), drawn, 0, 1);
    const cv::Mat ours = image.image(cv::Rect(60, 60, 5 * 60, squares_y * 60));
    // The squares agree exactly (pixels 2 px in from each square's
    // corners, outside any marker)...
    for (int y = 0; y < squares_y; ++y) {
      for (int x = 0; x < 5; ++x) {
        for (const int dy : {2, 57}) {
          for (const int dx : {2, 57}) {
            EXPECT_EQ(ours.at<uint8_t>(60 * y + dy, 60 * x + dx),
                      drawn.at<uint8_t>(60 * y + dy, 60 * x + dx))
                << squares_y << ": square " << x << ", " << y;
          }
        }
      }
    }
    // ...and the markers up to where OpenCV puts their cell edges (up to a
    // pixel off; measured 2.4% of the pixels differ).
    const double differing =
        cv::countNonZero(ours != drawn) / static_cast<double>(ours.total());
    EXPECT_LT(differing, 0.04) << squares_y;
  }
}

TEST(TargetImage, PixelsPerMetreIsRoundedToWholeSquares) {
  const CalibrationTarget target = MakeCheckerboardTarget(3, 3, 0.033).value();
  const TargetImage image = DrawTargetImage(target, 1000.0);  // 33 px
  EXPECT_NEAR(image.target_from_texture(0, 0), 0.001, 1e-15);
  const TargetImage coarse = DrawTargetImage(target, 1.0);  // 2 px minimum
  EXPECT_EQ(coarse.image.cols, 6 * 2);
  EXPECT_NEAR(coarse.target_from_texture(0, 0), 0.033 / 2, 1e-15);
}

}  // namespace
}  // namespace rcm::calib::target_image_test
