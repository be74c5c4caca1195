#include "rcm/frontend/locus_band.h"

#include <algorithm>
#include <cmath>

#include "rcm/camera/refractive_camera.h"
#include "rcm/camera/refractive_model.h"
#include "rcm/util/number_format.h"

namespace rcm {

Status RefractiveIndexInterval::Check() const {
  if (!std::isfinite(min) || !std::isfinite(max) || min > max ||
      min < RefractiveCamera::kMinIndex || max > RefractiveCamera::kMaxIndex) {
    return Status::Error("refractive index interval [" + FormatFixed(min, 4) +
                         ", " + FormatFixed(max, 4) +
                         "] must be ordered and lie within [1, 2]");
  }
  return Status::Ok();
}

RefractiveIndexInterval RefractiveIndexInterval::Around(double n,
                                                        double sigma_n,
                                                        double sigmas,
                                                        double min_half_width) {
  const double half = std::max(sigmas * sigma_n, min_half_width);
  RefractiveIndexInterval interval;
  interval.min = std::clamp(n - half, RefractiveCamera::kMinIndex,
                            RefractiveCamera::kMaxIndex);
  interval.max = std::clamp(n + half, RefractiveCamera::kMinIndex,
                            RefractiveCamera::kMaxIndex);
  return interval;
}

Status LocusBandOptions::Check() const {
  if (!(tolerance_px > 0.0) || !std::isfinite(tolerance_px)) {
    return Status::Error("band tolerance must be a positive number of pixels");
  }
  if (!(min_distance > 0.0) || !std::isfinite(min_distance)) {
    return Status::Error("nearest scene distance must be positive");
  }
  return Status::Ok();
}

StatusOr<LocusBand> LocusBand::Create(const StereoRig& rig,
                                      const RefractiveIndexInterval& interval,
                                      const LocusBandOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  RCM_RETURN_IF_ERROR(interval.Check());
  const double f_min = std::min(
      {rig.left().fx(), rig.left().fy(), rig.right().fx(), rig.right().fy()});
  return LocusBand(rig, RectifyStereoRig(rig), interval,
                   options.tolerance_px / f_min,
                   rig.Baseline() / options.min_distance);
}

LocusKey LocusBand::Key(const Camera& camera,
                        const Eigen::Matrix3d& camera_from_rect,
                        const Eigen::Vector2d& pixel) const {
  LocusKey key;
  const std::optional<Eigen::Vector2d> normalized =
      camera.NormalizedFromImage(pixel);
  if (!normalized) return key;
  const double ends[2] = {interval_.min, interval_.max};
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector3d bearing;
    FlatPortRefraction::BearingInWater(ends[k], normalized->x(),
                                       normalized->y(), bearing.data());
    const Eigen::Vector3d q = camera_from_rect.transpose() * bearing;
    const double radius = std::hypot(q.y(), q.z());
    if (!(radius > 0.0)) return key;  // along the baseline: no plane
    key.phi[k] = std::atan2(q.y(), q.z());
    key.u[k] = q.x() / radius;
  }
  key.valid = true;
  return key;
}

LocusKey LocusBand::LeftKey(const Eigen::Vector2d& pixel) const {
  return Key(rig_.left(), rectification_.left_camera_from_rect, pixel);
}

LocusKey LocusBand::RightKey(const Eigen::Vector2d& pixel) const {
  return Key(rig_.right(), rectification_.right_camera_from_rect, pixel);
}

std::vector<LocusKey> LocusBand::LeftKeys(
    const std::vector<cv::KeyPoint>& keypoints) const {
  std::vector<LocusKey> keys;
  keys.reserve(keypoints.size());
  for (const cv::KeyPoint& keypoint : keypoints) {
    keys.push_back(LeftKey(Eigen::Vector2d(keypoint.pt.x, keypoint.pt.y)));
  }
  return keys;
}

std::vector<LocusKey> LocusBand::RightKeys(
    const std::vector<cv::KeyPoint>& keypoints) const {
  std::vector<LocusKey> keys;
  keys.reserve(keypoints.size());
  for (const cv::KeyPoint& keypoint : keypoints) {
    keys.push_back(RightKey(Eigen::Vector2d(keypoint.pt.x, keypoint.pt.y)));
  }
  return keys;
}

}  // namespace rcm
