#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/dome_port_refraction.h"
#include "rcm/camera/refractive_camera.h"
#include "support/test_rigs.h"

namespace rcm::dome_port_test {
namespace {

using test::AcrylicDome;
using test::AllTestCameras;
using test::ImageGrid;
using test::PinholeCamera;

// A dome that does not refract gives the air camera up to rounding: a few
// ulps of the normalized point (<= 7 at the wide lenses' corners) times a
// focal length of a few hundred pixels, ~1e-13 px.
constexpr double kAirCameraTolerancePx = 1e-12;
// Round trip pixel -> ray -> point -> pixel: the Gauss-Newton solve
// converges to a few ulps of the normalized point.
constexpr double kRoundTripTolerancePx = 1e-9;
// Central differences of step h on functions of unit curvature scale:
// truncation h^2 ~ 1e-12, rounding eps / h ~ 1e-10, relative.
constexpr double kDerivativeTolerance = 1e-6;

// Decenterings of 1-10 mm in every direction (the range).
std::vector<Eigen::Vector3d> Decenterings() {
  return {{0.001, 0.0, 0.0},  {0.0, -0.002, 0.0},     {0.0, 0.0, 0.0072},
          {0.0, 0.0, -0.005}, {0.002, -0.001, 0.006}, {-0.006, 0.004, -0.005},
          {0.0, 0.0, 0.01},   {0.007, 0.007, 0.0}};
}

TEST(DomePort, DefaultIsValidAndCentred) {
  const DomePort dome;
  EXPECT_TRUE(dome.Check().ok());
  EXPECT_TRUE(dome.IsCentred());
  EXPECT_DOUBLE_EQ(dome.outer_radius(), 0.055);
}

TEST(DomePort, CameraOutsideTheInnerSphereIsRefused) {
  const DomePort dome = AcrylicDome({0.0, 0.0, 0.05});
  const Status status = dome.Check();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("outside the inner sphere"),
            std::string::npos)
      << status.message();
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
}

TEST(DomePort, MillimetresGivenAsMetresAreRefused) {
  DomePort dome;
  dome.inner_radius = 43.55;
  const Status status = dome.Check();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("millimetres"), std::string::npos)
      << status.message();
  dome = DomePort();
  dome.thickness = 1e-9;
  EXPECT_FALSE(dome.Check().ok());
  dome = DomePort();
  dome.glass_index = 2.5;
  EXPECT_FALSE(dome.Check().ok());
  dome = DomePort();
  dome.decentering.x() = NAN;
  EXPECT_FALSE(dome.Check().ok());
}

TEST(DomePort, RadiiThatContradictTheThicknessAreRefused) {
  // 0.0473 - 0.04355 is 0.0037500000000000033 in doubles; the nanometre
  // rounding gives the decimal thickness exactly.
  EXPECT_EQ(DomeThicknessFromRadii(0.04355, 0.0473, -1.0).value(), 0.00375);
  EXPECT_NEAR(DomeThicknessFromRadii(0.04355, 0.0473, 0.00375).value(), 0.00375,
              1e-15);
  const StatusOr<double> contradiction =
      DomeThicknessFromRadii(0.04355, 0.0473, 0.005);
  ASSERT_FALSE(contradiction.ok());
  EXPECT_NE(contradiction.status().message().find("not the 0.005 m given"),
            std::string::npos)
      << contradiction.status().message();
  EXPECT_FALSE(DomeThicknessFromRadii(0.05, 0.04, -1.0).ok());
}

TEST(DomePortCamera, BadIndexIsRefused) {
  EXPECT_FALSE(DomePortCamera::Create(PinholeCamera(), DomePort(), 0.9).ok());
  EXPECT_FALSE(DomePortCamera::Create(PinholeCamera(), DomePort(), NAN).ok());
  EXPECT_FALSE(
      DomePortCamera::Create(PinholeCamera(), AcrylicDome({0, 0, 0.1}), 1.33)
          .ok());
}

