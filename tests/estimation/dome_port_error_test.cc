#include "rcm/estimation/dome_port_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "rcm/camera/dome_port_camera.h"
#include "support/test_rigs.h"

namespace rcm::dome_port_error_test {
namespace {

using test::AcrylicDome;
using test::AllTestCameras;
using test::PinholeCamera;

// A centred dome does not refract: the errors are rounding, a few ulps of
// the normalized point times the focal length (dome_port_test.cc).
constexpr double kCentredTolerancePx = 1e-12;

DomePortCamera DomeCamera(const Camera& camera,
                          const Eigen::Vector3d& decentering,
                          double n = 1.333) {
  return DomePortCamera::Create(camera, AcrylicDome(decentering), n).value();
}

DomePortErrorOptions CoarseOptions() {
  DomePortErrorOptions options;
  options.num_depths = 5;
  options.grid_step = 24.0;
  return options;
}

TEST(DomePortError, CentredDomeCostsNothing) {
  for (const Camera& camera : AllTestCameras()) {
    for (const double n : {1.0, 1.333, 1.5}) {
      DomePortErrorOptions options = CoarseOptions();
      options.reference_depth = 1.0;
      const DomePortError error =
          EvaluateDomePortError(DomeCamera(camera, Eigen::Vector3d::Zero(), n),
                                options)
              .value();
      EXPECT_LE(error.max_px, kCentredTolerancePx)
          << LensModelName(camera.model()) << " n " << n;
      ASSERT_TRUE(error.central_max_px.has_value());
      EXPECT_LE(*error.central_max_px, kCentredTolerancePx);
      for (const DomePortErrorAtDepth& at : error.depths) {
        EXPECT_GT(at.ignored.num_samples, 0);
      }
    }
  }
}

// Paraxial optics of the dome (reduced angles u' = n u, surfaces of power
// (n2 - n1) / R, R = -r of a surface whose centre lies behind it), traced
// from the camera outwards for an axial decentering c: a ray leaving the
// camera centre at angle theta reaches height h(Z) theta at depth Z, so
// a pixel Delta off the principal point (theta = Delta / f) sees a point
// the air model images at f h theta / Z: e / Delta = h(Z) / Z - 1.
double ParaxialErrorRatio(const DomePort& dome, double n, double depth) {
  const double c = dome.decentering.z();
  const double r1 = dome.inner_radius;
  const double r2 = dome.outer_radius();
  const double ng = dome.glass_index;
  const double y1 = c + r1;                         // at the inner vertex
  const double u1 = 1.0 + (ng - 1.0) * y1 / r1;     // n_g u in the glass
  const double y2 = y1 + dome.thickness * u1 / ng;  // at the outer vertex
  const double u2 = u1 + (n - ng) * y2 / r2;        // n u in the water
  const double height = y2 + (depth - c - r2) * u2 / n;
  return height / depth - 1.0;
}

TEST(DomePortError, AxialDecenteringAgreesWithParaxialOptics) {
  const Camera camera = PinholeCamera();
  constexpr double kDelta = 0.01;  // px: paraxial to (Delta / f)^2 ~ 1e-9
  for (const double c : {-0.005, 0.002, 0.0072, 0.01}) {
    for (const double n : {1.0, 1.333}) {
      const DomePortCamera dome_camera =
          DomeCamera(camera, Eigen::Vector3d(0.0, 0.0, c), n);
      for (const double depth : {0.3, 1.0, 10.0, 1000.0}) {
        const double expected =
            ParaxialErrorRatio(dome_camera.dome(), n, depth);
        const std::optional<Eigen::Vector2d> error = IgnoredDomeError(
            dome_camera, Eigen::Vector2d(camera.cx() + kDelta, camera.cy()),
            depth);
        ASSERT_TRUE(error.has_value());
        EXPECT_NEAR(error->x() / kDelta, expected,
                    1e-6 * std::abs(expected) + 1e-9)
            << "c " << c << " n " << n << " depth " << depth;
        EXPECT_NEAR(error->y(), 0.0, 1e-12);
      }
    }
  }
}

TEST(DomePortError, FarPointsSeeTheDomeAsAWeakLens) {
  // The header's far-field scale (n - 1) c / (n r1) for a thin dome.
  DomePort dome = AcrylicDome(Eigen::Vector3d(0.0, 0.0, 0.0072));
  dome.thickness = 0.0;
  const double n = 1.333;
  EXPECT_NEAR(ParaxialErrorRatio(dome, n, 1e9),
              (n - 1.0) * 0.0072 / (n * dome.inner_radius), 1e-9);
}

// The definition read the other way: a point X on a pixel's ray, imaged
// through the dome by the forward solve and through the air model.
TEST(DomePortError, IsTheAirModelsImageLessTheDomesImage) {
  const Camera camera = test::EurocRadtanCamera();
  const DomePortCamera dome_camera =
      DomeCamera(camera, Eigen::Vector3d(0.003, -0.002, 0.006));
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(30.0, 40.0), Eigen::Vector2d(376.0, 240.0),
        Eigen::Vector2d(700.0, 450.0)}) {
    for (const double depth : {0.3, 2.0}) {
      const std::optional<RayInMedium> ray = dome_camera.RayFromImage(pixel);
      ASSERT_TRUE(ray.has_value());
      const Eigen::Vector3d point = ray->origin + (depth - ray->origin.z()) /
                                                      ray->direction.z() *
                                                      ray->direction;
      const Eigen::Vector2d through_dome =
          dome_camera.ImageFromPoint(point).value();
      const Eigen::Vector2d through_air =
          camera.ProjectNormalized(point.head<2>() / point.z()).value();
      const std::optional<Eigen::Vector2d> error =
          IgnoredDomeError(dome_camera, pixel, depth);
      ASSERT_TRUE(error.has_value());
      EXPECT_LT((*error - (through_air - through_dome)).norm(), 1e-8);
      EXPECT_GT(error->norm(), 0.1);
    }
  }
}

