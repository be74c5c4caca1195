#include "rcm/calib/target_renderer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <vector>

#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_detector.h"
#include "rcm/calib/target_image.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/sim/reference_rigs.h"
#include "support/test_rigs.h"

namespace rcm::calib::target_renderer_test {
namespace {

// ProjectTargetPoints against Camera::ProjectNormalized: the same
// arithmetic, so only rounding differs.
constexpr double kToleranceProjectionPx = 1e-9;

Camera SmallPinhole() {
  return Camera::Create(LensModelId::kPinhole, 160, 120, {150, 150, 79.5, 59.5},
                        {})
      .value();
}

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(5, 4, 0.05).value();
}

// The board frontal (camera x, y = target x, y), `distance` in front, its
// first inner corner at (x0, y0) in the camera frame.
Rigid3d Frontal(double distance, double x0 = -0.1, double y0 = -0.08) {
  Rigid3d pose;
  pose.translation = Eigen::Vector3d(x0, y0, distance);
  return pose;
}

// The texture pixel value at target point (x, y).
int TextureAt(const TargetImage& image, const Eigen::Vector2d& target_xy) {
  const Eigen::Matrix2d linear = image.target_from_texture.leftCols<2>();
  const Eigen::Vector2d texture =
      linear.inverse() * (target_xy - image.target_from_texture.col(2));
  const int col = static_cast<int>(std::floor(texture.x() + 0.5));
  const int row = static_cast<int>(std::floor(texture.y() + 0.5));
  if (col < 0 || row < 0 || col >= image.image.cols ||
      row >= image.image.rows) {
    return -1;
  }
  return image.image.at<uint8_t>(row, col);
}

// The point of the target plane that pixel position `pixel` sees under a
// frontal pose.
Eigen::Vector2d TargetSeenAt(const Camera& camera, const Rigid3d& pose,
                             const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d normalized = *camera.NormalizedFromImage(pixel);
  return normalized * pose.translation.z() - pose.translation.head<2>();
}

// Every pixel of `image` whose four corners see one texture pixel (where
// `seen_at` puts them on the target) has exactly its value, or
// `background` off the texture; and there are many of both.
void ExpectUniformPixelsAreTheirSquare(
    const cv::Mat& image, const TargetImage& texture,
    const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& seen_at,
    int background) {
  int uniform = 0;
  int off_target = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      // The texture values at the pixel's four corners.
      int values[4];
      for (int k = 0; k < 4; ++k) {
        values[k] = TextureAt(
            texture,
            seen_at(Eigen::Vector2d(x - 0.5 + (k & 1), y - 0.5 + k / 2)));
      }
      const bool same = values[0] == values[1] && values[1] == values[2] &&
                        values[2] == values[3];
      if (!same) continue;
      const int expected = values[0] < 0 ? background : values[0];
      EXPECT_EQ(image.at<uint8_t>(y, x), expected) << x << ", " << y;
      ++(values[0] < 0 ? off_target : uniform);
    }
  }
  // The test saw squares of both colours and the background.
  EXPECT_GT(uniform, 1000);
  EXPECT_GT(off_target, 100);
}

TEST(TargetRenderer, PixelInsideOneSquareHasExactlyItsColour) {
  const Camera camera = SmallPinhole();
  const TargetImage texture = DrawTargetImage(Checkerboard(), 2000.0);
  const TargetRenderer renderer =
      TargetRenderer::Create(camera, texture).value();
  const Rigid3d pose = Frontal(0.8);
  TargetRenderOptions options;
  options.background = 77;
  const cv::Mat image = renderer.Render(pose, options);
  ASSERT_EQ(image.type(), CV_8UC1);
  ASSERT_EQ(image.cols, 160);
  ASSERT_EQ(image.rows, 120);
  ExpectUniformPixelsAreTheirSquare(
      image, texture,
      [&](const Eigen::Vector2d& pixel) {
        return TargetSeenAt(camera, pose, pixel);
      },
      77);
}

TEST(TargetRenderer, BoardBehindCameraIsBackground) {
  const TargetRenderer renderer =
      TargetRenderer::Create(SmallPinhole(),
                             DrawTargetImage(Checkerboard(), 2000.0))
          .value();
  TargetRenderOptions options;
  options.background = 33;
  const cv::Mat image = renderer.Render(Frontal(-0.8), options);
  EXPECT_EQ(cv::countNonZero(image != 33), 0);
  // Edge-on (the camera in the target plane): background too.
  Rigid3d edge_on;
  edge_on.rotation = Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d::UnitX())
                         .toRotationMatrix();
  edge_on.translation = Eigen::Vector3d(0.0, 0.0, 0.0);
  EXPECT_EQ(cv::countNonZero(renderer.Render(edge_on, options) != 33), 0);
}