// Points at 0.2-5 m through every pixel of a grid of each test camera.
void ExpectAirCamera(const DomePort& dome, double n) {
  for (const Camera& camera : AllTestCameras()) {
    const DomePortCamera through =
        DomePortCamera::Create(camera, dome, n).value();
    int checked = 0;
    for (const Eigen::Vector2d& pixel : ImageGrid(camera, 40.0)) {
      const std::optional<Eigen::Vector2d> normalized =
          camera.NormalizedFromImage(pixel);
      if (!normalized) continue;
      const Eigen::Vector3d ray = normalized->homogeneous().normalized();
      for (double depth : {0.2, 1.0, 5.0}) {
        const Eigen::Vector3d point = depth * ray;
        const std::optional<Eigen::Vector2d> image =
            through.ImageFromPoint(point);
        const std::optional<Eigen::Vector2d> air =
            camera.ProjectNormalized(point.hnormalized());
        ASSERT_TRUE(image && air) << pixel.transpose();
        EXPECT_LT((*image - *air).norm(), kAirCameraTolerancePx)
            << pixel.transpose() << " at " << depth << " m";
        ++checked;
      }
      // The back-trace leaves the camera centre along the air ray.
      const std::optional<RayInMedium> traced = through.RayFromImage(pixel);
      ASSERT_TRUE(traced);
      EXPECT_LT((traced->direction - ray).norm(), 1e-14);
      EXPECT_LT(traced->origin.cross(ray).norm(), 1e-15);
    }
    EXPECT_GT(checked, 100);
  }
}

TEST(DomePortCamera, CentredDomeIsTheAirCamera) {
  ExpectAirCamera(AcrylicDome(Eigen::Vector3d::Zero()), 1.333);
  ExpectAirCamera(AcrylicDome(Eigen::Vector3d::Zero()), 1.9);
}

TEST(DomePortCamera, DomeOfNoThicknessInAirIsTheAirCamera) {
  for (const Eigen::Vector3d& decentering : Decenterings()) {
    DomePort dome = AcrylicDome(decentering);
    dome.thickness = 0.0;
    ExpectAirCamera(dome, 1.0);
  }
}

// A glass shell in air is a weak negative meniscus lens (focal length
// about -n_g r1 r2 / ((n_g - 1) tg) = -1.6 m for this dome): off its
// centre it bends rays. 7.2 mm behind the acrylic 4-inch dome it moves a
// point at 1 m by up to 2.5 px at the corners of a 400 px pinhole
// (measured 2.46): an air calibration made through the dome holds this
// in its lens, which is why the dome calibration can take the air views
// too and trace them through the dome at n = 1 (dome_calibration.h).
TEST(DomePortCamera, ThickDomeInAirIsAWeakLens) {
  const Camera camera = PinholeCamera();
  const DomePortCamera through =
      DomePortCamera::Create(camera, AcrylicDome({0.0, 0.0, 0.0072}), 1.0)
          .value();
  double largest = 0.0;
  for (const Eigen::Vector2d& pixel : ImageGrid(camera, 40.0)) {
    const Eigen::Vector3d point =
        camera.NormalizedFromImage(pixel)->homogeneous().normalized();
    const Eigen::Vector2d image = *through.ImageFromPoint(point);
    largest = std::max(largest, (image - pixel).norm());
  }
  // The thin-lens estimate: ray heights h ~ |C| sin(40 deg) = 4.6 mm give
  // deviations h / f ~ 2.8 mrad, 1.1 px; bounds a factor of 2-3 around.
  EXPECT_GT(largest, 0.5);
  EXPECT_LT(largest, 5.0);
}

TEST(DomePortCamera, RoundTripThroughDecenteredDomes) {
  for (const Camera& camera : AllTestCameras()) {
    for (const Eigen::Vector3d& decentering : Decenterings()) {
      for (double n : {1.0, 1.333, 1.6}) {
        const DomePortCamera through =
            DomePortCamera::Create(camera, AcrylicDome(decentering), n).value();
        int checked = 0;
        for (const Eigen::Vector2d& pixel : ImageGrid(camera, 60.0)) {
          const std::optional<RayInMedium> ray = through.RayFromImage(pixel);
          if (!ray) continue;
          for (double distance : {0.1, 0.7, 4.0}) {
            const Eigen::Vector3d point =
                ray->origin + distance * ray->direction;
            if (point.z() <= 0.0) continue;
            const std::optional<Eigen::Vector2d> back =
                through.ImageFromPoint(point);
            ASSERT_TRUE(back) << pixel.transpose() << " n " << n << " C "
                              << decentering.transpose();
            EXPECT_LT((*back - pixel).norm(), kRoundTripTolerancePx)
                << pixel.transpose() << " n " << n << " C "
                << decentering.transpose();
            ++checked;
          }
        }
        EXPECT_GT(checked, 50);
      }
    }
  }
}

