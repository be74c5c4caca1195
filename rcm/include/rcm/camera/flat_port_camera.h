// FlatPortCamera: an in-air calibrated Camera (lens model) behind an exact
// flat port (flat_port.h) in a medium of index n. A non-central camera:
// each pixel sees along its own ray in the medium, which starts on the
// outer glass face. The library's thick-port camera and the simulator's
// ground truth; with a thin port it is the paper's model
// (RefractiveCamera) computed another way.
#ifndef RCM_CAMERA_FLAT_PORT_CAMERA_H_
#define RCM_CAMERA_FLAT_PORT_CAMERA_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/camera/camera.h"
#include "rcm/camera/flat_port.h"
#include "rcm/util/status.h"

namespace rcm {

class FlatPortCamera {
 public:
  // Fails when the port or n is invalid (ExactFlatPort::Create).
  static StatusOr<FlatPortCamera> Create(const Camera& camera,
                                         const FlatPort& port, double n);

  const Camera& camera() const { return camera_; }
  const ExactFlatPort& port() const { return port_; }
  double n() const { return port_.n(); }

  // The ray in the medium (camera frame) seen by a raw pixel; nullopt when
  // the lens cannot undistort the pixel or the ray misses the port.
  std::optional<RayInMedium> RayFromImage(const Eigen::Vector2d& pixel) const;

  // The raw pixel that sees `point_in_camera` (a point in the medium);
  // nullopt when it is not visible through the port or the lens cannot
  // represent its ray (Camera::ProjectNormalized). The pixel may lie
  // outside the image (Camera::InImage).
  std::optional<Eigen::Vector2d> ImageFromPoint(
      const Eigen::Vector3d& point_in_camera) const;

 private:
  FlatPortCamera(const Camera& camera, const ExactFlatPort& port)
      : camera_(camera), port_(port) {}

  Camera camera_;
  ExactFlatPort port_;
};

}  // namespace rcm

#endif  // RCM_CAMERA_FLAT_PORT_CAMERA_H_
