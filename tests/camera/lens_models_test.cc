#include "rcm/camera/lens_models.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <iostream>
#include <cmath>
#include <limits>
#include <random>

#include "rcm/camera/camera.h"
#include <opencv2/calib3d.hpp>

#include "support/test_rigs.h"

namespace rcm::lens_models_test {
namespace {

// Pixel round trips: undistortion converges to a residual of 1e-14 in
// normalized units (lens_models.h), i.e. ~1e-11 px at these focal lengths,
// so 1e-9 px leaves two orders of margin.
constexpr double kRoundTripPixelTolerance = 1e-9;
// Analytic vs Jet derivatives evaluate the same expressions in another
// order: agreement to rounding, relative to the entry's magnitude.
constexpr double kJacobianTolerance = 1e-12;

// Returns the largest pixel error of the round trip.
double ExpectPixelRoundTrip(const Camera& camera, double step) {
  double worst = 0.0;
  int failures = 0;
  for (const Eigen::Vector2d& pixel : test::ImageGrid(camera, step)) {
    const std::optional<Eigen::Vector2d> normalized =
        camera.NormalizedFromImage(pixel);
    if (!normalized) {
      ++failures;
      continue;
    }
    worst = std::max(worst,
                     (camera.ImageFromNormalized(*normalized) - pixel).norm());
  }
  EXPECT_EQ(failures, 0) << "pixels that did not undistort";
  EXPECT_LT(worst, kRoundTripPixelTolerance);
  return worst;
}

TEST(LensModels, PinholeRoundTripFullImage) {
  ExpectPixelRoundTrip(test::PinholeCamera(), 4.0);
}

TEST(LensModels, RadTanRoundTripFullImage) {
  ExpectPixelRoundTrip(test::EurocRadtanCamera(), 4.0);
}

TEST(LensModels, EquidistantRoundTripFullImage) {
  ExpectPixelRoundTrip(test::AlphasenseCam0(), 4.0);
  ExpectPixelRoundTrip(test::AlphasenseCam1(), 4.0);
}

TEST(LensModels, EquidistantRoundTripNinetyDegreeFieldOfView) {
  const Camera camera = test::WideEquidistantCamera();
  ExpectPixelRoundTrip(camera, 8.0);
  // The corners do reach 89.5 degrees off axis.
  const Eigen::Vector2d corner =
      camera.NormalizedFromImage({-0.5, -0.5}).value();
  EXPECT_NEAR(std::atan(corner.norm()) * 180.0 / M_PI, 89.5, 1e-9);
}

// Found by fuzz_camera_model: with k1..k4 = -0.2157, theta_d rises to a
// maximum of 0.73 near 0.87 rad, then falls below zero before pi/2. Every
// pixel failed to unproject, because the angle solve only bracketed
// [0, pi/2]. Pixels inside the fold's radius unproject onto the rising
// branch; pixels beyond it have no ray.
TEST(EquidistantLens, UnprojectsWhenThetaDFoldsBeforeNinetyDegrees) {
  const double k = -0.21568627450980393;
  const Camera camera =
      Camera::Create(LensModelId::kEquidistant, 1687, 1687,
                     {1954.7, 1954.7, 1507.8, 1507.8}, {k, k, k, k})
          .value();
  const double dist[4] = {k, k, k, k};
  double peak = 0.0;
  double peak_theta = 0.0;
  for (double theta = 0.0; theta < 1.5; theta += 1e-4) {
    const double value = EquidistantLens::DistortedAngle(dist, theta);
    if (value > peak) {
      peak = value;
      peak_theta = theta;
    }
  }
  ASSERT_LT(EquidistantLens::DistortedAngle(dist, M_PI / 2), 0.0);
  int unprojected = 0;
  for (double radius = 0.01; radius < 0.99 * peak; radius += 0.01) {
    const Eigen::Vector2d pixel(1507.8 - 1954.7 * radius * 0.6,
                                1507.8 + 1954.7 * radius * 0.8);
    const std::optional<Eigen::Vector2d> normalized =
        camera.NormalizedFromImage(pixel);
    ASSERT_TRUE(normalized.has_value()) << radius;
    EXPECT_LT((camera.ImageFromNormalized(*normalized) - pixel).norm(),
              kRoundTripPixelTolerance);
    EXPECT_LT(std::atan(normalized->norm()), peak_theta) << "folded branch";
    ++unprojected;
  }
  EXPECT_GT(unprojected, 50);
  EXPECT_FALSE(camera.NormalizedFromImage({1507.8 + 1954.7 * 1.01 * peak,
                                           1507.8})
                   .has_value());
}

// Found by fuzz_camera_model: with k1 = k2 = -0.26, theta_d folds at 0.8
// rad and turns negative near 1.2 rad; beyond, the radial scale and its
// derivative are both negative, the Jacobian's determinant is positive
// again, and a point there projected onto the opposite side of the image.
TEST(LensModels, PrincipalBranchEndsAtTheFirstFold) {
  const Camera equidistant =
      Camera::Create(LensModelId::kEquidistant, 640, 480,
                     {300.0, 300.0, 320.0, 240.0}, {-0.26, -0.26, 0.0, 0.0})
          .value();
  const double fold = std::atan(equidistant.MaxInvertibleRadius());
  const double dist[4] = {-0.26, -0.26, 0.0, 0.0};
  double derivative;
  EquidistantLens::DistortedAngle(dist, fold, &derivative);
  EXPECT_NEAR(derivative, 0.0, 1e-12);
  const Eigen::Vector2d far_branch(0.0, std::tan(1.45));
  ASSERT_GT(equidistant.ImageFromNormalizedJacobian(far_branch).determinant(),
            0.0);
  EXPECT_FALSE(equidistant.LensInvertibleAt(far_branch));
  EXPECT_FALSE(equidistant.ProjectNormalized(far_branch).has_value());
  EXPECT_TRUE(equidistant.LensInvertibleAt({0.0, std::tan(0.99 * fold)}));

  // radtan r (1 + k1 r^2): the fold at r^2 = -1 / (3 k1).
  const Camera radtan =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {300.0, 300.0, 320.0, 240.0}, {-0.5, 0.0, 0.0, 0.0})
          .value();
  EXPECT_NEAR(radtan.MaxInvertibleRadius(), std::sqrt(1.0 / 1.5), 1e-15);
  // 1 + 3 k1 s + 5 k2 s^2 without a positive root: no fold.
  EXPECT_EQ(test::EurocRadtanCamera().MaxInvertibleRadius(),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(test::PinholeCamera().MaxInvertibleRadius(),
            std::numeric_limits<double>::infinity());
}

TEST(LensModels, NormalizedRoundTripUpToEightyNineDegrees) {
  // The other direction: normalized -> pixel -> normalized, on rays up to
  // 89 degrees off axis for the equidistant models and over the image for
  // the others, relative to the normalized radius.
  for (const Camera& camera : test::AllTestCameras()) {
    const double max_angle =
        camera.model() == LensModelId::kEquidistant ? 89.0 : 40.0;
    for (double angle = 0.0; angle <= max_angle; angle += 0.5) {
      for (double azimuth = 0.0; azimuth < 360.0; azimuth += 15.0) {
        const double r = std::tan(angle * M_PI / 180.0);
        const Eigen::Vector2d normalized(r * std::cos(azimuth * M_PI / 180.0),
                                         r * std::sin(azimuth * M_PI / 180.0));
        const std::optional<Eigen::Vector2d> back =
            camera.NormalizedFromImage(camera.ImageFromNormalized(normalized));
        ASSERT_TRUE(back.has_value()) << angle << " deg";
        EXPECT_LT((*back - normalized).norm(), 1e-12 * (1.0 + r))
            << LensModelName(camera.model()) << " at " << angle << " deg";
      }
    }
  }
}

TEST(LensModels, CenterPixelIsOpticalAxis) {
  for (const Camera& camera : test::AllTestCameras()) {
    const Eigen::Vector2d normalized =
        camera.NormalizedFromImage({camera.cx(), camera.cy()}).value();
    EXPECT_EQ(normalized, Eigen::Vector2d::Zero());
  }
}

// Analytic DistortWithJacobian vs the derivative parts of a Jet run of
// Distort, at points from the axis (series branch) to the image corners.
template <typename Lens>
void ExpectJacobianMatchesJets(const double* dist,
                               const std::vector<Eigen::Vector2d>& points) {
  using Jet = ceres::Jet<double, 2>;
  constexpr int kNumDist = std::max(Lens::kNumDistortionParams, 1);
  Jet dist_jet[kNumDist];
  for (int i = 0; i < kNumDist; ++i) dist_jet[i] = Jet(dist[i]);
  for (const Eigen::Vector2d& p : points) {
    Jet xd, yd;
    Lens::Distort(dist_jet, Jet(p.x(), 0), Jet(p.y(), 1), &xd, &yd);
    double fx, fy, jacobian[4];
    Lens::DistortWithJacobian(dist, p.x(), p.y(), &fx, &fy, jacobian);
    // Jet arithmetic rounds divisions differently: a few ulp.
    EXPECT_DOUBLE_EQ(fx, xd.a);
    EXPECT_DOUBLE_EQ(fy, yd.a);
    const double expected[4] = {xd.v[0], xd.v[1], yd.v[0], yd.v[1]};
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(jacobian[k], expected[k],
                  kJacobianTolerance * (1.0 + std::abs(expected[k])))
          << "entry " << k << " at (" << p.x() << ", " << p.y() << ")";
    }
  }
}

std::vector<Eigen::Vector2d> JacobianTestPoints() {
  std::vector<Eigen::Vector2d> points = {
      {0.0, 0.0},   {1e-9, -2e-9}, {3e-5, 1e-5}, {-0.2, 0.1},
      {0.7, -0.45}, {-1.1, -0.8},  {2.0, 1.5},   {-30.0, 12.0}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  for (int i = 0; i < 50; ++i) {
    // y before x, in a statement of its own (argument order is unspecified).
    const double y = uniform(rng);
    points.emplace_back(uniform(rng), y);
  }
  return points;
}

TEST(RadTanLens, JacobianMatchesJets) {
  const Camera camera = test::EurocRadtanCamera();
  ExpectJacobianMatchesJets<RadTanLens>(camera.params() + 4,
                                        JacobianTestPoints());
}

TEST(EquidistantLens, JacobianMatchesJets) {
  const Camera camera = test::AlphasenseCam1();
  ExpectJacobianMatchesJets<EquidistantLens>(camera.params() + 4,
                                             JacobianTestPoints());
}

TEST(PinholeLens, JacobianIsIdentity) {
  // The helper copies four coefficients into Jets; the pinhole reads none.
  const double no_distortion[4] = {0.0, 0.0, 0.0, 0.0};
  ExpectJacobianMatchesJets<PinholeLens>(no_distortion, JacobianTestPoints());
}

TEST(EquidistantLens, JacobianMatchesCentralDifferencesNearAxis) {
  // The series branch (r^2 < 1e-16) and the closed branch must agree where
  // they meet; central differences of Distort check both.
  const Camera camera = test::AlphasenseCam0();
  const double* dist = camera.params() + 4;
  for (double r : {1e-9, 0.99e-8, 1.01e-8, 1e-6}) {
    const double x = 0.6 * r, y = -0.8 * r;
    double fx, fy, jacobian[4];
    EquidistantLens::DistortWithJacobian(dist, x, y, &fx, &fy, jacobian);
    const double h = 1e-3;  // Distort is affine to 1e-16 at this scale.
    double xp, yp, xm, ym;
    EquidistantLens::Distort(dist, x + h * r, y, &xp, &yp);
    EquidistantLens::Distort(dist, x - h * r, y, &xm, &ym);
    EXPECT_NEAR(jacobian[0], (xp - xm) / (2 * h * r), 1e-7) << r;
    EXPECT_NEAR(jacobian[2], (yp - ym) / (2 * h * r), 1e-7) << r;
  }
}

// d(undistorted)/d(distorted) from a Jet run of Undistort must be the
// inverse of the analytic distortion Jacobian (implicit function theorem).
template <typename Lens>
void ExpectUndistortDerivativeIsInverseJacobian(const double* dist) {
  using Jet = ceres::Jet<double, 2>;
  constexpr int kNumDist = Lens::kNumDistortionParams;
  Jet dist_jet[kNumDist];
  for (int i = 0; i < kNumDist; ++i) dist_jet[i] = Jet(dist[i]);
  for (const Eigen::Vector2d& p :
       std::vector<Eigen::Vector2d>{{0.3, -0.2}, {-0.9, 0.7}, {1e-5, 2e-5}}) {
    double xd, yd, jacobian[4];
    Lens::DistortWithJacobian(dist, p.x(), p.y(), &xd, &yd, jacobian);
    Jet x, y;
    ASSERT_TRUE(Lens::Undistort(dist_jet, Jet(xd, 0), Jet(yd, 1), &x, &y));
    EXPECT_NEAR(x.a, p.x(), 1e-13);
    EXPECT_NEAR(y.a, p.y(), 1e-13);
    const Eigen::Matrix2d inverse =
        Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(jacobian)
            .inverse();
    EXPECT_NEAR(x.v[0], inverse(0, 0), 1e-10);
    EXPECT_NEAR(x.v[1], inverse(0, 1), 1e-10);
    EXPECT_NEAR(y.v[0], inverse(1, 0), 1e-10);
    EXPECT_NEAR(y.v[1], inverse(1, 1), 1e-10);
  }
}

TEST(RadTanLens, UndistortDerivativeIsInverseJacobian) {
  ExpectUndistortDerivativeIsInverseJacobian<RadTanLens>(
      test::EurocRadtanCamera().params() + 4);
}

TEST(EquidistantLens, UndistortDerivativeIsInverseJacobian) {
  ExpectUndistortDerivativeIsInverseJacobian<EquidistantLens>(
      test::AlphasenseCam0().params() + 4);
}

// The derivative of Undistort with respect to the distortion coefficients
// (what calibration needs) against central differences.
template <typename Lens>
void ExpectUndistortParameterDerivative(const double* dist) {
  constexpr int kNumDist = Lens::kNumDistortionParams;
  using Jet = ceres::Jet<double, kNumDist>;
  const double xd = 0.55, yd = -0.42;
  Jet dist_jet[kNumDist];
  for (int i = 0; i < kNumDist; ++i) dist_jet[i] = Jet(dist[i], i);
  Jet x, y;
  ASSERT_TRUE(Lens::Undistort(dist_jet, Jet(xd), Jet(yd), &x, &y));
  for (int i = 0; i < kNumDist; ++i) {
    // Central differences: truncation O(h^2) ~ 1e-12, rounding 1e-16 / h.
    const double h = 1e-6;
    double plus[kNumDist], minus[kNumDist];
    for (int k = 0; k < kNumDist; ++k) plus[k] = minus[k] = dist[k];
    plus[i] += h;
    minus[i] -= h;
    double xp, yp, xm, ym;
    ASSERT_TRUE(Lens::Undistort(plus, xd, yd, &xp, &yp));
    ASSERT_TRUE(Lens::Undistort(minus, xd, yd, &xm, &ym));
    EXPECT_NEAR(x.v[i], (xp - xm) / (2 * h), 1e-8) << "coefficient " << i;
    EXPECT_NEAR(y.v[i], (yp - ym) / (2 * h), 1e-8) << "coefficient " << i;
  }
}

TEST(RadTanLens, UndistortParameterDerivativeMatchesCentralDifferences) {
  ExpectUndistortParameterDerivative<RadTanLens>(
      test::EurocRadtanCamera().params() + 4);
}

TEST(EquidistantLens, UndistortParameterDerivativeMatchesCentralDifferences) {
  ExpectUndistortParameterDerivative<EquidistantLens>(
      test::AlphasenseCam0().params() + 4);
}

TEST(EquidistantLens, UndistortFailsAtAndBeyondNinetyDegrees) {
  const Camera camera = test::AlphasenseCam0();
  const double* dist = camera.params() + 4;
  const double theta_d_90 = EquidistantLens::DistortedAngle(dist, M_PI / 2);
  double x, y;
  EXPECT_TRUE(
      EquidistantLens::Undistort(dist, 0.999 * theta_d_90, 0.0, &x, &y));
  EXPECT_GT(x, 100.0);  // 89.9+ degrees: far out on the normalized plane.
  EXPECT_FALSE(EquidistantLens::Undistort(dist, theta_d_90, 0.0, &x, &y));
  EXPECT_FALSE(EquidistantLens::Undistort(dist, 0.8 * theta_d_90,
                                          0.8 * theta_d_90, &x, &y));
}

TEST(RadTanLens, UndistortFailsBeyondFold) {
  // r (1 - 0.5 r^2) peaks at 0.544 for r = 0.816: larger distorted radii
  // have no preimage.
  const double dist[4] = {-0.5, 0.0, 0.0, 0.0};
  double x, y;
  EXPECT_TRUE(RadTanLens::Undistort(dist, 0.5, 0.0, &x, &y));
  EXPECT_FALSE(RadTanLens::Undistort(dist, 0.6, 0.0, &x, &y));
}

TEST(LensModels, UndistortRejectsNonFinite) {
  const double dist[4] = {0.01, 0.001, 0.0, 0.0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  double x, y;
  EXPECT_FALSE(RadTanLens::Undistort(dist, nan, 0.1, &x, &y));
  EXPECT_FALSE(RadTanLens::Undistort(dist, 0.1, inf, &x, &y));
  EXPECT_FALSE(EquidistantLens::Undistort(dist, nan, 0.1, &x, &y));
  EXPECT_FALSE(EquidistantLens::Undistort(dist, inf, 0.1, &x, &y));
}

// ---------------------------------------------------------------------------
// The rational, double-sphere and EUCM models.

TEST(LensModels, RationalRoundTripOverTheImage) {
  const double worst = ExpectPixelRoundTrip(test::RationalCamera(), 2.0);
  std::cout << "rational round trip: max " << worst << " px\n";
}

TEST(LensModels, DoubleSphereRoundTripOverTheImage) {
  const double worst = ExpectPixelRoundTrip(test::DoubleSphereCamera(), 2.0);
  std::cout << "ds round trip: max " << worst << " px\n";
}

TEST(LensModels, EucmRoundTripOverTheImage) {
  const double worst = ExpectPixelRoundTrip(test::EucmCamera(), 2.0);
  std::cout << "eucm round trip: max " << worst << " px\n";
}

// The unified models out to the edge of the half space z > 0: an image
// whose corners see 88 degrees off axis.
TEST(LensModels, UnifiedModelsRoundTripToEightyEightDegrees) {
  for (const Camera& base : {test::DoubleSphereCamera(), test::EucmCamera()}) {
    const double r = std::tan(88.0 * M_PI / 180.0);
    double xd = 0.0, yd = 0.0;
    RCM_LENS_MODEL_SWITCH(base.model(),
                          LensModel::Distort(base.params() + 4, r, 0.0, &xd,
                                             &yd);
                          break;)
    const double f = std::hypot(320.0, 240.0) / xd;
    const Camera camera =
        Camera::Create(base.model(), 640, 480, {f, f, 319.5, 239.5},
                       base.Distortion())
            .value();
    const double worst = ExpectPixelRoundTrip(camera, 4.0);
    std::cout << LensModelName(camera.model()) << " to 88 deg: max " << worst
              << " px\n";
  }
}

TEST(RationalLens, JacobianMatchesJets) {
  ExpectJacobianMatchesJets<RationalLens>(test::RationalCamera().params() + 4,
                                          JacobianTestPoints());
}

TEST(DoubleSphereLens, JacobianMatchesJets) {
  ExpectJacobianMatchesJets<DoubleSphereLens>(
      test::DoubleSphereCamera().params() + 4, JacobianTestPoints());
  const double other[2] = {0.7, 0.2};
  ExpectJacobianMatchesJets<DoubleSphereLens>(other, JacobianTestPoints());
}

TEST(EucmLens, JacobianMatchesJets) {
  ExpectJacobianMatchesJets<EucmLens>(test::EucmCamera().params() + 4,
                                      JacobianTestPoints());
  const double other[2] = {0.3, 2.5};
  ExpectJacobianMatchesJets<EucmLens>(other, JacobianTestPoints());
}

TEST(RationalLens, UndistortDerivativeIsInverseJacobian) {
  ExpectUndistortDerivativeIsInverseJacobian<RationalLens>(
      test::RationalCamera().params() + 4);
}

TEST(DoubleSphereLens, UndistortDerivativeIsInverseJacobian) {
  ExpectUndistortDerivativeIsInverseJacobian<DoubleSphereLens>(
      test::DoubleSphereCamera().params() + 4);
}

TEST(EucmLens, UndistortDerivativeIsInverseJacobian) {
  ExpectUndistortDerivativeIsInverseJacobian<EucmLens>(
      test::EucmCamera().params() + 4);
}

TEST(RationalLens, UndistortParameterDerivativeMatchesCentralDifferences) {
  ExpectUndistortParameterDerivative<RationalLens>(
      test::RationalCamera().params() + 4);
}

TEST(DoubleSphereLens, UndistortParameterDerivativeMatchesCentralDifferences) {
  ExpectUndistortParameterDerivative<DoubleSphereLens>(
      test::DoubleSphereCamera().params() + 4);
}

TEST(EucmLens, UndistortParameterDerivativeMatchesCentralDifferences) {
  ExpectUndistortParameterDerivative<EucmLens>(test::EucmCamera().params() +
                                               4);
}

// cv::projectPoints with the 8-coefficient vector (k1, k2, p1, p2, k3, k4,
// k5, k6) is the reference of the rational model. Both evaluate the same
// rational function in double; the orders of operations differ, so the
// pixels agree to rounding (~1e-13 px), far inside 1e-9 px.
constexpr double kOpenCvAgreementPixels = 1e-9;

TEST(RationalLens, MatchesOpenCvProjectPoints) {
  const Camera camera = test::RationalCamera();
  std::vector<cv::Point3d> points;
  for (double x = -0.9; x <= 0.9; x += 0.05) {
    for (double y = -0.6; y <= 0.6; y += 0.05) points.emplace_back(x, y, 1.0);
  }
  const cv::Matx33d k(camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(),
                      camera.cy(), 0.0, 0.0, 1.0);
  const std::vector<double> d = camera.Distortion();
  ASSERT_EQ(d.size(), 8u);
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, d,
                    pixels);
  double worst = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d ours =
        camera.ImageFromNormalized(Eigen::Vector2d(points[i].x, points[i].y));
    worst = std::max(worst, (ours - Eigen::Vector2d(pixels[i].x, pixels[i].y))
                                .norm());
  }
  std::cout << "rational vs cv::projectPoints: max " << worst << " px over "
            << points.size() << " points\n";
  EXPECT_LT(worst, kOpenCvAgreementPixels);
}

TEST(RationalLens, ReducesToRadTan) {
  const double rational[8] = {-0.28, 0.07, 2e-4, -3e-4, 0.0, 0.0, 0.0, 0.0};
  const double radtan[4] = {-0.28, 0.07, 2e-4, -3e-4};
  for (const Eigen::Vector2d& p : JacobianTestPoints()) {
    double a[2], b[2];
    RationalLens::Distort(rational, p.x(), p.y(), &a[0], &a[1]);
    RadTanLens::Distort(radtan, p.x(), p.y(), &b[0], &b[1]);
    EXPECT_DOUBLE_EQ(a[0], b[0]);
    EXPECT_DOUBLE_EQ(a[1], b[1]);
  }
}

// The double sphere with xi = 0 is the EUCM with beta = 1: both are
// (x, y) / (alpha sqrt(r^2 + 1) + 1 - alpha).
TEST(DoubleSphereLens, WithZeroXiIsEucmWithUnitBeta) {
  const double ds[2] = {0.0, 0.57};
  const double eucm[2] = {0.57, 1.0};
  for (const Eigen::Vector2d& p : JacobianTestPoints()) {
    double a[2], b[2];
    DoubleSphereLens::Distort(ds, p.x(), p.y(), &a[0], &a[1]);
    EucmLens::Distort(eucm, p.x(), p.y(), &b[0], &b[1]);
    EXPECT_NEAR(a[0], b[0], 1e-15 * (1.0 + std::abs(b[0])));
    EXPECT_NEAR(a[1], b[1], 1e-15 * (1.0 + std::abs(b[1])));
  }
}

// Distorted radii beyond the image of 90 degrees off axis have no ray in
// front of the camera.
TEST(LensModels, UnifiedModelsUndistortFailsBeyondNinetyDegrees) {
  const double ds[2] = {-0.18, 0.59};
  const double eucm[2] = {0.63, 1.04};
  // The limits as r -> infinity: r / N(r) -> 1 / (alpha sqrt(1 + xi^2) +
  // (1 - alpha) xi) and 1 / (alpha sqrt(beta)).
  const double ds_edge =
      1.0 / (0.59 * std::sqrt(1.0 + 0.18 * 0.18) - 0.41 * 0.18);
  const double eucm_edge = 1.0 / (0.63 * std::sqrt(1.04));
  double x, y;
  EXPECT_TRUE(DoubleSphereLens::Undistort(ds, 0.999 * ds_edge, 0.0, &x, &y));
  EXPECT_GT(x, 50.0);
  EXPECT_FALSE(DoubleSphereLens::Undistort(ds, 1.001 * ds_edge, 0.0, &x, &y));
  EXPECT_TRUE(EucmLens::Undistort(eucm, 0.0, 0.999 * eucm_edge, &x, &y));
  EXPECT_GT(y, 50.0);
  EXPECT_FALSE(EucmLens::Undistort(eucm, 0.0, 1.001 * eucm_edge, &x, &y));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(DoubleSphereLens::Undistort(ds, nan, 0.0, &x, &y));
  EXPECT_FALSE(EucmLens::Undistort(eucm, 0.0, nan, &x, &y));
  EXPECT_FALSE(RationalLens::Undistort(test::RationalCamera().params() + 4,
                                       nan, 0.0, &x, &y));
}

// A denominator with a pole inside the image (k4..k6 of the fuzz finding,
// small tangential terms): near the pole the distorted radius grows without
// bound, so a pixel's distorted radius rd exceeds the pole's radius R and
// Newton from the distorted point starts beyond the pole. Undistortion must
// still return the preimage on the principal branch, the normalized point
// that was distorted, not only some point that reprojects. The map expands
// towards the pole (d rd / dr >= 1), so the round trip in normalized units
// is at most the undistortion tolerance, 1e-14 (1 + rd); 1e-12 leaves room.
TEST(RationalLens, UndistortsPixelsBeyondThePoleRadius) {
  const double dist[8] = {0.0, 0.0, 0.002, -0.001, 0.0,
                          -0.046722412109375, -0.046860399433210742,
                          -0.12499997294894172};
  const Camera camera =
      Camera::Create(LensModelId::kRational, 3175, 2893,
                     {3922.83, 2386.91, 0.0, -92.34},
                     std::vector<double>(dist, dist + 8))
          .value();
  const double pole = camera.MaxInvertibleRadius();
  ASSERT_NEAR(pole, 1.3506, 1e-3);
  constexpr double kNormalizedTolerance = 1e-12;
  int beyond_pole = 0;
  double worst = 0.0;
  for (double fraction = 0.05; fraction < 0.999; fraction += 0.0125) {
    for (int k = 0; k < 24; ++k) {
      const double angle = 2.0 * M_PI * k / 24.0;
      const Eigen::Vector2d x =
          fraction * pole * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      if (!camera.LensInvertibleAt(x)) continue;
      double xd, yd;
      RationalLens::Distort(dist, x.x(), x.y(), &xd, &yd);
      if (std::hypot(xd, yd) > pole) ++beyond_pole;
      Eigen::Vector2d back;
      ASSERT_TRUE(RationalLens::Undistort(dist, xd, yd, &back.x(), &back.y()))
          << "r " << x.norm() << " rd " << std::hypot(xd, yd);
      worst = std::max(worst, (back - x).norm());
    }
  }
  EXPECT_GT(beyond_pole, 24) << "the case the test is for was not reached";
  EXPECT_LT(worst, kNormalizedTolerance);
}

// A fold: with only k1 = -0.5 the radial part r (1 - r^2 / 2) rises to
// sqrt(2/3) * 2/3 = 0.5443 at r = sqrt(2/3) and falls after it. A distorted
// radius beyond that maximum has no preimage on the principal branch and is
// refused (Newton from it would land past the fold); one just below it is
// found on the branch.
TEST(RationalLens, UndistortRefusesRadiiBeyondTheFold) {
  const double dist[8] = {-0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const double fold = std::sqrt(2.0 / 3.0);
  const double highest = fold * (1.0 - 0.5 * fold * fold);
  double x, y;
  EXPECT_FALSE(RationalLens::Undistort(dist, 0.0, 1.01 * highest, &x, &y));
  ASSERT_TRUE(RationalLens::Undistort(dist, 0.0, 0.99 * highest, &x, &y));
  EXPECT_LT(std::hypot(x, y), fold);
  EXPECT_NEAR(y * (1.0 - 0.5 * y * y), 0.99 * highest, 1e-14);
}

TEST(LensModels, FoldsOfTheNewModels) {
  // Rational with only k1 is radtan's r (1 + k1 r^2): fold at
  // r^2 = -1 / (3 k1).
  const Camera rational =
      Camera::Create(LensModelId::kRational, 640, 480,
                     {300.0, 300.0, 320.0, 240.0},
                     {-0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0})
          .value();
  EXPECT_NEAR(rational.MaxInvertibleRadius(), std::sqrt(1.0 / 1.5), 1e-12);
  // A denominator 1 - r^2 has a pole at r = 1: the lens ends there.
  const Camera pole =
      Camera::Create(LensModelId::kRational, 640, 480,
                     {300.0, 300.0, 320.0, 240.0},
                     {0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0})
          .value();
  EXPECT_NEAR(pole.MaxInvertibleRadius(), 1.0, 1e-12);
  EXPECT_FALSE(pole.ProjectNormalized({0.0, 1.01}).has_value());
  // Double sphere with alpha = 0, xi = -0.5: N = 1 - d1 / 2 reaches 0 at
  // d1 = 2, r = sqrt(3).
  const Camera ds = Camera::Create(LensModelId::kDoubleSphere, 640, 480,
                                   {300.0, 300.0, 320.0, 240.0}, {-0.5, 0.0})
                        .value();
  EXPECT_NEAR(ds.MaxInvertibleRadius(), std::sqrt(3.0), 1e-9);
  EXPECT_FALSE(ds.ProjectNormalized({1.75, 0.0}).has_value());
  EXPECT_TRUE(ds.ProjectNormalized({1.7, 0.0}).has_value());
  // The real lenses of the tests never fold in front of the camera.
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  EXPECT_EQ(test::DoubleSphereCamera().MaxInvertibleRadius(), kInfinity);
  EXPECT_EQ(test::EucmCamera().MaxInvertibleRadius(), kInfinity);
  EXPECT_GT(test::RationalCamera().MaxInvertibleRadius(), 1.2);
}

}  // namespace
}  // namespace rcm::lens_models_test
