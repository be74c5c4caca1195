// Synthetic images of a printed calibration target seen through an in-air
// camera, with the exact corner positions to compare detectors against.
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
// Noise: the draw of pixel p is a function of (seed, p) only (SplitMix64
// counter hash, Box-Muller), so images are identical for any num_threads.
#ifndef RCM_CALIB_TARGET_RENDERER_H_
#define RCM_CALIB_TARGET_RENDERER_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_image.h"
#include "rcm/camera/camera.h"
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

  // An 8-bit gray image (CV_8UC1) of the camera's size. CHECKs
  // options.Check().
  cv::Mat Render(const Rigid3d& cam_from_target,
                 const TargetRenderOptions& options) const;

  const Camera& camera() const { return camera_; }
  const TargetImage& target_image() const { return target_image_; }

 private:
  TargetRenderer(const Camera& camera, TargetImage target_image)
      : camera_(camera), target_image_(std::move(target_image)) {}

  Camera camera_;
  TargetImage target_image_;
  // Unit ray direction of pixel corner (x - 0.5, y - 0.5) at index
  // y * (width + 1) + x; NaN where the lens cannot undistort it.
  std::vector<Eigen::Vector3f> corner_rays_;
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

}  // namespace rcm::calib

#endif  // RCM_CALIB_TARGET_RENDERER_H_
