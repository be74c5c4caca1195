#include "rcm/camera/refractive_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "support/test_rigs.h"

namespace rcm::refractive_camera_test {
namespace {

// Pixel round trips go through the iterative undistortion (1e-14 residual
// in normalized units, ~1e-11 px): 1e-9 px leaves two orders of margin.
constexpr double kPixelTolerance = 1e-9;
const double kIndices[] = {1.0, 1.33, 1.5};

TEST(RefractiveCamera, RoundTripWideFov) {
  // Every pixel of every test camera, including the 89.5-degree fisheye,
  // to a point in the medium at several depths and back.
  for (const Camera& camera : test::AllTestCameras()) {
    for (double n : kIndices) {
      const RefractiveCamera refractive =
          RefractiveCamera::Create(camera, n).value();
      double worst = 0.0;
      for (const Eigen::Vector2d& pixel : test::ImageGrid(camera, 8.0)) {
        const std::optional<Eigen::Vector3d> bearing =
            refractive.BearingInWaterFromImage(pixel);
        ASSERT_TRUE(bearing.has_value());
        EXPECT_NEAR(bearing->norm(), 1.0, 1e-15);
        for (double distance : {0.3, 2.0, 50.0}) {
          const std::optional<Eigen::Vector2d> back =
              refractive.ImageFromPointInWater(distance * *bearing);
          ASSERT_TRUE(back.has_value())
              << LensModelName(camera.model()) << " n = " << n << " at ("
              << pixel.transpose() << ")";
          worst = std::max(worst, (*back - pixel).norm());
        }
      }
      EXPECT_LT(worst, kPixelTolerance)
          << LensModelName(camera.model()) << " " << camera.width()
          << " px wide, n = " << n;
    }
  }
}

TEST(RefractiveCamera, BearingInvertsProjection) {
  // Points in the medium up to 40 degrees off axis (the critical angle is
  // 48.8 degrees): the bearing of their pixel points back at them.
  const RefractiveCamera refractive =
      RefractiveCamera::Create(test::AlphasenseCam0(), 1.33).value();
  for (double x = -1.0; x <= 1.0; x += 0.125) {
    for (double y = -0.75; y <= 0.75; y += 0.125) {
      const Eigen::Vector3d point(x, y, 1.5);
      const std::optional<Eigen::Vector2d> pixel =
          refractive.ImageFromPointInWater(point);
      ASSERT_TRUE(pixel.has_value());
      const Eigen::Vector3d bearing =
          refractive.BearingInWaterFromImage(*pixel).value();
      EXPECT_LT((bearing - point.normalized()).norm(), 1e-12);
    }
  }
}

TEST(RefractiveCamera, ReducesToPinholeAtNEqualsOne) {
  const Camera camera = test::PinholeCamera();
  const RefractiveCamera refractive =
      RefractiveCamera::Create(camera, 1.0).value();
  Eigen::Matrix3d k;
  k << camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(), camera.cy(), 0, 0, 1;
  EXPECT_EQ(refractive.VirtualPinholeMatrix(), k);
  for (double x = -1.0; x <= 1.0; x += 0.1) {
    for (double y = -0.8; y <= 0.8; y += 0.1) {
      const Eigen::Vector3d point(x, y, 1.3);
      const Eigen::Vector2d pinhole = (k * point).hnormalized();
      const Eigen::Vector2d pixel =
          refractive.ImageFromPointInWater(point).value();
      // 1e-12 relative to the pixel magnitude (a few hundred px).
      EXPECT_LT((pixel - pinhole).norm(), 1e-12 * pinhole.norm());
      const Eigen::Vector3d bearing =
          refractive.BearingInWaterFromImage(pinhole).value();
      EXPECT_LT((bearing - point.normalized()).norm(), 1e-12);
    }
  }
}

TEST(RefractiveCamera, RejectsIndexOutsideOneToTwo) {
  const Camera camera = test::PinholeCamera();
  for (double n : {0.99, 2.01, -1.33, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity()}) {
    const StatusOr<RefractiveCamera> refractive =
        RefractiveCamera::Create(camera, n);
    ASSERT_FALSE(refractive.ok()) << n;
    EXPECT_NE(refractive.status().message().find("is outside [1, 2]"),
              std::string::npos)
        << refractive.status().message();
  }
  EXPECT_TRUE(RefractiveCamera::Create(camera, 1.0).ok());
  EXPECT_TRUE(RefractiveCamera::Create(camera, 2.0).ok());
}

TEST(RefractiveCamera, ProjectionFailsBehindCameraAndPastCriticalAngle) {
  const RefractiveCamera refractive =
      RefractiveCamera::Create(test::WideEquidistantCamera(), 1.33).value();
  EXPECT_FALSE(refractive.ImageFromPointInWater({0.0, 0.0, -1.0}).has_value());
  const double critical = std::asin(1.0 / 1.33);
  EXPECT_TRUE(refractive
                  .ImageFromPointInWater({std::sin(critical - 1e-3), 0.0,
                                          std::cos(critical - 1e-3)})
                  .has_value());
  EXPECT_FALSE(refractive
                   .ImageFromPointInWater({std::sin(critical + 1e-3), 0.0,
                                           std::cos(critical + 1e-3)})
                   .has_value());
}

// Found by fuzz_camera_model: a pinhole pixel at u = 4e175 gave the bearing
// (0, 0, NaN). What overflows has no bearing.
TEST(RefractiveCamera, NoBearingForAPixelThatOverflows) {
  const Camera pinhole = Camera::Create(LensModelId::kPinhole, 3557, 1687,
                                        {1954.7, 1954.7, 1516.9, 1507.8}, {})
                             .value();
  const RefractiveCamera refractive =
      RefractiveCamera::Create(pinhole, 1.284).value();
  EXPECT_TRUE(refractive.BearingInWaterFromImage({1e5, -1000.0}).has_value());
  EXPECT_FALSE(
      refractive.BearingInWaterFromImage({4.03e175, -1000.0}).has_value());
  // r^2 just below the largest double: the bearing's length overflows.
  EXPECT_FALSE(
      refractive.BearingInWaterFromImage({1635.0, 2.6e157}).has_value());
}

TEST(RefractiveCamera, ProjectionRefusesFoldedLensBranch) {
  // A radtan lens that folds at r = 0.816: points beyond the fold would land
  // on wrong pixels inside the image.
  const Camera folded =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {300.0, 300.0, 319.5, 239.5}, {-0.5, 0.0, 0.0, 0.0})
          .value();
  const RefractiveCamera refractive =
      RefractiveCamera::Create(folded, 1.0).value();
  EXPECT_TRUE(refractive.ImageFromPointInWater({0.8, 0.0, 1.0}).has_value());
  EXPECT_FALSE(refractive.ImageFromPointInWater({1.2, 0.0, 1.0}).has_value());
}

TEST(RefractiveCamera, VirtualPinholeRoundTrip) {
  for (double n : kIndices) {
    const RefractiveCamera refractive =
        RefractiveCamera::Create(test::AlphasenseCam1(), n).value();
    for (const Eigen::Vector2d& pixel :
         test::ImageGrid(test::AlphasenseCam1(), 16.0)) {
      const Eigen::Vector2d virtual_pixel =
          refractive.VirtualPinholeFromImage(pixel).value();
      const Eigen::Vector2d back =
          refractive.ImageFromVirtualPinhole(virtual_pixel).value();
      EXPECT_LT((back - pixel).norm(), kPixelTolerance);
    }
  }
}

TEST(RefractiveCamera, VirtualPinholeProjectsWithKn) {
  // The virtual image is the pinhole K_n of the medium (eq. 9).
  const RefractiveCamera refractive =
      RefractiveCamera::Create(test::EurocRadtanCamera(), 1.34).value();
  const Eigen::Matrix3d k_n = refractive.VirtualPinholeMatrix();
  EXPECT_DOUBLE_EQ(k_n(0, 0), 1.34 * test::EurocRadtanCamera().fx());
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-0.9, 0.5, 1.1)}) {
    const Eigen::Vector2d pixel =
        refractive.ImageFromPointInWater(point).value();
    const Eigen::Vector2d virtual_pixel =
        refractive.VirtualPinholeFromImage(pixel).value();
    EXPECT_LT((virtual_pixel - (k_n * point).hnormalized()).norm(), 1e-9);
  }
}

