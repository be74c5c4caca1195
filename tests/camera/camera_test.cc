#include "rcm/camera/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/test_rigs.h"

namespace rcm::camera_test {
namespace {

TEST(Camera, CreatesValidCamera) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kRadTan, 752, 480, {458.0, 457.0, 367.0, 248.0},
      {-0.28, 0.07, 0.0002, 0.00002});
  ASSERT_TRUE(camera.ok()) << camera.status().message();
  EXPECT_EQ(camera->num_params(), 8);
  EXPECT_EQ(camera->fx(), 458.0);
  EXPECT_EQ(camera->cy(), 248.0);
  EXPECT_EQ(camera->Distortion(),
            (std::vector<double>{-0.28, 0.07, 0.0002, 0.00002}));
}

TEST(Camera, RejectsNonPositiveFocalLength) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 640, 480, {-300.0, 300.0, 320.0, 240.0}, {});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "focal length must be positive, got fx = -300");
  EXPECT_FALSE(Camera::Create(LensModelId::kPinhole, 640, 480,
                              {300.0, 0.0, 320.0, 240.0}, {})
                   .ok());
}

TEST(Camera, RejectsNonFiniteIntrinsics) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 640, 480, {300.0, 300.0, nan, 240.0}, {});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(), "cx is not a finite number");
}

TEST(Camera, RejectsWrongCoefficientCount) {
  const StatusOr<Camera> camera =
      Camera::Create(LensModelId::kEquidistant, 640, 480,
                     {300.0, 300.0, 320.0, 240.0}, {0.1, 0.2, 0.3});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "distortion model 'equidistant' takes 4 coefficients, got 3");
}

TEST(Camera, RejectsNonFiniteCoefficient) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kRadTan, 640, 480, {300.0, 300.0, 320.0, 240.0},
      {0.1, std::numeric_limits<double>::infinity(), 0.0, 0.0});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "distortion coefficient 1 is not a finite number");
}

// Found by fuzz_camera_model: k2 = 2.4e68 broke the series the equidistant
// model uses near the axis, and a pixel did not reproject onto itself.
TEST(Camera, RejectsAbsurdCoefficient) {
  const StatusOr<Camera> camera =
      Camera::Create(LensModelId::kEquidistant, 640, 480,
                     {300.0, 300.0, 320.0, 240.0}, {-1.0, 2.4e68, 0.0, 0.0});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "distortion coefficient 1 = 2.4e+68 is beyond the accepted "
            "magnitude of 1000");
}

TEST(Camera, RejectsNonPositiveImageSize) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 0, 480, {300.0, 300.0, 320.0, 240.0}, {});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "image size must be positive, got 0 x 480");
}

// A focal length in metres, or a denormal one (found by fuzz_camera_model:
// fy = 7e-322 passed "positive" and sent the unprojection to inf).
TEST(Camera, RejectsFocalLengthOutsidePixelRange) {
  const StatusOr<Camera> metres = Camera::Create(
      LensModelId::kPinhole, 640, 480, {0.004, 0.004, 320.0, 240.0}, {});
  ASSERT_FALSE(metres.ok());
  EXPECT_EQ(
      metres.status().message(),
      "fx = 0.004 is not a focal length in pixels (accepted: 1 to 1e+06)");
  EXPECT_FALSE(Camera::Create(LensModelId::kPinhole, 640, 480,
                              {300.0, 7e-322, 320.0, 240.0}, {})
                   .ok());
  EXPECT_FALSE(Camera::Create(LensModelId::kPinhole, 640, 480,
                              {2e6, 300.0, 320.0, 240.0}, {})
                   .ok());
  EXPECT_TRUE(Camera::Create(LensModelId::kPinhole, 640, 480,
                             {1.0, 1e6, 320.0, 240.0}, {})
                  .ok());
}

TEST(Camera, RejectsPrincipalPointOutsidePixelRange) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 640, 480, {300.0, 300.0, 320.0, -3e9}, {});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "cy = -3e+09 is not a principal point in pixels (accepted: within "
            "1e+06 of 0)");
}

TEST(Camera, RejectsImageSideBeyondLimit) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 640, 20001, {300.0, 300.0, 320.0, 240.0}, {});
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().message(),
            "image size 640 x 20001 is beyond the largest accepted side of "
            "20000 px");
}

// The unprojection refuses what has no finite normalized point instead of
// returning inf (found by fuzz_camera_model).
TEST(Camera, UnprojectionOfNonFinitePixelFails) {
  const StatusOr<Camera> camera = Camera::Create(
      LensModelId::kPinhole, 640, 480, {300.0, 300.0, 320.0, 240.0}, {});
  ASSERT_TRUE(camera.ok());
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(camera->NormalizedFromImage(Eigen::Vector2d(inf, 0.0)));
  EXPECT_FALSE(camera->NormalizedFromImage(Eigen::Vector2d(0.0, NAN)));
  EXPECT_TRUE(camera->NormalizedFromImage(Eigen::Vector2d(1e9, -1e9)));
}

TEST(Camera, LensModelNamesRoundTrip) {
  for (LensModelId id : AllLensModels()) {
    EXPECT_EQ(LensModelFromName(LensModelName(id)), id);
  }
  EXPECT_EQ(LensModelFromName("rational"), LensModelId::kRational);
  EXPECT_EQ(LensModelFromName("ds"), LensModelId::kDoubleSphere);
  EXPECT_EQ(LensModelFromName("eucm"), LensModelId::kEucm);
  EXPECT_EQ(NumDistortionParams(LensModelId::kRational), 8);
  EXPECT_EQ(NumDistortionParams(LensModelId::kDoubleSphere), 2);
  EXPECT_EQ(NumDistortionParams(LensModelId::kEucm), 2);
  EXPECT_EQ(LensModelNameList(),
            "none, radtan, equidistant, rational, ds, eucm");
  EXPECT_FALSE(LensModelFromName("fov").has_value());
  EXPECT_FALSE(LensModelFromName("").has_value());
}

