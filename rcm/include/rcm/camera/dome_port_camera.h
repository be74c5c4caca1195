// DomePortCamera: an in-air calibrated Camera (lens model) behind a dome
// port (dome_port_geometry.h) in a medium of index n. Like the thick flat
// port (flat_port_camera.h) a non-central camera: each pixel sees along its
// own ray, which starts on the dome's outer surface; the math is in
// dome_port_refraction.h. A centred dome, or a dome of no thickness in
// air, is the air camera (the tests hold the two together to 1e-12 px).
#ifndef RCM_CAMERA_DOME_PORT_CAMERA_H_
#define RCM_CAMERA_DOME_PORT_CAMERA_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port.h"
#include "rcm/util/status.h"

namespace rcm {

class DomePortCamera {
 public:
  // Fails when the dome fails DomePort::Check or n is not in [1, 2].
  static StatusOr<DomePortCamera> Create(const Camera& camera,
                                         const DomePort& dome, double n);

  const Camera& camera() const { return camera_; }
  const DomePort& dome() const { return dome_; }
  double n() const { return n_; }

  // The ray in the medium (camera frame) seen by a raw pixel; nullopt when
  // the lens cannot undistort the pixel or the ray is totally reflected.
  std::optional<RayInMedium> RayFromImage(const Eigen::Vector2d& pixel) const;
  // The same for a lens-undistorted normalized point.
  std::optional<RayInMedium> RayFromNormalized(
      const Eigen::Vector2d& normalized) const;

  // The lens-undistorted normalized point whose ray passes through
  // `point_in_camera` (a point in the medium beyond the dome); nullopt
  // when no forward ray reaches it (dome_port_refraction.h).
  std::optional<Eigen::Vector2d> NormalizedFromPoint(
      const Eigen::Vector3d& point_in_camera) const;
  // The raw pixel that sees `point_in_camera`; nullopt as above or where
  // the lens cannot represent the ray (Camera::ProjectNormalized). The
  // pixel may lie outside the image (Camera::InImage).
  std::optional<Eigen::Vector2d> ImageFromPoint(
      const Eigen::Vector3d& point_in_camera) const;

 private:
  DomePortCamera(const Camera& camera, const DomePort& dome, double n)
      : camera_(camera), dome_(dome), n_(n) {}

  Camera camera_;
  DomePort dome_;
  double n_;
};

}  // namespace rcm

#endif  // RCM_CAMERA_DOME_PORT_CAMERA_H_
