#include "rcm/camera/flat_port_camera.h"

namespace rcm {

StatusOr<FlatPortCamera> FlatPortCamera::Create(const Camera& camera,
                                                const FlatPort& port,
                                                double n) {
  StatusOr<ExactFlatPort> exact = ExactFlatPort::Create(port, n);
  if (!exact.ok()) return exact.status();
  return FlatPortCamera(camera, exact.value());
}

std::optional<RayInMedium> FlatPortCamera::RayFromImage(
    const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector2d> normalized =
      camera_.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  return port_.RayFromNormalized(*normalized);
}

std::optional<Eigen::Vector2d> FlatPortCamera::ImageFromPoint(
    const Eigen::Vector3d& point_in_camera) const {
  const std::optional<Eigen::Vector2d> normalized =
      port_.NormalizedFromPoint(point_in_camera);
  if (!normalized) return std::nullopt;
  return camera_.ProjectNormalized(*normalized);
}

}  // namespace rcm
