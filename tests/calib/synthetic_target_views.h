// Synthetic stereo views of a calibration target for the calibration
// tests: board poses that cover the image of cam0 at several tilts and
// depths, and the exact (or noisy) corner pixels in both cameras, in air or
// under water through exact flat ports.
#ifndef RCM_TESTS_CALIB_SYNTHETIC_TARGET_VIEWS_H_
#define RCM_TESTS_CALIB_SYNTHETIC_TARGET_VIEWS_H_

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_observation.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/refractive_model.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::calib::test {

// `count` board poses (cam0_from_target), deterministic in `seed`: the
// board's center is placed on the rays of a 3x3 grid of image points of
// the left camera (cycling, jittered) at depths [min_depth, max_depth],
// tilted by up to `max_tilt_deg` about x and y and rolled by up to 30
// degrees. The rays are those in a medium of index `n` behind a thin port
// ((xb, yb, m(n, rb)), refractive_model.h; n = 1: in air).
inline std::vector<Rigid3d> BoardPoses(
    const Camera& camera, const CalibrationTarget& target, int count,
    unsigned seed, double min_depth = 0.45, double max_depth = 0.9,
    double max_tilt_deg = 35.0, double n = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) center += p;
  center /= static_cast<double>(points.size());
  std::vector<Rigid3d> poses;
  for (int i = 0; i < count; ++i) {
    const int cell = i % 9;
    const double fx = 0.5 + 0.3 * (cell % 3 - 1) + 0.04 * unit(rng);
    const double fy = 0.5 + 0.3 * (cell / 3 - 1) + 0.04 * unit(rng);
    const Eigen::Vector2d pixel(fx * camera.width(), fy * camera.height());
    const Eigen::Vector2d undistorted =
        camera.NormalizedFromImage(pixel).value();
    const Eigen::Vector2d normalized =
        undistorted /
        FlatPortRefraction::RadialFactor(n, undistorted.squaredNorm());
    const double depth =
        min_depth + (max_depth - min_depth) * 0.5 * (1.0 + unit(rng));
    const double deg = M_PI / 180.0;
    Rigid3d pose;
    // Draws in statements of their own, last factor first (gcc's order):
    // the operands' evaluation order is unspecified.
    const double roll = max_tilt_deg * deg * unit(rng);
    const double pitch = max_tilt_deg * deg * unit(rng);
    const double yaw = 30.0 * deg * unit(rng);
    pose.rotation = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
    pose.translation =
        depth * Eigen::Vector3d(normalized.x(), normalized.y(), 1.0) -
        pose.rotation * center;
    poses.push_back(pose);
  }
  return poses;
}

// Where a camera images a point given in its frame; nullopt when it does
// not.
using PointProjection =
    std::function<std::optional<Eigen::Vector2d>(const Eigen::Vector3d&)>;

// The corners of the target that `project` images inside `camera`'s image
// at camera_from_target (points at least 5 cm in front of the camera),
// with Gaussian pixel noise of `noise_px` per axis. nullopt when fewer
// than `min_corners` are in the image.
inline std::optional<TargetObservation> ObserveTargetWith(
    const Camera& camera, const PointProjection& project,
    const Rigid3d& camera_from_target,
    const std::vector<Eigen::Vector3d>& points, double noise_px,
    std::mt19937* rng, int min_corners = 6) {
  std::normal_distribution<double> noise(0.0, 1.0);
  TargetObservation observation;
  observation.detector = "synthetic";
  for (int id = 0; id < static_cast<int>(points.size()); ++id) {
    const Eigen::Vector3d p = camera_from_target * points[id];
    if (!(p.z() > 0.05)) continue;
    const std::optional<Eigen::Vector2d> pixel = project(p);
    if (!pixel || !camera.InImage(*pixel)) continue;
    Eigen::Vector2d measured = *pixel;
    if (noise_px > 0.0) {
      const double noise_y = noise(*rng);  // before x, as above
      measured += noise_px * Eigen::Vector2d(noise(*rng), noise_y);
    }
    observation.point_ids.push_back(id);
    observation.pixels.push_back(measured);
  }
  if (observation.size() < min_corners) return std::nullopt;
  return observation;
}

// The pinhole camera in air: the lens of the point's normalized point.
inline PointProjection InAir(const Camera& camera) {
  return [&camera](const Eigen::Vector3d& p) {
    return camera.ProjectNormalized(p.head<2>() / p.z());
  };
}

