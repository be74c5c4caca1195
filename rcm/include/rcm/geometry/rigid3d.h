// Rigid3d: a rigid transform between two frames, named by what it maps,
// e.g. `cam1_from_cam0 * point_in_cam0 = point_in_cam1` (COLMAP's naming).
//
// The rotation is kept as the matrix it was read as, so that a camchain
// file read and written again is bit-identical; FromMatrix validates that
// the matrix is a proper rotation.
#ifndef RCM_GEOMETRY_RIGID3D_H_
#define RCM_GEOMETRY_RIGID3D_H_

#include <Eigen/Core>

#include "rcm/util/status.h"

namespace rcm {

struct Rigid3d {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // Largest tolerated |R^T R - I| (max abs entry) and |det R - 1| when a
  // transform is read from a file: calibration tools print 9+ digits, so
  // 1e-6 accepts every honest file and rejects a mistyped entry.
  static constexpr double kRotationTolerance = 1e-6;

  // Validates a homogeneous 4x4 [R t; 0 0 0 1]: finite entries, last row
  // exactly (0, 0, 0, 1), R orthonormal with det +1 within kRotationTolerance.
  static StatusOr<Rigid3d> FromMatrix(const Eigen::Matrix4d& matrix);
  Eigen::Matrix4d ToMatrix() const;

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  // (a_from_b * b_from_c) = a_from_c.
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d{rotation * other.rotation,
                   rotation * other.translation + translation};
  }
  Rigid3d Inverse() const {
    return Rigid3d{rotation.transpose(), -(rotation.transpose() * translation)};
  }
  // Rotation angle in radians (0 for the identity).
  double RotationAngle() const;
};

}  // namespace rcm

#endif  // RCM_GEOMETRY_RIGID3D_H_