TEST(DomePortError, GrowsWithTheDecentering) {
  const Camera camera = test::EurocRadtanCamera();
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0),
        Eigen::Vector3d(0.5, -0.5, 0.7).normalized()}) {
    double previous = 0.0;
    for (const double millimetres : {0.5, 1.0, 2.0, 4.0, 8.0}) {
      const DomePortError error =
          EvaluateDomePortError(
              DomeCamera(camera, 1e-3 * millimetres * direction),
              CoarseOptions())
              .value();
      EXPECT_GT(error.max_px, previous) << millimetres << " mm";
      EXPECT_LE(error.rms_px, error.max_px);
      previous = error.max_px;
    }
  }
}

TEST(DomePortError, CentralCameraIsExactAtItsReferenceDepth) {
  const Camera camera = test::EurocRadtanCamera();
  const DomePortCamera dome_camera =
      DomeCamera(camera, Eigen::Vector3d(0.002, 0.001, 0.0072));
  DomePortErrorOptions options = CoarseOptions();
  options.reference_depth = 1.5;
  const DomePortError error =
      EvaluateDomePortError(dome_camera, options).value();
  ASSERT_TRUE(error.at_reference.has_value());
  EXPECT_NEAR(error.at_reference->depth, 1.5, 0.0);
  EXPECT_LE(error.at_reference->central->max_px, 1e-9);
  EXPECT_GT(error.at_reference->ignored.max_px, 1.0);
  ASSERT_TRUE(error.central_max_px.has_value());
  // Non-central parallax: nonzero away from 1.5 m, largest at the near
  // end, far below the error of ignoring the dome.
  EXPECT_GT(*error.central_max_px, 0.01);
  EXPECT_LT(*error.central_max_px, 0.5 * error.max_px);
  EXPECT_EQ(error.depths.front().central->max_px, *error.central_max_px);
  // Per pixel: zero at the reference depth.
  const Eigen::Vector2d pixel(100.0, 50.0);
  EXPECT_LT(CentralDomeError(dome_camera, pixel, 1.5, 1.5)->norm(), 1e-9);
  EXPECT_GT(CentralDomeError(dome_camera, pixel, 0.3, 1.5)->norm(), 0.01);
}

