// VirtualPinholeRig: a stereo rig calibrated in air, behind flat ports in a
// medium of index n, turned into the rig of two ideal pinhole cameras whose
// images are the raw images remapped (virtual_pinhole_remap.h). Stereo and
// VIO pipelines built for pinhole pairs then run on the corrected images
// and the corrected calibration unchanged.
//
// The math (paper Sec. III-B). A raw pixel x of a camera with in-air lens
// model pi (intrinsics fx, fy, cx, cy and distortion) is undistorted to
// (xb, yb) = pi^-1(x); behind a thin flat port its ray in the medium is
//
//   d ~ (xb, yb, m(n, rb)),   m = sqrt(n^2 rb^2 + n^2 - rb^2),
//
// and all rays pass through the camera center: in the medium the camera
// is central, an ideal pinhole whose natural intrinsics are (eq. 9)
//
//   K_n = [n fx, 0, cx; 0, n fy, cy; 0, 0, 1],   x_n ~ K_n d.
//
// Each corrected camera is a view V = (K', w' x h', R) of that pinhole:
// K' = [fx', 0, cx'; 0, fy', cy'; 0, 0, 1], R = camera_from_view. It sees
// the ray d at p' ~ K' R^T d, so the raw pixel behind p' is
//
//   raw(p') = pi(refract^-1(K_n^-1 h(K_n R K'^-1 p')))
//
// which the remap maps store once per n for every output pixel; every
// image then costs one cv::remap.
//
// Choice of K' (VirtualPinholeFit; each a zoom K(s) about an anchor pixel,
// ZoomedViewFamily):
//   kVirtualPinhole   K' = K_n (s = 1);
//   kNoBorder         the widest view whose every pixel samples inside the
//                     raw image (no black border);
//   kFullFieldOfView  the narrowest view that still holds the ray of every
//                     raw border pixel (nothing of the raw image lost);
//   focal_px          fx' = focal_px, fy' = focal_px fy / fx (overrides
//                     the fit's scale, not its anchor).
// An output size other than the camera's keeps the principal point at the
// same fraction of the image: c' = (c + 1/2) w' / w - 1/2 (per axis).
//
// Extrinsics. With p = right_from_left = (R_rl, t) of the raw rig and the
// view rotations R_l, R_r, a point X_vl in the left view frame is
// R_l X_vl in the left camera, R_rl R_l X_vl + t in the right one, and
//
//   right_view_from_left_view = (R_r^T R_rl R_l, R_r^T t).
//
// Unrectified (R_l = R_r = I) this is p itself, and each camera keeps its
// own K_n family (its own n fx, n fy, cx, cy).
//
// Rectified (options.rectify): R_l, R_r from RectifyStereoRig
// (stereo_rectification.h), R_r = R_rl R_l, so the rotation above is I and
// the translation R_l^T R_rl^T t = -R_l^T c = (-b, 0, 0) with c the right
// center in the left frame and b = |c|: the ideal rectified pair, set
// exactly. Both views share one K' (rows agree only if fy' and cy' do):
//   focal     f0 = (n fx, n fy) of the left camera, times the fit's s;
//   anchor    kVirtualPinhole: the left camera's (cx, cy) sees the
//             rectified axis (d = 0; the demo's view);
//             kNoBorder: the output center sees the center of the
//             intersection of both cameras' inner boxes (FieldOfViewInView),
//             the part of the view both raw images cover;
//             kFullFieldOfView: the output center sees the center of the
//             union of both outer boxes;
//   scale     FitFocalScale over both rotated cameras at once, so the fit
//             holds for both.
// ROS camera_info of rectified images: R = I (the images are rectified
// already), P_left = [K' | 0], P_right = [K' | (-fx' b, 0, 0)^T].
#ifndef RCM_STEREO_VIRTUAL_PINHOLE_RIG_H_
#define RCM_STEREO_VIRTUAL_PINHOLE_RIG_H_

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/camera/virtual_pinhole_remap.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct VirtualPinholeRigOptions {
  // How the output focal length is chosen (and, rectified, the principal
  // point): see the header comment.
  VirtualPinholeFit fit = VirtualPinholeFit::kNoBorder;
  // Output image size (width, height), both > 0; unset: each camera's own
  // (rectified: the left camera's, for both).
  std::optional<cv::Size> output_size;
  // Output fx' in pixels, > 0 and finite; unset: the fit's.
  std::optional<double> focal_px;
  // Rotate both views to the rectified pair and give them one K'.
  bool rectify = false;
  // Threads building each camera's maps, >= 1.
  int num_threads = 2;
  // Also build the fixed-point maps (cv::remap's fast path).
  bool fixed_point_maps = true;
  // A rig with a thick port (StereoRig::HasThickPort): the depth, in
  // meters, at which the corrected images are exact pinhole images
  // (RefractiveCamera::CreateWithPort); points nearer or farther are off
  // by the port's parallax. Finite and > 0; unused for thin ports.
  double reference_depth = 2.0;
  // Dome ports in front of the cameras (a camchain's dome blocks; the rig
  // then has no flat ports): each camera is its dome's camera made central
  // at reference_depth (RefractiveCamera::CreateWithDome), whose virtual
  // pinhole is the air camera's K. Both or neither.
  std::optional<std::array<DomePort, 2>> domes;

  Status Check() const;
};