// The board turned by 0.4 rad about a skew axis, 0.4 m ahead.
Rigid3d Oblique() {
  Rigid3d pose;
  pose.rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1.0, 0.2).normalized())
          .toRotationMatrix();
  pose.translation = Eigen::Vector3d(-0.1, -0.05, 0.4);
  return pose;
}

TEST(TargetRenderer, ProjectTargetPointsAgreesWithCamera) {
  const Camera camera = AlphasenseFrontCam0();
  const CalibrationTarget target = Checkerboard();
  const Rigid3d pose = Oblique();
  const std::vector<std::optional<Eigen::Vector2d>> pixels =
      ProjectTargetPoints(camera, pose, target);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(pixels.size(), points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d in_camera = pose * points[k];
    const Eigen::Vector2d expected =
        camera.ImageFromNormalized(in_camera.hnormalized());
    ASSERT_TRUE(pixels[k].has_value()) << k;
    EXPECT_NEAR((*pixels[k] - expected).norm(), 0.0, kToleranceProjectionPx);
  }
}

TEST(TargetRenderer, ProjectTargetPointsOutsideOrBehindIsNullopt) {
  const Camera camera = SmallPinhole();
  const CalibrationTarget target = Checkerboard();
  for (const std::optional<Eigen::Vector2d>& pixel :
       ProjectTargetPoints(camera, Frontal(-0.5), target)) {
    EXPECT_FALSE(pixel.has_value());
  }
  // Shifted so that only the first column of corners is in the image:
  // x0 = 0.1 m at 0.3 m is 50 px right of the centre, the next column
  // (0.15 m) 75 px, beyond the 80 px half width only from the third.
  const std::vector<std::optional<Eigen::Vector2d>> pixels =
      ProjectTargetPoints(camera, Frontal(0.3, 0.1, -0.05), target);
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const std::optional<Eigen::Vector2d>& pixel = pixels[r * target.cols + c];
      EXPECT_EQ(pixel.has_value(), c < 2) << r << ", " << c;
      if (pixel) {
        EXPECT_TRUE(camera.InImage(*pixel));
      }
    }
  }
}

TEST(TargetRenderer, DeterministicForAnyThreadCount) {
  const Camera camera = AlphasenseFrontCam0();
  const TargetRenderer renderer =
      TargetRenderer::Create(camera, DrawTargetImage(Checkerboard(), 2000.0))
          .value();
  Rigid3d pose = Frontal(0.5);
  pose.rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  TargetRenderOptions options;
  options.supersampling = 3;
  options.blur_sigma_px = 0.7;
  options.noise_sigma = 3.0;
  options.seed = 42;
  options.num_threads = 1;
  const cv::Mat one = renderer.Render(pose, options);
  options.num_threads = 3;
  const cv::Mat three = renderer.Render(pose, options);
  EXPECT_EQ(cv::countNonZero(one != three), 0);
  // Another seed gives other noise.
  options.seed = 43;
  EXPECT_GT(cv::countNonZero(renderer.Render(pose, options) != three), 1000);
}

TEST(TargetRenderer, RenderTimeIsReported) {
  // Not a timing test: prints the time of one 720x540 render at 4x4
  // supersampling on 2 threads, for the record.
  const CalibrationTarget target = MakeAprilGridTarget(6, 6, 0.05, 0.3).value();
  const TargetRenderer renderer =
      TargetRenderer::Create(AlphasenseFrontCam0(),
                             DrawTargetImage(target, 4000.0))
          .value();
  Rigid3d pose;
  pose.rotation = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  pose.translation = Eigen::Vector3d(-0.18, 0.18, 0.5);
  TargetRenderOptions options;
  options.blur_sigma_px = 0.5;
  options.noise_sigma = 2.0;
  const auto start = std::chrono::steady_clock::now();
  const cv::Mat image = renderer.Render(pose, options);
  const double ms = std::chrono::duration<double, std::milli>(
                        std::chrono::steady_clock::now() - start)
                        .count();
  std::printf("720x540 render, 4x4 supersampling, 2 threads: %.1f ms\n", ms);
  EXPECT_EQ(image.cols, 720);
}