TEST(DomePortError, StatisticsAndDepths) {
  const DomePortCamera dome_camera =
      DomeCamera(PinholeCamera(), Eigen::Vector3d(0.0, 0.0, 0.0072));
  const DomePortErrorOptions options = CoarseOptions();
  const std::vector<double> depths = DomePortErrorDepths(options);
  ASSERT_EQ(depths.size(), 5u);
  EXPECT_EQ(depths.front(), 0.3);
  EXPECT_EQ(depths.back(), 10.0);
  for (size_t i = 1; i + 1 < depths.size(); ++i) {
    EXPECT_NEAR(depths[i] * depths[i], depths[i - 1] * depths[i + 1], 1e-12);
  }
  const DomePortError error =
      EvaluateDomePortError(dome_camera, options).value();
  ASSERT_EQ(error.depths.size(), 5u);
  double largest = 0.0;
  for (const DomePortErrorAtDepth& at : error.depths) {
    largest = std::max(largest, at.ignored.max_px);
    EXPECT_EQ(at.num_unusable, 0);
    EXPECT_FALSE(at.central.has_value());
  }
  EXPECT_EQ(error.max_px, largest);
  EXPECT_EQ(error.depths[error.worst_index].ignored.max_px, largest);
  EXPECT_TRUE(error.worst_field.Check().ok());
  double field_max = 0.0;
  for (const auto& e : error.worst_field.errors) {
    ASSERT_TRUE(e.has_value());
    field_max = std::max(field_max, e->norm());
  }
  EXPECT_EQ(field_max, largest);
  EXPECT_FALSE(error.at_reference.has_value());
  EXPECT_FALSE(error.central_max_px.has_value());

  DomePortErrorOptions one = options;
  one.min_depth = one.max_depth = 2.0;
  EXPECT_EQ(DomePortErrorDepths(one), std::vector<double>{2.0});
  EXPECT_EQ(EvaluateDomePortError(dome_camera, one)->depths.size(), 1u);
}

TEST(DomePortError, BadInputIsRefused) {
  const DomePortCamera dome_camera =
      DomeCamera(PinholeCamera(), Eigen::Vector3d(0.0, 0.0, 0.0072));
  const auto message = [&](const DomePortErrorOptions& options) {
    const StatusOr<DomePortError> error =
        EvaluateDomePortError(dome_camera, options);
    EXPECT_FALSE(error.ok());
    return error.ok() ? std::string() : error.status().message();
  };
  DomePortErrorOptions options;
  options.min_depth = 0.0;
  EXPECT_NE(message(options).find("min_depth 0 m is outside"),
            std::string::npos);
  options = DomePortErrorOptions();
  options.max_depth = 0.2;
  EXPECT_NE(message(options).find("max_depth 0.2 m is below min_depth"),
            std::string::npos);
  options = DomePortErrorOptions();
  options.max_depth = NAN;
  EXPECT_FALSE(message(options).empty());
  options = DomePortErrorOptions();
  options.num_depths = 1;
  EXPECT_NE(message(options).find("num_depths 1"), std::string::npos);
  options = DomePortErrorOptions();
  options.grid_step = 0.0;
  EXPECT_NE(message(options).find("grid_step 0"), std::string::npos);
  options = DomePortErrorOptions();
  options.grid_step = 1e-3;
  EXPECT_NE(message(options).find("samples"), std::string::npos);
  // Inside the dome: its outer surface reaches 7.2 + 47.3 mm.
  options = DomePortErrorOptions();
  options.min_depth = 0.05;
  EXPECT_NE(message(options).find("depth 0.05 m is not beyond the dome: its "
                                  "outer surface reaches z = 0.0545 m"),
            std::string::npos);
  options = DomePortErrorOptions();
  options.reference_depth = 0.01;
  EXPECT_NE(message(options).find("not beyond the dome"), std::string::npos);
  // A camera outside the inner sphere is refused by the camera.
  EXPECT_FALSE(DomePortCamera::Create(PinholeCamera(),
                                      AcrylicDome({0.0, 0.0, 0.05}), 1.333)
                   .ok());
}

}  // namespace
}  // namespace rcm::dome_port_error_test