// Fermat's principle, which shares nothing with the vector Snell's law of
// the trace: the optical length |p1| + n_g |p2 - p1| + n |P - p2| of the
// traced path is stationary when p1 or p2 slides along its sphere.
TEST(DomePortCamera, TracedPathsAreStationaryInOpticalLength) {
  const double n = 1.34;
  for (const Eigen::Vector3d& decentering : Decenterings()) {
    const DomePort dome = AcrylicDome(decentering);
    const DomePortCamera through =
        DomePortCamera::Create(PinholeCamera(), dome, n).value();
    for (const Eigen::Vector2d& normalized :
         {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.6, 0.5),
          Eigen::Vector2d(0.0, 0.05)}) {
      const RayInMedium ray = *through.RayFromNormalized(normalized);
      const Eigen::Vector3d point = ray.origin + 0.8 * ray.direction;
      // p1: the air ray on the inner sphere.
      const Eigen::Vector3d v0 = normalized.homogeneous().normalized();
      const double b = v0.dot(decentering);
      const Eigen::Vector3d p1 =
          (b + std::sqrt(b * b + dome.inner_radius * dome.inner_radius -
                         decentering.squaredNorm())) *
          v0;
      const auto length = [&](const Eigen::Vector3d& a,
                              const Eigen::Vector3d& c) {
        return a.norm() + dome.glass_index * (c - a).norm() +
               n * (point - c).norm();
      };
      // Slide a point of a sphere of radius r about C by angle h about
      // axis k.
      const auto slide = [&](const Eigen::Vector3d& p,
                             const Eigen::Vector3d& axis, double h) {
        return Eigen::Vector3d(decentering +
                               Eigen::AngleAxisd(h, axis.normalized()) *
                                   (p - decentering));
      };
      constexpr double kStep = 1e-5;
      for (const Eigen::Vector3d& axis :
           {Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.0, 0.0),
            Eigen::Vector3d(1.0, 2.0, 0.5)}) {
        const double d1 = (length(slide(p1, axis, kStep), ray.origin) -
                           length(slide(p1, axis, -kStep), ray.origin)) /
                          (2.0 * kStep);
        const double d2 = (length(p1, slide(ray.origin, axis, kStep)) -
                           length(p1, slide(ray.origin, axis, -kStep))) /
                          (2.0 * kStep);
        // A sliding of 1 rad would change the length by ~r1 ~ 0.04 m
        // times the sines of the angles; stationary means 0 to the
        // differences' rounding, 1e-16 m / 1e-5.
        EXPECT_LT(std::abs(d1), 1e-9) << decentering.transpose();
        EXPECT_LT(std::abs(d2), 1e-9) << decentering.transpose();
      }
    }
  }
}

TEST(DomePortCamera, PointsInsideTheDomeAreNotImaged) {
  const DomePortCamera through =
      DomePortCamera::Create(PinholeCamera(), AcrylicDome({0, 0, 0.007}), 1.33)
          .value();
  EXPECT_FALSE(through.ImageFromPoint({0.0, 0.0, 0.04}));
  EXPECT_FALSE(through.ImageFromPoint({0.0, 0.0, -1.0}));
  EXPECT_FALSE(through.ImageFromPoint({NAN, 0.0, 1.0}));
  EXPECT_TRUE(through.ImageFromPoint({0.0, 0.0, 0.06}));
}

