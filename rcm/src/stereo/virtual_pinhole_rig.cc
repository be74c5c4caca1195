#include "rcm/stereo/virtual_pinhole_rig.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "rcm/stereo/stereo_rectification.h"

namespace rcm {
namespace {

// The principal point coordinate c of an axis of `size` pixels moved to an
// axis of `new_size` at the same fraction of the image (pixel centers at
// integers, the image spanning [-1/2, size - 1/2]); exactly c when the size
// is unchanged.
double ScaledPrincipalPoint(double c, int size, int new_size) {
  if (size == new_size) return c;
  return (c + 0.5) * new_size / size - 0.5;
}

cv::Size OutputSize(const VirtualPinholeRigOptions& options,
                    const Camera& camera) {
  return options.output_size.value_or(
      cv::Size(camera.width(), camera.height()));
}

// K_n of `camera` zoomed about its principal point, at `size`.
ZoomedViewFamily OwnFamily(const RefractiveCamera& camera, cv::Size size) {
  ZoomedViewFamily family = VirtualPinholeFamily(camera);
  const Camera& lens = camera.camera();
  family.anchor_pixel = Eigen::Vector2d(
      ScaledPrincipalPoint(lens.cx(), lens.width(), size.width),
      ScaledPrincipalPoint(lens.cy(), lens.height(), size.height));
  family.width = size.width;
  family.height = size.height;
  return family;
}

StatusOr<double> ScaleOf(const VirtualPinholeRigOptions& options,
                         const std::vector<RotatedCamera>& cameras,
                         const ZoomedViewFamily& family) {
  if (options.focal_px) {
    RCM_RETURN_IF_ERROR(family.Check());
    return *options.focal_px / family.base_focal.x();
  }
  return FitFocalScale(cameras, family, options.fit);
}

// The one family of a rectified pair (see the header).
StatusOr<ZoomedViewFamily> RectifiedFamily(
    const VirtualPinholeRigOptions& options, const RotatedCamera& left,
    const RotatedCamera& right) {
  const Camera& lens = left.camera.camera();
  ZoomedViewFamily family = OwnFamily(left.camera, OutputSize(options, lens));
  const Eigen::Vector2d center(0.5 * (family.width - 1),
                               0.5 * (family.height - 1));
  switch (options.fit) {
    case VirtualPinholeFit::kVirtualPinhole:
      break;  // the left principal point sees the rectified axis
    case VirtualPinholeFit::kNoBorder: {
      const Eigen::AlignedBox2d both =
          FieldOfViewInView(left).inner.intersection(
              FieldOfViewInView(right).inner);
      if (both.isEmpty()) {
        return Status::Error(
            "no rectified view without black borders: the two cameras' "
            "images do not overlap once rectified");
      }
      family.anchor_pixel = center;
      family.anchor_direction = both.center();
      break;
    }
    case VirtualPinholeFit::kFullFieldOfView: {
      const Eigen::AlignedBox2d left_outer = FieldOfViewInView(left).outer;
      const Eigen::AlignedBox2d right_outer = FieldOfViewInView(right).outer;
      if (left_outer.isEmpty() || right_outer.isEmpty()) {
        return Status::Error(
            "no rectified view with the whole field of view: a raw border "
            "pixel sees a ray 90 degrees or more off the rectified axis");
      }
      family.anchor_pixel = center;
      family.anchor_direction = left_outer.merged(right_outer).center();
      break;
    }
  }
  return family;
}

StatusOr<VirtualPinholeCamera> MakeCamera(
    const RefractiveCamera& camera, const VirtualPinholeView& view,
    const VirtualPinholeRigOptions& options) {
  StatusOr<RemapMaps> maps = BuildVirtualPinholeMaps(
      camera, view, options.num_threads, options.fixed_point_maps);
  if (!maps.ok()) return maps.status();
  StatusOr<Camera> pinhole = Camera::Create(
      LensModelId::kPinhole, view.width, view.height,
      {view.k(0, 0), view.k(1, 1), view.k(0, 2), view.k(1, 2)}, {});
  if (!pinhole.ok()) return pinhole.status();
  return VirtualPinholeCamera{camera, view, std::move(*maps), *pinhole};
}

}  // namespace

Status VirtualPinholeRigOptions::Check() const {
  if (output_size && (output_size->width <= 0 || output_size->height <= 0)) {
    std::ostringstream message;
    message << "output size " << output_size->width << " x "
            << output_size->height << " is not positive";
    return Status::Error(message.str());
  }
  if (focal_px && (!std::isfinite(*focal_px) || !(*focal_px > 0.0))) {
    std::ostringstream message;
    message << "output focal length " << *focal_px
            << " px must be positive and finite";
    return Status::Error(message.str());
  }
  if (num_threads < 1) {
    return Status::Error("num_threads = " + std::to_string(num_threads) +
                         " must be at least 1");
  }
  if (!std::isfinite(reference_depth) || !(reference_depth > 0.0)) {
    std::ostringstream message;
    message << "reference depth " << reference_depth
            << " m must be positive and finite";
    return Status::Error(message.str());
  }
  return Status::Ok();
}

StatusOr<RefractiveCamera> RefractiveCameraOfRig(
    const StereoRig& rig, bool left, double n, double reference_depth,
    const std::optional<std::array<DomePort, 2>>& domes) {
  const Camera& camera = left ? rig.left() : rig.right();
  if (domes.has_value()) {
    if (rig.ports().has_value()) {
      return Status::Error(
          "a rig with flat ports cannot also look through domes");
    }
    StatusOr<RefractiveCamera> result = RefractiveCamera::CreateWithDome(
        camera, n, (*domes)[left ? 0 : 1], reference_depth);
    if (!result.ok()) {
      return result.status().WithContext(left ? "left camera" : "right camera");
    }
    return result;
  }
  if (!rig.HasThickPort()) return RefractiveCamera::Create(camera, n);
  const FlatPort& port = left ? rig.ports()->left : rig.ports()->right;
  StatusOr<RefractiveCamera> result =
      RefractiveCamera::CreateWithPort(camera, n, port, reference_depth);
  if (!result.ok()) {
    return result.status().WithContext(left ? "left camera" : "right camera");
  }
  return result;
}

double VirtualPinholeCamera::FocalScale() const {
  return VirtualPinholeFocalScale(camera, view);
}

double VirtualPinholeCamera::BlackFraction() const {
  return static_cast<double>(maps.num_invalid) /
         (static_cast<double>(view.width) * view.height);
}

cv::Mat VirtualPinholeCamera::Correct(const cv::Mat& raw) const {
  return RemapToVirtualPinhole(raw, maps);
}

void VirtualPinholeCamera::Correct(const cv::Mat& raw,
                                   cv::Mat* corrected) const {
  RemapToVirtualPinhole(raw, maps, corrected);
}

std::optional<Eigen::Vector2d> VirtualPinholeCamera::CorrectedFromRaw(
    const Eigen::Vector2d& raw_pixel) const {
  const std::optional<Eigen::Vector3d> bearing =
      camera.BearingInWaterFromImage(raw_pixel);
  if (!bearing) return std::nullopt;
  const Eigen::Vector3d in_view = view.camera_from_view.transpose() * *bearing;
  if (!(in_view.z() > 0.0)) return std::nullopt;
  return (view.k * in_view).hnormalized();
}

std::optional<Eigen::Vector2d> VirtualPinholeCamera::RawFromCorrected(
    const Eigen::Vector2d& corrected_pixel) const {
  const Eigen::Vector3d ray =
      view.camera_from_view *
      (view.k.inverse() * corrected_pixel.homogeneous());
  if (camera.port().has_value() || camera.dome().has_value()) {
    // A thick port or a dome is central only at its reference depth: the
    // point there (any point of the ray for a thin port).
    if (!(ray.z() > 0.0)) return std::nullopt;
    return camera.ImageFromPointInWater(ray *
                                        (camera.reference_depth() / ray.z()));
  }
  return camera.ImageFromPointInWater(ray);
}

StatusOr<VirtualPinholeRig> VirtualPinholeRig::Create(
    const StereoRig& rig, double n, const VirtualPinholeRigOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  const auto start = std::chrono::steady_clock::now();
  const StatusOr<RefractiveCamera> left = RefractiveCameraOfRig(
      rig, /*left=*/true, n, options.reference_depth, options.domes);
  if (!left.ok()) return left.status();
  const StatusOr<RefractiveCamera> right = RefractiveCameraOfRig(
      rig, /*left=*/false, n, options.reference_depth, options.domes);
  if (!right.ok()) return right.status();

  VirtualPinholeView left_view;
  VirtualPinholeView right_view;
  Rigid3d corrected_right_from_left = rig.right_from_left();
  if (!options.rectify) {
    // Each camera zooms its own K_n.
    for (const auto& [camera, view] :
         {std::pair{&*left, &left_view}, std::pair{&*right, &right_view}}) {
      const ZoomedViewFamily family =
          OwnFamily(*camera, OutputSize(options, camera->camera()));
      const StatusOr<double> scale =
          ScaleOf(options, {RotatedCamera{*camera}}, family);
      if (!scale.ok()) return scale.status();
      *view = family.At(*scale);
    }
  } else {
    const StereoRectification rectification = RectifyStereoRig(rig);
    const RotatedCamera left_rotated{*left,
                                     rectification.left_camera_from_rect};
    const RotatedCamera right_rotated{*right,
                                      rectification.right_camera_from_rect};
    const StatusOr<ZoomedViewFamily> family =
        RectifiedFamily(options, left_rotated, right_rotated);
    if (!family.ok()) return family.status();
    const StatusOr<double> scale =
        ScaleOf(options, {left_rotated, right_rotated}, *family);
    if (!scale.ok()) return scale.status();
    left_view = family->At(*scale, left_rotated.camera_from_view);
    right_view = family->At(*scale, right_rotated.camera_from_view);
    // R_r^T R_rl R_l = I and R_r^T t = (-b, 0, 0), exactly by construction.
    corrected_right_from_left.rotation = Eigen::Matrix3d::Identity();
    corrected_right_from_left.translation =
        Eigen::Vector3d(-rig.Baseline(), 0.0, 0.0);
  }

  StatusOr<VirtualPinholeCamera> left_camera =
      MakeCamera(*left, left_view, options);
  if (!left_camera.ok()) return left_camera.status();
  StatusOr<VirtualPinholeCamera> right_camera =
      MakeCamera(*right, right_view, options);
  if (!right_camera.ok()) return right_camera.status();
  const StatusOr<StereoRig> corrected = StereoRig::Create(
      left_camera->pinhole, right_camera->pinhole, corrected_right_from_left);
  if (!corrected.ok()) return corrected.status();
  VirtualPinholeRig result(rig, n, options, std::move(*left_camera),
                           std::move(*right_camera), *corrected);
  result.build_ms_ = std::chrono::duration<double, std::milli>(
                         std::chrono::steady_clock::now() - start)
                         .count();
  return result;
}

}  // namespace rcm
