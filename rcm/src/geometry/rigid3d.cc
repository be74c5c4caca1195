#include "rcm/geometry/rigid3d.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rcm {

StatusOr<Rigid3d> Rigid3d::FromMatrix(const Eigen::Matrix4d& matrix) {
  if (!matrix.allFinite()) {
    return Status::Error("transform has a non-finite entry");
  }
  if (matrix.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
    std::ostringstream message;
    message << "not a rigid transform: last row is [" << matrix.row(3)
            << "], expected [0 0 0 1]";
    return Status::Error(message.str());
  }
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double orthonormality =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  if (orthonormality > kRotationTolerance) {
    std::ostringstream message;
    message << "not a rigid transform: rotation is not orthonormal "
               "(max |R^T R - I| = "
            << orthonormality << ")";
    return Status::Error(message.str());
  }
  const double determinant = rotation.determinant();
  if (std::abs(determinant - 1.0) > kRotationTolerance) {
    std::ostringstream message;
    message << "not a rigid transform: rotation has determinant " << determinant
            << " (a reflection)";
    return Status::Error(message.str());
  }
  return Rigid3d{rotation, matrix.topRightCorner<3, 1>()};
}

Eigen::Matrix4d Rigid3d::ToMatrix() const {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix.topLeftCorner<3, 3>() = rotation;
  matrix.topRightCorner<3, 1>() = translation;
  return matrix;
}

double Rigid3d::RotationAngle() const {
  // atan2 of |axis * sin| and cos is accurate at both small and large angles.
  const Eigen::Vector3d axis_sin(rotation(2, 1) - rotation(1, 2),
                                 rotation(0, 2) - rotation(2, 0),
                                 rotation(1, 0) - rotation(0, 1));
  const double cos_angle = 0.5 * (rotation.trace() - 1.0);
  return std::atan2(0.5 * axis_sin.norm(), cos_angle);
}

}  // namespace rcm
