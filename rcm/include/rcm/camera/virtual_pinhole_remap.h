// Virtual pinhole images: resampling the raw (lens-distorted, refracted)
// image of a camera behind a flat port into the image of an ideal pinhole
// in the medium, which stereo and VIO pipelines built for pinhole cameras
// consume unchanged (paper Sec. III-B, eq. 9).
//
// An output view K' = [fx', 0, cx'; 0, fy', cy'; 0, 0, 1] of size w' x h',
// rotated by R = camera_from_view (identity unless the view is rectified,
// e.g. stereo_rectification.h), sees a ray d in the medium (camera frame)
// at p' ~ K' R^T d. The camera's own virtual pinhole K_n = diag(n fx, n fy,
// 1) (principal point cx, cy) sees it at K_n d, so the raw pixel behind
// output pixel p' is, with H = K_n R K'^-1 (a homography; affine when
// R = I) and h(x) = (x_0 / x_2, x_1 / x_2):
//
//   raw(p') = ImageFromVirtualPinhole(h(H p'))     (H p' in front: x_2 > 0)
//
// (RefractiveCamera, refractive_camera.h). The remap maps store raw(p') for
// every output pixel center; cv::remap samples the raw image there
// bilinearly. Output pixels whose ray the camera does not see (past the
// critical angle, off the sensor) read black.
#ifndef RCM_CAMERA_VIRTUAL_PINHOLE_REMAP_H_
#define RCM_CAMERA_VIRTUAL_PINHOLE_REMAP_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>

#include "rcm/camera/refractive_camera.h"
#include "rcm/util/status.h"

namespace rcm {

// The output image: a pinhole without skew, optionally rotated.
struct VirtualPinholeView {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  int width = 0;
  int height = 0;
  // Rotation taking view coordinates to camera coordinates (identity: the
  // view looks along the camera's optical axis).
  Eigen::Matrix3d camera_from_view = Eigen::Matrix3d::Identity();

  // Size positive, k finite with positive focal lengths, zero skew and
  // last row (0, 0, 1), camera_from_view a rotation (to 1e-9).
  Status Check() const;
};

enum class VirtualPinholeFit {
  // K_n itself at the camera's image size: distances in the output are
  // those of the paper's virtual pinhole. Where K_n sees rays the camera
  // does not (corners of a narrow lens in water), the output is black.
  kVirtualPinhole,
  // K_n with both focal lengths scaled by the smallest s (widest view)
  // for which every output pixel samples the raw image inside
  // [0, w - 1] x [0, h - 1], so bilinear interpolation never reaches past
  // the border: no black borders. Same size and principal point. Found by
  // bisection on the border pixels of the output (the map is radial about
  // the principal point up to tangential distortion, so the border bounds
  // the interior), to a relative 1e-6. The Alphasense fisheye in water
  // (n = 1.333) gets s = 0.918: a wider view than K_n.
  kNoBorder,
};

// The output view for a fit. Errors: kNoBorder when the principal point
// lies outside the image or no scale in [1e-3, 1e3] works.
StatusOr<VirtualPinholeView> ChooseVirtualPinholeView(
    const RefractiveCamera& camera,
    VirtualPinholeFit fit = VirtualPinholeFit::kVirtualPinhole);

// The focal scale s of a view chosen for `camera`: k(0, 0) / (n fx).
double VirtualPinholeFocalScale(const RefractiveCamera& camera,
                                const VirtualPinholeView& view);

struct RemapMaps {
  // Raw pixel (x, y) of every output pixel, CV_32FC1 of the view's size;
  // -1 in both where the camera does not see the ray or its raw pixel lies
  // off the sensor (outside [-0.5, w - 0.5] x [-0.5, h - 0.5]).
  cv::Mat map_x;
  cv::Mat map_y;
  // The same maps in OpenCV's fixed-point form, exactly what
  // cv::convertMaps(map_x, map_y, ..., CV_16SC2, false) gives: integer
  // pixel (CV_16SC2) and index of the 1/32 px fraction in OpenCV's
  // interpolation table (CV_16UC1). cv::remap reads them without
  // conversion; empty when not built.
  cv::Mat fixed_xy;
  cv::Mat fixed_table;
  // Size of the raw images the maps sample.
  cv::Size raw_size;
  // Output pixels marked -1.
  int64_t num_invalid = 0;
};

// Builds the maps of `view` (rows split over num_threads >= 1 threads),
// and their fixed-point form when `fixed_point`: 720x540 in about 27 ms on
// one thread, 14 ms on two. Errors: view.Check(), num_threads < 1.
StatusOr<RemapMaps> BuildVirtualPinholeMaps(const RefractiveCamera& camera,
                                            const VirtualPinholeView& view,
                                            int num_threads = 2,
                                            bool fixed_point = true);

// The virtual pinhole image of a raw image of the camera (any type
// cv::remap takes; CHECKs raw.size() == maps.raw_size): bilinear, black
// where the maps are invalid. Uses the fixed-point maps when present:
// cv::remap rounds an 8-bit image's sampling positions to 1/32 px from
// either form (the images are identical), but converts float maps on
// every call. A 720x540 CV_8UC1 image takes about 0.5 ms on two cores,
// 0.8 ms on one (float maps: 0.9-1.0 ms on one).
cv::Mat RemapToVirtualPinhole(const cv::Mat& raw, const RemapMaps& maps);

}  // namespace rcm

#endif  // RCM_CAMERA_VIRTUAL_PINHOLE_REMAP_H_
