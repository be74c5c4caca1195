#include "rcm/camera/refractive_camera.h"

#include <cmath>
#include <sstream>

#include "rcm/camera/refractive_model.h"

namespace rcm {

StatusOr<RefractiveCamera> RefractiveCamera::Create(const Camera& camera,
                                                    double n) {
  if (!std::isfinite(n) || n < kMinIndex || n > kMaxIndex) {
    std::ostringstream message;
    message << "refractive index n = " << n << " is outside [" << kMinIndex
            << ", " << kMaxIndex << "]";
    return Status::Error(message.str());
  }
  return RefractiveCamera(camera, n);
}

std::optional<Eigen::Vector3d> RefractiveCamera::BearingInWaterFromImage(
    const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  Eigen::Vector3d bearing;
  FlatPortRefraction::BearingInWater(n_, normalized->x(), normalized->y(),
                                     bearing.data());
  return bearing.normalized();
}

std::optional<Eigen::Vector2d> RefractiveCamera::ImageFromPointInWater(
    const Eigen::Vector3d& point_in_camera) const {
  Eigen::Vector2d normalized;
  if (!FlatPortRefraction::NormalizedFromPointInWater(
          n_, point_in_camera.data(), &normalized.x(), &normalized.y())) {
    return std::nullopt;
  }
  return camera_.ProjectNormalized(normalized);
}

Eigen::Matrix3d RefractiveCamera::VirtualPinholeMatrix() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = n_ * camera_.fx();
  k(1, 1) = n_ * camera_.fy();
  k(0, 2) = camera_.cx();
  k(1, 2) = camera_.cy();
  return k;
}

std::optional<Eigen::Vector2d> RefractiveCamera::VirtualPinholeFromImage(
    const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  double xv, yv;
  FlatPortRefraction::VirtualFromNormalized(n_, normalized->x(),
                                            normalized->y(), &xv, &yv);
  return Eigen::Vector2d(camera_.fx() * xv + camera_.cx(),
                         camera_.fy() * yv + camera_.cy());
}

std::optional<Eigen::Vector2d> RefractiveCamera::ImageFromVirtualPinhole(
    const Eigen::Vector2d& virtual_pixel) const {
  const double xv = (virtual_pixel.x() - camera_.cx()) / camera_.fx();
  const double yv = (virtual_pixel.y() - camera_.cy()) / camera_.fy();
  Eigen::Vector2d normalized;
  if (!FlatPortRefraction::NormalizedFromVirtual(n_, xv, yv, &normalized.x(),
                                                 &normalized.y())) {
    return std::nullopt;
  }
  return camera_.ProjectNormalized(normalized);
}

}  // namespace rcm