TEST(Camera, InImageUsesPixelCenterConvention) {
  const Camera camera = test::PinholeCamera();  // 640 x 480
  EXPECT_TRUE(camera.InImage({-0.5, -0.5}));
  EXPECT_TRUE(camera.InImage({639.5, 479.5}));
  EXPECT_FALSE(camera.InImage({-0.51, 10.0}));
  EXPECT_FALSE(camera.InImage({10.0, 479.51}));
  EXPECT_FALSE(camera.InImage({std::nan(""), 10.0}));
}

TEST(Camera, ImageFromNormalizedJacobianMatchesCentralDifferences) {
  for (const Camera& camera : test::AllTestCameras()) {
    const Eigen::Vector2d p(0.31, -0.22);
    const Eigen::Matrix2d jacobian = camera.ImageFromNormalizedJacobian(p);
    const double h = 1e-6;  // truncation ~1e-12 * f, rounding ~1e-10 * f
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d step = h * Eigen::Vector2d::Unit(k);
      const Eigen::Vector2d column = (camera.ImageFromNormalized(p + step) -
                                      camera.ImageFromNormalized(p - step)) /
                                     (2 * h);
      EXPECT_NEAR((jacobian.col(k) - column).norm(), 0.0, 1e-6 * camera.fx());
    }
  }
}

// The pixel and the Jacobian from one lens evaluation are the two calls'
// numbers, bit for bit, for every model, near the axis (the equidistant
// series) and off it.
TEST(Camera, JacobianWithPixelIsBothCallsExactly) {
  for (const Camera& camera : test::AllTestCameras()) {
    for (const Eigen::Vector2d& p :
         {Eigen::Vector2d(0.31, -0.22), Eigen::Vector2d(-0.05, 0.4),
          Eigen::Vector2d(1e-9, -2e-9), Eigen::Vector2d(0.0, 0.0)}) {
      Eigen::Vector2d pixel;
      const Eigen::Matrix2d jacobian =
          camera.ImageFromNormalizedJacobian(p, &pixel);
      const Eigen::Vector2d expected = camera.ImageFromNormalized(p);
      EXPECT_EQ(pixel.x(), expected.x()) << p.transpose();
      EXPECT_EQ(pixel.y(), expected.y()) << p.transpose();
      const Eigen::Matrix2d expected_jacobian =
          camera.ImageFromNormalizedJacobian(p);
      for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(jacobian(k), expected_jacobian(k)) << p.transpose();
      }
    }
  }
}

// Out-of-range coefficients of the unified models: one line naming the
// coefficient.
TEST(Camera, RejectsUnifiedModelCoefficientsOutOfRange) {
  const std::array<double, 4> k = {300.0, 300.0, 320.0, 240.0};
  const struct {
    LensModelId model;
    std::vector<double> distortion;
    const char* expected;
  } kCases[] = {
      {LensModelId::kDoubleSphere,
       {1.5, 0.5},
       "ds xi = 1.5 is outside (-1, 1]"},
      {LensModelId::kDoubleSphere,
       {-1.0, 0.5},
       "ds xi = -1 is outside (-1, 1]"},
      {LensModelId::kDoubleSphere,
       {0.1, -0.1},
       "ds alpha = -0.1 is outside [0, 1]"},
      {LensModelId::kDoubleSphere,
       {0.1, 1.2},
       "ds alpha = 1.2 is outside [0, 1]"},
      {LensModelId::kEucm, {1.01, 1.0}, "eucm alpha = 1.01 is outside [0, 1]"},
      {LensModelId::kEucm, {0.5, 0.0}, "eucm beta = 0 is outside (0, 1000]"},
      {LensModelId::kEucm, {0.5, -2.0}, "eucm beta = -2 is outside (0, 1000]"},
  };
  for (const auto& c : kCases) {
    const StatusOr<Camera> camera =
        Camera::Create(c.model, 640, 480, k, c.distortion);
    ASSERT_FALSE(camera.ok()) << c.expected;
    EXPECT_EQ(camera.status().message(), c.expected);
    EXPECT_EQ(camera.status().message().find('\n'), std::string::npos);
  }
  // The edges of the ranges are accepted.
  EXPECT_TRUE(
      Camera::Create(LensModelId::kDoubleSphere, 640, 480, k, {1.0, 0.0}).ok());
  EXPECT_TRUE(
      Camera::Create(LensModelId::kDoubleSphere, 640, 480, k, {-0.99, 1.0})
          .ok());
  EXPECT_TRUE(
      Camera::Create(LensModelId::kEucm, 640, 480, k, {1.0, 1e-3}).ok());
  EXPECT_TRUE(Camera::Create(LensModelId::kEucm, 640, 480, k, {0.0, 1.0}).ok());
  // Rational: 8 coefficients, any sign.
  EXPECT_FALSE(
      Camera::Create(LensModelId::kRational, 640, 480, k, {0.1, 0.0, 0.0, 0.0})
          .ok());
}

TEST(Camera, LensInvertibleAtDetectsFold) {
  const Camera folded =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {300.0, 300.0, 320.0, 240.0}, {-0.5, 0.0, 0.0, 0.0})
          .value();
  // d/dr [r (1 - 0.5 r^2)] = 1 - 1.5 r^2 vanishes at r = 0.816.
  EXPECT_TRUE(folded.LensInvertibleAt({0.8, 0.0}));
  EXPECT_FALSE(folded.LensInvertibleAt({0.83, 0.0}));
}

}  // namespace
}  // namespace rcm::camera_test
