#include "rcm/geometry/rigid3d.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace rcm::rigid3d_test {
namespace {

Rigid3d SomeTransform() {
  return Rigid3d{
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized())
          .toRotationMatrix(),
      Eigen::Vector3d(0.1, -0.2, 0.3)};
}

TEST(Rigid3d, FromMatrixAcceptsRigidTransform) {
  const Rigid3d transform = SomeTransform();
  const StatusOr<Rigid3d> parsed = Rigid3d::FromMatrix(transform.ToMatrix());
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->rotation, transform.rotation);
  EXPECT_EQ(parsed->translation, transform.translation);
}

TEST(Rigid3d, FromMatrixRejectsNonOrthonormalRotation) {
  Eigen::Matrix4d matrix = SomeTransform().ToMatrix();
  matrix(0, 1) += 1e-3;
  const StatusOr<Rigid3d> parsed = Rigid3d::FromMatrix(matrix);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.status().message().find("rotation is not orthonormal"),
            std::string::npos)
      << parsed.status().message();
}

TEST(Rigid3d, FromMatrixToleratesPrintedPrecision) {
  // Calibration files print ~9 digits: 1e-9 errors must pass.
  Eigen::Matrix4d matrix = SomeTransform().ToMatrix();
  matrix(0, 1) += 1e-9;
  EXPECT_TRUE(Rigid3d::FromMatrix(matrix).ok());
}

TEST(Rigid3d, FromMatrixRejectsReflection) {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix(2, 2) = -1.0;
  const StatusOr<Rigid3d> parsed = Rigid3d::FromMatrix(matrix);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.status().message().find("determinant -1"), std::string::npos)
      << parsed.status().message();
}

TEST(Rigid3d, FromMatrixRejectsBadLastRow) {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix(3, 0) = 0.5;
  const StatusOr<Rigid3d> parsed = Rigid3d::FromMatrix(matrix);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.status().message().find("last row"), std::string::npos);
}

TEST(Rigid3d, FromMatrixRejectsNonFinite) {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix(0, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(Rigid3d::FromMatrix(matrix).ok());
}

TEST(Rigid3d, InverseAndComposition) {
  const Rigid3d a_from_b = SomeTransform();
  const Rigid3d identity = a_from_b * a_from_b.Inverse();
  EXPECT_LT((identity.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT(identity.translation.norm(), 1e-15);
  const Eigen::Vector3d point_in_b(1.0, 2.0, 3.0);
  EXPECT_LT((a_from_b.Inverse() * (a_from_b * point_in_b) - point_in_b).norm(),
            1e-15);
}

TEST(Rigid3d, RotationAngle) {
  for (double angle : {0.0, 1e-9, 0.01, 1.0, 3.0}) {
    const Rigid3d transform{
        Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2, 0.3, -1).normalized())
            .toRotationMatrix(),
        Eigen::Vector3d::Zero()};
    EXPECT_NEAR(transform.RotationAngle(), angle, 1e-15 + 1e-14 * angle);
  }
}

}  // namespace
}  // namespace rcm::rigid3d_test
