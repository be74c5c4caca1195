#include "rcm/geometry/stereo_rig.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rcm/camera/refractive_camera.h"
#include "support/test_rigs.h"

namespace rcm {
namespace {

TEST(StereoRig, RejectsZeroBaseline) {
  const StatusOr<StereoRig> rig = StereoRig::Create(
      test::AlphasenseCam0(), test::AlphasenseCam1(), Rigid3d());
  ASSERT_FALSE(rig.ok());
  EXPECT_NE(rig.status().message().find("zero baseline"), std::string::npos);
}

TEST(StereoRig, IdealRigIsRectified) {
  const StereoRig rig = test::AlphasenseIdealRig();
  EXPECT_DOUBLE_EQ(rig.Baseline(), 0.11);
  EXPECT_EQ(rig.DeviationFromRectified().rotation, 0.0);
  EXPECT_EQ(rig.DeviationFromRectified().baseline_off_axis, 0.0);
}

TEST(StereoRig, MeasuresDeviationFromRectified) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  EXPECT_NEAR(rig.DeviationFromRectified().rotation, 0.5 * M_PI / 180, 1e-15);
  EXPECT_NEAR(rig.DeviationFromRectified().baseline_off_axis,
              std::atan2(std::hypot(0.0015, 0.002), 0.11), 1e-15);
}

TEST(StereoRig, NormalizesBothPixels) {
  const StereoRig rig = test::AlphasenseIdealRig();
  StereoCorrespondence match;
  match.left_pixel = Eigen::Vector2d(100.0, 80.0);
  match.right_pixel = Eigen::Vector2d(90.0, 81.0);
  const NormalizedCorrespondence normalized = rig.Normalize(match).value();
  EXPECT_LT((rig.left().ImageFromNormalized(normalized.left) - match.left_pixel)
                .norm(),
            1e-9);
  EXPECT_LT(
      (rig.right().ImageFromNormalized(normalized.right) - match.right_pixel)
          .norm(),
      1e-9);
}

TEST(StereoRig, NormalizeFailsOnUndistortablePixel) {
  const StereoRig rig = test::AlphasenseIdealRig();
  StereoCorrespondence match;
  match.left_pixel = Eigen::Vector2d(std::nan(""), 80.0);
  EXPECT_FALSE(rig.Normalize(match).has_value());
  match.left_pixel = Eigen::Vector2d(1e6, 80.0);  // beyond 90 degrees
  EXPECT_FALSE(rig.Normalize(match).has_value());
}

}  // namespace
}  // namespace rcm