// Stereo views at the given target poses of two cameras that image points
// by `left` and `right` (each in its own frame), cam1 at right_from_left.
// The corners are those of the board bowed by `board_warp` [m]
// (board_warp.h; 0: flat).
inline std::vector<StereoView> ObserveStereoWith(
    const Camera& left_camera, const PointProjection& left,
    const Camera& right_camera, const PointProjection& right,
    const Rigid3d& right_from_left, const CalibrationTarget& target,
    const std::vector<Rigid3d>& cam0_from_target, double noise_px,
    unsigned seed,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero()) {
  std::mt19937 rng(seed);
  const std::vector<Eigen::Vector3d> points =
      WarpedTargetPoints(target, board_warp);
  std::vector<StereoView> views;
  for (size_t v = 0; v < cam0_from_target.size(); ++v) {
    StereoView view;
    view.left_name = "left" + std::to_string(v) + ".png";
    view.right_name = "right" + std::to_string(v) + ".png";
    view.left = ObserveTargetWith(left_camera, left, cam0_from_target[v],
                                  points, noise_px, &rng);
    view.right = ObserveTargetWith(right_camera, right,
                                   right_from_left * cam0_from_target[v],
                                   points, noise_px, &rng);
    views.push_back(std::move(view));
  }
  return views;
}

// Stereo views of `rig` (left = cam0) in air at the given target poses.
inline std::vector<StereoView> ObserveStereo(
    const StereoRig& rig, const CalibrationTarget& target,
    const std::vector<Rigid3d>& cam0_from_target, double noise_px,
    unsigned seed,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero()) {
  return ObserveStereoWith(rig.left(), InAir(rig.left()), rig.right(),
                           InAir(rig.right()), rig.right_from_left(), target,
                           cam0_from_target, noise_px, seed, board_warp);
}

// Stereo views of `rig` under water, in a medium of index n, imaged through
// the exact flat ports of the rig (FlatPortCamera::ImageFromPoint; thin
// ports when the rig has none).
inline std::vector<StereoView> ObserveStereoUnderwater(
    const StereoRig& rig, double n, const CalibrationTarget& target,
    const std::vector<Rigid3d>& cam0_from_target, double noise_px,
    unsigned seed,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero()) {
  const StereoRig::Ports ports =
      rig.ports() ? *rig.ports() : StereoRig::Ports{FlatPort(), FlatPort()};
  const FlatPortCamera left =
      FlatPortCamera::Create(rig.left(), ports.left, n).value();
  const FlatPortCamera right =
      FlatPortCamera::Create(rig.right(), ports.right, n).value();
  const auto through = [](const FlatPortCamera& camera) -> PointProjection {
    return [&camera](const Eigen::Vector3d& p) {
      return camera.ImageFromPoint(p);
    };
  };
  return ObserveStereoWith(rig.left(), through(left), rig.right(),
                           through(right), rig.right_from_left(), target,
                           cam0_from_target, noise_px, seed, board_warp);
}

// Moves each corner of `views` with probability `fraction` by 8-20 px in a
// random direction (a detector confusing corners), deterministic in
// `seed`; returns how many were moved.
inline int AddGrossOutliers(double fraction, unsigned seed,
                            std::vector<StereoView>* views) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int num_moved = 0;
  for (StereoView& view : *views) {
    for (std::optional<TargetObservation>* side : {&view.left, &view.right}) {
      if (!side->has_value()) continue;
      for (Eigen::Vector2d& pixel : (*side)->pixels) {
        if (unit(rng) < fraction) {
          const double angle = 2.0 * M_PI * unit(rng);
          const double length = 8.0 + 12.0 * unit(rng);
          pixel += length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          ++num_moved;
        }
      }
    }
  }
  return num_moved;
}

// A narrow radtan pair: 640x480, f = 520 px (63 degrees across in air,
// 47 under water), a 65 mm baseline, cam1 turned 0.3 degrees.
inline StereoRig NarrowRadTanRig() {
  const Camera left =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {520.0, 521.5, 318.0, 243.0}, {-0.12, 0.05, 2e-4, -1e-4})
          .value();
  const Camera right =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {523.0, 522.0, 324.5, 237.0}, {-0.11, 0.04, -1e-4, 3e-4})
          .value();
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(0.3 * (M_PI / 180.0),
                        Eigen::Vector3d(-0.2, 1.0, 0.3).normalized())
          .toRotationMatrix();
  right_from_left.translation = Eigen::Vector3d(-0.065, 0.0004, 0.0008);
  return StereoRig::Create(left, right, right_from_left).value();
}

}  // namespace rcm::calib::test

#endif  // RCM_TESTS_CALIB_SYNTHETIC_TARGET_VIEWS_H_
