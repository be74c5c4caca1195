// RefractiveCamera: an in-air calibrated Camera behind a flat port in a
// medium of refractive index n (paper Sec. III-A; the math is in
// refractive_model.h). Maps raw pixels to rays in the medium and back, and
// to the virtual pinhole image K_n that a VIO can consume.
#ifndef RCM_CAMERA_REFRACTIVE_CAMERA_H_
#define RCM_CAMERA_REFRACTIVE_CAMERA_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/camera/camera.h"
#include "rcm/util/status.h"

namespace rcm {

class RefractiveCamera {
 public:
  // The refractive indices the toolkit accepts: air (1) up to well beyond
  // any liquid or glass a port looks into (2).
  static constexpr double kMinIndex = 1.0;
  static constexpr double kMaxIndex = 2.0;

  // Fails when n is not finite or outside [kMinIndex, kMaxIndex].
  static StatusOr<RefractiveCamera> Create(const Camera& camera, double n);

  const Camera& camera() const { return camera_; }
  double n() const { return n_; }

  // Unit bearing in the medium (camera frame) of a raw pixel; nullopt when
  // the lens cannot undistort it.
  std::optional<Eigen::Vector3d> BearingInWaterFromImage(
      const Eigen::Vector2d& pixel) const;

  // Raw pixel of a point in the medium (camera frame); nullopt behind the
  // camera, past total internal reflection, or where the lens model cannot
  // represent the ray. The pixel may lie outside the image (see
  // Camera::InImage).
  std::optional<Eigen::Vector2d> ImageFromPointInWater(
      const Eigen::Vector3d& point_in_camera) const;

  // The virtual pinhole K_n = [n fx, 0, cx; 0, n fy, cy; 0, 0, 1] (eq. 9).
  Eigen::Matrix3d VirtualPinholeMatrix() const;
  // Virtual pinhole pixel of a raw pixel (refraction and lens removed).
  std::optional<Eigen::Vector2d> VirtualPinholeFromImage(
      const Eigen::Vector2d& pixel) const;
  // Raw pixel of a virtual pinhole pixel: the map an image remap needs.
  // nullopt past the critical angle or where the lens cannot represent it.
  std::optional<Eigen::Vector2d> ImageFromVirtualPinhole(
      const Eigen::Vector2d& virtual_pixel) const;

 private:
  RefractiveCamera(const Camera& camera, double n) : camera_(camera), n_(n) {}

  Camera camera_;
  double n_;
};

}  // namespace rcm

#endif  // RCM_CAMERA_REFRACTIVE_CAMERA_H_
