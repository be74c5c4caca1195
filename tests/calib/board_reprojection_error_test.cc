#include "rcm/calib/board_reprojection_error.h"

#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "support/test_rigs.h"

namespace rcm::calib::board_reprojection_error_test {
namespace {

// A board corner 0.8 m in front of the rig, a little off axis.
struct Fixture {
  StereoRig rig = rcm::test::AlphasenseRealisticRig();
  double cam0_from_target[6] = {0.2, -0.3, 0.1, -0.05, 0.02, 0.8};
  double cam1_from_cam0[6];
  Eigen::Vector3d point_in_target{0.12, 0.08, 0.0};

  Fixture() {
    const Eigen::Matrix3d r = rig.right_from_left().rotation;
    ceres::RotationMatrixToAngleAxis(r.data(), cam1_from_cam0);
    for (int i = 0; i < 3; ++i) {
      cam1_from_cam0[3 + i] = rig.right_from_left().translation[i];
    }
  }
  Eigen::Vector3d PointInCam0() const {
    Eigen::Vector3d p;
    ceres::AngleAxisRotatePoint(cam0_from_target, point_in_target.data(),
                                p.data());
    return p + Eigen::Vector3d(cam0_from_target[3], cam0_from_target[4],
                               cam0_from_target[5]);
  }
};

// Residuals are differences of pixels computed two ways in double: a few
// ulp of a 300-700 px coordinate.
constexpr double kPixelTolerance = 1e-9;

TEST(BoardReprojectionError, ZeroAtTheCameraProjection) {
  const Fixture f;
  const Eigen::Vector3d p0 = f.PointInCam0();
  const Eigen::Vector2d pixel0 =
      f.rig.left().ImageFromNormalized(Eigen::Vector2d(p0.head<2>() / p0.z()));
  double residual[2];
  ASSERT_TRUE(
      Cam0BoardReprojectionError<EquidistantLens>(f.point_in_target, pixel0)(
          f.rig.left().params(), f.cam0_from_target, residual));
  EXPECT_NEAR(residual[0], 0.0, kPixelTolerance);
  EXPECT_NEAR(residual[1], 0.0, kPixelTolerance);

  const Eigen::Vector3d p1 = f.rig.right_from_left() * p0;
  const Eigen::Vector2d pixel1 =
      f.rig.right().ImageFromNormalized(Eigen::Vector2d(p1.head<2>() / p1.z()));
  ASSERT_TRUE(Cam1BoardReprojectionError<EquidistantLens>(
      f.point_in_target, pixel1)(f.rig.right().params(), f.cam0_from_target,
                                 f.cam1_from_cam0, residual));
  EXPECT_NEAR(residual[0], 0.0, kPixelTolerance);
  EXPECT_NEAR(residual[1], 0.0, kPixelTolerance);

  // A measured pixel 1.5 px right and 0.5 px up: the residual is
  // projected - measured.
  ASSERT_TRUE(Cam0BoardReprojectionError<EquidistantLens>(
      f.point_in_target, pixel0 + Eigen::Vector2d(1.5, -0.5))(
      f.rig.left().params(), f.cam0_from_target, residual));
  EXPECT_NEAR(residual[0], -1.5, kPixelTolerance);
  EXPECT_NEAR(residual[1], 0.5, kPixelTolerance);
}

TEST(BoardReprojectionError, BehindTheCameraIsRejected) {
  Fixture f;
  f.cam0_from_target[5] = -0.8;
  double residual[2];
  EXPECT_FALSE(Cam0BoardReprojectionError<RadTanLens>(
      f.point_in_target, Eigen::Vector2d(100, 100))(
      rcm::test::EurocRadtanCamera().params(), f.cam0_from_target, residual));
}

TEST(BoardReprojectionError, AutodiffMatchesCentralDifferences) {
  // Ceres' autodiff Jacobian of the cam1 residual against central
  // differences with step 1e-6 (relative to the parameter's scale): the
  // truncation error h^2 f''' / 6 and the rounding error eps f / h are both
  // below 1e-6 of the entries here.
  const Fixture f;
  ceres::CostFunction* cost =
      Cam1BoardReprojectionError<EquidistantLens>::Create(
          f.point_in_target, Eigen::Vector2d(300.0, 200.0));
  double lens[8];
  std::copy(f.rig.right().params(), f.rig.right().params() + 8, lens);
  double pose[6];
  double extrinsics[6];
  std::copy(f.cam0_from_target, f.cam0_from_target + 6, pose);
  std::copy(f.cam1_from_cam0, f.cam1_from_cam0 + 6, extrinsics);
  double* blocks[3] = {lens, pose, extrinsics};
  const int sizes[3] = {8, 6, 6};
  double residual[2];
  double jacobian_lens[16];
  double jacobian_pose[12];
  double jacobian_extrinsics[12];
  double* jacobians[3] = {jacobian_lens, jacobian_pose, jacobian_extrinsics};
  ASSERT_TRUE(cost->Evaluate(blocks, residual, jacobians));
  for (int b = 0; b < 3; ++b) {
    for (int i = 0; i < sizes[b]; ++i) {
      const double saved = blocks[b][i];
      const double step = 1e-6 * std::max(1.0, std::abs(saved));
      double plus[2];
      double minus[2];
      blocks[b][i] = saved + step;
      ASSERT_TRUE(cost->Evaluate(blocks, plus, nullptr));
      blocks[b][i] = saved - step;
      ASSERT_TRUE(cost->Evaluate(blocks, minus, nullptr));
      blocks[b][i] = saved;
      for (int r = 0; r < 2; ++r) {
        const double numeric = (plus[r] - minus[r]) / (2.0 * step);
        const double analytic = jacobians[b][r * sizes[b] + i];
        EXPECT_NEAR(analytic, numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
            << "block " << b << " parameter " << i << " residual " << r;
      }
    }
  }
  delete cost;
}

}  // namespace
}  // namespace rcm::calib::board_reprojection_error_test