TEST(RefractiveCamera, VirtualPinholeBeyondCriticalAngleHasNoSource) {
  // The virtual pinhole image is unbounded, the camera's view is not: a
  // virtual pixel past the critical angle has no raw pixel.
  const RefractiveCamera refractive =
      RefractiveCamera::Create(test::PinholeCamera(), 1.33).value();
  const double critical_tan = std::tan(std::asin(1.0 / 1.33));
  const double fx = test::PinholeCamera().fx() * 1.33;
  EXPECT_FALSE(
      refractive
          .ImageFromVirtualPinhole({319.5 + 1.01 * critical_tan * fx, 239.5})
          .has_value());
}

}  // namespace
}  // namespace rcm::refractive_camera_test

// --- A thick port made central at a reference depth (CreateWithPort).

namespace rcm::refractive_camera_test {
namespace {

FlatPort HousingPort() {
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  return port;
}

TEST(RefractiveCameraWithPort, ThinPortIsThePapersCamera) {
  const Camera lens = test::AlphasenseCam0();
  const RefractiveCamera paper = RefractiveCamera::Create(lens, 1.333).value();
  const RefractiveCamera with_port =
      RefractiveCamera::CreateWithPort(lens, 1.333, FlatPort(), 2.0).value();
  for (const Eigen::Vector2d& pixel : test::ImageGrid(lens, 40.0)) {
    EXPECT_EQ(with_port.BearingInWaterFromImage(pixel),
              paper.BearingInWaterFromImage(pixel));
    EXPECT_EQ(with_port.VirtualPinholeFromImage(pixel),
              paper.VirtualPinholeFromImage(pixel));
  }
}

// At the reference depth the central camera is exact: a pixel's bearing
// hits its own ray there, and projecting that point gives the pixel back
// (the exact port's Newton solve: 1e-12 in normalized coordinates, so
// 1e-9 px); the virtual pinhole round trip likewise.
TEST(RefractiveCameraWithPort, ExactAtTheReferenceDepth) {
  constexpr double kTolerancePx = 1e-9;
  constexpr double kDepth = 1.5;
  const Camera lens = test::AlphasenseCam0();
  const RefractiveCamera camera =
      RefractiveCamera::CreateWithPort(lens, 1.333, HousingPort(), kDepth)
          .value();
  int checked = 0;
  for (const Eigen::Vector2d& pixel : test::ImageGrid(lens, 30.0)) {
    const std::optional<Eigen::Vector3d> bearing =
        camera.BearingInWaterFromImage(pixel);
    if (!bearing) continue;
    const Eigen::Vector3d point = *bearing * (kDepth / bearing->z());
    const std::optional<Eigen::Vector2d> back =
        camera.ImageFromPointInWater(point);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - pixel).norm(), kTolerancePx);
    const std::optional<Eigen::Vector2d> virtual_pixel =
        camera.VirtualPinholeFromImage(pixel);
    ASSERT_TRUE(virtual_pixel.has_value());
    const std::optional<Eigen::Vector2d> raw =
        camera.ImageFromVirtualPinhole(*virtual_pixel);
    ASSERT_TRUE(raw.has_value());
    EXPECT_LT((*raw - pixel).norm(), kTolerancePx);
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

// Away from the reference depth the central approximation is off by the
// port's parallax, largest for near points: a 4 m reference against a
// point at 0.5 m is pixels off at the image border.
TEST(RefractiveCameraWithPort, ParallaxAwayFromTheReferenceDepth) {
  const Camera lens = test::AlphasenseCam0();
  const RefractiveCamera camera =
      RefractiveCamera::CreateWithPort(lens, 1.333, HousingPort(), 4.0).value();
  const Eigen::Vector2d pixel(600.0, 400.0);
  const Eigen::Vector3d bearing = camera.BearingInWaterFromImage(pixel).value();
  const Eigen::Vector2d at_reference =
      camera.ImageFromPointInWater(bearing * (4.0 / bearing.z())).value();
  const Eigen::Vector2d near =
      camera.ImageFromPointInWater(bearing * (0.5 / bearing.z())).value();
  EXPECT_LT((at_reference - pixel).norm(), 1e-9);
  EXPECT_GT((near - pixel).norm(), 1.0);
}

// The fuzz_camera_model case (a wide equidistant lens, a 23.5 mm port of
// index 1.69, n = 1.896) with the thinnest accepted air gap: the virtual
// pinhole round trip still closes. The solves are exact to ~1e-11 in
// normalized units, but the ray through a micron gap leaves it nearly
// grazing, which amplifies that to ~1e-5 px: 1e-4 px bounds it.
TEST(RefractiveCameraWithPort, VirtualPinholeRoundTripAtTheThinnestAirGap) {
  constexpr double kTolerancePx = 1e-4;
  const Camera lens = Camera::Create(LensModelId::kEquidistant, 3375, 3430,
                                     {4995.73, 952.767, 3039.06, 0.0},
                                     {0.0, 0.0, 0.0, 0.0})
                          .value();
  FlatPort port;
  port.air_gap = FlatPort::kMinLayerThickness;
  port.glass_thickness = 0.0235;
  port.glass_index = 1.6875;
  const RefractiveCamera camera =
      RefractiveCamera::CreateWithPort(lens, 1.896, port, 9.96).value();
  int checked = 0;
  for (const Eigen::Vector2d& pixel : test::ImageGrid(lens, 300.0)) {
    const std::optional<Eigen::Vector2d> raw =
        camera.ImageFromVirtualPinhole(pixel);
    if (!raw || !lens.InImage(*raw)) continue;
    const std::optional<Eigen::Vector2d> back =
        camera.VirtualPinholeFromImage(*raw);
    ASSERT_TRUE(back.has_value()) << pixel.transpose();
    EXPECT_LT((*back - pixel).norm(), kTolerancePx) << pixel.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

// Found by fuzz_camera_model: a fisheye (equidistant, f = 2387 px) whose
// principal point is in the image corner, behind a 281 mm air gap. A
// virtual pixel 6e135 px from the image maps to a raw pixel 0.01 degrees
// from grazing in air, and its bearing in water to within rounding of 90
// degrees, so the back map cannot recover it; it must fail cleanly. Within
// ten image sizes (the bearing up to 86.5 degrees off the axis) the round
// trip closes to 1e-9 px (measured); 1e-6 px bounds it.
TEST(RefractiveCameraWithPort, VirtualPinholeRoundTripUpToGrazingBearings) {
  constexpr double kTolerancePx = 1e-6;
  const Camera lens = Camera::Create(LensModelId::kEquidistant, 3963, 3945,
                                     {2386.94, 2386.91, 0.0, 0.0},
                                     {0.0, 0.0, 0.0, 0.0})
                          .value();
  FlatPort port;
  port.air_gap = 0.281;
  port.glass_thickness = 0.0522;
  port.glass_index = 1.4569;
  const RefractiveCamera camera =
      RefractiveCamera::CreateWithPort(lens, 1.4569, port, 3.8125).value();
  for (const double x : {0.0, 500.0, -3000.0}) {
    for (const double y : {100.0, 3000.0, 10000.0, 10.0 * lens.height()}) {
      const Eigen::Vector2d pixel(x, y);
      const std::optional<Eigen::Vector2d> raw =
          camera.ImageFromVirtualPinhole(pixel);
      ASSERT_TRUE(raw.has_value()) << pixel.transpose();
      const std::optional<Eigen::Vector2d> back =
          camera.VirtualPinholeFromImage(*raw);
      ASSERT_TRUE(back.has_value()) << pixel.transpose();
      EXPECT_LT((*back - pixel).norm(), kTolerancePx) << pixel.transpose();
    }
  }
  const Eigen::Vector2d far(0.0, 6.2251598974964918e+135);
  const std::optional<Eigen::Vector2d> raw =
      camera.ImageFromVirtualPinhole(far);
  if (raw) {
    EXPECT_TRUE(raw->allFinite());
    const std::optional<Eigen::Vector2d> back =
        camera.VirtualPinholeFromImage(*raw);
    if (back) {
      EXPECT_TRUE(back->allFinite());
    }
  }
}

TEST(RefractiveCameraWithPort, RejectsReferenceDepthInsideTheHousing) {
  const Camera lens = test::AlphasenseCam0();
  EXPECT_NE(RefractiveCamera::CreateWithPort(lens, 1.333, HousingPort(), 0.01)
                .status()
                .message()
                .find("not beyond the port's glass"),
            std::string::npos);
  FlatPort bad = HousingPort();
  bad.air_gap = -1.0;
  EXPECT_FALSE(RefractiveCamera::CreateWithPort(lens, 1.333, bad, 2.0).ok());
  EXPECT_FALSE(
      RefractiveCamera::CreateWithPort(lens, 2.5, HousingPort(), 2.0).ok());
  EXPECT_EQ(RefractiveCamera::CreateWithPort(lens, 1.333, HousingPort(), 1e217)
                .status()
                .message(),
            "reference depth 1e+217 m is beyond the accepted 10000 m");
  EXPECT_TRUE(RefractiveCamera::CreateWithPort(
                  lens, 1.333, HousingPort(),
                  RefractiveCamera::kMaxReferenceDepth)
                  .ok());
  // Found by fuzz_camera_model: 4e-217 m is beyond a thin port's glass, but
  // not by the millimetre the arithmetic needs.
  EXPECT_FALSE(
      RefractiveCamera::CreateWithPort(lens, 1.333, FlatPort(), 4e-217).ok());
  EXPECT_TRUE(
      RefractiveCamera::CreateWithPort(lens, 1.333, FlatPort(), 1e-3).ok());
}

}  // namespace
}  // namespace rcm::refractive_camera_test
