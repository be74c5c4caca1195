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
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string_view>
#include <vector>

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
  // K_n with both focal lengths scaled by the largest s (narrowest view)
  // for which the ray of every raw border pixel the camera can unproject
  // (pixel centers on the four edges) lands inside [0, w' - 1] x
  // [0, h' - 1] of the output: the whole field of view in one image, black
  // where the camera sees nothing (the corners, for a lens with barrel
  // distortion). Same size and principal point. The output pixel of a ray
  // moves away from the principal point linearly in s (see
  // ZoomedViewFamily), so "every border ray inside" holds exactly for
  // s <= s*; bisection to a relative 1e-6. The Alphasense fisheye in water
  // (n = 1.333) gets s = 0.865, 3.3 % of the output black.
  kFullFieldOfView,
};

// "virtual-pinhole", "no-border", "full"; and back (nullopt for any other
// name).
const char* VirtualPinholeFitName(VirtualPinholeFit fit);
std::optional<VirtualPinholeFit> VirtualPinholeFitFromName(
    std::string_view name);

// The output view for a fit. Errors: kNoBorder and kFullFieldOfView when
// the principal point lies outside the image or no scale in [1e-3, 1e3]
// works; kFullFieldOfView when a raw border pixel sees a ray 90 degrees or
// more off the optical axis (no pinhole image holds it).
StatusOr<VirtualPinholeView> ChooseVirtualPinholeView(
    const RefractiveCamera& camera,
    VirtualPinholeFit fit = VirtualPinholeFit::kVirtualPinhole);

// The focal scale s of a view chosen for `camera`: k(0, 0) / (n fx).
double VirtualPinholeFocalScale(const RefractiveCamera& camera,
                                const VirtualPinholeView& view);

// Views of one size that differ only by a zoom s about a fixed output
// pixel a = anchor_pixel, which sees the view-frame direction
// (d_x, d_y, 1), d = anchor_direction, at every s:
//
//   K(s) = [s f0x,   0,   a_x - s f0x d_x;
//             0,   s f0y, a_y - s f0y d_y;
//             0,     0,         1        ]
//
// An output pixel p' sees the view-frame direction (d + (p' - a) / (s f0),
// 1) (component-wise division), and a view-frame direction (x, y, z),
// z > 0, lands on p'(s) = a + s f0 (x / z - d_x, y / z - d_y): on a ray
// from a, linearly in s. Larger s, narrower view. ChooseVirtualPinholeView
// zooms K_n about its principal point: f0 = (n fx, n fy), a = (cx, cy),
// d = 0, the camera's size; a rectified pair shares one family and rotates
// it differently per camera (virtual_pinhole_rig.h).
struct ZoomedViewFamily {
  Eigen::Vector2d base_focal = Eigen::Vector2d::Ones();
  Eigen::Vector2d anchor_pixel = Eigen::Vector2d::Zero();
  Eigen::Vector2d anchor_direction = Eigen::Vector2d::Zero();
  int width = 0;
  int height = 0;

  // The view K(s) of this size, rotated by camera_from_view.
  VirtualPinholeView At(double scale, const Eigen::Matrix3d& camera_from_view =
                                          Eigen::Matrix3d::Identity()) const;
  // Size positive, every entry finite, base focal lengths positive.
  Status Check() const;
};

// K_n zoomed about the principal point, at the camera's size.
ZoomedViewFamily VirtualPinholeFamily(const RefractiveCamera& camera);

// The fits' "inside [0, w - 1] x [0, h - 1]" tolerates this much: products
// of K and its inverse round, and a pinhole in air, whose K' is its K, must
// get s = 1 exactly (the identity map) rather than s = 1 +- 1e-6.
inline constexpr double kVirtualPinholeFitSlackPx = 1e-9;

// A camera and the rotation of its view, for a fit that several cameras
// share (a rectified pair: one K, two rotations).
struct RotatedCamera {
  RefractiveCamera camera;
  Eigen::Matrix3d camera_from_view = Eigen::Matrix3d::Identity();
};

// The focal scale s for which the views family.At(s, camera_from_view)
// satisfy `fit` for every camera at once (kVirtualPinhole: 1).
//   kNoBorder: every output border pixel p' of every view samples its raw
//     image inside [0, w - 1] x [0, h - 1], through H = K_n R K(s)^-1 as
//     the maps do; holds for s >= s* when each camera's raw image, seen
//     from its view, contains every segment from its view of `a` to its
//     own border (true of the lenses here, since a is near the principal
//     point), and the border of the output bounds its interior. The
//     smallest such s, to a relative 1e-6 (the returned s holds).
//   kFullFieldOfView: every raw border pixel (centers on the four edges)
//     that the lens can unproject has its ray R^T b (view frame) land in
//     [0, w' - 1] x [0, h' - 1] at K(s) R^T b; holds exactly for s <= s*
//     (rays move linearly away from a, which lies inside). The largest such
//     s, to a relative 1e-6 (the returned s holds).
// "Inside" tolerates kVirtualPinholeFitSlackPx.
// Errors: no camera; family.Check(); a camera_from_view that is not a
// rotation; for both fits, an anchor pixel outside the output image ("the
// principal point lies outside the image") and no s in [1e-3, 1e3] that
// works; for kFullFieldOfView a border ray 90 degrees or more off a view's
// axis.
StatusOr<double> FitFocalScale(const std::vector<RotatedCamera>& cameras,
                               const ZoomedViewFamily& family,
                               VirtualPinholeFit fit);

// Where a camera's raw image lies in its view's normalized plane, from the
// view-frame directions (x / z, y / z) of the rays of its raw border pixels
// (centers on the four edges; those the lens cannot unproject skipped):
struct ViewFieldOfView {
  // The box between the innermost point of each edge (largest x on the
  // left edge, smallest on the right, largest y on the top, smallest on
  // the bottom): about the largest axis-aligned box inside the image.
  // Empty (min > max) when the edges cross.
  Eigen::AlignedBox2d inner;
  // The bounding box of all border rays; empty when a border ray is 90
  // degrees or more off the view axis (no pinhole view holds it).
  Eigen::AlignedBox2d outer;
};
ViewFieldOfView FieldOfViewInView(const RotatedCamera& camera);

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
// The same into `output`, whose buffer is reused when it already has the
// view's size and the raw image's type: a sequence of images then costs no
// allocation (a fresh 720x540 image is ~100 page faults, 0.1-0.3 ms).
void RemapToVirtualPinhole(const cv::Mat& raw, const RemapMaps& maps,
                           cv::Mat* output);

}  // namespace rcm

#endif  // RCM_CAMERA_VIRTUAL_PINHOLE_REMAP_H_
