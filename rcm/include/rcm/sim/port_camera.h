// PortCamera: a simulated camera behind its port, the exact flat port
// (flat_port_camera.h) or a dome (dome_port_camera.h), for the simulator's
// tracing: the renderer's sample rays, the board's visibility, the
// matches. Both are non-central cameras with the same two maps,
//
//   pixel -> ray in the medium (origin, unit direction; camera frame),
//   point in the medium (camera frame) -> pixel,
//
// so the simulator traces either the same way; only where the rays come
// from differs. The dome is chosen per camera by an optional DomePort
// beside the flat port (SequenceOptions::left_dome, StereoRenderer::Create,
// PlanBoardFrames): StereoRig keeps its flat ports.
#ifndef RCM_SIM_PORT_CAMERA_H_
#define RCM_SIM_PORT_CAMERA_H_

#include <Eigen/Core>
#include <optional>
#include <utility>
#include <variant>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/util/status.h"

namespace rcm {

class PortCamera {
 public:
  // Implicit: either camera is a PortCamera.
  PortCamera(FlatPortCamera camera)  // NOLINT(runtime/explicit)
      : camera_(std::move(camera)) {}
  PortCamera(DomePortCamera camera)  // NOLINT(runtime/explicit)
      : camera_(std::move(camera)) {}

  // `camera` behind `dome` when one is given, else behind `flat`, in a
  // medium of index n; fails as FlatPortCamera::Create or
  // DomePortCamera::Create.
  static StatusOr<PortCamera> Create(const Camera& camera, const FlatPort& flat,
                                     const std::optional<DomePort>& dome,
                                     double n) {
    if (dome) {
      StatusOr<DomePortCamera> through =
          DomePortCamera::Create(camera, *dome, n);
      if (!through.ok()) return through.status();
      return PortCamera(std::move(through).value());
    }
    StatusOr<FlatPortCamera> through = FlatPortCamera::Create(camera, flat, n);
    if (!through.ok()) return through.status();
    return PortCamera(std::move(through).value());
  }

  bool is_dome() const {
    return std::holds_alternative<DomePortCamera>(camera_);
  }
  const Camera& camera() const {
    return std::visit([](const auto& c) -> const Camera& { return c.camera(); },
                      camera_);
  }
  // The ray in the medium seen by a raw pixel; nullopt where there is none.
  std::optional<RayInMedium> RayFromImage(const Eigen::Vector2d& pixel) const {
    return std::visit([&](const auto& c) { return c.RayFromImage(pixel); },
                      camera_);
  }
  // The raw pixel that sees `point_in_camera`; nullopt where none does
  // (it may lie outside the image).
  std::optional<Eigen::Vector2d> ImageFromPoint(
      const Eigen::Vector3d& point_in_camera) const {
    return std::visit(
        [&](const auto& c) { return c.ImageFromPoint(point_in_camera); },
        camera_);
  }

 private:
  std::variant<FlatPortCamera, DomePortCamera> camera_;
};

}  // namespace rcm

#endif  // RCM_SIM_PORT_CAMERA_H_
