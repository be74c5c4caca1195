#include "rcm/sim/reference_rigs.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rcm/camera/flat_port_camera.h"

namespace rcm::reference_rigs_test {
namespace {

constexpr double kDegree = M_PI / 180.0;

TEST(ReferenceRigs, NarrowFieldRigIsTheDocumentedHousing) {
  const StereoRig rig = NarrowFieldRig();
  for (const Camera* camera : {&rig.left(), &rig.right()}) {
    EXPECT_EQ(camera->model(), LensModelId::kRadTan);
    EXPECT_EQ(camera->width(), 640);
    EXPECT_EQ(camera->height(), 480);
    EXPECT_NEAR(camera->fx(), 500.0, 5.0);
    EXPECT_NEAR(camera->Distortion()[0], -0.12, 0.01);
    EXPECT_NEAR(camera->Distortion()[1], 0.05, 0.01);
  }
  EXPECT_NE(rig.left(), rig.right());
  EXPECT_NEAR(rig.Baseline(), kNarrowFieldBaseline, 1e-15);
  EXPECT_NEAR(rig.right_from_left().RotationAngle(), kNarrowFieldToeIn, 1e-15);
  // cam1's center is 65 mm along cam0's +x.
  const Rigid3d left_from_right = rig.right_from_left().Inverse();
  EXPECT_NEAR(
      (left_from_right.translation - Eigen::Vector3d(0.065, 0.0, 0.0)).norm(),
      0.0, 1e-15);
  // The documented field of view of cam0, horizontal and vertical, in air
  // and in water (n = 1.333): 67 x 52 and 49 x 38 degrees.
  const Camera& camera = rig.left();
  const double half_width =
      std::atan(camera.NormalizedFromImage({-0.5, camera.cy()})->norm());
  const double half_height =
      std::atan(camera.NormalizedFromImage({camera.cx(), -0.5})->norm());
  EXPECT_NEAR(2.0 * half_width / kDegree, 67.0, 1.0);
  EXPECT_NEAR(2.0 * half_height / kDegree, 52.0, 1.0);
  EXPECT_NEAR(2.0 * std::asin(std::sin(half_width) / 1.333) / kDegree, 49.0,
              1.0);
  EXPECT_NEAR(2.0 * std::asin(std::sin(half_height) / 1.333) / kDegree, 38.0,
              1.0);
}

TEST(ReferenceRigs, NarrowFieldToeInMakesTheAxesMeet) {
  // The toe-in's sign: a point on cam0's optical axis b / tan(2.5 deg) =
  // 1.49 m ahead is imaged at cam1's principal point, in air and in water,
  // through a thin and a thick port (the axial ray is not bent); nearer,
  // it is left of it (cam1 is to the right), farther, right of it.
  const StereoRig rig = NarrowFieldRig();
  const double meet = kNarrowFieldBaseline / std::tan(kNarrowFieldToeIn);
  FlatPort thick;
  thick.air_gap = 0.008;
  thick.glass_thickness = 0.006;
  for (const FlatPort& port : {FlatPort(), thick}) {
    for (const double n : {1.0, 1.34}) {
      const FlatPortCamera right =
          FlatPortCamera::Create(rig.right(), port, n).value();
      const auto pixel_of_depth = [&](double depth) {
        return right
            .ImageFromPoint(rig.right_from_left() *
                            Eigen::Vector3d(0.0, 0.0, depth))
            .value();
      };
      const Eigen::Vector2d principal(rig.right().cx(), rig.right().cy());
      EXPECT_NEAR((pixel_of_depth(meet) - principal).norm(), 0.0, 1e-6)
          << "n " << n << ", air gap " << port.air_gap;
      EXPECT_LT(pixel_of_depth(0.8 * meet).x(), principal.x() - 1.0);
      EXPECT_GT(pixel_of_depth(1.5 * meet).x(), principal.x() + 1.0);
    }
  }
}

}  // namespace
}  // namespace rcm::reference_rigs_test
