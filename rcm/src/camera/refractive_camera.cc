#include "rcm/camera/refractive_camera.h"

#include <cmath>
#include <sstream>
#include <utility>

#include "rcm/camera/refractive_model.h"

namespace rcm {

namespace {

// A reference depth beyond the port's farthest point `nearest` (meters) by
// kMinReferenceDepthBeyondGlass and at most kMaxReferenceDepth; `what`
// names the port in the error ("the port's glass", "the dome").
Status CheckReferenceDepth(double reference_depth, double nearest,
                           const char* what) {
  std::ostringstream message;
  if (!std::isfinite(reference_depth) ||
      !(reference_depth >=
        nearest + RefractiveCamera::kMinReferenceDepthBeyondGlass)) {
    message << "reference depth " << reference_depth << " m is not beyond "
            << what << " (" << nearest << " m) by "
            << RefractiveCamera::kMinReferenceDepthBeyondGlass * 1e3
            << " mm at least";
    return Status::Error(message.str());
  }
  if (reference_depth > RefractiveCamera::kMaxReferenceDepth) {
    message << "reference depth " << reference_depth
            << " m is beyond the accepted "
            << RefractiveCamera::kMaxReferenceDepth << " m";
    return Status::Error(message.str());
  }
  return Status::Ok();
}

}  // namespace

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

StatusOr<RefractiveCamera> RefractiveCamera::CreateWithPort(
    const Camera& camera, double n, const FlatPort& port,
    double reference_depth) {
  StatusOr<RefractiveCamera> result = Create(camera, n);
  if (!result.ok()) return result.status();
  RCM_RETURN_IF_ERROR(port.Check());
  RCM_RETURN_IF_ERROR(CheckReferenceDepth(reference_depth,
                                          port.air_gap + port.glass_thickness,
                                          "the port's glass"));
  result->port_ = port;
  result->reference_depth_ = reference_depth;
  if (!port.IsThin()) {
    StatusOr<FlatPortCamera> thick = FlatPortCamera::Create(camera, port, n);
    if (!thick.ok()) return thick.status();
    result->thick_ = std::move(thick).value();
  }
  return result;
}

StatusOr<RefractiveCamera> RefractiveCamera::CreateWithDome(
    const Camera& camera, double n, const DomePort& dome,
    double reference_depth) {
  StatusOr<RefractiveCamera> result = Create(camera, n);
  if (!result.ok()) return result.status();
  StatusOr<DomePortCamera> through = DomePortCamera::Create(camera, dome, n);
  if (!through.ok()) return through.status();
  RCM_RETURN_IF_ERROR(CheckReferenceDepth(
      reference_depth, dome.decentering.z() + dome.outer_radius(), "the dome"));
  result->dome_ = dome;
  result->dome_camera_ = std::move(through).value();
  result->reference_depth_ = reference_depth;
  return result;
}

namespace {

// `value`, or nullopt when an entry is not finite: a pixel far outside the
// image (found by fuzz_camera_model: u = 4e175 overflowed the bearing).
template <int kRows>
std::optional<Eigen::Matrix<double, kRows, 1>> IfFinite(
    const Eigen::Matrix<double, kRows, 1>& value) {
  if (!value.allFinite()) return std::nullopt;
  return value;
}

// `direction` scaled to unit length, or nullopt when its length is not a
// positive finite number (it overflowed or underflowed).
std::optional<Eigen::Vector3d> UnitOrNothing(const Eigen::Vector3d& direction) {
  const double length = direction.norm();
  if (!std::isfinite(length) || !(length > 0.0)) return std::nullopt;
  return IfFinite<3>(direction / length);
}

}  // namespace

std::optional<Eigen::Vector3d> RefractiveCamera::BearingInWaterFromImage(
    const Eigen::Vector2d& pixel) const {
  if (CentralOnlyAtReferenceDepth()) {
    // Where the pixel's ray reaches the reference depth, seen from the
    // center.
    const std::optional<RayInMedium> ray =
        dome_camera_ ? dome_camera_->RayFromImage(pixel)
                     : thick()->RayFromImage(pixel);
    if (!ray || !(ray->direction.z() > 0.0)) return std::nullopt;
    const double along =
        (reference_depth_ - ray->origin.z()) / ray->direction.z();
    if (!(along > 0.0)) return std::nullopt;
    return UnitOrNothing(ray->origin + along * ray->direction);
  }
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  Eigen::Vector3d bearing;
  FlatPortRefraction::BearingInWater(n_, normalized->x(), normalized->y(),
                                     bearing.data());
  return UnitOrNothing(bearing);
}

std::optional<Eigen::Vector2d> RefractiveCamera::ImageFromPointInWater(
    const Eigen::Vector3d& point_in_camera) const {
  if (dome_camera_) return dome_camera_->ImageFromPoint(point_in_camera);
  if (const FlatPortCamera* thick = this->thick()) {
    return thick->ImageFromPoint(point_in_camera);
  }
  Eigen::Vector2d normalized;
  if (!FlatPortRefraction::NormalizedFromPointInWater(
          n_, point_in_camera.data(), &normalized.x(), &normalized.y())) {
    return std::nullopt;
  }
  return camera_.ProjectNormalized(normalized);
}

Eigen::Matrix3d RefractiveCamera::VirtualPinholeMatrix() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = VirtualFocalScale() * camera_.fx();
  k(1, 1) = VirtualFocalScale() * camera_.fy();
  k(0, 2) = camera_.cx();
  k(1, 2) = camera_.cy();
  return k;
}

std::optional<Eigen::Vector2d> RefractiveCamera::VirtualPinholeFromImage(
    const Eigen::Vector2d& pixel) const {
  if (CentralOnlyAtReferenceDepth()) {
    // K_n applied to the bearing: u = s fx X / Z + cx (eq. 9).
    const std::optional<Eigen::Vector3d> bearing =
        BearingInWaterFromImage(pixel);
    if (!bearing || !(bearing->z() > 0.0)) return std::nullopt;
    const double s = VirtualFocalScale();
    return IfFinite<2>(Eigen::Vector2d(
        s * camera_.fx() * bearing->x() / bearing->z() + camera_.cx(),
        s * camera_.fy() * bearing->y() / bearing->z() + camera_.cy()));
  }
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  double xv, yv;
  FlatPortRefraction::VirtualFromNormalized(n_, normalized->x(),
                                            normalized->y(), &xv, &yv);
  return IfFinite<2>(Eigen::Vector2d(camera_.fx() * xv + camera_.cx(),
                                     camera_.fy() * yv + camera_.cy()));
}

std::optional<Eigen::Vector2d> RefractiveCamera::ImageFromVirtualPinhole(
    const Eigen::Vector2d& virtual_pixel) const {
  const double xv = (virtual_pixel.x() - camera_.cx()) / camera_.fx();
  const double yv = (virtual_pixel.y() - camera_.cy()) / camera_.fy();
  if (CentralOnlyAtReferenceDepth()) {
    // The virtual point (xv, yv) is the ray (xv, yv, s) (eq. 10): the
    // point at the reference depth along it.
    const double s = VirtualFocalScale();
    return ImageFromPointInWater(Eigen::Vector3d(xv, yv, s) *
                                 (reference_depth_ / s));
  }
  Eigen::Vector2d normalized;
  if (!FlatPortRefraction::NormalizedFromVirtual(n_, xv, yv, &normalized.x(),
                                                 &normalized.y())) {
    return std::nullopt;
  }
  return camera_.ProjectNormalized(normalized);
}

}  // namespace rcm
