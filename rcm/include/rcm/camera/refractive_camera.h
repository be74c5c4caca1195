// RefractiveCamera: an in-air calibrated Camera behind a flat port in a
// medium of refractive index n (paper Sec. III-A; the math is in
// refractive_model.h). Maps raw pixels to rays in the medium and back, and
// to the virtual pinhole image K_n that a VIO can consume.
#ifndef RCM_CAMERA_REFRACTIVE_CAMERA_H_
#define RCM_CAMERA_REFRACTIVE_CAMERA_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/flat_port_geometry.h"
#include "rcm/util/status.h"

namespace rcm {

class RefractiveCamera {
 public:
  // The refractive indices the toolkit accepts: air (1) up to well beyond
  // any liquid or glass a port looks into (2).
  static constexpr double kMinIndex = 1.0;
  static constexpr double kMaxIndex = 2.0;
  // The largest reference depth of CreateWithPort, meters: far beyond what
  // a camera sees under water, small enough that the bearings' arithmetic
  // cannot overflow (found by fuzz_camera_model: 1e217 m gave the bearing
  // (0, 0, 0)).
  static constexpr double kMaxReferenceDepth = 1e4;
  // How far beyond the outer glass face the reference depth must lie,
  // meters: nearer, the central camera's arithmetic degenerates (found by
  // fuzz_camera_model: a reference depth of 4e-217 m).
  static constexpr double kMinReferenceDepthBeyondGlass = 1e-3;

  // Fails when n is not finite or outside [kMinIndex, kMaxIndex].
  static StatusOr<RefractiveCamera> Create(const Camera& camera, double n);

  // The camera behind a thick port (flat_port_camera.h: an air gap, glass,
  // a tilted normal), made central for the tools that need a camera with
  // one center in the water (corrected images, water-side models): a
  // pixel's bearing is the direction from the camera center to the point
  // where its ray in the water reaches the depth `reference_depth` (Z in
  // the camera frame, meters), so that the virtual pinhole images points
  // at that depth exactly. A point at depth Z' is imaged through the real
  // port (ImageFromPointInWater is exact at any depth); seen through the
  // bearings it is off by the parallax of the port's lateral ray offset
  // delta (a few mm), about delta |1/Z' - 1/Z| times the focal length.
  // A thin port gives the camera of Create at any reference depth.
  // Errors: those of Create, an invalid port, a reference depth that is
  // not finite, not kMinReferenceDepthBeyondGlass beyond the glass
  // (air_gap + glass_thickness) or beyond kMaxReferenceDepth.
  static StatusOr<RefractiveCamera> CreateWithPort(const Camera& camera,
                                                   double n,
                                                   const FlatPort& port,
                                                   double reference_depth);
  // The camera behind a dome port (dome_port_camera.h), made central at
  // `reference_depth` as CreateWithPort does for a thick flat port: a
  // pixel's bearing is the direction from the camera centre to the point
  // where its ray in the water reaches that depth. The virtual pinhole of a
  // dome is the air camera's K (no factor n: a centred dome does not
  // refract, and a decentered one is a weak lens, so its bearings are
  // within a few percent of the air rays). A point at another depth Z' is
  // seen through the bearings off by the parallax of the rays' offsets from
  // the camera centre, about f |C_perp| |1/Z' - 1/Z| pixels
  // (rcm/estimation/dome_port_error.h maps it). Errors: an invalid n or
  // dome, a reference depth that is not finite, not
  // kMinReferenceDepthBeyondGlass beyond the dome's outer surface (C_z +
  // r2), or beyond kMaxReferenceDepth.
  static StatusOr<RefractiveCamera> CreateWithDome(const Camera& camera,
                                                   double n,
                                                   const DomePort& dome,
                                                   double reference_depth);

  // The port and reference depth of CreateWithPort; nullopt for Create.
  const std::optional<FlatPort>& port() const { return port_; }
  // The dome of CreateWithDome; nullopt otherwise.
  const std::optional<DomePort>& dome() const { return dome_; }
  double reference_depth() const { return reference_depth_; }
  // True for a camera that is central only at its reference depth (a
  // thick port or a dome).
  bool CentralOnlyAtReferenceDepth() const {
    return thick_.has_value() || dome_camera_.has_value();
  }

  const Camera& camera() const { return camera_; }
  double n() const { return n_; }

  // Unit bearing in the medium (camera frame) of a raw pixel; nullopt when
  // the lens cannot undistort it or the pixel is so far outside the image
  // that the bearing overflows.
  std::optional<Eigen::Vector3d> BearingInWaterFromImage(
      const Eigen::Vector2d& pixel) const;

  // Raw pixel of a point in the medium (camera frame); nullopt behind the
  // camera, past total internal reflection, or where the lens model cannot
  // represent the ray. The pixel may lie outside the image (see
  // Camera::InImage).
  std::optional<Eigen::Vector2d> ImageFromPointInWater(
      const Eigen::Vector3d& point_in_camera) const;

  // The virtual pinhole K_n = [s fx, 0, cx; 0, s fy, cy; 0, 0, 1] with
  // s = n behind a flat port (eq. 9) and s = 1 behind a dome.
  Eigen::Matrix3d VirtualPinholeMatrix() const;
  double VirtualFocalScale() const { return dome_camera_ ? 1.0 : n_; }
  // Virtual pinhole pixel of a raw pixel (refraction and lens removed);
  // nullopt as for BearingInWaterFromImage.
  std::optional<Eigen::Vector2d> VirtualPinholeFromImage(
      const Eigen::Vector2d& pixel) const;
  // Raw pixel of a virtual pinhole pixel: the map an image remap needs.
  // nullopt past the critical angle or where the lens cannot represent it.
  std::optional<Eigen::Vector2d> ImageFromVirtualPinhole(
      const Eigen::Vector2d& virtual_pixel) const;

 private:
  RefractiveCamera(const Camera& camera, double n) : camera_(camera), n_(n) {}

  // The thick port's camera, when it is not thin.
  const FlatPortCamera* thick() const {
    return thick_.has_value() ? &*thick_ : nullptr;
  }

  Camera camera_;
  double n_;
  std::optional<FlatPort> port_;
  std::optional<FlatPortCamera> thick_;
  std::optional<DomePort> dome_;
  std::optional<DomePortCamera> dome_camera_;
  double reference_depth_ = 0.0;
};

}  // namespace rcm

#endif  // RCM_CAMERA_REFRACTIVE_CAMERA_H_
