#include "rcm/stereo/locus.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rcm/camera/refractive_model.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::locus_test {
namespace {

// yr from the locus vs yr from the sampler: both exact, so agreement to the
// undistortion floor (1e-14) scaled by the coordinates (< 3).
constexpr double kTolerance = 1e-12;

TEST(RectifiedLocus, ExactMatchesLieOnTheLocus) {
  const StereoRig rig = test::AlphasenseIdealRig();
  for (double n : {1.0, 1.333, 1.5}) {
    for (const StereoCorrespondence& c : test::ExactMatches(rig, n, 500)) {
      const NormalizedCorrespondence m = rig.Normalize(c).value();
      const RectifiedLocus locus(n, m.left.x(), m.left.y());
      EXPECT_NEAR(locus.RightY(m.right.x()), m.right.y(), kTolerance);
      EXPECT_NEAR(locus.Residual(m.right.x(), m.right.y()), 0.0, kTolerance);
      if (std::abs(m.left.y()) > 0.05) {
        // Eq. 16 itself: O(1 / S^2) terms, S >= 0.05 / m.
        EXPECT_NEAR(locus.Hyperbola(m.right.x(), m.right.y()), 0.0, 1e-9);
      }
    }
  }
}

TEST(RectifiedLocus, IsTheEpipolarLineInAir) {
  const RectifiedLocus locus(1.0, 0.4, -0.3);
  for (double xr : {-1.0, 0.0, 0.4, 2.0}) {
    EXPECT_EQ(locus.RightY(xr), -0.3);
  }
}

TEST(RectifiedLocus, PassesThroughTheLeftPoint) {
  // The match of a point at infinity has the same normalized coordinates.
  for (double n : {1.2, 1.333, 1.8}) {
    const RectifiedLocus locus(n, -0.7, 0.45);
    EXPECT_NEAR(locus.RightY(-0.7), 0.45, 1e-15);
    EXPECT_NEAR(locus.Hyperbola(-0.7, 0.45), 0.0, 1e-14);
  }
}

TEST(RectifiedLocus, SMatchesEquationFifteen) {
  const double n = 1.333, xl = 0.3, yl = -0.4;
  const RectifiedLocus locus(n, xl, yl);
  EXPECT_DOUBLE_EQ(locus.S(),
                   yl / FlatPortRefraction::RadialFactor(n, xl * xl + yl * yl));
}

TEST(RectifiedLocus, DegeneratesToAxisForPointsOnTheAxis) {
  const RectifiedLocus locus(1.333, 0.5, 0.0);
  EXPECT_EQ(locus.S(), 0.0);
  EXPECT_EQ(locus.RightY(0.2), 0.0);
  EXPECT_TRUE(std::isinf(locus.Hyperbola(0.2, 0.0)));
  EXPECT_EQ(locus.Residual(0.2, 0.0), 0.0);
}

}  // namespace
}  // namespace rcm::locus_test
