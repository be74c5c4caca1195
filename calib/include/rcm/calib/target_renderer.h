// Synthetic images of a printed calibration target seen through an in-air
// camera, or through a dome port under water, with the exact corner
// positions to compare detectors against.
//
// Each pixel (x, y) (centers at integers) is split into s x s sub-samples
// at (x + (i + 0.5) / s - 0.5, y + (j + 0.5) / s - 0.5), i, j = 0 .. s - 1.
// The ray through a sub-sample (camera frame, through the lens) meets the
// target plane z = 0 at
//
//   (x, y, w)^T ~ [r1 r2 t]^-1 d,   target point (x / w, y / w)
//
// with cam_from_target = (R = [r1 r2 r3], t) and d the ray direction; w > 0
// exactly when the hit is in front of the camera. The texture
// (target_image.h) is sampled at the nearest texture pixel of
// target_from_texture^-1 (x, y): its edges are pixel edges, so the
// sub-sample grid resolves them exactly. Samples that miss the texture, hit
// the plane behind the camera, or whose ray the lens cannot give get
// `background`. The pixel is the mean of its sub-samples, then (optionally)
// blurred by a Gaussian of blur_sigma_px and given Gaussian noise of
// noise_sigma gray levels, rounded and clamped to [0, 255].
//
// Rays: Create undistorts once the (width + 1) x (height + 1) pixel corners
// (x - 0.5, y - 0.5) into unit directions; a sub-sample's direction is the
// bilinear blend of its pixel's four corner directions (off the exact ray
// by ~0.002 px at the edge of the 82-degree equidistant lens; a pixel with
// a corner the lens cannot undistort is background). Per render, only the
// corners are mapped through the homography; the s^2 sub-samples of a
// pixel are blends of its four corners' homogeneous target points.
//
// A bowed board (options.board_warp, board_warp.h): each pixel corner's
// ray is intersected with the surface z = h(x, y) of the target frame by
// Newton's method on the depth s along the ray, from the plane's hit,
//   f(s) = P_z(s) - h(P_x(s), P_y(s)),   P(s) = R^T (s d - t),
// until the step is below 1e-12 m (a few iterations: the slope of a bow
// of millimetres over a board of decimetres is ~0.01); its texture point
// is scaled by the plane hit's w so that the blends stay those of the
// flat board when the warp is 0. A corner whose iteration does not
// converge (a ray grazing the board) is background.
//
// Through a dome port (Create from a DomePortCamera, dome_port_camera.h):
// the rays do not leave the camera centre. Create traces each pixel
// corner's ray in the medium, origin o (on the dome's outer surface) and
// unit direction d, camera frame; per render it meets the target plane at
//
//   P(s) = o_t + s d_t,  o_t = R^T (o - t),  d_t = R^T d,
//   s = -o_t,z / d_t,z,  target point (P_x, P_y),
//
// and its homogeneous texture point is T (P_x, P_y, 1) / s: for o = 0 that
// is the central [r1 r2 t]^-1 d above (whose w is 1 / s for a unit d), so
// the sub-samples blend as for the air camera, with the plane behind the
// ray's origin (s < 0) background as behind the camera. The bowed board
// is met by the same Newton from o_t. The corner rays are exact; only the
// blend inside a pixel is bilinear (the dome bends rays smoothly over a
// pixel, so it adds nothing measurable to the air lens's ~0.002 px).
//
// Noise: the draw of pixel p is a function of (seed, p) only (SplitMix64
// counter hash, Box-Muller), so images are identical for any num_threads.
#ifndef RCM_CALIB_TARGET_RENDERER_H_
#define RCM_CALIB_TARGET_RENDERER_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_image.h"
#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm::calib {

struct TargetRenderOptions {
  int supersampling = 4;       // sub-samples per pixel along each axis, 1..16
  double blur_sigma_px = 0.0;  // Gaussian blur sigma [pixels], >= 0 (0: none)
  double noise_sigma = 0.0;    // Gaussian noise sigma [gray levels], >= 0
  uint64_t seed = 0;           // the noise depends on it and the pixel only
  int background = 160;        // gray level where the target is not, 0..255
  int num_threads = 2;         // >= 1
  // The board's bow (header; BoardWarpSurfaceOf); warp 0 (the default) is
  // the flat board. Finite, with a positive extent.
  BoardWarpSurface board_warp;
  Status Check() const;
};

class TargetRenderer {
 public:
  // Fails when the texture is not a non-empty CV_8UC1 image, its
  // target_from_texture is not invertible, or no pixel of the camera can
  // be undistorted.
  static StatusOr<TargetRenderer> Create(const Camera& camera,
                                         TargetImage target_image);
  // Through a dome port (header): the same, with the rays in the medium
  // of `camera`; fails too when no pixel's ray leaves the dome.
  static StatusOr<TargetRenderer> Create(const DomePortCamera& camera,
                                         TargetImage target_image);

  // An 8-bit gray image (CV_8UC1) of the camera's size. CHECKs
  // options.Check().
  cv::Mat Render(const Rigid3d& cam_from_target,
                 const TargetRenderOptions& options) const;

  // The lens (behind the dome when there is one).
  const Camera& camera() const { return camera_; }
  // The dome the renderer traces through; nullopt in air.
  const std::optional<DomePortCamera>& dome_camera() const {
    return dome_camera_;
  }
  const TargetImage& target_image() const { return target_image_; }

 private:
  TargetRenderer(const Camera& camera, TargetImage target_image)
      : camera_(camera), target_image_(std::move(target_image)) {}

  // The pixel corners' rays through `ray` (origin, unit direction; nullopt
  // where there is none), and the error when no corner has one.
  Status TraceCorners(
      const std::function<std::optional<RayInMedium>(const Eigen::Vector2d&)>&
          ray,
      bool central);

  Camera camera_;
  std::optional<DomePortCamera> dome_camera_;
  TargetImage target_image_;
  // Unit ray direction of pixel corner (x - 0.5, y - 0.5) at index
  // y * (width + 1) + x; NaN where the lens cannot undistort it (or the
  // ray does not leave the dome).
  std::vector<Eigen::Vector3f> corner_rays_;
  // Through a dome, the rays' origins (camera frame, meters) at the same
  // indices; empty for the central air camera.
  std::vector<Eigen::Vector3f> corner_origins_;
};

// The ground-truth pixel of each TargetPoints(target) point seen by
// `camera` at `cam_from_target`; nullopt for a point behind the camera (or
// on its plane), one the lens cannot project, or outside the image
// (Camera::InImage). With `board_warp` [m], the points of the bowed board
// (WarpedTargetPoints).
std::vector<std::optional<Eigen::Vector2d>> ProjectTargetPoints(
    const Camera& camera, const Rigid3d& cam_from_target,
    const CalibrationTarget& target,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero());
// The same through a dome port (DomePortCamera::ImageFromPoint): nullopt
// for a point no forward ray reaches, one the lens cannot project, or
// outside the image.
std::vector<std::optional<Eigen::Vector2d>> ProjectTargetPoints(
    const DomePortCamera& camera, const Rigid3d& cam_from_target,
    const CalibrationTarget& target,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero());

}  // namespace rcm::calib

#endif  // RCM_CALIB_TARGET_RENDERER_H_
