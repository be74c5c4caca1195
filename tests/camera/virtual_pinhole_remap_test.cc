#include "rcm/camera/virtual_pinhole_remap.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "support/test_rigs.h"

namespace rcm::virtual_pinhole_remap_test {
namespace {

RefractiveCamera Refractive(const Camera& camera, double n) {
  return RefractiveCamera::Create(camera, n).value();
}

// Float storage rounds a coordinate below 1024 to 3.1e-5 px.
constexpr double kMapTolerance = 1e-4;

TEST(VirtualPinholeRemap, MapsAgreeWithTheCamera) {
  // The three lens models, in air and in water.
  const std::vector<std::pair<Camera, double>> cases = {
      {test::AlphasenseCam0(), 1.0},
      {test::AlphasenseCam0(), 1.333},
      {test::EurocRadtanCamera(), 1.333},
      {test::EurocRadtanCamera(), 1.5},
      {test::PinholeCamera(), 1.333},
      {test::WideEquidistantCamera(), 1.333},
  };
  for (const auto& [camera, n] : cases) {
    const RefractiveCamera refractive = Refractive(camera, n);
    for (VirtualPinholeFit fit :
         {VirtualPinholeFit::kVirtualPinhole, VirtualPinholeFit::kNoBorder,
          VirtualPinholeFit::kFullFieldOfView}) {
      const VirtualPinholeView view =
          ChooseVirtualPinholeView(refractive, fit).value();
      const RemapMaps maps =
          BuildVirtualPinholeMaps(refractive, view, 2, false).value();
      ASSERT_EQ(maps.map_x.type(), CV_32FC1);
      ASSERT_EQ(maps.map_x.cols, view.width);
      ASSERT_EQ(maps.map_y.rows, view.height);
      EXPECT_TRUE(maps.fixed_xy.empty());
      const Eigen::Matrix3d virtual_from_output =
          refractive.VirtualPinholeMatrix() * view.k.inverse();
      double worst = 0.0;
      int64_t invalid = 0;
      for (int v = 0; v < view.height; v += 3) {
        for (int u = 0; u < view.width; u += 3) {
          const std::optional<Eigen::Vector2d> raw =
              refractive.ImageFromVirtualPinhole(
                  (virtual_from_output * Eigen::Vector3d(u, v, 1))
                      .hnormalized());
          const double x = maps.map_x.at<float>(v, u);
          const double y = maps.map_y.at<float>(v, u);
          if (raw && camera.InImage(*raw)) {
            worst = std::max(worst, (*raw - Eigen::Vector2d(x, y)).norm());
          } else {
            EXPECT_EQ(x, -1.0);
            EXPECT_EQ(y, -1.0);
            ++invalid;
          }
        }
      }
      EXPECT_LT(worst, kMapTolerance)
          << LensModelName(camera.model()) << " n = " << n;
      if (fit == VirtualPinholeFit::kNoBorder) {
        EXPECT_EQ(invalid, 0);
      }
    }
  }
}

TEST(VirtualPinholeRemap, IdentityForPinholeInAir) {
  const RefractiveCamera air = Refractive(test::PinholeCamera(), 1.0);
  const VirtualPinholeView view = ChooseVirtualPinholeView(air).value();
  EXPECT_TRUE(view.k.isApprox(air.VirtualPinholeMatrix()));
  EXPECT_EQ(view.width, 640);
  EXPECT_EQ(view.height, 480);
  const RemapMaps maps = BuildVirtualPinholeMaps(air, view).value();
  EXPECT_EQ(maps.num_invalid, 0);
  double worst = 0.0;
  for (int v = 0; v < view.height; ++v) {
    for (int u = 0; u < view.width; ++u) {
      const double dx = maps.map_x.at<float>(v, u) - u;
      const double dy = maps.map_y.at<float>(v, u) - v;
      worst = std::max({worst, std::abs(dx), std::abs(dy)});
    }
  }
  EXPECT_LT(worst, kMapTolerance);
  // The remapped image is the image.
  cv::Mat raw(480, 640, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(raw, cv::RNG::UNIFORM, 0, 256);
  EXPECT_EQ(cv::norm(RemapToVirtualPinhole(raw, maps), raw, cv::NORM_INF), 0.0);
}

TEST(VirtualPinholeRemap, NoBorderViewIsCoveredAndMaximal) {
  for (const Camera& camera :
       {test::AlphasenseCam0(), test::EurocRadtanCamera()}) {
    for (double n : {1.0, 1.333}) {
      const RefractiveCamera refractive = Refractive(camera, n);
      const VirtualPinholeView view =
          ChooseVirtualPinholeView(refractive, VirtualPinholeFit::kNoBorder)
              .value();
      const double scale = VirtualPinholeFocalScale(refractive, view);
      SCOPED_TRACE(::testing::Message() << LensModelName(camera.model())
                                        << " n = " << n << " scale " << scale);
      EXPECT_EQ(view.width, camera.width());
      EXPECT_EQ(view.height, camera.height());
      EXPECT_DOUBLE_EQ(view.k(0, 2), camera.cx());
      EXPECT_DOUBLE_EQ(view.k(1, 2), camera.cy());
      EXPECT_NEAR(view.k(1, 1) / view.k(0, 0), camera.fy() / camera.fx(),
                  1e-12);
      // Every output pixel samples inside [0, w - 1] x [0, h - 1].
      const RemapMaps maps =
          BuildVirtualPinholeMaps(refractive, view, 2, false).value();
      EXPECT_EQ(maps.num_invalid, 0);
      double min_x, max_x, min_y, max_y;
      cv::minMaxLoc(maps.map_x, &min_x, &max_x);
      cv::minMaxLoc(maps.map_y, &min_y, &max_y);
      EXPECT_GE(min_x, 0.0);
      EXPECT_LE(max_x, camera.width() - 1.0);
      EXPECT_GE(min_y, 0.0);
      EXPECT_LE(max_y, camera.height() - 1.0);
      // A view 1 % wider does not.
      VirtualPinholeView wider = view;
      wider.k(0, 0) *= 0.99;
      wider.k(1, 1) *= 0.99;
      const RemapMaps wider_maps =
          BuildVirtualPinholeMaps(refractive, wider, 2, false).value();
      cv::minMaxLoc(wider_maps.map_x, &min_x, &max_x);
      cv::minMaxLoc(wider_maps.map_y, &min_y, &max_y);
      EXPECT_TRUE(min_x < 0.0 || max_x > camera.width() - 1.0 || min_y < 0.0 ||
                  max_y > camera.height() - 1.0);
    }
  }
}

// Output pixel of the ray of each raw border pixel (centers on the four
// edges) that the lens unprojects, in `view`: K' R^T b, computed as
// FitFocalScale does.
std::vector<Eigen::Vector2d> BorderRaysInOutput(
    const RefractiveCamera& camera, const VirtualPinholeView& view) {
  const Camera& lens = camera.camera();
  std::vector<Eigen::Vector2d> pixels;
  const auto add = [&](int u, int v) {
    const std::optional<Eigen::Vector3d> bearing =
        camera.BearingInWaterFromImage(Eigen::Vector2d(u, v));
    if (!bearing) return;
    const Eigen::Vector3d in_view =
        view.camera_from_view.transpose() * *bearing;
    EXPECT_GT(in_view.z(), 0.0);
    pixels.push_back((view.k * in_view).hnormalized());
  };
  for (int u = 0; u < lens.width(); ++u) {
    add(u, 0);
    add(u, lens.height() - 1);
  }
  for (int v = 0; v < lens.height(); ++v) {
    add(0, v);
    add(lens.width() - 1, v);
  }
  return pixels;
}

// Number of `pixels` outside [0, w - 1] x [0, h - 1] of `view`, with the
// fits' slack.
int CountOutside(const std::vector<Eigen::Vector2d>& pixels,
                 const VirtualPinholeView& view) {
  constexpr double kSlack = kVirtualPinholeFitSlackPx;
  int outside = 0;
  for (const Eigen::Vector2d& pixel : pixels) {
    if (pixel.x() < -kSlack || pixel.x() > view.width - 1.0 + kSlack ||
        pixel.y() < -kSlack || pixel.y() > view.height - 1.0 + kSlack) {
      ++outside;
    }
  }
  return outside;
}

// The bisection's relative tolerance on s: the found s holds, one larger
// (narrower view) by this factor must not.
constexpr double kScaleTolerance = 1e-6;

TEST(VirtualPinholeRemap, FullFieldOfViewHoldsEveryBorderRayAndIsMaximal) {
  for (const Camera& camera :
       {test::AlphasenseCam0(), test::EurocRadtanCamera(),
        test::PinholeCamera()}) {
    for (double n : {1.0, 1.333}) {
      const RefractiveCamera refractive = Refractive(camera, n);
      const VirtualPinholeView view =
          ChooseVirtualPinholeView(refractive,
                                   VirtualPinholeFit::kFullFieldOfView)
              .value();
      const double scale = VirtualPinholeFocalScale(refractive, view);
      SCOPED_TRACE(::testing::Message() << LensModelName(camera.model())
                                        << " n = " << n << " scale " << scale);
      EXPECT_EQ(view.width, camera.width());
      EXPECT_EQ(view.height, camera.height());
      EXPECT_DOUBLE_EQ(view.k(0, 2), camera.cx());
      EXPECT_DOUBLE_EQ(view.k(1, 2), camera.cy());
      const std::vector<Eigen::Vector2d> rays =
          BorderRaysInOutput(refractive, view);
      EXPECT_GT(rays.size(), 2u * (camera.width() + camera.height()) - 8u);
      EXPECT_EQ(CountOutside(rays, view), 0);
      VirtualPinholeView narrower = view;
      narrower.k(0, 0) *= 1.0 + kScaleTolerance;
      narrower.k(1, 1) *= 1.0 + kScaleTolerance;
      EXPECT_GT(
          CountOutside(BorderRaysInOutput(refractive, narrower), narrower), 0);
      // The whole field of view is wider than the view without borders
      // (equal for a pinhole in air: both are the camera itself).
      const double no_border_scale = VirtualPinholeFocalScale(
          refractive,
          ChooseVirtualPinholeView(refractive, VirtualPinholeFit::kNoBorder)
              .value());
      if (camera.model() == LensModelId::kPinhole && n == 1.0) {
        EXPECT_EQ(scale, 1.0);
        EXPECT_EQ(no_border_scale, 1.0);
      } else {
        EXPECT_LT(scale, no_border_scale);
      }
    }
  }
}

TEST(VirtualPinholeRemap, FitNamesRoundTrip) {
  for (VirtualPinholeFit fit :
       {VirtualPinholeFit::kVirtualPinhole, VirtualPinholeFit::kNoBorder,
        VirtualPinholeFit::kFullFieldOfView}) {
    EXPECT_EQ(VirtualPinholeFitFromName(VirtualPinholeFitName(fit)), fit);
  }
  EXPECT_EQ(std::string(VirtualPinholeFitName(VirtualPinholeFit::kNoBorder)),
            "no-border");
  EXPECT_FALSE(VirtualPinholeFitFromName("none").has_value());
}

TEST(VirtualPinholeRemap, RotatedNoBorderFitIsCoveredAndMaximal) {
  // A view rotated 3 degrees: the bisection runs through the rotation, on
  // the output border, exactly as the maps sample.
  const RefractiveCamera camera = Refractive(test::AlphasenseCam0(), 1.333);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(3.0 * M_PI / 180.0,
                        Eigen::Vector3d(0.2, 1.0, -0.3).normalized())
          .toRotationMatrix();
  const ZoomedViewFamily family = VirtualPinholeFamily(camera);
  const double scale = FitFocalScale({RotatedCamera{camera, rotation}}, family,
                                     VirtualPinholeFit::kNoBorder)
                           .value();
  const RemapMaps maps =
      BuildVirtualPinholeMaps(camera, family.At(scale, rotation)).value();
  EXPECT_EQ(maps.num_invalid, 0);
  // Rotated off the principal point, the view must zoom in further than
  // the unrotated one.
  const double unrotated = FitFocalScale({RotatedCamera{camera}}, family,
                                         VirtualPinholeFit::kNoBorder)
                               .value();
  EXPECT_GT(scale, unrotated);
  const RemapMaps wider =
      BuildVirtualPinholeMaps(
          camera, family.At(scale * (1.0 - 2.0 * kScaleTolerance), rotation))
          .value();
  double min_x, max_x, min_y, max_y;
  cv::minMaxLoc(wider.map_x, &min_x, &max_x);
  cv::minMaxLoc(wider.map_y, &min_y, &max_y);
  EXPECT_TRUE(wider.num_invalid > 0 || min_x < 0.0 ||
              max_x > camera.camera().width() - 1.0 || min_y < 0.0 ||
              max_y > camera.camera().height() - 1.0);
}

TEST(VirtualPinholeRemap, ZoomedFamilyKeepsTheAnchor) {
  // The anchor pixel sees the anchor direction at every scale.
  ZoomedViewFamily family;
  family.base_focal = Eigen::Vector2d(400.0, 410.0);
  family.anchor_pixel = Eigen::Vector2d(319.5, 239.5);
  family.anchor_direction = Eigen::Vector2d(0.05, -0.02);
  family.width = 640;
  family.height = 480;
  for (double scale : {0.5, 1.0, 1.7}) {
    const VirtualPinholeView view = family.At(scale);
    EXPECT_TRUE(view.Check().ok());
    EXPECT_DOUBLE_EQ(view.k(0, 0), 400.0 * scale);
    EXPECT_DOUBLE_EQ(view.k(1, 1), 410.0 * scale);
    const Eigen::Vector2d seen =
        (view.k * Eigen::Vector3d(0.05, -0.02, 1.0)).hnormalized();
    EXPECT_NEAR((seen - family.anchor_pixel).norm(), 0.0, 1e-12);
  }
  ZoomedViewFamily bad = family;
  bad.base_focal.x() = 0.0;
  EXPECT_FALSE(bad.Check().ok());
  EXPECT_FALSE(FitFocalScale({}, family, VirtualPinholeFit::kNoBorder).ok());
}

TEST(VirtualPinholeRemap, FixedPointMapsAreOpenCvs) {
  // The fixed-point maps built alongside equal cv::convertMaps of the
  // float maps, invalid pixels included (a wider view than the camera
  // sees has some).
  const RefractiveCamera refractive =
      Refractive(test::EurocRadtanCamera(), 1.333);
  VirtualPinholeView view = ChooseVirtualPinholeView(refractive).value();
  view.k(0, 0) *= 0.6;
  view.k(1, 1) *= 0.6;
  const RemapMaps maps = BuildVirtualPinholeMaps(refractive, view).value();
  ASSERT_GT(maps.num_invalid, 1000);
  cv::Mat xy, table;
  cv::convertMaps(maps.map_x, maps.map_y, xy, table, CV_16SC2, false);
  ASSERT_EQ(maps.fixed_xy.type(), CV_16SC2);
  ASSERT_EQ(maps.fixed_table.type(), CV_16UC1);
  EXPECT_EQ(cv::norm(maps.fixed_xy, xy, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(maps.fixed_table, table, cv::NORM_INF), 0.0);
  // Both forms remap alike; invalid pixels read black.
  cv::Mat raw(refractive.camera().height(), refractive.camera().width(),
              CV_8UC1);
  cv::RNG rng(2);
  rng.fill(raw, cv::RNG::UNIFORM, 1, 256);
  RemapMaps float_maps = maps;
  float_maps.fixed_xy = cv::Mat();
  float_maps.fixed_table = cv::Mat();
  const cv::Mat fixed = RemapToVirtualPinhole(raw, maps);
  EXPECT_EQ(
      cv::norm(fixed, RemapToVirtualPinhole(raw, float_maps), cv::NORM_INF),
      0.0);
  EXPECT_GE(view.width * view.height - cv::countNonZero(fixed),
            maps.num_invalid);
}

// Raw image of points in the water: a Gaussian spot of sigma 1.2 px at the
// raw pixel of each point, on black.
cv::Mat RenderSpots(const RefractiveCamera& camera,
                    const std::vector<Eigen::Vector3d>& points) {
  const Camera& lens = camera.camera();
  cv::Mat image(lens.height(), lens.width(), CV_32FC1, cv::Scalar(0));
  constexpr double kSigma = 1.2;
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector2d pixel = camera.ImageFromPointInWater(point).value();
    const int u0 = static_cast<int>(std::lround(pixel.x()));
    const int v0 = static_cast<int>(std::lround(pixel.y()));
    for (int v = std::max(0, v0 - 6); v <= std::min(lens.height() - 1, v0 + 6);
         ++v) {
      for (int u = std::max(0, u0 - 6); u <= std::min(lens.width() - 1, u0 + 6);
           ++u) {
        const double d2 = (Eigen::Vector2d(u, v) - pixel).squaredNorm();
        image.at<float>(v, u) +=
            250.0 * std::exp(-0.5 * d2 / (kSigma * kSigma));
      }
    }
  }
  cv::Mat image8;
  image.convertTo(image8, CV_8UC1);
  return image8;
}

// Intensity centroid of `image` in a window around `guess`.
Eigen::Vector2d Centroid(const cv::Mat& image, const Eigen::Vector2d& guess) {
  const int u0 = static_cast<int>(std::lround(guess.x()));
  const int v0 = static_cast<int>(std::lround(guess.y()));
  double sum = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (int v = v0 - 7; v <= v0 + 7; ++v) {
    for (int u = u0 - 7; u <= u0 + 7; ++u) {
      if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
      const double value = image.at<uchar>(v, u);
      sum += value;
      weighted += value * Eigen::Vector2d(u, v);
    }
  }
  return weighted / sum;
}

TEST(VirtualPinholeRemap, GridPointsLandWhereTheVirtualPinholeSeesThem) {
  // A planar grid of points 1.5 m away in water: in the raw fisheye image
  // its rows bend; in the virtual pinhole image every point sits at
  // K_n (X/Z, Y/Z, 1) and the rows are straight.
  const double n = 1.333;
  const RefractiveCamera refractive = Refractive(test::AlphasenseCam0(), n);
  const Eigen::Matrix3d k_n = refractive.VirtualPinholeMatrix();
  std::vector<Eigen::Vector3d> points;
  const double depth = 1.5;
  for (int row = -4; row <= 4; ++row) {
    for (int column = -6; column <= 6; ++column) {
      points.emplace_back(0.12 * column, 0.12 * row, depth);
    }
  }
  const cv::Mat raw = RenderSpots(refractive, points);
  const VirtualPinholeView view = ChooseVirtualPinholeView(refractive).value();
  for (bool fixed_point : {false, true}) {
    const RemapMaps maps =
        BuildVirtualPinholeMaps(refractive, view, 2, fixed_point).value();
    const cv::Mat remapped = RemapToVirtualPinhole(raw, maps);
    ASSERT_EQ(remapped.type(), CV_8UC1);
    double worst = 0.0;
    double worst_row_bend = 0.0;
    double worst_raw_row_bend = 0.0;
    for (int row = 0; row < 9; ++row) {
      double v_min = 1e9, v_max = -1e9, raw_min = 1e9, raw_max = -1e9;
      for (int column = 0; column < 13; ++column) {
        const Eigen::Vector3d& point = points[row * 13 + column];
        const Eigen::Vector2d expected = (k_n * point).hnormalized();
        const Eigen::Vector2d found = Centroid(remapped, expected);
        worst = std::max(worst, (found - expected).norm());
        v_min = std::min(v_min, found.y());
        v_max = std::max(v_max, found.y());
        const Eigen::Vector2d raw_pixel =
            refractive.ImageFromPointInWater(point).value();
        raw_min = std::min(raw_min, raw_pixel.y());
        raw_max = std::max(raw_max, raw_pixel.y());
      }
      worst_row_bend = std::max(worst_row_bend, v_max - v_min);
      worst_raw_row_bend = std::max(worst_raw_row_bend, raw_max - raw_min);
    }
    SCOPED_TRACE(fixed_point ? "fixed-point maps" : "float maps");
    EXPECT_LT(worst, 0.1);
    EXPECT_LT(worst_row_bend, 0.15);
    EXPECT_GT(worst_raw_row_bend, 5.0);  // the raw rows do bend
  }
}

TEST(VirtualPinholeRemap, RotatedViewSeesTheRotatedRays) {
  // A view rotated by R sees the ray R d_view at the output pixel K' d_view:
  // the map holds the raw pixel of that ray in the medium.
  const RefractiveCamera camera = Refractive(test::AlphasenseCam0(), 1.333);
  VirtualPinholeView view = ChooseVirtualPinholeView(camera).value();
  view.camera_from_view =
      Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, -1.0, 0.2).normalized())
          .toRotationMatrix();
  const RemapMaps maps = BuildVirtualPinholeMaps(camera, view).value();
  int compared = 0;
  for (int v = 0; v < view.height; v += 23) {
    for (int u = 0; u < view.width; u += 31) {
      const Eigen::Vector3d ray =
          view.camera_from_view * view.k.inverse() * Eigen::Vector3d(u, v, 1);
      const std::optional<Eigen::Vector2d> raw =
          camera.ImageFromPointInWater(ray);
      if (!raw || !camera.camera().InImage(*raw)) {
        EXPECT_EQ(maps.map_x.at<float>(v, u), -1.0f);
        continue;
      }
      EXPECT_NEAR(maps.map_x.at<float>(v, u), raw->x(), kMapTolerance);
      EXPECT_NEAR(maps.map_y.at<float>(v, u), raw->y(), kMapTolerance);
      ++compared;
    }
  }
  EXPECT_GT(compared, 400);
  view.camera_from_view(0, 0) = 1.1;  // not a rotation
  EXPECT_FALSE(BuildVirtualPinholeMaps(camera, view).ok());
}

TEST(VirtualPinholeRemap, RejectsBadInput) {
  const RefractiveCamera refractive = Refractive(test::AlphasenseCam0(), 1.33);
  VirtualPinholeView view = ChooseVirtualPinholeView(refractive).value();
  EXPECT_EQ(BuildVirtualPinholeMaps(refractive, view, 0).status().message(),
            "num_threads = 0 must be at least 1");
  VirtualPinholeView empty = view;
  empty.width = 0;
  EXPECT_EQ(BuildVirtualPinholeMaps(refractive, empty).status().message(),
            "virtual pinhole view: size 0 x 540 is not positive");
  VirtualPinholeView skewed = view;
  skewed.k(0, 1) = 0.5;
  EXPECT_FALSE(skewed.Check().ok());
  VirtualPinholeView negative = view;
  negative.k(1, 1) = -1.0;
  EXPECT_FALSE(BuildVirtualPinholeMaps(refractive, negative).ok());

  // A principal point off the image has no border-free view.
  const Camera off_center =
      Camera::Create(LensModelId::kPinhole, 100, 100, {80, 80, 150, 50}, {})
          .value();
  const StatusOr<VirtualPinholeView> none = ChooseVirtualPinholeView(
      Refractive(off_center, 1.33), VirtualPinholeFit::kNoBorder);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().message(),
            "no virtual pinhole view without black borders: the principal "
            "point lies outside the image");
}

}  // namespace
}  // namespace rcm::virtual_pinhole_remap_test