// Through a dome port (the 4-inch acrylic dome, decentered 2 mm, -1 mm and
// 7 mm) in water.
DomePortCamera BehindDome(const Camera& camera,
                          const Eigen::Vector3d& decentering) {
  return DomePortCamera::Create(camera, ::rcm::test::AcrylicDome(decentering),
                                1.333)
      .value();
}

const Eigen::Vector3d kDecentering(0.002, -0.001, 0.007);

// The point of the target plane that pixel position `pixel` sees through
// the dome under a frontal pose: P = o - t + s d on z = 0.
Eigen::Vector2d TargetSeenThroughDomeAt(const DomePortCamera& camera,
                                        const Rigid3d& pose,
                                        const Eigen::Vector2d& pixel) {
  const RayInMedium ray = *camera.RayFromImage(pixel);
  const Eigen::Vector3d origin = ray.origin - pose.translation;
  return (origin - origin.z() / ray.direction.z() * ray.direction).head<2>();
}

// As PixelInsideOneSquareHasExactlyItsColour: the corner rays are the
// dome's exact ones, so a pixel whose four corners see one square is that
// square's colour.
TEST(TargetRenderer, DomePixelInsideOneSquareHasExactlyItsColour) {
  const DomePortCamera camera = BehindDome(SmallPinhole(), kDecentering);
  const TargetImage texture = DrawTargetImage(Checkerboard(), 2000.0);
  const TargetRenderer renderer =
      TargetRenderer::Create(camera, texture).value();
  ASSERT_TRUE(renderer.dome_camera().has_value());
  const Rigid3d pose = Frontal(0.8);
  TargetRenderOptions options;
  options.background = 77;
  const cv::Mat image = renderer.Render(pose, options);
  ExpectUniformPixelsAreTheirSquare(
      image, texture,
      [&](const Eigen::Vector2d& pixel) {
        return TargetSeenThroughDomeAt(camera, pose, pixel);
      },
      77);
  // Behind the camera: background.
  options.background = 33;
  EXPECT_EQ(cv::countNonZero(renderer.Render(Frontal(-0.8), options) != 33), 0);
}

// A centred dome does not refract: its image is the air camera's, up to
// the blend's weights (w = 1 / s from the dome's outer surface, not the
// camera centre), which move a sub-sample by far less than a pixel.
TEST(TargetRenderer, CentredDomeRendersTheAirImage) {
  const Camera camera = AlphasenseFrontCam0();
  const TargetImage texture = DrawTargetImage(Checkerboard(), 2000.0);
  const TargetRenderer air = TargetRenderer::Create(camera, texture).value();
  const TargetRenderer dome =
      TargetRenderer::Create(BehindDome(camera, Eigen::Vector3d::Zero()),
                             texture)
          .value();
  Rigid3d pose = Frontal(0.5);
  pose.rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  TargetRenderOptions options;
  options.board_warp =
      BoardWarpSurfaceOf(Checkerboard(), Eigen::Vector2d(0.002, -0.001));
  cv::Mat difference;
  cv::absdiff(air.Render(pose, options), dome.Render(pose, options),
              difference);
  double max_difference = 0.0;
  cv::minMaxLoc(difference, nullptr, &max_difference);
  EXPECT_LE(max_difference, 1.0);
}

