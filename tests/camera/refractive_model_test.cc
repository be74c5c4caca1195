#include "rcm/camera/refractive_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>

namespace rcm::refractive_model_test {
namespace {

// Closed-form expressions of O(1) quantities: agreement to a few ulp.
constexpr double kTolerance = 1e-12;
const double kIndices[] = {1.0, 1.33, 1.5};

TEST(FlatPortRefraction, RadialFactorIsTangentRatioOfSnell) {
  // Eq. 3: m = tan(theta_a) / tan(theta_w) with sin(theta_a) = n sin(theta_w).
  for (double n : kIndices) {
    for (double theta_a = 0.01; theta_a < 1.56; theta_a += 0.05) {
      const double theta_w = std::asin(std::sin(theta_a) / n);
      const double rb = std::tan(theta_a);
      EXPECT_NEAR(FlatPortRefraction::RadialFactor(n, rb * rb),
                  rb / std::tan(theta_w), kTolerance * (1.0 + rb))
          << "n = " << n << ", theta_a = " << theta_a;
    }
  }
}

TEST(FlatPortRefraction, RadialFactorMatchesEquationFive) {
  // The evaluated form sqrt(n^2 + (n^2 - 1) rb^2) is eq. 5 rearranged.
  for (double n : kIndices) {
    for (double rb = 0.0; rb < 5.0; rb += 0.1) {
      EXPECT_NEAR(FlatPortRefraction::RadialFactor(n, rb * rb),
                  std::sqrt(n * n * rb * rb + n * n - rb * rb),
                  kTolerance * (1.0 + rb));
    }
  }
}

TEST(FlatPortRefraction, ReducesToPinholeAtNEqualsOne) {
  for (double xb = -3.0; xb <= 3.0; xb += 0.25) {
    for (double yb = -3.0; yb <= 3.0; yb += 0.25) {
      double bearing[3];
      FlatPortRefraction::BearingInWater(1.0, xb, yb, bearing);
      EXPECT_EQ(bearing[0], xb);
      EXPECT_EQ(bearing[1], yb);
      EXPECT_EQ(bearing[2], 1.0);

      const double point[3] = {2.0 * xb, 2.0 * yb, 2.0};
      double x, y;
      ASSERT_TRUE(
          FlatPortRefraction::NormalizedFromPointInWater(1.0, point, &x, &y));
      EXPECT_NEAR(x, xb, kTolerance);
      EXPECT_NEAR(y, yb, kTolerance);
    }
  }
}

TEST(FlatPortRefraction, ProjectionInvertsUnprojection) {
  // Up to 89.9 degrees in air: normalized radius tan(89.9 deg) ~ 573.
  for (double n : kIndices) {
    for (double theta_a = 0.0; theta_a < 89.95; theta_a += 0.1) {
      for (double azimuth : {0.3, 1.9, 4.0}) {
        const double rb = std::tan(theta_a * M_PI / 180.0);
        const double xb = rb * std::cos(azimuth), yb = rb * std::sin(azimuth);
        double bearing[3];
        FlatPortRefraction::BearingInWater(n, xb, yb, bearing);
        const double depth = 3.7;
        const double point[3] = {bearing[0] * depth / bearing[2],
                                 bearing[1] * depth / bearing[2], depth};
        double x, y;
        ASSERT_TRUE(
            FlatPortRefraction::NormalizedFromPointInWater(n, point, &x, &y));
        EXPECT_NEAR(x, xb, kTolerance * (1.0 + rb * rb));
        EXPECT_NEAR(y, yb, kTolerance * (1.0 + rb * rb));
      }
    }
  }
}

TEST(FlatPortRefraction, ProjectedRayObeysSnell) {
  for (double n : kIndices) {
    const double point[3] = {0.8, -1.1, 2.0};
    double x, y;
    ASSERT_TRUE(
        FlatPortRefraction::NormalizedFromPointInWater(n, point, &x, &y));
    const double sin_air = std::hypot(x, y) / std::sqrt(1.0 + x * x + y * y);
    const double sin_water =
        std::hypot(point[0], point[1]) /
        std::sqrt(point[0] * point[0] + point[1] * point[1] +
                  point[2] * point[2]);
    EXPECT_NEAR(sin_air, n * sin_water, kTolerance);
    // Refraction keeps the azimuth.
    EXPECT_NEAR(std::atan2(y, x), std::atan2(point[1], point[0]), kTolerance);
  }
}

TEST(FlatPortRefraction, RejectsPointsBehindCamera) {
  const double behind[3] = {0.1, 0.2, -1.0};
  const double in_plane[3] = {0.1, 0.2, 0.0};
  double x, y;
  EXPECT_FALSE(
      FlatPortRefraction::NormalizedFromPointInWater(1.33, behind, &x, &y));
  EXPECT_FALSE(
      FlatPortRefraction::NormalizedFromPointInWater(1.33, in_plane, &x, &y));
  EXPECT_FALSE(
      FlatPortRefraction::NormalizedFromPointInWater(1.0, behind, &x, &y));
}

TEST(FlatPortRefraction, RejectsTotalInternalReflection) {
  // Beyond the critical angle asin(1/n) no ray in air reaches the camera.
  for (double n : {1.33, 1.5}) {
    const double critical = std::asin(1.0 / n);
    double x, y;
    const double inside[3] = {std::tan(critical - 1e-6), 0.0, 1.0};
    const double outside[3] = {std::tan(critical + 1e-6), 0.0, 1.0};
    EXPECT_TRUE(
        FlatPortRefraction::NormalizedFromPointInWater(n, inside, &x, &y));
    EXPECT_GT(x, 100.0);  // Grazing in air.
    EXPECT_FALSE(
        FlatPortRefraction::NormalizedFromPointInWater(n, outside, &x, &y));
  }
}

TEST(FlatPortRefraction, VirtualPinholeIsIdealPinholeInWater) {
  // Eq. 9: the virtual pinhole sees the point in the medium at n (X/Z, Y/Z);
  // eq. 10: [u, v, 1] ~ [x, y, m / n].
  for (double n : kIndices) {
    const double point[3] = {-0.6, 0.9, 1.7};
    double xb, yb;
    ASSERT_TRUE(
        FlatPortRefraction::NormalizedFromPointInWater(n, point, &xb, &yb));
    double xv, yv;
    FlatPortRefraction::VirtualFromNormalized(n, xb, yb, &xv, &yv);
    EXPECT_NEAR(xv, n * point[0] / point[2], kTolerance);
    EXPECT_NEAR(yv, n * point[1] / point[2], kTolerance);
    const double m_over_n =
        FlatPortRefraction::RadialFactor(n, xb * xb + yb * yb) / n;
    EXPECT_NEAR(xv, xb / m_over_n, kTolerance);

    double xb_back, yb_back;
    ASSERT_TRUE(FlatPortRefraction::NormalizedFromVirtual(n, xv, yv, &xb_back,
                                                          &yb_back));
    EXPECT_NEAR(xb_back, xb, kTolerance);
    EXPECT_NEAR(yb_back, yb, kTolerance);
  }
}

TEST(FlatPortRefraction, JetDerivativesMatchCentralDifferences) {
  // d(xb, yb)/d(n, X, Y, Z) through the projection; h = 1e-6 gives
  // truncation ~1e-12 and rounding ~1e-10.
  using Jet = ceres::Jet<double, 4>;
  const double n = 1.33;
  const double point[4] = {0.4, -0.3, 1.2};
  const Jet n_jet(n, 0);
  const Jet point_jet[3] = {Jet(point[0], 1), Jet(point[1], 2),
                            Jet(point[2], 3)};
  Jet x, y;
  ASSERT_TRUE(
      FlatPortRefraction::NormalizedFromPointInWater(n_jet, point_jet, &x, &y));
  const double h = 1e-6;
  for (int k = 0; k < 4; ++k) {
    double args_plus[4] = {n, point[0], point[1], point[2]};
    double args_minus[4] = {n, point[0], point[1], point[2]};
    args_plus[k] += h;
    args_minus[k] -= h;
    double xp, yp, xm, ym;
    ASSERT_TRUE(FlatPortRefraction::NormalizedFromPointInWater(
        args_plus[0], args_plus + 1, &xp, &yp));
    ASSERT_TRUE(FlatPortRefraction::NormalizedFromPointInWater(
        args_minus[0], args_minus + 1, &xm, &ym));
    EXPECT_NEAR(x.v[k], (xp - xm) / (2 * h), 1e-8) << k;
    EXPECT_NEAR(y.v[k], (yp - ym) / (2 * h), 1e-8) << k;
  }
}

TEST(FlatPortRefraction, RadialFactorDerivativeFiniteOnAxis) {
  using Jet = ceres::Jet<double, 2>;
  const Jet m = FlatPortRefraction::RadialFactor(Jet(1.33, 0), Jet(0.0, 1));
  EXPECT_EQ(m.a, 1.33);
  EXPECT_EQ(m.v[0], 1.0);  // dm/dn = 1 on axis
  EXPECT_NEAR(m.v[1], (1.33 * 1.33 - 1.0) / (2 * 1.33), kTolerance);
}

}  // namespace
}  // namespace rcm::refractive_model_test
