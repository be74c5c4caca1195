#include "rcm/camera/dome_port_camera.h"

#include <cmath>
#include <sstream>

#include "rcm/camera/dome_port_refraction.h"
#include "rcm/camera/refractive_camera.h"

namespace rcm {

StatusOr<DomePortCamera> DomePortCamera::Create(const Camera& camera,
                                                const DomePort& dome,
                                                double n) {
  RCM_RETURN_IF_ERROR(dome.Check());
  if (!std::isfinite(n) || n < RefractiveCamera::kMinIndex ||
      n > RefractiveCamera::kMaxIndex) {
    std::ostringstream message;
    message << "refractive index n = " << n << " is outside ["
            << RefractiveCamera::kMinIndex << ", "
            << RefractiveCamera::kMaxIndex << "]";
    return Status::Error(message.str());
  }
  return DomePortCamera(camera, dome, n);
}

std::optional<RayInMedium> DomePortCamera::RayFromNormalized(
    const Eigen::Vector2d& normalized) const {
  RayInMedium ray;
  if (!normalized.allFinite() ||
      !DomePortRefraction::RayInMedium(
          n_, dome_.decentering.data(), dome_, normalized.x(), normalized.y(),
          ray.origin.data(), ray.direction.data()) ||
      !ray.origin.allFinite() || !ray.direction.allFinite()) {
    return std::nullopt;
  }
  return ray;
}

std::optional<RayInMedium> DomePortCamera::RayFromImage(
    const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  return RayFromNormalized(*normalized);
}

std::optional<Eigen::Vector2d> DomePortCamera::NormalizedFromPoint(
    const Eigen::Vector3d& point_in_camera) const {
  Eigen::Vector2d normalized;
  if (!point_in_camera.allFinite() ||
      !DomePortRefraction::NormalizedFromPoint(n_, dome_.decentering.data(),
                                               dome_, point_in_camera.data(),
                                               normalized.data())) {
    return std::nullopt;
  }
  return normalized;
}

std::optional<Eigen::Vector2d> DomePortCamera::ImageFromPoint(
    const Eigen::Vector3d& point_in_camera) const {
  const std::optional<Eigen::Vector2d> normalized =
      NormalizedFromPoint(point_in_camera);
  if (!normalized) return std::nullopt;
  return camera_.ProjectNormalized(*normalized);
}

}  // namespace rcm