// Detected corners on renders through a decentered dome against
// DomePortCamera::ImageFromPoint of the true corners: the detector's
// tolerance class of target_detector_test.cc (median 0.1 px, max 0.35 px
// for the chessboard on 4x4 supersampled renders, blur 0.5 px, noise 2
// gray levels).
TEST(TargetRenderer, DomeCornersAreDetectedWhereTheyProject) {
  constexpr double kToleranceMedianPx = 0.1;
  constexpr double kToleranceMaxPx = 0.35;
  const CalibrationTarget target = MakeCheckerboardTarget(8, 5, 0.04).value();
  const DomePortCamera camera = BehindDome(AlphasenseFrontCam0(), kDecentering);
  const TargetRenderer renderer =
      TargetRenderer::Create(camera, DrawTargetImage(target, 4000.0)).value();
  // The board's centre at (cx, cy, z), tilted about x and y.
  const double views[][5] = {{0.0, 0.0, 0.55, 0.0, 0.0},
                             {0.05, -0.03, 0.6, 0.35, -0.3},
                             {-0.08, 0.06, 0.5, -0.3, 0.35}};
  const Eigen::Vector3d centre(0.5 * 7 * 0.04 - 0.02, 0.5 * 4 * 0.04 - 0.02,
                               0.0);
  std::vector<double> errors;
  int missing = 0;
  uint64_t seed = 1;
  for (const auto& view : views) {
    Rigid3d pose;
    pose.rotation = (Eigen::AngleAxisd(view[3], Eigen::Vector3d::UnitX()) *
                     Eigen::AngleAxisd(view[4], Eigen::Vector3d::UnitY()))
                        .toRotationMatrix();
    pose.translation =
        Eigen::Vector3d(view[0], view[1], view[2]) - pose.rotation * centre;
    TargetRenderOptions options;
    options.blur_sigma_px = 0.5;
    options.noise_sigma = 2.0;
    options.seed = seed++;
    const std::optional<TargetObservation> observation =
        DetectTarget(renderer.Render(pose, options), target);
    ASSERT_TRUE(observation.has_value()) << "view " << seed - 1;
    const std::vector<std::optional<Eigen::Vector2d>> truth =
        ProjectTargetPoints(camera, pose, target);
    int visible = 0;
    for (const auto& pixel : truth) visible += pixel.has_value();
    missing += visible - observation->size();
    for (int k = 0; k < observation->size(); ++k) {
      const std::optional<Eigen::Vector2d>& pixel =
          truth[observation->point_ids[k]];
      ASSERT_TRUE(pixel.has_value()) << observation->point_ids[k];
      errors.push_back((observation->pixels[k] - *pixel).norm());
    }
  }
  std::sort(errors.begin(), errors.end());
  ASSERT_FALSE(errors.empty());
  const double median = errors[errors.size() / 2];
  std::printf(
      "chessboard through a dome: %zu corners, %d missed, median "
      "%.3f px, max %.3f px\n",
      errors.size(), missing, median, errors.back());
  EXPECT_EQ(missing, 0);
  EXPECT_LT(median, kToleranceMedianPx);
  EXPECT_LT(errors.back(), kToleranceMaxPx);
}

TEST(TargetRenderer, ProjectTargetPointsThroughADomeAgreesWithTheDome) {
  const DomePortCamera camera = BehindDome(AlphasenseFrontCam0(), kDecentering);
  const CalibrationTarget target = Checkerboard();
  const Rigid3d pose = Oblique();
  const Eigen::Vector2d warp(0.001, 0.0005);
  const std::vector<std::optional<Eigen::Vector2d>> pixels =
      ProjectTargetPoints(camera, pose, target, warp);
  const std::vector<Eigen::Vector3d> points = WarpedTargetPoints(target, warp);
  ASSERT_EQ(pixels.size(), points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    ASSERT_TRUE(pixels[k].has_value()) << k;
    EXPECT_EQ(*pixels[k], *camera.ImageFromPoint(pose * points[k]));
  }
  for (const std::optional<Eigen::Vector2d>& pixel :
       ProjectTargetPoints(camera, Frontal(-0.5), target)) {
    EXPECT_FALSE(pixel.has_value());
  }
}

TEST(TargetRenderer, CreateRejectsBadTexture) {
  TargetImage empty;
  EXPECT_EQ(TargetRenderer::Create(SmallPinhole(), empty).status().message(),
            "target image must be a non-empty 8-bit gray image");
  TargetImage singular = DrawTargetImage(Checkerboard(), 1000.0);
  singular.target_from_texture.setZero();
  EXPECT_EQ(TargetRenderer::Create(SmallPinhole(), singular).status().message(),
            "target_from_texture is not invertible");
  EXPECT_EQ(
      TargetRenderer::Create(BehindDome(SmallPinhole(), kDecentering), singular)
          .status()
          .message(),
      "target_from_texture is not invertible");
}

TEST(TargetRenderOptions, Check) {
  EXPECT_TRUE(TargetRenderOptions().Check().ok());
  TargetRenderOptions options;
  options.supersampling = 0;
  EXPECT_EQ(options.Check().message(), "supersampling = 0 must be in [1, 16]");
  options = TargetRenderOptions();
  options.noise_sigma = -1.0;
  EXPECT_FALSE(options.Check().ok());
  options = TargetRenderOptions();
  options.background = 256;
  EXPECT_EQ(options.Check().message(), "background = 256 must be in [0, 255]");
  options = TargetRenderOptions();
  options.blur_sigma_px = std::nan("");
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm::calib::target_renderer_test