// The normalized point of a point as a function of (n, C, P): the Jet's
// derivatives against central differences of the double solve.
TEST(DomePortRefraction, ProjectionDerivativesMatchCentralDifferences) {
  using Jet = ceres::Jet<double, 7>;
  const DomePort dome = AcrylicDome({0.002, -0.001, 0.006});
  const auto project = [&](const Eigen::Matrix<double, 7, 1>& theta) {
    const double centre[3] = {theta[1], theta[2], theta[3]};
    const double point[3] = {theta[4], theta[5], theta[6]};
    Eigen::Vector2d normalized;
    EXPECT_TRUE(DomePortRefraction::NormalizedFromPoint(
        theta[0], centre, dome, point, normalized.data()));
    return normalized;
  };
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.3, -0.2, 0.9), Eigen::Vector3d(0.0, 0.0, 2.0),
        Eigen::Vector3d(-1.2, 0.4, 0.7)}) {
    Eigen::Matrix<double, 7, 1> theta;
    theta << 1.335, dome.decentering, point;
    Jet jets[7];
    for (int i = 0; i < 7; ++i) jets[i] = Jet(theta[i], i);
    Jet normalized[2];
    ASSERT_TRUE(DomePortRefraction::NormalizedFromPoint(jets[0], jets + 1, dome,
                                                        jets + 4, normalized));
    const Eigen::Vector2d value = project(theta);
    // The step in T rounds differently from the double solve's last one.
    for (int r = 0; r < 2; ++r) EXPECT_NEAR(normalized[r].a, value[r], 1e-15);
    for (int i = 0; i < 7; ++i) {
      const double h = 1e-6;
      Eigen::Matrix<double, 7, 1> plus = theta, minus = theta;
      plus[i] += h;
      minus[i] -= h;
      const Eigen::Vector2d numeric =
          (project(plus) - project(minus)) / (2.0 * h);
      for (int r = 0; r < 2; ++r) {
        EXPECT_NEAR(normalized[r].v[i], numeric[r],
                    kDerivativeTolerance * (1.0 + std::abs(numeric[r])))
            << "d x" << r << " / d theta" << i << " at " << point.transpose();
      }
    }
  }
}

// At C = 0 the image is a smooth function of C (the lateral decentering
// moves it linearly), though every ray then meets the dome along its
// normal: the Jet's derivatives there are finite and match differences.
TEST(DomePortRefraction, DerivativesAtTheCentredDome) {
  using Jet = ceres::Jet<double, 3>;
  const DomePort dome = AcrylicDome(Eigen::Vector3d::Zero());
  const double point[3] = {0.25, -0.1, 1.1};
  const Jet jet_point[3] = {Jet(point[0]), Jet(point[1]), Jet(point[2])};
  const Jet centre[3] = {Jet(0.0, 0), Jet(0.0, 1), Jet(0.0, 2)};
  Jet normalized[2];
  ASSERT_TRUE(DomePortRefraction::NormalizedFromPoint(Jet(1.333), centre, dome,
                                                      jet_point, normalized));
  for (int i = 0; i < 3; ++i) {
    const double h = 1e-6;
    double plus_c[3] = {0, 0, 0}, minus_c[3] = {0, 0, 0};
    plus_c[i] = h;
    minus_c[i] = -h;
    double plus[2], minus[2];
    ASSERT_TRUE(DomePortRefraction::NormalizedFromPoint(1.333, plus_c, dome,
                                                        point, plus));
    ASSERT_TRUE(DomePortRefraction::NormalizedFromPoint(1.333, minus_c, dome,
                                                        point, minus));
    for (int r = 0; r < 2; ++r) {
      const double numeric = (plus[r] - minus[r]) / (2.0 * h);
      EXPECT_TRUE(std::isfinite(normalized[r].v[i]));
      EXPECT_NEAR(normalized[r].v[i], numeric,
                  kDerivativeTolerance * (1.0 + std::abs(numeric)));
    }
  }
}

// The back-trace's ray as a function of (n, C) against central
// differences.
TEST(DomePortRefraction, RayDerivativesMatchCentralDifferences) {
  using Jet = ceres::Jet<double, 4>;
  const DomePort dome = AcrylicDome({-0.003, 0.002, 0.008});
  const auto trace = [&](const Eigen::Vector4d& theta) {
    const double centre[3] = {theta[1], theta[2], theta[3]};
    Eigen::Matrix<double, 6, 1> ray;
    EXPECT_TRUE(DomePortRefraction::RayInMedium(
        theta[0], centre, dome, 0.4, -0.3, ray.data(), ray.data() + 3));
    return ray;
  };
  const Eigen::Vector4d theta(1.34, -0.003, 0.002, 0.008);
  Jet jets[4];
  for (int i = 0; i < 4; ++i) jets[i] = Jet(theta[i], i);
  Jet ray[6];
  ASSERT_TRUE(DomePortRefraction::RayInMedium(jets[0], jets + 1, dome, Jet(0.4),
                                              Jet(-0.3), ray, ray + 3));
  for (int i = 0; i < 4; ++i) {
    const double h = 1e-6;
    Eigen::Vector4d plus = theta, minus = theta;
    plus[i] += h;
    minus[i] -= h;
    const Eigen::Matrix<double, 6, 1> numeric =
        (trace(plus) - trace(minus)) / (2.0 * h);
    for (int r = 0; r < 6; ++r) {
      EXPECT_NEAR(ray[r].v[i], numeric[r],
                  kDerivativeTolerance * (1.0 + std::abs(numeric[r])));
    }
  }
}