// The camera of one side of `rig` in the water at index n: its dome's
// camera at the reference depth when `domes` are given
// (RefractiveCamera::CreateWithDome), its ports' thick-port camera there
// when the rig has a thick port (RefractiveCamera::CreateWithPort), the
// paper's camera otherwise.
StatusOr<RefractiveCamera> RefractiveCameraOfRig(
    const StereoRig& rig, bool left, double n, double reference_depth,
    const std::optional<std::array<DomePort, 2>>& domes = std::nullopt);

// One corrected camera: its camera in the medium, its view, the maps from
// its raw images, and the pinhole camera its corrected images are.
struct VirtualPinholeCamera {
  RefractiveCamera camera;
  VirtualPinholeView view;
  RemapMaps maps;
  // LensModelId::kPinhole with the view's K' and size.
  Camera pinhole;

  // fx' / (n fx): the output focal over the camera's own K_n.
  double FocalScale() const;
  // Fraction of the output pixels that see nothing of the raw image.
  double BlackFraction() const;
  // The corrected image of a raw image of the camera's size (CHECKed).
  cv::Mat Correct(const cv::Mat& raw) const;
  // The same into `corrected`, reusing its buffer (see
  // RemapToVirtualPinhole): for image sequences.
  void Correct(const cv::Mat& raw, cv::Mat* corrected) const;
  // Corrected pixel of a raw pixel (exact, not through the maps); nullopt
  // where the lens cannot undistort it or the ray is behind the view. May
  // lie outside the output image.
  std::optional<Eigen::Vector2d> CorrectedFromRaw(
      const Eigen::Vector2d& raw_pixel) const;
  // Raw pixel of a corrected pixel (exact); nullopt where the camera does
  // not see the ray. May lie outside the raw image.
  std::optional<Eigen::Vector2d> RawFromCorrected(
      const Eigen::Vector2d& corrected_pixel) const;
};

class VirtualPinholeRig {
 public:
  // Builds both views, their maps (once: reuse the rig for every image of
  // this n) and the corrected rig. Errors: options.Check(), n outside
  // [1, 2], and the fit's (FitFocalScale).
  static StatusOr<VirtualPinholeRig> Create(
      const StereoRig& rig, double n,
      const VirtualPinholeRigOptions& options = VirtualPinholeRigOptions());

  const StereoRig& raw_rig() const { return raw_rig_; }
  double n() const { return n_; }
  const VirtualPinholeRigOptions& options() const { return options_; }
  const VirtualPinholeCamera& left() const { return left_; }
  const VirtualPinholeCamera& right() const { return right_; }
  // The two pinhole cameras with right_view_from_left_view.
  const StereoRig& corrected_rig() const { return corrected_rig_; }
  // Milliseconds spent choosing the views and building the maps.
  double build_ms() const { return build_ms_; }

 private:
  VirtualPinholeRig(const StereoRig& raw_rig, double n,
                    const VirtualPinholeRigOptions& options,
                    VirtualPinholeCamera left, VirtualPinholeCamera right,
                    const StereoRig& corrected_rig)
      : raw_rig_(raw_rig),
        n_(n),
        options_(options),
        left_(std::move(left)),
        right_(std::move(right)),
        corrected_rig_(corrected_rig) {}

  StereoRig raw_rig_;
  double n_;
  VirtualPinholeRigOptions options_;
  VirtualPinholeCamera left_;
  VirtualPinholeCamera right_;
  StereoRig corrected_rig_;
  double build_ms_ = 0.0;
};

}  // namespace rcm

#endif  // RCM_STEREO_VIRTUAL_PINHOLE_RIG_H_
