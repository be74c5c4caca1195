#include "rcm/stereo/stereo_rig.h"

#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <cmath>

#include "rcm/camera/refractive_camera.h"
#include "support/test_rigs.h"

namespace rcm::stereo_rig_test {
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

// cam1 turned about its own center: its center stays where it was, and a
// point's bearing in cam1 turns by the rotation; a translation change adds
// to t. Ports come along.
TEST(StereoRig, WithCam1MovedTurnsCam1AboutItsCenter) {
  FlatPort port;
  port.air_gap = 0.01;
  const StereoRig rig =
      test::AlphasenseRealisticRig().WithPorts(port, port).value();
  const Eigen::Vector3d rotation(0.004, -0.007, 0.0015);  // radians
  const StereoRig turned = rig.WithCam1Moved(rotation).value();
  const auto center = [](const Rigid3d& cam1_from_cam0) {
    return Eigen::Vector3d(
        -(cam1_from_cam0.rotation.transpose() * cam1_from_cam0.translation));
  };
  EXPECT_LT(
      (center(turned.right_from_left()) - center(rig.right_from_left())).norm(),
      1e-15);
  const Eigen::Vector3d point(0.3, -0.2, 2.0);
  const Eigen::Vector3d before = rig.right_from_left() * point;
  const Eigen::Vector3d after = turned.right_from_left() * point;
  Eigen::Vector3d rotated;
  ceres::AngleAxisRotatePoint(rotation.data(), before.data(), rotated.data());
  EXPECT_LT((after - rotated).norm(), 1e-15);
  ASSERT_TRUE(turned.ports().has_value());
  EXPECT_EQ(turned.ports()->left, rig.ports()->left);

  const Eigen::Vector3d shift(0.001, -0.002, 0.0005);
  const StereoRig shifted =
      rig.WithCam1Moved(Eigen::Vector3d::Zero(), shift).value();
  EXPECT_EQ(shifted.right_from_left().rotation, rig.right_from_left().rotation);
  EXPECT_LT((shifted.right_from_left().translation -
             rig.right_from_left().translation - shift)
                .norm(),
            1e-17);
}

TEST(StereoRig, WithCam1MovedRefusesNonFiniteAndZeroBaseline) {
  const StereoRig rig = test::AlphasenseIdealRig();
  EXPECT_FALSE(rig.WithCam1Moved(Eigen::Vector3d(NAN, 0, 0)).ok());
  EXPECT_FALSE(rig.WithCam1Moved(Eigen::Vector3d::Zero(),
                                 -rig.right_from_left().translation)
                   .ok());
}

}  // namespace
}  // namespace rcm::stereo_rig_test