// The central camera of a dome (RefractiveCamera::CreateWithDome) images
// every point at its reference depth exactly: pixel -> bearing -> the point
// at the reference depth -> pixel, and through the virtual pinhole and
// back, to the round trip's 1e-9 px.
TEST(RefractiveCameraWithDome, ExactAtTheReferenceDepth) {
  const Camera camera = ::rcm::test::AlphasenseCam0();
  constexpr double kReferenceDepth = 1.5;
  const RefractiveCamera central =
      RefractiveCamera::CreateWithDome(
          camera, 1.333, AcrylicDome({0.002, -0.001, 0.007}), kReferenceDepth)
          .value();
  EXPECT_EQ(central.VirtualFocalScale(), 1.0);
  EXPECT_TRUE(central.CentralOnlyAtReferenceDepth());
  int checked = 0;
  for (const Eigen::Vector2d& pixel : ImageGrid(camera, 40.0)) {
    const std::optional<Eigen::Vector3d> bearing =
        central.BearingInWaterFromImage(pixel);
    if (!bearing || !(bearing->z() > 0.05)) continue;
    const Eigen::Vector3d point = *bearing * (kReferenceDepth / bearing->z());
    EXPECT_LT((*central.ImageFromPointInWater(point) - pixel).norm(),
              kRoundTripTolerancePx);
    const std::optional<Eigen::Vector2d> virtual_pixel =
        central.VirtualPinholeFromImage(pixel);
    ASSERT_TRUE(virtual_pixel);
    EXPECT_LT((*central.ImageFromVirtualPinhole(*virtual_pixel) - pixel).norm(),
              kRoundTripTolerancePx);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// A centred dome's central camera is the air camera at every depth: its
// virtual pinhole is the air camera's K applied to the air ray.
TEST(RefractiveCameraWithDome, CentredDomeIsTheAirPinhole) {
  const Camera camera = ::rcm::test::AlphasenseCam0();
  const RefractiveCamera central =
      RefractiveCamera::CreateWithDome(
          camera, 1.333, AcrylicDome(Eigen::Vector3d::Zero()), 2.0)
          .value();
  const Eigen::Matrix3d k = central.VirtualPinholeMatrix();
  EXPECT_EQ(k(0, 0), camera.fx());
  EXPECT_EQ(k(1, 1), camera.fy());
  for (const Eigen::Vector2d& pixel : ImageGrid(camera, 60.0)) {
    const std::optional<Eigen::Vector2d> normalized =
        camera.NormalizedFromImage(pixel);
    if (!normalized) continue;
    const std::optional<Eigen::Vector2d> virtual_pixel =
        central.VirtualPinholeFromImage(pixel);
    ASSERT_TRUE(virtual_pixel);
    const Eigen::Vector2d expected(camera.fx() * normalized->x() + camera.cx(),
                                   camera.fy() * normalized->y() + camera.cy());
    EXPECT_LT((*virtual_pixel - expected).norm(),
              1e-9 * (1.0 + expected.norm()));
  }
}

TEST(RefractiveCameraWithDome, ReferenceDepthInsideTheDomeIsRefused) {
  const StatusOr<RefractiveCamera> inside = RefractiveCamera::CreateWithDome(
      PinholeCamera(), 1.333, AcrylicDome({0.0, 0.0, 0.007}), 0.04);
  ASSERT_FALSE(inside.ok());
  EXPECT_NE(inside.status().message().find("is not beyond the dome"),
            std::string::npos)
      << inside.status().message();
  EXPECT_FALSE(RefractiveCamera::CreateWithDome(PinholeCamera(), 1.333,
                                                AcrylicDome({0, 0, 0.05}), 2.0)
                   .ok());
}

}  // namespace
}  // namespace rcm::dome_port_test
