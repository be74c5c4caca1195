#include "rcm/stereo/stereo_rectification.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "rcm/sim/reference_rigs.h"

namespace rcm::stereo_rectification_test {
namespace {

bool IsRotation(const Eigen::Matrix3d& r) {
  return (r.transpose() * r).isIdentity(1e-12) &&
         std::abs(r.determinant() - 1.0) < 1e-12;
}

TEST(StereoRectification, RectifiedRigIsLeftAlone) {
  const StereoRectification rectification =
      RectifyStereoRig(AlphasenseFrontRectifiedRig());
  EXPECT_TRUE(rectification.left_camera_from_rect.isIdentity(1e-15));
  EXPECT_TRUE(rectification.right_camera_from_rect.isIdentity(1e-15));
}

TEST(StereoRectification, RectifiedViewsAreTheIdealPair) {
  // In the rectified views, right_from_left is (I, (-b, 0, 0)) and a point
  // has the same normalized y in both views (to rounding).
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const StereoRectification rectification = RectifyStereoRig(rig);
  ASSERT_TRUE(IsRotation(rectification.left_camera_from_rect));
  ASSERT_TRUE(IsRotation(rectification.right_camera_from_rect));
  const Eigen::Matrix3d rect_rotation =
      rectification.right_camera_from_rect.transpose() *
      rig.right_from_left().rotation * rectification.left_camera_from_rect;
  EXPECT_TRUE(rect_rotation.isIdentity(1e-12));
  const Eigen::Vector3d rect_translation =
      rectification.right_camera_from_rect.transpose() *
      rig.right_from_left().translation;
  EXPECT_NEAR(rect_translation.x(), -rig.Baseline(), 1e-15);
  EXPECT_NEAR(rect_translation.y(), 0.0, 1e-15);
  EXPECT_NEAR(rect_translation.z(), 0.0, 1e-15);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-2.0, 2.0);
  std::uniform_real_distribution<double> depth(0.5, 6.0);
  for (int i = 0; i < 100; ++i) {
    // z, y, x, in statements of their own (argument order is unspecified).
    const double z = depth(rng);
    const double y = lateral(rng);
    const Eigen::Vector3d point_in_left(lateral(rng), y, z);
    const Eigen::Vector3d in_left_view =
        rectification.left_camera_from_rect.transpose() * point_in_left;
    const Eigen::Vector3d in_right_view =
        rectification.right_camera_from_rect.transpose() *
        (rig.right_from_left() * point_in_left);
    EXPECT_NEAR(in_left_view.y() / in_left_view.z(),
                in_right_view.y() / in_right_view.z(), 1e-12);
  }
}

TEST(StereoRectification, ViewsLookAlongTheAverageAxis) {
  // Each view's axis is within the rig's rotation angle of its camera's.
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const StereoRectification rectification = RectifyStereoRig(rig);
  const double max_angle = rig.right_from_left().RotationAngle() + 0.03;
  EXPECT_LT(Eigen::AngleAxisd(rectification.left_camera_from_rect).angle(),
            max_angle);
  EXPECT_LT(Eigen::AngleAxisd(rectification.right_camera_from_rect).angle(),
            max_angle);
}

}  // namespace
}  // namespace rcm::stereo_rectification_test
